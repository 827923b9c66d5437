//! Scenes: a shot of one or more walking subjects, relit by an environment that may
//! change over time, seen along a camera path, shadowed and composited over a backdrop.
//! This crate sits above the renderer (`frf-render`), which knows nothing of scenes: what
//! the planner decides reaches it as plain data (`frf_render::pose_plan::PosePlan`).
//!
//! - [`file`]: the TOML a person writes (read, and written by the viewer's recorder), and
//!   its errors (naming the field and line); [`path`]: virtual camera paths (keyframes,
//!   orbit); [`error`]: what can go wrong, each fault in its class;
//! - [`Scene`]: the checked scene, and what it asks for at each frame time (camera,
//!   lighting, and the pose of each walker: the walk cycle at that time, looping);
//! - [`plan`]: what a scene needs from a field, computed before any work, so that only
//!   that is read, relit and drawn;
//! - [`shot`]: the poses made resident as the frames need them, and a frame drawn;
//!   [`render_shot::render_shot`]: the loop over a shot's frames, writing each (and
//!   resuming) through an [`output::Output`] directory.
//!
//! **Frames.** The scene frame is the world of the shot (metres, `+y` up, the ground
//! `y = 0`). Each walker (an *instance*) stands at its position, turned by its heading
//! about `+y`, or walks along a path ([`walk`]: its position and heading at each
//! instant, its walk's phase advanced by the distance walked), its walk `time_offset`
//! seconds ahead; its subject frame at an instant is `world_from_subject = T(position) ·
//! R_y(heading)` ([`Placement`]). With one instance at the origin the scene frame is the
//! subject frame of the field.

pub mod bench_frame;
mod check;
pub mod error;
pub mod explain;
pub mod file;
mod of_field;
pub mod output;
pub mod path;
pub mod plan;
pub mod plan_report;
pub mod probes;
pub mod render_shot;
pub mod settings;
pub mod shot;
pub mod shot_report;
pub mod spline;
pub mod sprites;
pub mod text;
pub mod walk;

use std::path::{Path, PathBuf};

use frf_core::camera::Camera;
use frf_core::env::EnvSource;
use frf_core::light::turn_radians;
use frf_reflectance::project::FloorModel;

pub use crate::error::{Result, SceneError};
use crate::path::Trajectory;
use file::{Reporter, SceneToml};
use frf_render::composite::GroundLook;
use frf_render::morph::Variant;
pub use of_field::{FIELD_PREVIEW_FPS, FieldLook};

/// Most frames a scene may have (an hour at 30 fps and more).
pub const MAX_FRAMES: usize = 200_000;
/// Largest scene (or camera path) file, bytes ([`crate::path::MAX_FILE_BYTES`]).
pub use path::MAX_FILE_BYTES;
/// Largest frame side, pixels (8K).
pub const MAX_SIDE_PX: u32 = 8192;
/// The latest instant a scene may name, seconds from its clock's zero (either way): f64
/// resolves a microsecond there, so frames `1 / fps` apart stay apart.
pub const MAX_TIME_S: f64 = 1e9;
/// The brightest an environment may be scaled (`lighting.intensity`, the viewer's
/// `intensity`): far above any exposure a frame can show, far below f32's overflow.
pub const MAX_INTENSITY: f32 = 1e6;
pub use walk::{Gait, Instance, MAX_DISTANCE_M, Placement};

/// The animated preview of a render.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Preview {
    /// Animated PNG.
    Apng,
    /// GIF (256 colours).
    Gif,
    /// None.
    None,
}

impl Preview {
    /// Its name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Preview::Apng => "apng",
            Preview::Gif => "gif",
            Preview::None => "none",
        }
    }
}

/// What the subject is put over.
#[derive(Debug, Clone, PartialEq)]
pub enum BackdropSpec {
    /// Nothing (transparent; the shadow as a black layer).
    None,
    /// The environment, with this ground.
    Environment(GroundLook),
    /// A photograph taken by the (single-key) camera.
    Plate(PathBuf),
}

/// Where the shadow comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShadowSpec {
    /// The field's attenuation maps, relit.
    Maps,
    /// The environment's lights traced against the visual hull.
    Traced,
    /// No shadow.
    None,
}

