//! The scene file: TOML a person writes by hand, read and checked field by field.
//! Errors name the file, the field and its line. Paths are relative to the file. The
//! same structs are written: the viewer records a camera move as a scene file through
//! them ([`written`] values).
//!
//! ```toml
//! field = "../demo-out/walker.frf"    # the flowed reflectance field
//!
//! [time]                              # seconds; frames at start + i / fps, i = 0, 1, ...
//! start = 0.0                         # (a still when end equals start)
//! end = 2.0                           # exclusive
//! fps = 12.0
//! interpolate = "flow"                # between captured poses: "flow" (default, when
//!                                     # the field holds pose-to-pose flows) or "nearest"
//!
//! [output]
//! size = [480, 270]
//! exposure = 0.0                      # stops, PNG frames only
//! layers = false                      # EXR layers per frame: subject, shadow, backdrop
//! preview = "apng"                    # animated preview: "apng", "gif" or "none"
//! variant = "fourway"                 # or "twoway", "linear", "nearest"
//!
//! [lighting]                          # the environment, scene frame
//! env = "../assets/envmaps/map.hdr"   # a .hdr/.exr file, "sky", "uniform" or "none"
//! yaw_deg = 0.0
//! intensity = 1.0
//! floor = "env"                       # or "ground": what lights the subject from below
//! # [[lighting.key]]                  # keyframes, piecewise linear in time; a key may
//! # time = 1.0                        # name another map, cross-faded from the previous
//! # yaw_deg = 90.0                    # key's; omitted values carry over
//! # sun = { azimuth_deg = 60.0, elevation_deg = 35.0, angular_diameter_deg = 0.53,
//! #         illuminance = 12.0 }       # or direction = [x, y, z]; or radiance = L;
//! #                                   # colour = [r, g, b]. Added to env (turned by yaw,
//! #                                   # scaled by intensity); alone with env = "none"
//! # [[lighting.probe]]                # light probes (frf_scene::probes): each walker is
//! # position = [-4.0, 1.2, 0.0]       # lit by them interpolated where it stands, the
//! # env = "shade.hdr"                 # key's intensity and the sun added; the backdrop
//! # yaw_deg = 0.0                     # still shows env; suns = false: the map's
//! #                                   # suns taken out (in shade)
//!
//! [camera]                            # an orbit over the time range, or keys
//! orbit = { radius = 3.2, height = 1.4, start_deg = -30.0, sweep_deg = 120.0,
//!           look_at = [0.0, 0.9, 0.0], fov_deg = 35.0 }
//! # [[camera.key]]                    # as camera path files (frf_scene::path)
//! # time = 0.0
//! # position = [2.5, 1.4, 3.0]
//! # look_at = [0.0, 0.9, 0.0]
//! # fov_deg = 30.0
//!
//! [composite]
//! backdrop = "env"                    # "env", "plate" or "none"
//! ground = "env"                      # or an albedo: 0.3 or [0.3, 0.25, 0.2]
//! shadow = "maps"                     # "maps", "traced" or "none"
//! # plate = "plate.png"               # with backdrop = "plate" and one camera key
//!
//! [[instance]]                        # default: one walker at the origin
//! position = [0.0, 0.0, 0.0]          # metres, on the ground y = 0
//! heading_deg = 0.0                   # about +y; 0 walks toward +x
//! time_offset = 0.0                   # seconds added to the scene's time for its walk
//!
//! [[instance]]                        # a walker walking a path (frf_scene::walk): keys
//! time_offset = 0.25                  # instead of position; it faces where it walks
//! [[instance.key]]                    # (or heading_deg at every key) and its walk
//! time = 0.0                          # advances with the distance walked
//! position = [-3.0, 0.0, 0.0]
//! [[instance.key]]
//! time = 4.0
//! position = [2.0, 0.0, -2.0]
//! ```

use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use toml::Spanned;

use crate::error::{Result, SceneError};

/// A value and where it was written.
pub type At<T> = Spanned<T>;

/// A value written by a program (no place in a text): what a recorded scene holds.
pub fn written<T>(value: T) -> At<T> {
    At::new(0..0, value)
}

/// The file as written (see the module docs).
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneToml {
    /// The field.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub field: Option<At<String>>,
    /// Time range and rate.
    pub time: At<TimeToml>,
    /// Output.
    #[serde(default)]
    pub output: OutputToml,
    /// Lighting.
    pub lighting: At<LightingToml>,
    /// Camera.
    pub camera: At<CameraToml>,
    /// Backdrop, ground and shadow.
    #[serde(default)]
    pub composite: CompositeToml,
    /// The walkers.
    #[serde(default)]
    pub instance: Vec<At<InstanceToml>>,
}

