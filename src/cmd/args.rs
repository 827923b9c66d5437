//! Argument types and parsers shared by the subcommands, each written once: flow presets,
//! floor models, interpolation variants, sizes, points, pose lists, the lighting and the
//! camera path. Parsers return `String` errors that name the flag and what it expects, as
//! clap prints them.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use frf_core::env::{EnvMap, EnvSource};
use frf_core::sun::Sun;
use frf_flow::Preset;
use frf_ingest::shadows::{DEFAULT_LIGHT_SAMPLES, DEFAULT_MISSES, ShadowOptions};
use frf_reflectance::project::FloorModel;
use frf_render::morph::Variant;
use frf_render::resident::Lighting;
use frf_scene::path::{CameraPath, Orbit, Trajectory};
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
    /// Four-way morph, each view sampled where it shows the output's point (the
    /// renderer's).
    Fourway,
    /// The four-way morph of Einarsson et al. (each view displaced by the flows into it,
    /// read at the output pixel).
    FourwayE06,
    /// Ablation: E06's four-way morph weighing its sources by the consistency of their
    /// flows.
    FourwayOcclusion,
    /// Ablation: the four-way morph without the visual hull (rays beyond the grid's rows
    /// read along their direction).
    FourwayNoProxy,
}

impl From<VariantArg> for Variant {
    fn from(v: VariantArg) -> Self {
        match v {
            VariantArg::Nearest => Variant::Nearest,
            VariantArg::Linear => Variant::Linear,
            VariantArg::Twoway => Variant::TwoWay,
            VariantArg::Fourway => Variant::FourWay,
            VariantArg::FourwayE06 => Variant::FourWayE06,
            VariantArg::FourwayOcclusion => Variant::FourWayOcclusion,
            VariantArg::FourwayNoProxy => Variant::FourWayNoProxy,
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

/// Refuses an `--out` whose extension is not `wanted` (`why`: what the command writes
/// instead); a name without an extension (a device) is taken as it is.
pub fn expect_out_extension(
    out: &std::path::Path,
    wanted: &str,
    why: &str,
) -> Result<(), frf_core::BadArgument> {
    match out.extension().map(|e| e.to_string_lossy().to_lowercase()) {
        Some(ext) if ext != wanted => Err(frf_core::BadArgument::new(
            "--out",
            out.display(),
            format!("a .{wanted} file, not .{ext}: {why}"),
        )),
        _ => Ok(()),
    }
}

/// Parses `x,y,z` (metres).
pub fn parse_point(s: &str) -> Result<[f32; 3], String> {
    let v = numbers(s, "point")?;
    <[f32; 3]>::try_from(v).map_err(|_| format!("point `{s}`: expected x,y,z"))
}

/// Parses an angle in degrees: a finite number (a scene file refuses the same values).
pub fn parse_degrees(s: &str) -> Result<f32, String> {
    let v: f32 = s
        .trim()
        .parse()
        .map_err(|e| format!("`{s}`: {e} (degrees)"))?;
    if !v.is_finite() {
        return Err(format!("`{s}` degrees: an angle is a finite number"));
    }
    Ok(v)
}

/// Parses a turn (a light's yaw, a sun's azimuth) in degrees: read in double precision
/// and kept as the same turn within ±180° ([`frf_core::light::within_half_turn`]: 1e9 is
/// -80, the turn 1e9 mod 360 names), refused where not finite or beyond
/// [`frf_core::light::MOST_TURN_DEG`].
pub fn parse_turn(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|e| format!("`{s}`: {e} (degrees)"))?;
    let v = frf_core::light::checked_turn(v).map_err(|e| format!("`{s}`: {e}"))?;
    Ok(frf_core::light::within_half_turn(v))
}

/// Parses a vertical field of view in degrees, within the range a camera path allows.
pub fn parse_fov(s: &str) -> Result<f32, String> {
    use frf_scene::path::{MAX_FOV_DEG, MIN_FOV_DEG};
    let v = parse_degrees(s)?;
    if !(v > MIN_FOV_DEG && v < MAX_FOV_DEG) {
        return Err(format!(
            "`{s}` degrees: a vertical field of view is within ({MIN_FOV_DEG}, {MAX_FOV_DEG})"
        ));
    }
    Ok(v)
}

/// Writes a path into JSON as text, any invalid UTF-8 replaced: settings and reports
/// name paths, and a path is not always a string.
pub fn path_text<S: serde::Serializer>(p: &std::path::Path, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(&p.display())
}

/// [`path_text`] of an optional path.
pub fn opt_path_text<S: serde::Serializer>(p: &Option<PathBuf>, s: S) -> Result<S::Ok, S::Error> {
    match p {
        Some(p) => s.serialize_some(&p.display().to_string()),
        None => s.serialize_none(),
    }
}

/// Parses a light tolerance: `DEG` (a walker's heading) or `DEG,WEIGHT` (and a probe's
/// weight).
pub fn parse_light_tolerance(s: &str) -> Result<frf_scene::shot::LightTolerance, String> {
    let bad = || {
        format!(
            "light tolerance `{s}`: expected DEG or DEG,WEIGHT (a heading within 0 to 180 \
             degrees, a probe's weight within 0 to 1)"
        )
    };
    let mut parts = s
        .split(',')
        .map(|p| p.trim().parse::<f32>().map_err(|_| bad()));
    let deg = parts.next().ok_or_else(bad)??;
    let weight = parts.next().transpose()?.unwrap_or(0.0);
    if parts.next().is_some() || !(0.0..=180.0).contains(&deg) || !(0.0..=1.0).contains(&weight) {
        return Err(bad());
    }
    Ok(frf_scene::shot::LightTolerance {
        heading: deg.to_radians(),
        weight,
    })
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
    const LIKE: &str = "poses, e.g. 0,1 or 0..4";
    let bad = || LIKE.to_string();
    if s.trim().is_empty() {
        return Err(format!("{LIKE} (none given)"));
    }
    let most = frf_core::capture::MAX_POSES_PER_CYCLE;
    if let Some((a, b)) = s.split_once("..") {
        let (a, b): (u32, u32) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        );
        if a >= b {
            return Err(format!(
                "a range whose end is after its start, e.g. 0..4 for poses 0 to 3 ({a}..{b} \
                 holds no pose)"
            ));
        }
        if b > most {
            return Err(format!("poses below {most} (a cycle holds at most {most})"));
        }
        return Ok((a..b).collect());
    }
    let poses: Vec<u32> = s
        .split(',')
        .map(|p| p.trim().parse().map_err(|_| bad()))
        .collect::<Result<_, _>>()?;
    if let Some(p) = poses.iter().find(|&&p| p >= most) {
        return Err(format!(
            "poses below {most} (pose {p} is beyond any cycle of at most {most})"
        ));
    }
    if let Some((k, p)) = (poses.iter().enumerate()).find(|(k, p)| poses[..*k].contains(p)) {
        return Err(format!(
            "each pose once (pose {p} is given twice, the second time at place {})",
            k + 1
        ));
    }
    Ok(poses)
}

/// The poses `flag` names ([`parse_poses`]), refused naming the flag and the value.
pub fn poses_arg(flag: &str, s: &str) -> Result<Vec<u32>, frf_core::BadArgument> {
    parse_poses(s).map_err(|e| frf_core::BadArgument::new(flag, s, e))
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
    pub env: Option<EnvSource>,
    /// Yaw of the environment about the vertical axis, degrees (any turn; kept within
    /// ±180°).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_turn)]
    pub yaw: f64,
    /// What lights the subject from below.
    #[arg(long, value_enum, default_value = "env")]
    pub floor: FloorArg,
    /// A sun added to the environment (alone with `--env none`), turned with it by
    /// `--yaw`: `AZIMUTH,ELEVATION[,DIAMETER[,ILLUMINANCE]]`, degrees (azimuth from +z
    /// toward +x) and `∫ L dω` over the disc in the environment's units (default 0.53°
    /// and 10, about the built-in sky's sun). Below the horizon it is not a sun: over
    /// `--floor ground` it lights nothing, over `env` it lights from below through the
    /// floor conditions.
    #[arg(long, value_parser = parse_sun, allow_hyphen_values = true, value_name = "AZ,EL[,DIAM[,E]]")]
    pub sun: Option<SunSpec>,
}

/// `--sun AZIMUTH,ELEVATION[,DIAMETER[,ILLUMINANCE]]`.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct SunSpec {
    /// Degrees.
    pub azimuth_deg: f32,
    /// Degrees.
    pub elevation_deg: f32,
    /// Degrees.
    pub diameter_deg: f32,
    /// `∫ L dω` over the disc.
    pub illuminance: f32,
}

