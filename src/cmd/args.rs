//! Argument types and parsers shared by the subcommands, each written once: flow presets,
//! floor models, interpolation variants, sizes, points, pose lists, the lighting and the
//! camera path. Parsers return `String` errors that name the flag and what it expects, as
//! clap prints them.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use frf_core::env::{EnvMap, EnvSource};
use frf_flow::Preset;
use frf_reflectance::project::FloorModel;
use frf_render::morph::Variant;
use frf_render::path::{CameraPath, Orbit, Trajectory};
use frf_render::resident::Lighting;
use glam::Vec3;
use serde::Serialize;

use crate::CliResult;

/// Largest frame side the command line accepts, pixels (8K).
pub const MAX_SIDE_PX: u32 = 8192;

/// A preset of the optical-flow estimator.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FlowPresetArg {
    /// Fastest: luminance, solved up to half resolution.
    Fast,
    /// Colour, full resolution, median filtering.
    Balanced,
    /// Classic+NL-style: texture decomposition, GNC, weighted median.
    Accurate,
}

impl From<FlowPresetArg> for Preset {
    fn from(p: FlowPresetArg) -> Self {
        match p {
            FlowPresetArg::Fast => Preset::Fast,
            FlowPresetArg::Balanced => Preset::Balanced,
            FlowPresetArg::Accurate => Preset::Accurate,
        }
    }
}

/// What lights the subject from below (the floor conditions of the basis).
#[derive(Clone, Copy, Debug, ValueEnum, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum FloorArg {
    /// The environment's own lower hemisphere.
    Env,
    /// A grey Lambertian ground (albedo 0.3) lit by the upper hemisphere.
    Ground,
}

/// Albedo of the `ground` floor model: a mid-grey ground.
const GROUND_ALBEDO: f32 = 0.3;

impl From<FloorArg> for FloorModel {
    fn from(f: FloorArg) -> Self {
        match f {
            FloorArg::Env => FloorModel::Environment,
            FloorArg::Ground => FloorModel::LambertianGround {
                albedo: [GROUND_ALBEDO; 3],
            },
        }
    }
}

/// The interpolation between views (the ablations of `frf eval`).
#[derive(Clone, Copy, Debug, ValueEnum, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum VariantArg {
    /// Nearest view, unwarped.
    Nearest,
    /// Bilinear blend of the quad's views, unwarped.
    Linear,
    /// Two-way flowed morph along the nearer row.
    Twoway,
    /// Four-way flowed morph.
    Fourway,
}

impl From<VariantArg> for Variant {
    fn from(v: VariantArg) -> Self {
        match v {
            VariantArg::Nearest => Variant::Nearest,
            VariantArg::Linear => Variant::Linear,
            VariantArg::Twoway => Variant::TwoWay,
            VariantArg::Fourway => Variant::FourWay,
        }
    }
}

/// Comma-separated finite numbers, for the flag `what`.
fn numbers(s: &str, what: &str) -> Result<Vec<f32>, String> {
    s.split(',')
        .map(|t| match t.trim().parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("{what} `{s}`: `{t}` is not a finite number")),
        })
        .collect()
}

/// Parses `x,y,z` (metres).
pub fn parse_point(s: &str) -> Result<[f32; 3], String> {
    let v = numbers(s, "point")?;
    <[f32; 3]>::try_from(v).map_err(|_| format!("point `{s}`: expected x,y,z"))
}

/// Parses `WxH`, each side 1 to [`MAX_SIDE_PX`].
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size `{s}`: expected WxH"))?;
    let parse = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|e| format!("size `{s}`: {e}"))
    };
    let (w, h) = (parse(w)?, parse(h)?);
    if !(1..=MAX_SIDE_PX).contains(&w) || !(1..=MAX_SIDE_PX).contains(&h) {
        return Err(format!(
            "size `{s}`: each side must be 1 to {MAX_SIDE_PX} pixels"
        ));
    }
    Ok((w, h))
}

/// Parses `--poses`: a list `0,1` or a half-open range `0..4`.
pub fn parse_poses(s: &str) -> Result<Vec<u32>, String> {
    let bad = || format!("--poses {s:?}: expected e.g. 0,1 or 0..4");
    if let Some((a, b)) = s.split_once("..") {
        let (a, b): (u32, u32) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        );
        if a >= b {
            return Err(bad());
        }
        return Ok((a..b).collect());
    }
    s.split(',')
        .map(|p| p.trim().parse().map_err(|_| bad()))
        .collect()
}

/// Parses an environment: a `.hdr` / `.exr` file, `sky`, `uniform` or `none`.
pub fn parse_env(s: &str) -> Result<EnvSource, String> {
    s.parse()
}