/// One lighting keyframe, every value given (carried over from the previous key).
#[derive(Debug, Clone, PartialEq)]
pub struct LightKey {
    /// Seconds.
    pub time: f64,
    /// The environment from this key on.
    pub env: EnvSource,
    /// Its turn about `+y`, degrees as given (keys turning more than half a turn apart
    /// turn the light that far between them); the light at an instant takes it within
    /// ±180° in double precision ([`frf_core::light::turn_radians`]).
    pub yaw_deg: f64,
    /// Multiplier of the environment's radiance.
    pub intensity: f32,
}

/// The lighting at one instant: a blend of at most two maps (a cross-fade between keys
/// naming different maps), turned by `yaw` and scaled by `intensity`.
#[derive(Debug, Clone, PartialEq)]
pub struct LightingAt {
    /// `(environment, weight)`; weights sum to 1.
    pub maps: Vec<(EnvSource, f32)>,
    /// Radians.
    pub yaw: f32,
    /// Multiplier.
    pub intensity: f32,
    /// The scene's sun, turned by `yaw` and scaled by `intensity` as the maps are.
    pub sun: Option<frf_core::sun::Sun>,
}

/// A light probe: the light at a place of the scene ([`probes`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Probe {
    /// Where it was taken (scene frame, metres).
    pub position: glam::Vec3,
    /// Its map.
    pub env: EnvSource,
    /// Its turn about `+y`, radians.
    pub yaw: f32,
    /// Multiplier of its radiance.
    pub intensity: f32,
    /// Whether its map keeps its suns (`false`: taken out, the probe in shade).
    pub suns: bool,
}

/// The scene's light probes and how they interpolate.
#[derive(Debug, Clone, PartialEq)]
pub struct Probes {
    /// The probes.
    pub probes: Vec<Probe>,
    /// Their layout on the ground.
    pub layout: probes::ProbeLayout,
}

/// What a frame between two captured poses shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum TimeInterpolation {
    /// The captured pose nearest its instant.
    Nearest,
    /// Both poses' renders morphed in time by the motion between them
    /// ([`frf_render::motion`]).
    Flow,
}

impl TimeInterpolation {
    /// Its name in scene files and reports.
    pub fn name(self) -> &'static str {
        match self {
            TimeInterpolation::Nearest => "nearest",
            TimeInterpolation::Flow => "flow",
        }
    }
}

/// A checked scene (see the module docs and [`file`]).
#[derive(Debug, Clone)]
pub struct Scene {
    /// The scene file.
    pub path: PathBuf,
    /// The field, if the file names one.
    pub field: Option<PathBuf>,
    /// Seconds (every time of the scene is 64-bit: 32 bits resolve 1/16 s at 10^6 s).
    pub start: f64,
    /// Seconds, exclusive (equal to `start` for a still).
    pub end: f64,
    /// Frames per second.
    pub fps: f64,
    /// What a frame between captured poses shows; `None`: the morph in time when the
    /// field holds pose-to-pose flows, else the nearest pose.
    pub interpolate: Option<TimeInterpolation>,
    /// Frame size, if the file gives one.
    pub size: Option<(u32, u32)>,
    /// Stops.
    pub exposure: f32,
    /// EXR layers per frame.
    pub layers: bool,
    /// Animated preview.
    pub preview: Preview,
    /// Interpolation.
    pub variant: Variant,
    /// Lighting keys, in time order (at least one).
    pub lighting: Vec<LightKey>,
    /// A sun added to the lighting (`lighting.sun`; [`frf_core::sun`]).
    pub sun: Option<frf_core::sun::Sun>,
    /// Light probes that light the walkers where they stand (`lighting.probe`).
    pub probes: Option<Probes>,
    /// What lights the subject from below.
    pub floor: FloorModel,
    /// The camera.
    pub camera: Trajectory,
    /// Backdrop.
    pub backdrop: BackdropSpec,
    /// Shadow.
    pub shadow: ShadowSpec,
    /// Walkers (at least one).
    pub instances: Vec<Instance>,
}

impl Scene {
    /// The field to render the scene from: `given` (the command line's), else the one the
    /// file names; an error naming the file when neither does.
    pub fn field_or(&self, given: Option<&Path>) -> Result<PathBuf> {
        given
            .map(Path::to_path_buf)
            .or_else(|| self.field.clone())
            .ok_or_else(|| SceneError::NoField {
                scene: self.path.clone(),
            })
    }