impl SunSpec {
    /// The sun it names.
    pub fn sun(&self) -> CliResult<Sun> {
        let d = frf_core::light::direction_from_azimuth_elevation(
            self.azimuth_deg.to_radians(),
            self.elevation_deg.to_radians(),
        );
        Ok(Sun::new(d, self.diameter_deg, [self.illuminance; 3])
            .map_err(|e| format!("--sun: {e}"))?)
    }
}

/// Parses `--sun`.
pub fn parse_sun(s: &str) -> Result<SunSpec, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            format!("{s:?} is not AZIMUTH,ELEVATION[,DIAMETER[,ILLUMINANCE]] in numbers")
        })?;
    if !(2..=4).contains(&v.len()) || v.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "{s:?} is not AZIMUTH,ELEVATION[,DIAMETER[,ILLUMINANCE]] (2 to 4 finite numbers)"
        ));
    }
    let azimuth = frf_core::light::checked_turn(v[0]).map_err(|e| format!("azimuth {e}"))?;
    let spec = SunSpec {
        azimuth_deg: frf_core::light::within_half_turn(azimuth) as f32,
        elevation_deg: v[1] as f32,
        diameter_deg: v
            .get(2)
            .map_or(frf_core::sun::SUN_DIAMETER_DEG, |&d| d as f32),
        illuminance: v.get(3).map_or(10.0, |&e| e as f32),
    };
    if !(-90.0..=90.0).contains(&spec.elevation_deg) {
        return Err(format!(
            "elevation {}° is not within ±90°",
            spec.elevation_deg
        ));
    }
    spec.sun().map_err(|e| e.to_string())?;
    Ok(spec)
}

