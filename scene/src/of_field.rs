//! The scene of a field given without a scene file (`frf render FIELD --orbit ...`,
//! `frf view FIELD`): one walker at the origin of the field's subject frame, its walk at
//! a pose, lit by one environment ([`FieldLook`]), seen along a camera path, over a
//! backdrop with a shadow. A still at time 0 by default; the viewer plays it.

use std::path::Path;

use frf_core::env::EnvSource;
use frf_reflectance::FieldHeader;
use frf_reflectance::project::FloorModel;
use frf_render::composite::GroundLook;
use frf_render::morph::Variant;
use glam::Vec3;

use crate::path::{Orbit, Trajectory};
use crate::plan::ShotFrame;
use crate::{BackdropSpec, Instance, LightKey, Preview, Scene, ShadowSpec};

/// The rate of a field's preview (a typical video rate).
pub const FIELD_PREVIEW_FPS: f64 = 12.0;

/// How a field is shown: what a scene file would say of its lighting, camera, backdrop
/// and shadow.
#[derive(Debug, Clone)]
pub struct FieldLook {
    /// The environment.
    pub env: EnvSource,
    /// Its yaw, degrees.
    pub yaw_deg: f64,
    /// A sun added to it (`--sun`).
    pub sun: Option<frf_core::sun::Sun>,
    /// What lights the subject from below.
    pub floor: FloorModel,
    /// The camera.
    pub camera: Trajectory,
    /// What the walker is put over.
    pub backdrop: BackdropSpec,
    /// Where its shadow comes from.
    pub shadow: ShadowSpec,
}

impl FieldLook {
    /// How the viewer shows a field: lit by `env` (turned by `yaw_deg`) over that
    /// environment with the maps' shadow (nothing behind it unlit), the plan of its live
    /// shot made from an orbit around the walker (the viewer starts at a captured view).
    pub fn viewer(env: EnvSource, yaw_deg: f64, floor: FloorModel) -> Self {
        let lit = env != EnvSource::None;
        FieldLook {
            env,
            yaw_deg,
            sun: None,
            floor,
            camera: Trajectory::Orbit(Orbit {
                radius: 3.2,
                height: 1.4,
                start_deg: 0.0,
                sweep_deg: 360.0,
                look_at: Vec3::new(0.0, 0.9, 0.0),
                fov_deg: 35.0,
            }),
            backdrop: if lit {
                BackdropSpec::Environment(GroundLook::Environment)
            } else {
                BackdropSpec::None
            },
            shadow: ShadowSpec::Maps,
        }
    }
}

impl Scene {
    /// The scene of the field at `field` (whose header is `header`) seen as `look`: one
    /// walker at the origin, heading 0, its walk `pose` poses into the cycle; a still at
    /// time 0 in four-way interpolation, with an animated PNG preview at
    /// [`FIELD_PREVIEW_FPS`]. Callers that play it set `end`, `fps` and `size`.
    pub fn of_field(field: &Path, header: &FieldHeader, pose: u32, look: FieldLook) -> Scene {
        let cycle = f64::from(header.poses_per_cycle.max(1));
        Scene {
            path: field.to_path_buf(),
            field: Some(field.to_path_buf()),
            start: 0.0,
            end: 0.0,
            fps: FIELD_PREVIEW_FPS,
            interpolate: None,
            size: None,
            exposure: 0.0,
            layers: false,
            preview: Preview::Apng,
            variant: Variant::FourWay,
            lighting: vec![LightKey {
                time: f64::NEG_INFINITY,
                env: look.env,
                yaw_deg: look.yaw_deg,
                intensity: 1.0,
            }],
            sun: look.sun,
            probes: None,
            floor: look.floor,
            camera: look.camera,
            backdrop: look.backdrop,
            shadow: look.shadow,
            instances: vec![Instance::standing(
                Vec3::ZERO,
                0.0,
                f64::from(pose) / cycle * header.cycle_seconds,
            )],
        }
    }

    /// `n` frames of `size` along the camera path, the walk frozen at time 0 (a field
    /// render: the walker's time offset picks its pose).
    pub fn frozen_frames(&self, n: usize, size: (u32, u32)) -> crate::Result<Vec<ShotFrame>> {
        let frames = self
            .camera
            .cameras(n, size.0, size.1)?
            .into_iter()
            .enumerate()
            .map(|(index, camera)| ShotFrame {
                index,
                time: 0.0,
                camera,
            })
            .collect();
        Ok(frames)
    }
}
