//! Scenes: a shot of one or more walking subjects, relit by an environment that may
//! change over time, seen along a camera path, shadowed and composited over a backdrop.
//!
//! - [`file`]: the TOML a person writes, and its errors (naming the field and line);
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
//! about `+y`, its walk `time_offset` seconds ahead of the scene's clock; its subject
//! frame is `world_from_subject = T(position) · R_y(heading)`. With one instance at the
//! origin the scene frame is the subject frame of the field.

pub mod file;
pub mod output;
pub mod plan;
pub mod render_shot;
pub mod shot;

use std::path::{Path, PathBuf};

use frf_core::camera::{Camera, Rigid};
use frf_core::env::EnvSource;
use frf_reflectance::project::FloorModel;
use glam::Vec3;

use crate::composite::GroundLook;
use crate::error::{RenderError, Result};
use crate::morph::Variant;
use crate::path::{CameraPath, Orbit, Trajectory};
use file::{At, Reporter, SceneToml};

/// Most frames a scene may have (an hour at 30 fps and more).
pub const MAX_FRAMES: usize = 200_000;
/// Largest frame side, pixels (8K).
pub const MAX_SIDE_PX: u32 = 8192;

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
    pub time: f32,
    /// The environment from this key on.
    pub env: EnvSource,
    /// Radians.
    pub yaw: f32,
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
}

/// One walker of the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instance {
    /// Where it stands (scene frame, metres).
    pub position: Vec3,
    /// Its heading about `+y`, radians.
    pub heading: f32,
    /// Seconds its walk is ahead of the scene's clock.
    pub time_offset: f32,
}

impl Instance {
    /// `world_from_subject`.
    pub fn world_from_subject(&self) -> Rigid {
        let r = Rigid::rotation_y(self.heading);
        Rigid {
            rotation: r.rotation,
            translation: self.position,
        }
    }

    /// A scene camera as this walker's subject frame sees it.
    pub fn camera_in_subject_frame(&self, camera: &Camera) -> Camera {
        camera.transformed(&self.world_from_subject().inverse())
    }
}

/// A checked scene (see the module docs and [`file`]).
#[derive(Debug, Clone)]
pub struct Scene {
    /// The scene file.
    pub path: PathBuf,
    /// The field, if the file names one.
    pub field: Option<PathBuf>,
    /// Seconds.
    pub start: f32,
    /// Seconds, exclusive (equal to `start` for a still).
    pub end: f32,
    /// Frames per second.
    pub fps: f32,
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

/// Albedo of `floor = "ground"`: a mid-grey ground.
const GROUND_FLOOR_ALBEDO: f32 = 0.3;

fn word<'w>(r: &Reporter, field: &str, v: &'w At<String>, allowed: &[&str]) -> Result<&'w str> {
    let s = v.get_ref().as_str();
    if allowed.contains(&s) {
        Ok(s)
    } else {
        Err(r.error(
            field,
            v.span(),
            format!("`{s}`: expected one of {allowed:?}"),
        ))
    }
}

fn finite(r: &Reporter, field: &str, v: &At<f32>) -> Result<f32> {
    let x = *v.get_ref();
    if x.is_finite() {
        Ok(x)
    } else {
        Err(r.error(field, v.span(), format!("{x} is not a finite number")))
    }
}

fn env(r: &Reporter, field: &str, v: &At<String>) -> Result<EnvSource> {
    let source: EnvSource = v
        .get_ref()
        .parse()
        .map_err(|e: String| r.error(field, v.span(), e))?;
    Ok(match source {
        EnvSource::File(p) => EnvSource::File(r.resolve(&p.to_string_lossy())),
        other => other,
    })
}

fn ground(r: &Reporter, v: &At<toml::Value>) -> Result<GroundLook> {
    let number = |x: &toml::Value| x.as_float().or_else(|| x.as_integer().map(|i| i as f64));
    let albedo = match v.get_ref() {
        toml::Value::String(s) if s == "env" => return Ok(GroundLook::Environment),
        toml::Value::Array(a) if a.len() == 3 => {
            let c: Vec<f64> = a.iter().filter_map(number).collect();
            (c.len() == 3).then(|| [c[0] as f32, c[1] as f32, c[2] as f32])
        }
        other => number(other).map(|a| [a as f32; 3]),
    };
    match albedo {
        Some(a) if a.iter().all(|x| (0.0..=1.0).contains(x)) => Ok(GroundLook::Albedo(a)),
        _ => Err(r.error(
            "composite.ground",
            v.span(),
            "expected \"env\", an albedo in 0 to 1, or [r, g, b]",
        )),
    }
}