impl LightingArgs {
    /// The lighting in words, for reports: the environment, and the sun when there is
    /// one.
    pub fn name(&self) -> CliResult<String> {
        let env = self.source()?.to_string();
        Ok(match &self.sun {
            Some(s) => format!(
                "{env} + a sun (azimuth {}°, elevation {}°, {}° across, illuminance {})",
                s.azimuth_deg, s.elevation_deg, s.diameter_deg, s.illuminance
            ),
            None => env,
        })
    }

    /// The sun asked for.
    pub fn sun(&self) -> CliResult<Option<Sun>> {
        self.sun.as_ref().map(SunSpec::sun).transpose()
    }

    /// The environment asked for.
    pub fn source(&self) -> CliResult<&EnvSource> {
        Ok(self
            .env
            .as_ref()
            .ok_or("give --env ENV.hdr|sky|uniform|none")?)
    }

    /// The lighting of a field of `conditions` basis conditions, and the environment
    /// for truth renders (`None` for `none`).
    pub fn lighting(&self, conditions: usize) -> CliResult<(Lighting, Option<EnvMap>)> {
        let source = self.source()?;
        let mut env = source
            .load()
            .map_err(crate::context::context(format!("environment {source}")))?;
        if let Some(sun) = self.sun()? {
            if let Some(note) = sun.below_horizon(self.floor == FloorArg::Ground) {
                eprintln!("--sun: {note}");
            }
            // Added before the yaw, which turns it with the map; alone, a black sky.
            let base = env.unwrap_or_else(|| EnvMap::uniform([0.0; 3], 128));
            env = Some(sun.lit(&base)?);
        }
        let yaw = frf_core::light::turn_radians(self.yaw);
        Ok(Lighting::of(env, yaw, self.floor.into(), conditions)?)
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

/// Parses `RADIUS,HEIGHT`, metres (a camera circling the walker at one height).
pub fn parse_radius_height(s: &str) -> Result<(f32, f32), String> {
    match numbers(s, "radius and height")?[..] {
        [r, h] => Ok((r, h)),
        _ => Err(format!("`{s}`: expected RADIUS,HEIGHT in metres")),
    }
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
    /// Keyframed camera path (TOML; see `frf_scene::path`).
    #[arg(long, conflicts_with = "orbit")]
    #[serde(serialize_with = "opt_path_text")]
    pub camera: Option<PathBuf>,
    /// Orbit about the vertical axis through --look-at: `RADIUS,HEIGHT[,SWEEP_DEG]`,
    /// metres and degrees (default sweep 360, a loop).
    #[arg(long, value_parser = parse_orbit, allow_hyphen_values = true)]
    pub orbit: Option<OrbitSpec>,
    /// Orbit: the point looked at, `x,y,z` metres.
    #[arg(long, value_parser = parse_point, default_value = "0,0.9,0", allow_hyphen_values = true)]
    pub look_at: [f32; 3],
    /// Orbit: vertical field of view, degrees.
    #[arg(long, default_value_t = 35.0, value_parser = parse_fov)]
    pub fov: f32,
    /// Orbit: azimuth of the first frame, degrees.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_degrees)]
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
        // The orbit names its fields; the user gave them as flags.
        orbit.validate().map_err(|e| {
            let flag = match e.name.as_str() {
                "radius" => "--orbit radius",
                "height" => "--orbit height",
                "sweep_deg" => "--orbit sweep",
                "start_deg" => "--start",
                "look_at" => "--look-at",
                _ => "--fov",
            };
            e.renamed(flag)
        })?;
        Ok(Trajectory::Orbit(orbit))
    }
}

/// The visual hull and shadow maps made in ingest (`frf ingest`, `frf stage field`).
#[derive(Args)]
pub struct ShadowArgs {
    /// Make neither visual hulls nor shadow maps.
    #[arg(long)]
    no_shadows: bool,
    /// Voxel side of the visual hull, metres [default: half a pixel's footprint on the
    /// turntable axis, within 5 mm and 2 cm: 5 mm at 160x224].
    #[arg(long)]
    hull_voxel: Option<f32>,
    /// Views allowed to disagree when carving the hull (its views come from different
    /// walk cycles).
    #[arg(long, default_value_t = DEFAULT_MISSES)]
    hull_misses: usize,
    /// Texels per side of the shadow maps [default: 128 per 3 m of patch].
    #[arg(long)]
    shadow_texels: Option<u32>,
    /// Side of the ground patch under the subject the shadow maps cover, metres [default:
    /// 3; with `frf ingest --for SCENE`, enough for the shadow of the scene's lighting].
    #[arg(long)]
    shadow_extent: Option<f32>,
    /// Directions traced per light of a condition, spread over the solid angle it stands
    /// for (1: toward the light only).
    #[arg(long, default_value_t = DEFAULT_LIGHT_SAMPLES)]
    shadow_samples: usize,
}

impl ShadowArgs {
    /// The options, checked; `None` with `--no-shadows`.
    pub fn options(&self) -> CliResult<Option<ShadowOptions>> {
        self.options_for(None)
    }

