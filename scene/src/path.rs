//! Virtual camera paths: keyframes of position, look-at point and vertical field of view
//! at given times, interpolated smoothly (a Catmull–Rom spline with tangents from the
//! neighbouring keys over their time spans, so that unevenly spaced keys keep a
//! continuous velocity; clamped at the ends), and the orbit shortcut (exactly on its
//! circle).
//!
//! A path file is TOML in the subject frame (metres, `+y` up; see the conventions):
//!
//! ```toml
//! [[key]]
//! time = 0.0                 # seconds, strictly increasing
//! position = [2.5, 1.4, 3.0]
//! look_at = [0.0, 0.9, 0.0]
//! fov_deg = 30.0             # vertical field of view
//!
//! [[key]]
//! time = 2.0
//! position = [-2.5, 1.0, 3.0]
//! look_at = [0.0, 0.9, 0.0]
//! fov_deg = 35.0
//! ```

use std::path::Path;

use frf_core::BadArgument;
use frf_core::camera::Camera;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::error::{Result, SceneError};

/// Largest camera path (or scene) file, bytes: hand-written text.
pub const MAX_FILE_BYTES: u64 = 16 << 20;

/// The narrowest vertical field of view a camera may have, degrees (exclusive).
pub const MIN_FOV_DEG: f32 = 0.1;
/// The widest, degrees (exclusive): a pinhole's image diverges toward 180.
pub const MAX_FOV_DEG: f32 = 170.0;

/// One keyframe.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Key {
    /// Time, seconds (64-bit, as every time of a scene).
    pub time: f64,
    /// Camera centre, subject frame, metres.
    pub position: [f32; 3],
    /// Point the camera looks at.
    pub look_at: [f32; 3],
    /// Vertical field of view, degrees.
    pub fov_deg: f32,
}

/// A validated camera path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraPath {
    /// Keyframes in increasing time.
    #[serde(rename = "key")]
    pub keys: Vec<Key>,
}

/// The orbit shortcut: a circle about the vertical axis through `look_at`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    /// Horizontal distance from the axis, metres.
    pub radius: f32,
    /// Camera height, metres.
    pub height: f32,
    /// Azimuth of the first frame, degrees (0 on `+z`, increasing toward `+x`).
    pub start_deg: f32,
    /// Angle swept over the path, degrees (360 for a full turn).
    pub sweep_deg: f32,
    /// Point looked at.
    pub look_at: Vec3,
    /// Vertical field of view, degrees.
    pub fov_deg: f32,
}

/// Key `key` of a path refused for `problem`.
fn key_error(key: usize, problem: String) -> SceneError {
    SceneError::CameraKey { key, problem }
}

impl Key {
    /// The camera of this key.
    pub fn camera(&self, width: u32, height: u32) -> Result<Camera> {
        Ok(Camera::look_at(
            Vec3::from(self.position),
            Vec3::from(self.look_at),
            Vec3::Y,
            self.fov_deg.to_radians(),
            width,
            height,
        )?)
    }

    fn check(&self, i: usize) -> Result<()> {
        let finite = self.time.is_finite()
            && self
                .position
                .iter()
                .chain(&self.look_at)
                .all(|c| c.is_finite())
            && self.fov_deg.is_finite();
        if !finite {
            return Err(key_error(i, "a value is not finite".into()));
        }
        if !(self.fov_deg > MIN_FOV_DEG && self.fov_deg < MAX_FOV_DEG) {
            return Err(key_error(
                i,
                format!(
                    "fov_deg {} is outside ({MIN_FOV_DEG}, {MAX_FOV_DEG})",
                    self.fov_deg
                ),
            ));
        }
        let forward = Vec3::from(self.look_at) - Vec3::from(self.position);
        if forward.length() < 1e-4 || forward.normalize().cross(Vec3::Y).length() < 1e-4 {
            return Err(key_error(
                i,
                "look_at equals position or lies straight above or below it".into(),
            ));
        }
        Ok(())
    }
}

impl CameraPath {
    /// A path from keys; refuses an empty path, non-increasing times, non-finite values,
    /// absurd fields of view and degenerate views.
    pub fn new(keys: Vec<Key>) -> Result<Self> {
        if keys.is_empty() {
            return Err(BadArgument::new("a camera path", "of no key", "at least one key").into());
        }
        for (i, k) in keys.iter().enumerate() {
            k.check(i)?;
            if i > 0 && k.time <= keys[i - 1].time {
                return Err(key_error(
                    i,
                    format!("time {} does not follow {}", k.time, keys[i - 1].time),
                ));
            }
        }
        Ok(Self { keys })
    }