    /// The frame size of a render: a plate's own (a plate is seen by its camera), else
    /// `given` (the command line's), else the scene's, else the field's image size.
    pub fn frame_size(&self, given: Option<(u32, u32)>, field: (u32, u32)) -> Result<(u32, u32)> {
        let plate = match &self.backdrop {
            BackdropSpec::Plate(p) => {
                let (w, h) = frf_core::io::image_dimensions(p)?;
                Some((w as u32, h as u32))
            }
            _ => None,
        };
        Ok(plate.or(given).or(self.size).unwrap_or(field))
    }

    /// Whether `path` names a scene file (`.toml`) rather than a field.
    pub fn is_scene_file(path: &Path) -> bool {
        path.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
    }

    /// The scene file at `path` with the command line's overrides: every lighting key's
    /// environment replaced by `env`, the field by `field`; the scene and its field.
    pub fn load_overridden(
        path: &Path,
        env: Option<&EnvSource>,
        field: Option<&Path>,
    ) -> Result<(Self, PathBuf)> {
        let mut scene = Self::load(path)?;
        if let Some(env) = env {
            for k in &mut scene.lighting {
                k.env = env.clone();
            }
        }
        let field = scene.field_or(field)?;
        Ok((scene, field))
    }

    /// Reads and checks the scene file at `path`.
    pub fn load(path: &Path) -> Result<Self> {
        if frf_reflectance::container::is_field_file(path) {
            return Err(SceneError::Syntax {
                path: path.to_path_buf(),
                line: String::new(),
                problem: "is a field file, not a scene file (TOML): give it as --field, or \
                          render it with its own flags (frf render FIELD.frf --env ... --orbit ...)"
                    .into(),
            });
        }
        let text = frf_core::io::read_text(path, MAX_FILE_BYTES)?;
        Self::parse(path, &text)
    }

    /// Checks the scene file `text` read from `path`.
    pub fn parse(path: &Path, text: &str) -> Result<Self> {
        let raw: SceneToml = file::parse(path, text)?;
        let r = Reporter::new(path, text);
        let (start, end, fps) = check::time(&r, &raw)?;
        let interpolate = check::interpolate(&r, &raw)?;
        let (size, exposure, preview, variant) = check::output(&r, &raw.output)?;
        let (lighting, floor) = check::lighting(&r, &raw.lighting)?;
        let sun = check::sun(&r, &raw.lighting)?;
        let probes = check::probes(&r, &raw.lighting)?;
        let camera = check::camera(&r, &raw.camera)?;
        let (backdrop, shadow) =
            check::composite(&r, &raw.composite, (&camera, &raw.camera), &lighting)?;
        let instances = check::instances(&r, &raw)?;
        let o = &raw.output;
        Ok(Self {
            path: path.to_path_buf(),
            field: raw.field.as_ref().map(|f| r.resolve(f.get_ref())),
            start,
            end,
            fps,
            interpolate,
            size,
            exposure,
            layers: o.layers,
            preview,
            variant,
            lighting,
            sun,
            probes,
            floor,
            camera,
            backdrop,
            shadow,
            instances,
        })
    }

    /// The frame times: `start + i / fps` for every `i` whose instant is before `end`
    /// (each computed from `i`, never accumulated); one frame (a still) when `end ==
    /// start`.
    pub fn frame_times(&self) -> Vec<f64> {
        let at = |i: usize| self.start + i as f64 / self.fps;
        // The count from the half-open interval, corrected where rounding put the last
        // instant on `end` or short of it.
        let mut n = ((self.end - self.start) * self.fps).ceil().max(0.0) as usize;
        while n > 0 && at(n - 1) >= self.end {
            n -= 1;
        }
        while at(n) < self.end {
            n += 1;
        }
        (0..n.max(1)).map(at).collect()
    }

    /// The camera at time `t`, frames of `size`: an orbit sweeps the time range (a full
    /// turn loops without repeating its first frame); keys are in scene seconds.
    pub fn camera_at(&self, t: f64, size: (u32, u32)) -> Result<Camera> {
        match &self.camera {
            Trajectory::Path(p) => p.at(t).camera(size.0, size.1),
            Trajectory::Orbit(o) => {
                let span = self.end - self.start;
                let f = if span > 0.0 {
                    (t - self.start) / span
                } else {
                    0.0
                };
                o.key(f as f32).camera(size.0, size.1)
            }
        }
    }