    /// [`ShadowArgs::options`] with a patch of side `needed` metres (a scene's need) where
    /// `--shadow-extent` is not given ([`ShadowOptions::ground_for`]).
    pub fn options_for(&self, needed: Option<f32>) -> CliResult<Option<ShadowOptions>> {
        if self.no_shadows {
            return Ok(None);
        }
        let ground = ShadowOptions::ground_for(self.shadow_extent, self.shadow_texels, needed);
        let o = ShadowOptions {
            hull_voxel_m: self.hull_voxel,
            hull_misses: self.hull_misses,
            ground,
            light_samples: self.shadow_samples,
        };
        o.validate()?;
        Ok(Some(o))
    }
}

/// What a frame's subject is put over.
#[derive(Clone, Copy, Debug, ValueEnum, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum BackdropArg {
    /// Nothing: transparent, the shadow as a black layer of alpha 1 − S.
    None,
    /// The lighting environment, with a ground plane at y = 0.
    Env,
    /// A photograph taken by the camera (`--plate`), its ground at y = 0.
    Plate,
}

/// The ground of an environment backdrop: `env` (the environment below the horizon) or
/// a Lambertian albedo `A` or `R,G,B`.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub enum GroundArg {
    /// The environment's lower hemisphere.
    Env,
    /// A Lambertian ground of this albedo.
    Albedo([f32; 3]),
}