    /// Reads and validates a TOML path file; errors name the file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = frf_core::io::read_text(path, MAX_FILE_BYTES)?;
        let in_file = |problem: String| SceneError::CameraPath {
            path: path.to_path_buf(),
            problem,
        };
        let raw: Self = toml::from_str(&text).map_err(|e| in_file(e.to_string()))?;
        Self::new(raw.keys).map_err(|e| in_file(e.to_string()))
    }

    /// Time span `(first, last)`.
    pub fn span(&self) -> (f64, f64) {
        (self.keys[0].time, self.keys[self.keys.len() - 1].time)
    }

    /// The interpolated key at time `t` (clamped to the span).
    pub fn at(&self, t: f64) -> Key {
        let k = &self.keys;
        let (t0, t1) = self.span();
        let t = t.clamp(t0, t1);
        if k.len() == 1 {
            return k[0];
        }
        let times: Vec<f64> = k.iter().map(|key| key.time).collect();
        let along = |f: &dyn Fn(&Key) -> Vec3| crate::spline::catmull_rom(&times, &|j| f(&k[j]), t);
        let position = along(&|key| Vec3::from(key.position));
        let look_at = along(&|key| Vec3::from(key.look_at));
        let fov = along(&|key| Vec3::splat(key.fov_deg)).x;
        Key {
            time: t,
            position: position.to_array(),
            look_at: look_at.to_array(),
            fov_deg: fov.clamp(MIN_FOV_DEG, MAX_FOV_DEG),
        }
    }

    /// `frames` cameras of `width` x `height` evenly spaced in time over the span (the
    /// first and last frames on the first and last keys).
    pub fn cameras(&self, frames: usize, width: u32, height: u32) -> Result<Vec<Camera>> {
        if frames == 0 || frames > 100_000 {
            return Err(BadArgument::new("frames", frames, "1 to 100000").into());
        }
        let (t0, t1) = self.span();
        (0..frames)
            .map(|f| {
                let s = if frames == 1 {
                    0.0
                } else {
                    f as f64 / (frames - 1) as f64
                };
                self.at(t0 + s * (t1 - t0)).camera(width, height)
            })
            .collect()
    }
}

impl Orbit {
    /// Refuses non-finite or absurd parameters, each named as a field of the orbit
    /// (`radius`, `height`, `start_deg`, `sweep_deg`, `look_at`, `fov_deg`; the command
    /// line renames them as its flags).
    pub fn validate(&self) -> Result<(), BadArgument> {
        if !(self.radius.is_finite() && self.radius > 1e-3 && self.radius < 1e4) {
            let allowed = "more than 0.001 and less than 10000 metres";
            return Err(BadArgument::new("radius", self.radius, allowed));
        }
        if !(self.sweep_deg.is_finite() && self.sweep_deg.abs() <= 3600.0) {
            let allowed = "-3600 to 3600 degrees";
            return Err(BadArgument::new("sweep_deg", self.sweep_deg, allowed));
        }
        if !(self.fov_deg > MIN_FOV_DEG && self.fov_deg < MAX_FOV_DEG) {
            let allowed = format!("more than {MIN_FOV_DEG} and less than {MAX_FOV_DEG} degrees");
            return Err(BadArgument::new("fov_deg", self.fov_deg, allowed));
        }
        let finite = [
            (
                "height",
                self.height.is_finite(),
                format!("{}", self.height),
            ),
            (
                "start_deg",
                self.start_deg.is_finite(),
                format!("{}", self.start_deg),
            ),
            (
                "look_at",
                self.look_at.is_finite(),
                format!("{:?}", self.look_at.to_array()),
            ),
        ];
        match finite.into_iter().find(|(_, ok, _)| !ok) {
            Some((name, _, value)) => Err(BadArgument::new(name, value, "finite values")),
            // The camera is `radius` from the vertical through `look_at`: never straight
            // above or below it.
            None => Ok(()),
        }
    }

    /// The key at fraction `f` of the sweep: exactly on the circle.
    pub fn key(&self, f: f32) -> Key {
        let a = (self.start_deg + f * self.sweep_deg).to_radians();
        Key {
            time: f as f64,
            position: [
                self.look_at.x + self.radius * a.sin(),
                self.height,
                self.look_at.z + self.radius * a.cos(),
            ],
            look_at: self.look_at.to_array(),
            fov_deg: self.fov_deg,
        }
    }
}

/// Where the virtual camera goes: keyframes or an orbit.
#[derive(Debug, Clone, PartialEq)]
pub enum Trajectory {
    /// A keyframed path.
    Path(CameraPath),
    /// The orbit shortcut.
    Orbit(Orbit),
}