/// `[time]`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TimeToml {
    /// Seconds (64-bit: a frame's instant is `start + i / fps` at any time of day).
    #[serde(default = "zero_f64")]
    pub start: At<f64>,
    /// Seconds, exclusive.
    pub end: At<f64>,
    /// Frames per second.
    pub fps: At<f64>,
    /// What a frame between captured poses shows.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interpolate: Option<At<String>>,
}

/// `[output]`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OutputToml {
    /// Frame width and height (read as a list: a fixed-size array would take the first
    /// two of a longer one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub size: Option<At<Vec<u32>>>,
    /// Stops, PNG only.
    #[serde(default = "zero")]
    pub exposure: At<f32>,
    /// EXR layers.
    #[serde(default)]
    pub layers: bool,
    /// Animated preview.
    #[serde(default = "default_preview")]
    pub preview: At<String>,
    /// Interpolation.
    #[serde(default = "default_variant")]
    pub variant: At<String>,
}

impl Default for OutputToml {
    fn default() -> Self {
        Self {
            size: None,
            exposure: At::new(0..0, 0.0),
            layers: false,
            preview: default_preview(),
            variant: default_variant(),
        }
    }
}

fn default_preview() -> At<String> {
    At::new(0..0, "apng".into())
}

fn default_variant() -> At<String> {
    At::new(0..0, "fourway".into())
}

/// `[lighting]`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LightingToml {
    /// Environment (with keys, the first key's when omitted).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub env: Option<At<String>>,
    /// Degrees.
    #[serde(default = "zero_f64")]
    pub yaw_deg: At<f64>,
    /// Multiplier.
    #[serde(default = "one")]
    pub intensity: At<f32>,
    /// "env" or "ground".
    #[serde(default = "env_word")]
    pub floor: At<String>,
    /// Keyframes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub key: Vec<At<LightKeyToml>>,
    /// A sun added to the environment (or lighting alone, with `env = "none"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sun: Option<At<SunToml>>,
    /// Light probes: each walker is lit by them interpolated where it stands
    /// ([`crate::probes`]) instead of by `env`, which the backdrop still shows.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub probe: Vec<At<ProbeToml>>,
}

/// `[[lighting.probe]]`: the light at a place of the scene.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeToml {
    /// Where it was taken, metres (its height is not used).
    pub position: [f32; 3],
    /// Its map: a `.hdr`/`.exr` file, an `frf env-sh` file (`.json`), `"sky"` or
    /// `"uniform"`.
    pub env: String,
    /// Its turn about `+y`, degrees.
    #[serde(default)]
    pub yaw_deg: f64,
    /// Multiplier of its radiance.
    #[serde(default = "one_f32")]
    pub intensity: f32,
    /// `false`: the map with its suns taken out, as in the shade of something between
    /// the probe and the sun (default `true`).
    #[serde(default = "yes")]
    pub suns: bool,
}

fn yes() -> bool {
    true
}

fn one_f32() -> f32 {
    1.0
}

/// `lighting.sun`: a direction (by azimuth and elevation, or a vector), an angular
/// diameter, and a strength (an illuminance or a radiance, times a colour).
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SunToml {
    /// Degrees from `+z` toward `+x`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub azimuth_deg: Option<f64>,
    /// Degrees above the horizon.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elevation_deg: Option<f32>,
    /// Toward the sun, scene frame (instead of azimuth and elevation).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub direction: Option<[f32; 3]>,
    /// Degrees (default 0.53, the real sun's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub angular_diameter_deg: Option<f32>,
    /// `∫ L dω` over the disc, the environment's units (or give `radiance`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub illuminance: Option<f32>,
    /// The disc's radiance (instead of `illuminance`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radiance: Option<f32>,
    /// Multiplies the strength per channel (default white).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub colour: Option<[f32; 3]>,
}

fn zero() -> At<f32> {
    At::new(0..0, 0.0)
}

fn zero_f64() -> At<f64> {
    At::new(0..0, 0.0)
}

fn one() -> At<f32> {
    At::new(0..0, 1.0)
}

fn env_word() -> At<String> {
    At::new(0..0, "env".into())
}

/// `[[lighting.key]]`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LightKeyToml {
    /// Seconds.
    pub time: At<f64>,
    /// Another map from this key on.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub env: Option<At<String>>,
    /// Degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yaw_deg: Option<At<f64>>,
    /// Multiplier.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intensity: Option<At<f32>>,
}

/// `[camera]`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CameraToml {
    /// An orbit over the time range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orbit: Option<At<OrbitToml>>,
    /// Keys.
    #[serde(default)]
    pub key: Vec<At<crate::path::Key>>,
}