/// Parses `env`, `A` or `R,G,B` (albedos in 0..=1).
pub fn parse_ground(s: &str) -> Result<GroundArg, String> {
    if s == "env" {
        return Ok(GroundArg::Env);
    }
    let v = numbers(s, "ground")?;
    let albedo = match v[..] {
        [a] => [a; 3],
        [r, g, b] => [r, g, b],
        _ => return Err(format!("ground `{s}`: expected env, an albedo A or R,G,B")),
    };
    if albedo.iter().any(|a| !(0.0..=1.0).contains(a)) {
        return Err(format!("ground `{s}`: albedos lie in 0 to 1"));
    }
    Ok(GroundArg::Albedo(albedo))
}

/// The scene a frame is composited into: shared by `frf render` and `frf eval`.
#[derive(Args, Clone, Serialize, PartialEq)]
pub struct BackdropArgs {
    /// What the subject is put over (with its shadow on the ground when the field has
    /// shadow maps).
    #[arg(long, value_enum, default_value = "none")]
    pub backdrop: BackdropArg,
    /// The plate of `--backdrop plate`: a photograph (8-bit PNG/JPEG as sRGB; 16-bit PNG,
    /// EXR, HDR linear) taken by the camera, which must then be a `--camera` path of one
    /// key; frames take its size.
    #[arg(long)]
    #[serde(serialize_with = "opt_path_text")]
    pub plate: Option<PathBuf>,
    /// Ground of `--backdrop env`: `env` (the environment below the horizon) or a
    /// Lambertian albedo `A` or `R,G,B` lit by the environment's upper hemisphere.
    #[arg(long, value_parser = parse_ground, default_value = "env")]
    pub ground: GroundArg,
    /// The subject's shadow on the ground: `maps` (the field's attenuation maps relit
    /// with the environment), `traced` (the environment's median-cut lights traced
    /// against the pose's visual hull) or `none`.
    #[arg(long, value_enum, default_value = "maps")]
    pub shadow: ShadowArg,
    /// Median-cut lights of the environment for `--shadow traced`.
    #[arg(long, default_value_t = 256)]
    pub shadow_lights: usize,
}

/// Where the subject's shadow comes from.
#[derive(Clone, Copy, Debug, ValueEnum, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ShadowArg {
    /// The field's attenuation maps, relit (the original's method).
    Maps,
    /// The environment's lights traced against the pose's visual hull.
    Traced,
    /// No shadow.
    None,
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
        // An empty or reversed range is named as such, and the flag and value once (it
        // read "--poses \"\": expected --poses \"\": expected ...").
        let e = poses_arg("--poses", "3..3").unwrap_err().to_string();
        assert!(e.contains("3..3 holds no pose"), "{e}");
        assert_eq!(e.matches("--poses").count(), 1, "{e}");
        assert!(
            parse_poses("1..0")
                .unwrap_err()
                .contains("1..0 holds no pose")
        );
        assert!(parse_poses("").unwrap_err().contains("none given"));
        assert!(parse_poses(" ").unwrap_err().contains("none given"));
        // Bounded before anything is allocated (issue 35: 0..4294967295 took 23 GB).
        assert!(
            parse_poses("0..4294967295")
                .unwrap_err()
                .contains("at most")
        );
        assert!(parse_poses("1,4294967295").unwrap_err().contains("beyond"));
        // A pose given twice is refused (it exported, merged and rendered twice).
        assert!(
            parse_poses("0,0")
                .unwrap_err()
                .contains("pose 0 is given twice")
        );
        assert!(parse_poses("2,1,2").unwrap_err().contains("twice"));
        let o = parse_orbit("3,1.2").unwrap();
        assert_eq!((o.radius, o.height, o.sweep_deg), (3.0, 1.2, 360.0));
        assert_eq!(parse_env("none"), Ok(EnvSource::None));
        assert_eq!(parse_ground("env"), Ok(GroundArg::Env));
        assert_eq!(parse_ground("0.3"), Ok(GroundArg::Albedo([0.3; 3])));
        assert!(parse_ground("1.5").unwrap_err().contains("0 to 1"));
        assert!(parse_ground("0.1,0.2").unwrap_err().contains("R,G,B"));
    }
}