impl Trajectory {
    /// `frames` cameras of `width` x `height`, evenly spaced in time. A full-turn orbit
    /// does not repeat its first frame at the end, so that it loops.
    pub fn cameras(&self, frames: usize, width: u32, height: u32) -> Result<Vec<Camera>> {
        match self {
            Self::Path(p) => p.cameras(frames, width, height),
            Self::Orbit(o) => {
                o.validate()?;
                if frames == 0 || frames > 100_000 {
                    return Err(BadArgument::new("frames", frames, "1 to 100000").into());
                }
                let closed = (o.sweep_deg.abs() % 360.0).abs() < 1e-3;
                let steps = if closed || frames == 1 {
                    frames
                } else {
                    frames - 1
                };
                (0..frames)
                    .map(|f| o.key(f as f32 / steps as f32).camera(width, height))
                    .collect()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f64, x: f32) -> Key {
        Key {
            time,
            position: [x, 1.0, 3.0],
            look_at: [0.0, 0.9, 0.0],
            fov_deg: 30.0 + x,
        }
    }

    #[test]
    fn the_path_passes_through_its_keys_and_is_smooth() {
        let p = CameraPath::new(vec![key(0.0, 0.0), key(1.0, 1.0), key(3.0, -2.0)]).unwrap();
        for k in &p.keys {
            let at = p.at(k.time);
            assert!((Vec3::from(at.position) - Vec3::from(k.position)).length() < 1e-5);
            assert!((at.fov_deg - k.fov_deg).abs() < 1e-4);
        }
        // Velocity is continuous across the middle key.
        let x = |t: f64| p.at(t).position[0];
        let (e, t) = (1e-3, 1.0);
        let before = (x(t) - x(t - e)) / e as f32;
        let after = (x(t + e) - x(t)) / e as f32;
        assert!((before - after).abs() < 0.02, "{before} vs {after}");
    }

    #[test]
    fn the_orbit_stays_on_its_circle() {
        let o = Orbit {
            radius: 3.0,
            height: 1.2,
            start_deg: 10.0,
            sweep_deg: 360.0,
            look_at: Vec3::new(0.0, 0.9, 0.0),
            fov_deg: 30.0,
        };
        let cams = Trajectory::Orbit(o).cameras(36, 16, 24).unwrap();
        for (i, c) in cams.iter().enumerate() {
            let e = c.centre();
            let r = (e.x * e.x + e.z * e.z).sqrt();
            assert!((r - 3.0).abs() < 1e-5, "radius {r}");
            assert!((e.y - 1.2).abs() < 1e-5);
            // Ten degrees apart, the last one short of the first: the orbit loops.
            let next = cams[(i + 1) % cams.len()].centre();
            let step = (e - Vec3::new(0.0, 1.2, 0.0))
                .angle_between(next - Vec3::new(0.0, 1.2, 0.0))
                .to_degrees();
            assert!((step - 10.0).abs() < 1e-2, "step {step}");
        }
        let mut bad = o;
        bad.radius = f32::INFINITY;
        let e = Trajectory::Orbit(bad)
            .cameras(4, 8, 8)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "radius inf: expected more than 0.001 and less than 10000 metres"
        );
    }

    #[test]
    fn bad_paths_are_refused_with_reasons() {
        let e = CameraPath::new(vec![]).unwrap_err().to_string();
        assert!(e.contains("at least one key"), "{e}");
        let e = CameraPath::new(vec![key(1.0, 0.0), key(1.0, 1.0)]).unwrap_err();
        assert!(e.to_string().contains("key 1"), "{e}");
        let mut k = key(0.0, 0.0);
        k.fov_deg = 0.0;
        let e = CameraPath::new(vec![k]).unwrap_err().to_string();
        assert!(e.contains("key 0: fov_deg 0 is outside"), "{e}");
        k = key(0.0, 0.0);
        k.position[1] = f32::NAN;
        let e = CameraPath::new(vec![k]).unwrap_err().to_string();
        assert!(e.contains("key 0: a value is not finite"), "{e}");
        k = key(0.0, 0.0);
        k.position = [0.0, 5.0, 0.0];
        let e = CameraPath::new(vec![k]).unwrap_err().to_string();
        assert!(e.contains("key 0: look_at equals position"), "{e}");
        let p = CameraPath::new(vec![key(0.0, 0.0)]).unwrap();
        let e = p.cameras(0, 8, 8).unwrap_err().to_string();
        assert_eq!(e, "frames 0: expected 1 to 100000");
        let text = "[[key]]\ntime = 0.0\nposition = [1.0, 1.0, 3.0]\nlook_at = [0.0, 0.9, 0.0]\nfov_deg = 30.0\nzoom = 2\n";
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("path.toml");
        std::fs::write(&f, text).unwrap();
        let e = CameraPath::load(&f).unwrap_err().to_string();
        assert!(e.contains("path.toml") && e.contains("zoom"), "{e}");
    }
}