/// `camera.orbit`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitToml {
    /// Metres from the vertical axis through `look_at`.
    pub radius: f32,
    /// Camera height, metres.
    pub height: f32,
    /// Degrees.
    #[serde(default)]
    pub start_deg: f32,
    /// Degrees swept over the time range.
    #[serde(default = "full_turn")]
    pub sweep_deg: f32,
    /// Point looked at.
    #[serde(default = "waist")]
    pub look_at: [f32; 3],
    /// Vertical field of view, degrees.
    #[serde(default = "default_fov")]
    pub fov_deg: f32,
}

fn full_turn() -> f32 {
    360.0
}

fn waist() -> [f32; 3] {
    [0.0, 0.9, 0.0]
}

fn default_fov() -> f32 {
    35.0
}

/// `[composite]`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CompositeToml {
    /// "env", "plate" or "none".
    #[serde(default = "no_backdrop")]
    pub backdrop: At<String>,
    /// "env", an albedo or `[r, g, b]`.
    #[serde(default)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ground: Option<At<toml::Value>>,
    /// "maps", "traced" or "none".
    #[serde(default = "maps_word")]
    pub shadow: At<String>,
    /// The plate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plate: Option<At<String>>,
}

impl Default for CompositeToml {
    fn default() -> Self {
        Self {
            backdrop: no_backdrop(),
            ground: None,
            shadow: maps_word(),
            plate: None,
        }
    }
}

fn no_backdrop() -> At<String> {
    At::new(0..0, "none".into())
}

fn maps_word() -> At<String> {
    At::new(0..0, "maps".into())
}

/// `[[instance]]`: a walker standing (`position`, `heading_deg`) or walking a path
/// (`key`s, [`crate::walk`]).
#[derive(Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct InstanceToml {
    /// Metres (a walker standing; default the origin).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position: Option<[f32; 3]>,
    /// Degrees (a walker standing; default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heading_deg: Option<f64>,
    /// Seconds.
    #[serde(default)]
    pub time_offset: f64,
    /// The path's keys (a walker walking).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub key: Vec<At<WalkKeyToml>>,
}

impl InstanceToml {
    /// How `instance` is written (the viewer's recorder).
    pub fn of(instance: &crate::walk::Instance) -> Self {
        let keys = instance.path.as_ref().map_or(Vec::new(), |p| {
            p.keys()
                .iter()
                .map(|k| {
                    written(WalkKeyToml {
                        time: k.time,
                        position: k.position.to_array(),
                        heading_deg: k.heading.map(f64::to_degrees),
                    })
                })
                .collect()
        });
        let standing = keys.is_empty();
        Self {
            position: standing.then(|| instance.position.to_array()),
            heading_deg: standing.then(|| f64::from(instance.heading).to_degrees()),
            time_offset: instance.time_offset,
            key: keys,
        }
    }
}

/// `[[instance.key]]`: where a walker is at a time, and optionally its heading.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WalkKeyToml {
    /// Seconds, scene clock.
    pub time: f64,
    /// Metres, on the ground.
    pub position: [f32; 3],
    /// Degrees about `+y` (at every key or none: else the walker faces where it walks).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heading_deg: Option<f64>,
}

/// Errors about one scene file, pointing at lines.
pub struct Reporter<'a> {
    path: &'a Path,
    text: &'a str,
}

impl<'a> Reporter<'a> {
    /// The reporter of `path`, whose contents are `text`.
    pub fn new(path: &'a Path, text: &'a str) -> Self {
        Self { path, text }
    }

    /// Line (1-based) of byte `offset`.
    pub fn line(&self, offset: usize) -> usize {
        self.text[..offset.min(self.text.len())]
            .matches('\n')
            .count()
            + 1
    }

    /// An error about `field`, written at `span` (an empty span: the field was left out).
    pub fn error(
        &self,
        field: &str,
        span: Range<usize>,
        problem: impl std::fmt::Display,
    ) -> SceneError {
        let place = if span.is_empty() && span.start == 0 {
            "(not given)".to_string()
        } else {
            format!("line {}", self.line(span.start))
        };
        SceneError::File {
            path: self.path.to_path_buf(),
            field: field.to_string(),
            place,
            problem: problem.to_string(),
        }
    }

    /// A path written in the file, relative to the file's directory.
    pub fn resolve(&self, written: &str) -> PathBuf {
        let p = Path::new(written);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.path.parent().unwrap_or(Path::new(".")).join(p)
        }
    }
}

/// Parses the file's text; syntax and type errors name the file and the line.
pub fn parse(path: &Path, text: &str) -> Result<SceneToml> {
    toml::from_str(text).map_err(|e| {
        let line = e.span().map_or(String::new(), |s| {
            format!(" (line {})", Reporter::new(path, text).line(s.start))
        });
        SceneError::Syntax {
            path: path.to_path_buf(),
            line,
            problem: e.message().to_string(),
        }
    })
}