impl Scene {
    /// The field to render the scene from: `given` (the command line's), else the one the
    /// file names; an error naming the file when neither does.
    pub fn field_or(&self, given: Option<&Path>) -> Result<PathBuf> {
        given
            .map(Path::to_path_buf)
            .or_else(|| self.field.clone())
            .ok_or_else(|| {
                RenderError::BadParameter(format!(
                    "{}: no field (give field = \"...\" or --field)",
                    self.path.display()
                ))
            })
    }

    /// Reads and checks the scene file at `path`.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| frf_core::CoreError::io(path, e))?;
        Self::parse(path, &text)
    }

    /// Checks the scene file `text` read from `path`.
    pub fn parse(path: &Path, text: &str) -> Result<Self> {
        let raw: SceneToml = file::parse(path, text)?;
        let r = Reporter::new(path, text);
        let t = raw.time.get_ref();
        let (start, end, fps) = (
            finite(&r, "time.start", &t.start)?,
            finite(&r, "time.end", &t.end)?,
            finite(&r, "time.fps", &t.fps)?,
        );
        if end < start {
            return Err(r.error(
                "time.end",
                t.end.span(),
                format!("{end} s is before start {start} s"),
            ));
        }
        if !(fps > 0.0 && fps <= 1000.0) {
            return Err(r.error(
                "time.fps",
                t.fps.span(),
                format!("{fps}: expected (0, 1000]"),
            ));
        }
        if ((end - start) * fps) as f64 > MAX_FRAMES as f64 {
            return Err(r.error(
                "time",
                raw.time.span(),
                format!("{} frames: at most {MAX_FRAMES}", (end - start) * fps),
            ));
        }
        let o = &raw.output;
        let size = match &o.size {
            Some(s) => {
                let [w, h] = *s.get_ref();
                if !(1..=MAX_SIDE_PX).contains(&w) || !(1..=MAX_SIDE_PX).contains(&h) {
                    return Err(r.error(
                        "output.size",
                        s.span(),
                        format!("{w}x{h}: each side 1 to {MAX_SIDE_PX}"),
                    ));
                }
                Some((w, h))
            }
            None => None,
        };
        let exposure = finite(&r, "output.exposure", &o.exposure)?;
        if exposure.abs() > 30.0 {
            return Err(r.error(
                "output.exposure",
                o.exposure.span(),
                format!("{exposure} stops: expected -30 to 30"),
            ));
        }
        let preview = match word(&r, "output.preview", &o.preview, &["apng", "gif", "none"])? {
            "apng" => Preview::Apng,
            "gif" => Preview::Gif,
            _ => Preview::None,
        };
        let variant = Variant::ALL
            .into_iter()
            .find(|v| v.name() == o.variant.get_ref())
            .ok_or_else(|| {
                r.error(
                    "output.variant",
                    o.variant.span(),
                    format!(
                        "`{}`: expected nearest, linear, twoway or fourway",
                        o.variant.get_ref()
                    ),
                )
            })?;

        let l = raw.lighting.get_ref();
        let mut lighting = vec![LightKey {
            time: f32::NEG_INFINITY,
            env: env(&r, "lighting.env", &l.env)?,
            yaw: finite(&r, "lighting.yaw_deg", &l.yaw_deg)?.to_radians(),
            intensity: finite(&r, "lighting.intensity", &l.intensity)?,
        }];
        for (i, k) in l.key.iter().enumerate() {
            let key = k.get_ref();
            let field = |name: &str| format!("lighting.key[{i}].{name}");
            let prev = lighting.last().expect("at least the base").clone();
            let time = finite(&r, &field("time"), &key.time)?;
            if time <= prev.time {
                return Err(r.error(
                    &field("time"),
                    key.time.span(),
                    format!("{time} s does not follow the previous key"),
                ));
            }
            lighting.push(LightKey {
                time,
                env: match &key.env {
                    Some(e) => env(&r, &field("env"), e)?,
                    None => prev.env.clone(),
                },
                yaw: match &key.yaw_deg {
                    Some(y) => finite(&r, &field("yaw_deg"), y)?.to_radians(),
                    None => prev.yaw,
                },
                intensity: match &key.intensity {
                    Some(v) => finite(&r, &field("intensity"), v)?,
                    None => prev.intensity,
                },
            });
        }
        for (i, k) in lighting.iter().enumerate() {
            if !(k.intensity >= 0.0 && k.intensity <= 1e6) {
                let span = if i == 0 {
                    l.intensity.span()
                } else {
                    l.key[i - 1].span()
                };
                return Err(r.error(
                    "lighting.intensity",
                    span,
                    format!("{}: expected 0 to 10^6", k.intensity),
                ));
            }
        }
        if lighting.iter().any(|k| k.env == EnvSource::None) && lighting.len() > 1 {
            return Err(r.error("lighting.env", l.env.span(), "`none` cannot be keyframed"));
        }
        let floor = match word(&r, "lighting.floor", &l.floor, &["env", "ground"])? {
            "env" => FloorModel::Environment,
            _ => FloorModel::LambertianGround {
                albedo: [GROUND_FLOOR_ALBEDO; 3],
            },
        };

        let c = raw.camera.get_ref();
        let camera = match (&c.orbit, c.key.is_empty()) {
            (Some(o), true) => {
                let orbit = o.get_ref();
                let orbit = Orbit {
                    radius: orbit.radius,
                    height: orbit.height,
                    start_deg: orbit.start_deg,
                    sweep_deg: orbit.sweep_deg,
                    look_at: Vec3::from(orbit.look_at),
                    fov_deg: orbit.fov_deg,
                };
                orbit
                    .validate()
                    .map_err(|e| r.error("camera.orbit", o.span(), e))?;
                Trajectory::Orbit(orbit)
            }
            (None, false) => {
                let keys = c.key.iter().map(|k| *k.get_ref()).collect();
                Trajectory::Path(
                    CameraPath::new(keys)
                        .map_err(|e| r.error("camera.key", raw.camera.span(), e))?,
                )
            }
            _ => {
                return Err(r.error(
                    "camera",
                    raw.camera.span(),
                    "give either an orbit or keys ([[camera.key]])",
                ));
            }
        };

        let comp = &raw.composite;
        let backdrop = match word(
            &r,
            "composite.backdrop",
            &comp.backdrop,
            &["env", "plate", "none"],
        )? {
            "env" => BackdropSpec::Environment(match &comp.ground {
                Some(g) => ground(&r, g)?,
                None => GroundLook::Environment,
            }),
            "plate" => {
                let plate = comp.plate.as_ref().ok_or_else(|| {
                    r.error(
                        "composite.plate",
                        comp.backdrop.span(),
                        "backdrop = \"plate\" needs plate = \"FILE\"",
                    )
                })?;
                if !matches!(&camera, Trajectory::Path(p) if p.keys.len() == 1) {
                    return Err(r.error(
                        "camera",
                        raw.camera.span(),
                        "a plate is seen by its own camera: give one camera key",
                    ));
                }
                BackdropSpec::Plate(r.resolve(plate.get_ref()))
            }
            _ => BackdropSpec::None,
        };
        if matches!(backdrop, BackdropSpec::Environment(_))
            && lighting.iter().any(|k| k.env == EnvSource::None)
        {
            return Err(r.error(
                "composite.backdrop",
                comp.backdrop.span(),
                "an environment backdrop needs an environment (lighting.env)",
            ));
        }
        let shadow = match word(
            &r,
            "composite.shadow",
            &comp.shadow,
            &["maps", "traced", "none"],
        )? {
            "maps" => ShadowSpec::Maps,
            "traced" => ShadowSpec::Traced,
            _ => ShadowSpec::None,
        };

        let mut instances = Vec::new();
        for (i, inst) in raw.instance.iter().enumerate() {
            let v = inst.get_ref();
            let finite_all = v.position.iter().all(|c| c.is_finite())
                && v.heading_deg.is_finite()
                && v.time_offset.is_finite();
            if !finite_all || v.position.iter().any(|c| c.abs() > 1e4) || v.time_offset.abs() > 1e6
            {
                return Err(r.error(
                    &format!("instance[{i}]"),
                    inst.span(),
                    "values must be finite (positions within 10 km)",
                ));
            }
            if v.position[1] != 0.0 {
                return Err(r.error(
                    &format!("instance[{i}].position"),
                    inst.span(),
                    "walkers stand on the ground: y must be 0",
                ));
            }
            instances.push(Instance {
                position: Vec3::from(v.position),
                heading: v.heading_deg.to_radians(),
                time_offset: v.time_offset,
            });
        }
        if instances.is_empty() {
            instances.push(Instance {
                position: Vec3::ZERO,
                heading: 0.0,
                time_offset: 0.0,
            });
        }
        Ok(Self {
            path: path.to_path_buf(),
            field: raw.field.as_ref().map(|f| r.resolve(f.get_ref())),
            start,
            end,
            fps,
            size,
            exposure,
            layers: o.layers,
            preview,
            variant,
            lighting,
            floor,
            camera,
            backdrop,
            shadow,
            instances,
        })
    }

    /// The frame times: `start + i / fps` before `end`; one frame (a still) when
    /// `end == start`.
    pub fn frame_times(&self) -> Vec<f32> {
        let n = ((self.end - self.start) as f64 * self.fps as f64 - 1e-6)
            .ceil()
            .max(1.0) as usize;
        (0..n).map(|i| self.start + i as f32 / self.fps).collect()
    }

    /// The camera at time `t`, frames of `size`: an orbit sweeps the time range (a full
    /// turn loops without repeating its first frame); keys are in scene seconds.
    pub fn camera_at(&self, t: f32, size: (u32, u32)) -> Result<Camera> {
        match &self.camera {
            Trajectory::Path(p) => p.at(t).camera(size.0, size.1),
            Trajectory::Orbit(o) => {
                let span = self.end - self.start;
                let f = if span > 0.0 {
                    (t - self.start) / span
                } else {
                    0.0
                };
                o.key(f).camera(size.0, size.1)
            }
        }
    }

    /// The lighting at time `t`: piecewise linear between keys, the map cross-faded from
    /// one key's to the next's when they differ.
    pub fn lighting_at(&self, t: f32) -> LightingAt {
        let k = &self.lighting;
        let i = k.partition_point(|key| key.time <= t).max(1) - 1;
        let a = &k[i];
        let Some(b) = k.get(i + 1) else {
            return LightingAt {
                maps: vec![(a.env.clone(), 1.0)],
                yaw: a.yaw,
                intensity: a.intensity,
            };
        };
        let s = if a.time.is_finite() {
            ((t - a.time) / (b.time - a.time)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let maps = if a.env == b.env || s == 0.0 {
            vec![(a.env.clone(), 1.0)]
        } else {
            vec![(a.env.clone(), 1.0 - s), (b.env.clone(), s)]
        };
        LightingAt {
            maps,
            yaw: a.yaw + s * (b.yaw - a.yaw),
            intensity: a.intensity + s * (b.intensity - a.intensity),
        }
    }

    /// The pose of the walk cycle (`poses_per_cycle` poses over `cycle_seconds`) that
    /// instance `i` shows at time `t`: the nearest pose to its phase, looping.
    pub fn pose_at(&self, i: usize, t: f32, cycle_seconds: f64, poses_per_cycle: u32) -> u32 {
        let n = poses_per_cycle.max(1) as f64;
        let phase = ((t + self.instances[i].time_offset) as f64 / cycle_seconds).rem_euclid(1.0);
        ((phase * n).round() as u32) % poses_per_cycle.max(1)
    }

    /// Every environment the scene names.
    pub fn environments(&self) -> Vec<EnvSource> {
        let mut out: Vec<EnvSource> = Vec::new();
        for k in &self.lighting {
            if !out.contains(&k.env) {
                out.push(k.env.clone());
            }
        }
        out
    }
}

#[cfg(test)]
mod tests;