/// How the field is lit: shared by `frf render` and `frf eval`.
#[derive(Args, Clone, Serialize, PartialEq)]
pub struct LightingArgs {
    /// HDR environment (latitude-longitude .hdr or .exr, subject frame), `sky` for the
    /// built-in sky, `uniform` for a white furnace, or `none` to show a field of
    /// photographs as captured (a file named like one of the words: `./sky`).
    #[arg(long, value_parser = parse_env)]
    pub env: EnvSource,
    /// Yaw of the environment about the vertical axis, degrees.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub yaw: f32,
    /// What lights the subject from below.
    #[arg(long, value_enum, default_value = "env")]
    pub floor: FloorArg,
}

impl LightingArgs {
    /// The lighting of a field of `conditions` basis conditions, and the environment
    /// for truth renders (`None` for `none`).
    pub fn lighting(&self, conditions: usize) -> CliResult<(Lighting, Option<EnvMap>)> {
        let Some(env) = self
            .env
            .load()
            .map_err(|e| format!("environment {}: {e}", self.env))?
        else {
            return Ok((Lighting::Unlit, None));
        };
        if conditions <= 1 {
            return Err(format!(
                "the field holds {conditions} lighting condition(s), photographs rather than \
                 a reflectance basis: it cannot be relit; use --env none"
            )
            .into());
        }
        let env = env.rotated(self.yaw.to_radians());
        Ok((
            Lighting::Environment {
                env: env.clone(),
                floor: self.floor.into(),
            },
            Some(env),
        ))
    }
}

/// `--orbit RADIUS,HEIGHT[,SWEEP_DEG]`.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct OrbitSpec {
    /// Metres from the axis.
    pub radius: f32,
    /// Camera height, metres.
    pub height: f32,
    /// Degrees swept.
    pub sweep_deg: f32,
}

/// Parses `RADIUS,HEIGHT[,SWEEP_DEG]`.
pub fn parse_orbit(s: &str) -> Result<OrbitSpec, String> {
    let v = numbers(s, "orbit")?;
    if !(2..=3).contains(&v.len()) {
        return Err(format!("orbit `{s}`: expected RADIUS,HEIGHT[,SWEEP_DEG]"));
    }
    Ok(OrbitSpec {
        radius: v[0],
        height: v[1],
        sweep_deg: v.get(2).copied().unwrap_or(360.0),
    })
}

/// Where the camera goes: shared by `frf render` and `frf eval`.
#[derive(Args, Clone, Serialize, PartialEq)]
pub struct CameraArgs {
    /// Keyframed camera path (TOML; see `frf_render::path`).
    #[arg(long, conflicts_with = "orbit", required_unless_present = "orbit")]
    pub camera: Option<PathBuf>,
    /// Orbit about the vertical axis through --look-at: `RADIUS,HEIGHT[,SWEEP_DEG]`,
    /// metres and degrees (default sweep 360, a loop).
    #[arg(long, value_parser = parse_orbit, allow_hyphen_values = true)]
    pub orbit: Option<OrbitSpec>,
    /// Orbit: the point looked at, `x,y,z` metres.
    #[arg(long, value_parser = parse_point, default_value = "0,0.9,0", allow_hyphen_values = true)]
    pub look_at: [f32; 3],
    /// Orbit: vertical field of view, degrees.
    #[arg(long, default_value_t = 35.0)]
    pub fov: f32,
    /// Orbit: azimuth of the first frame, degrees.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub start: f32,
}

impl CameraArgs {
    /// The trajectory.
    pub fn trajectory(&self) -> CliResult<Trajectory> {
        if let Some(path) = &self.camera {
            return Ok(Trajectory::Path(CameraPath::load(path)?));
        }
        let o = self
            .orbit
            .ok_or("give --camera PATH.toml or --orbit RADIUS,HEIGHT")?;
        let orbit = Orbit {
            radius: o.radius,
            height: o.height,
            sweep_deg: o.sweep_deg,
            start_deg: self.start,
            look_at: Vec3::from(self.look_at),
            fov_deg: self.fov,
        };
        orbit.validate()?;
        Ok(Trajectory::Orbit(orbit))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parsers_accept_what_they_document_and_name_what_they_refuse() {
        assert_eq!(parse_size("320x448"), Ok((320, 448)));
        assert!(parse_size("0x10").unwrap_err().contains("1 to 8192"));
        assert!(parse_size("320").unwrap_err().contains("WxH"));
        assert_eq!(parse_point("-2, 1.2,-2"), Ok([-2.0, 1.2, -2.0]));
        assert!(parse_point("1,2").unwrap_err().contains("x,y,z"));
        assert!(
            parse_point("1,nan,2")
                .unwrap_err()
                .contains("not a finite number")
        );
        assert_eq!(parse_poses("0..3"), Ok(vec![0, 1, 2]));
        assert_eq!(parse_poses("4,1"), Ok(vec![4, 1]));
        assert!(parse_poses("3..3").unwrap_err().contains("--poses"));
        let o = parse_orbit("3,1.2").unwrap();
        assert_eq!((o.radius, o.height, o.sweep_deg), (3.0, 1.2, 360.0));
        assert_eq!(parse_env("none"), Ok(EnvSource::None));
    }
}
