//! One truth image on request (`frf stage truth`): the walker at a pose (or any instant
//! of its cycle), seen by a captured view's camera or a virtual one, lit by an
//! environment (reduced to median-cut lights) or by a weighted combination of the basis
//! conditions.

use frf_core::BadArgument;
use frf_core::camera::Camera;
use frf_core::env::EnvMap;
use frf_core::image::{Image, Rgba};
use frf_core::io::rgba_from;
use glam::Vec3;

use crate::error::Result;
use crate::stage::Stage;
use crate::truth::environment_lights;

/// Who sees the walker.
#[derive(Debug, Clone, Copy)]
pub enum TruthCamera {
    /// The camera of captured view `(u, v)` of the pose, as seen from the subject.
    View(usize, usize),
    /// A virtual camera: centre and point looked at (metres, subject frame), vertical
    /// field of view in degrees, and frame size.
    Eye {
        /// Centre.
        eye: [f32; 3],
        /// Point looked at.
        look_at: [f32; 3],
        /// Vertical field of view, degrees.
        fov_deg: f32,
        /// Width and height, pixels.
        size: (u32, u32),
    },
}

/// What lights the walker.
#[derive(Debug, Clone)]
pub enum TruthLight {
    /// An environment (subject frame, already rotated) reduced to `lights` median-cut
    /// lights; `name` says which in the report.
    Environment {
        /// The map.
        env: EnvMap,
        /// Its name.
        name: String,
        /// Median-cut lights.
        lights: usize,
    },
    /// A weighted sum of the basis conditions, the turntable at `turntable_deg`.
    Basis {
        /// Per condition.
        weights: Vec<f32>,
        /// Degrees.
        turntable_deg: f32,
    },
}

/// A truth image and what made it.
pub struct TruthShot {
    /// Linear, premultiplied.
    pub rgba: Image<Rgba>,
    /// The camera.
    pub camera: Camera,
    /// Directional lights it was lit by.
    pub lights: usize,
    /// The lighting, in words.
    pub what: String,
    /// Mean alpha.
    pub coverage: f32,
}

impl Stage {
    /// The truth image of pose `pose` (or, with `time`, the walker at that instant of
    /// its cycle, seconds) seen by `camera`, lit by `light`.
    pub fn truth_shot(
        &self,
        pose: u32,
        camera: TruthCamera,
        light: &TruthLight,
        time: Option<f64>,
    ) -> Result<TruthShot> {
        let camera = match camera {
            TruthCamera::View(u, v) => self.subject_camera(pose, u, v)?,
            TruthCamera::Eye {
                eye,
                look_at,
                fov_deg,
                size,
            } => Camera::look_at(
                Vec3::from(eye),
                Vec3::from(look_at),
                Vec3::Y,
                fov_deg.to_radians(),
                size.0,
                size.1,
            )?,
        };
        let (lights, what) = match light {
            TruthLight::Environment { env, name, lights } => {
                frf_core::argument::within("--lights", *lights, 1, 65536, "")
                    .map_err(frf_core::CoreError::from)?;
                (
                    environment_lights(env, *lights),
                    format!("environment {name}"),
                )
            }
            TruthLight::Basis {
                weights,
                turntable_deg,
            } => (
                self.basis_lights(weights, turntable_deg.to_radians())?,
                "basis combination".to_string(),
            ),
        };
        let instant = match time {
            Some(t) if !t.is_finite() => {
                let e = BadArgument::new("--time", t, "a finite number of seconds");
                return Err(frf_core::CoreError::from(e).into());
            }
            Some(t) => t.rem_euclid(self.config().gait.cycle_seconds()),
            None => self.pose_time_s(pose),
        };
        let image = self.truth_image_at(instant, &camera, &lights);
        let rgba = rgba_from(&image.color, &image.alpha)?;
        let alpha = image.alpha.pixels();
        Ok(TruthShot {
            rgba,
            camera,
            lights: lights.len(),
            what,
            coverage: alpha.iter().sum::<f32>() / alpha.len() as f32,
        })
    }
}

/// Parses basis weights `condition=weight,...` over `conditions` conditions (the others
/// weigh 0).
pub fn parse_basis(spec: &str, conditions: usize) -> Result<Vec<f32>> {
    let mut weights = vec![0.0; conditions];
    for item in spec.split(',') {
        let bad = || {
            let allowed = format!("condition=weight with condition < {conditions}");
            frf_core::CoreError::from(BadArgument::new(
                "--basis item",
                format!("{item:?}"),
                allowed,
            ))
        };
        let (c, w) = item.split_once('=').ok_or_else(bad)?;
        let c: usize = c.trim().parse().map_err(|_| bad())?;
        let w: f32 = w.trim().parse().map_err(|_| bad())?;
        if c >= conditions || !w.is_finite() {
            return Err(bad().into());
        }
        weights[c] = w;
    }
    Ok(weights)
}
