//! Argument types shared by the subcommands, each written once: flow presets, floor
//! models, interpolation variants, the lighting, the camera path, shadows and backdrops.
//! Their values' parsers are the scene crate's ([`frf_scene::text`]).

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use frf_core::env::{EnvMap, EnvSource};
use frf_core::sun::Sun;
use frf_ingest::shadows::{DEFAULT_LIGHT_SAMPLES, DEFAULT_MISSES, ShadowOptions};
use frf_reflectance::project::FloorModel;
use frf_render::morph::Variant;
use frf_render::resident::Lighting;
use frf_scene::path::{CameraPath, Orbit, Trajectory};
use glam::Vec3;
use serde::Serialize;

use crate::CliResult;
pub use frf_scene::text::{
    GroundArg, OrbitSpec, SunSpec, parse_degrees, parse_fov, parse_ground, parse_light_tolerance,
    parse_orbit, parse_point, parse_poses, parse_radius_height, parse_size, parse_sun, parse_turn,
    poses_arg,
};

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
        Ok(self.sun.as_ref().map(SunSpec::sun).transpose()?)
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