    /// The lighting at time `t`: piecewise linear between keys, the map cross-faded from
    /// one key's to the next's when they differ.
    pub fn lighting_at(&self, t: f64) -> LightingAt {
        let k = &self.lighting;
        let i = k.partition_point(|key| key.time <= t).max(1) - 1;
        let a = &k[i];
        let sun = |yaw: f32, intensity: f32| self.sun.map(|s| s.rotated(yaw).scaled(intensity));
        let Some(b) = k.get(i + 1) else {
            let yaw = turn_radians(a.yaw_deg);
            return LightingAt {
                maps: vec![(a.env.clone(), 1.0)],
                yaw,
                intensity: a.intensity,
                sun: sun(yaw, a.intensity),
            };
        };
        let s = if a.time.is_finite() {
            ((t - a.time) / (b.time - a.time)).clamp(0.0, 1.0) as f32
        } else {
            0.0
        };
        let maps = if a.env == b.env || s == 0.0 {
            vec![(a.env.clone(), 1.0)]
        } else {
            vec![(a.env.clone(), 1.0 - s), (b.env.clone(), s)]
        };
        let (yaw, intensity) = (
            turn_radians(a.yaw_deg + f64::from(s) * (b.yaw_deg - a.yaw_deg)),
            a.intensity + s * (b.intensity - a.intensity),
        );
        LightingAt {
            maps,
            yaw,
            intensity,
            sun: sun(yaw, intensity),
        }
    }

    /// Where instance `i` stands at time `t`, and which way it faces.
    pub fn placement(&self, i: usize, t: f64) -> Placement {
        self.instances[i].at(t)
    }

    /// The pose of the walk cycle (`poses_per_cycle` poses of `gait`) that instance `i`
    /// shows at time `t`: the nearest pose to its phase, looping.
    pub fn pose_at(&self, i: usize, t: f64, gait: &Gait, poses_per_cycle: u32) -> u32 {
        let n = poses_per_cycle.max(1) as f64;
        let phase = self.phase_at(i, t, gait);
        ((phase * n).round() as u32) % poses_per_cycle.max(1)
    }

    /// Where in its walk cycle instance `i` is at time `t`, in cycles, `[0, 1)`: pose `k`
    /// of `n` per cycle is at phase `k / n` ([`Instance::phase`]: by the distance walked
    /// on a path, by time on the spot).
    pub fn phase_at(&self, i: usize, t: f64, gait: &Gait) -> f64 {
        self.instances[i].phase(t, gait)
    }

    /// The probes' weights where walker `i` stands at time `t` (`(probe, weight)`,
    /// [`probes::ProbeLayout::weights`]); empty without probes.
    pub fn probe_weights(&self, i: usize, t: f64) -> Vec<(usize, f32)> {
        self.probes.as_ref().map_or(Vec::new(), |p| {
            let at = self.placement(i, t).position;
            p.layout.weights(glam::Vec2::new(at.x, at.z))
        })
    }

    /// Every environment the scene names (its lighting keys', then its probes').
    pub fn environments(&self) -> Vec<EnvSource> {
        let mut out: Vec<EnvSource> = Vec::new();
        let probes = self
            .probes
            .iter()
            .flat_map(|p| p.probes.iter().map(|p| &p.env));
        for env in self.lighting.iter().map(|k| &k.env).chain(probes) {
            if !out.contains(env) {
                out.push(env.clone());
            }
        }
        out
    }

    /// Whether walker `i`'s own light changes during the shot: it turns, it moves
    /// between probes, or (`walker_shadows`) another walker may stand between it and a
    /// sun, whose shadow on it changes as that walker walks.
    pub fn walker_light_changes(&self, i: usize, walker_shadows: bool) -> bool {
        let inst = &self.instances[i];
        let between_probes = self.probes.as_ref().is_some_and(|p| p.probes.len() > 1);
        let others = walker_shadows && self.instances.len() > 1;
        inst.turns() || (between_probes && inst.moves()) || others
    }
}

#[cfg(test)]
mod tests;
