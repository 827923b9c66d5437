//! Ground truth. Because the stage knows its scene exactly, it can say for every pixel
//! which point of the body it shows, and so:
//!
//! - the **true optical flow** between any two views or instants: the surface point seen
//!   through pixel `s` of view A, moved with its body part to view B's instant and
//!   projected into B's camera, lands at `s + F(s)` ([`frf_core::conventions`]); with a
//!   mask of the pixels whose point B cannot see (hidden by the body or out of frame);
//! - the **true alpha** of every view (sub-pixel coverage at the reference instant);
//! - the **true image** of the unperturbed walker at any pose from any virtual camera
//!   under any weighted combination of basis conditions or any HDR environment (reduced
//!   to many lights by median cut, [`frf_core::env::EnvMap::median_cut`]), so that the
//!   error of projecting an environment onto the basis can be told apart from the error of
//!   view interpolation.

use frf_core::camera::{Camera, Rigid};
use frf_core::env::EnvMap;
use frf_core::flo::UNKNOWN;
pub use frf_core::grid::Neighbour;
use frf_core::image::{FlowImage, GrayImage, Image, RgbImage};
use frf_core::light::DirLight;
use glam::Vec2;
use rayon::prelude::*;

use crate::error::{Result, StageError};
use crate::geometry::Ray;
use crate::render::{Scene, SurfacePoint, render};
use crate::rig;
use crate::stage::{Stage, ViewSetup};
use crate::studio::Illumination;

/// A point counts as visible in the other view when the other camera's ray meets the
/// body within this distance of it: 2 mm, well above f32 rounding at 5 m (~1 µm) and
/// far below the thinnest part (a hand, 5 cm).
const VISIBILITY_TOLERANCE_M: f32 = 0.002;

/// Median-cut lights used for truth images under an environment by default. Measured
/// (160x224, against 8192 lights, mean absolute luminance): 0.43 % for a uniform sphere,
/// 0.34 % for the built-in sky, 0.26 % for Grace Cathedral; each doubling halves it.
pub const DEFAULT_ENVIRONMENT_LIGHTS: usize = 512;

/// A true flow field and where its correspondences are hidden.
#[derive(Debug, Clone)]
pub struct TrueFlow {
    /// The flow; [`UNKNOWN`] where the source pixel does not see the actor.
    pub flow: FlowImage,
    /// 1 where the point is hidden in the target view (by the body, or out of its
    /// frame), 0 where it is visible or the flow is unknown.
    pub occluded: GrayImage,
}

/// The true flow from the pixels of a view whose surface points are `surface` (from
/// [`crate::render::Rendered::surface`]) to the view `to`.
pub fn flow_between(surface: &Image<Option<SurfacePoint>>, to: &ViewSetup) -> TrueFlow {
    let (w, h) = surface.size();
    let cam = &to.camera;
    let results: Vec<([f32; 2], f32)> = surface
        .pixels()
        .par_iter()
        .enumerate()
        .map(|(i, sp)| {
            let Some(sp) = sp else {
                return ([UNKNOWN; 2], 0.0);
            };
            let s = Vec2::new((i % w) as f32, (i / w) as f32);
            let p = to.actor.point(sp.part, sp.local);
            let Some(target) = cam.project(p) else {
                return ([UNKNOWN; 2], 0.0);
            };
            let inside = target.x >= -0.5
                && target.y >= -0.5
                && target.x <= cam.width as f32 - 0.5
                && target.y <= cam.height as f32 - 0.5;
            let to_point = p - cam.centre();
            let dist = to_point.length();
            let ray = Ray {
                origin: cam.centre(),
                dir: to_point / dist,
            };
            let visible = inside
                && to
                    .actor
                    .intersect(&ray, 0.0, f32::INFINITY)
                    .is_some_and(|hit| (hit.t - dist).abs() < VISIBILITY_TOLERANCE_M);
            let f = target - s;
            ([f.x, f.y], if visible { 0.0 } else { 1.0 })
        })
        .collect();
    let (flow, occluded): (Vec<_>, Vec<_>) = results.into_iter().unzip();
    TrueFlow {
        flow: Image::from_vec(w, h, flow).expect("w*h pixels"),
        occluded: Image::from_vec(w, h, occluded).expect("w*h pixels"),
    }
}

/// A truth image: premultiplied colour on black and alpha.
#[derive(Debug, Clone)]
pub struct TruthImage {
    /// Premultiplied linear colour.
    pub color: RgbImage,
    /// Coverage.
    pub alpha: GrayImage,
}

impl Stage {
    /// The surface points and alpha of view `(cycle, camera)` at pose `pose`'s reference
    /// instant (the true matte of that view).
    pub fn reference_surface(
        &self,
        pose: u32,
        cycle: usize,
        camera: usize,
    ) -> Result<(Image<Option<SurfacePoint>>, GrayImage)> {
        let setup = self.view_setup(pose, cycle, camera, 0.0)?;
        let scene = Scene {
            actor: Some(&setup.actor),
            studio: false,
            illumination: &Illumination::Dark,
        };
        let r = render(&setup.camera, &scene, self.config().samples_per_axis);
        Ok((r.surface, r.alpha))
    }

    /// True flow from view `(cycle, camera)` to a grid neighbour at pose `pose` (both at
    /// the pose's reference instant). `None` if the neighbour does not exist.
    pub fn true_neighbour_flow(
        &self,
        pose: u32,
        cycle: usize,
        camera: usize,
        neighbour: Neighbour,
    ) -> Result<Option<TrueFlow>> {
        let Some((u2, v2)) = neighbour.of(cycle, camera, self.cycles(), self.cameras().len(), true)
        else {
            return Ok(None);
        };
        let (surface, _) = self.reference_surface(pose, cycle, camera)?;
        let to = self.view_setup(pose, u2, v2, 0.0)?;
        Ok(Some(flow_between(&surface, &to)))
    }

    /// True flow from the reference track frame T1 of a set to slot `slot` of the same set
    /// and view: `T1(s) ~ frame_slot(s + F(s))`.
    pub fn true_set_flow(
        &self,
        pose: u32,
        cycle: usize,
        camera: usize,
        slot: usize,
    ) -> Result<TrueFlow> {
        if slot >= self.schedule().len() {
            return Err(StageError::OutOfRange {
                what: "slot",
                value: slot.to_string(),
            });
        }
        let (surface, _) = self.reference_surface(pose, cycle, camera)?;
        let to = self.view_setup(pose, cycle, camera, rig::slot_time_offset_s(slot))?;
        Ok(flow_between(&surface, &to))
    }

    /// Capture view `(cycle, camera)` of pose `pose` at its reference instant, as seen
    /// from the subject frame (the world camera turned by `-θ`).
    pub fn subject_camera(&self, pose: u32, cycle: usize, camera: usize) -> Result<Camera> {
        let setup = self.view_setup(pose, cycle, camera, 0.0)?;
        let theta = self.turntable_angle(cycle, self.pose_time_s(pose));
        Ok(setup.camera.transformed(&Rigid::rotation_y(-theta)))
    }

    /// The true image of capture view `(cycle, camera)` at pose `pose`'s reference
    /// instant (the perturbed actor of that cycle, as filmed) under dome lights
    /// `lights_world`, without studio or noise: what a perfectly registered and matted
    /// frame of the set would be.
    pub fn true_view_image(
        &self,
        pose: u32,
        cycle: usize,
        camera: usize,
        lights_world: &[DirLight],
    ) -> Result<TruthImage> {
        let setup = self.view_setup(pose, cycle, camera, 0.0)?;
        let illumination = Illumination::Lights(lights_world.to_vec());
        let scene = Scene {
            actor: Some(&setup.actor),
            studio: false,
            illumination: &illumination,
        };
        let r = render(&setup.camera, &scene, self.config().samples_per_axis);
        Ok(TruthImage {
            color: r.color,
            alpha: r.alpha,
        })
    }

    /// The true image of the unperturbed walker at pose `pose`'s reference instant, seen by
    /// `camera` (subject frame) under `lights` (subject frame), without studio or noise.
    pub fn truth_image(&self, pose: u32, camera: &Camera, lights: &[DirLight]) -> TruthImage {
        self.truth_image_at(self.pose_time_s(pose), camera, lights)
    }

    /// [`Stage::truth_image`] at any instant of the walk: `time_s` seconds into its cycle
    /// (pose `k`'s instant is `k / 30` s; between two poses the walker is in between,
    /// as the gait is a continuous function of time).
    pub fn truth_image_at(&self, time_s: f64, camera: &Camera, lights: &[DirLight]) -> TruthImage {
        let actor = self.actor(None, time_s);
        let illumination = Illumination::Lights(lights.to_vec());
        let scene = Scene {
            actor: Some(&actor),
            studio: false,
            illumination: &illumination,
        };
        let r = render(camera, &scene, self.config().samples_per_axis);
        TruthImage {
            color: r.color,
            alpha: r.alpha,
        }
    }

    /// The surface points and alpha of the unperturbed walker at pose `pose`'s reference
    /// instant, seen by `camera` (subject frame): what [`Stage::truth_image`] shows, point
    /// by point.
    pub fn truth_surface(
        &self,
        pose: u32,
        camera: &Camera,
    ) -> (Image<Option<SurfacePoint>>, GrayImage) {
        let actor = self.actor(None, self.pose_time_s(pose));
        let scene = Scene {
            actor: Some(&actor),
            studio: false,
            illumination: &Illumination::Dark,
        };
        let r = render(camera, &scene, self.config().samples_per_axis);
        (r.surface, r.alpha)
    }

    /// The true flow, for the unperturbed walker at pose `pose`'s reference instant, from
    /// the pixels of a view whose surface points are `surface` ([`Stage::truth_surface`])
    /// to camera `to` (subject frame), with the pixels whose point `to` does not see.
    pub fn truth_flow(
        &self,
        pose: u32,
        surface: &Image<Option<SurfacePoint>>,
        to: &Camera,
    ) -> TrueFlow {
        let setup = ViewSetup {
            camera: *to,
            actor: self.actor(None, self.pose_time_s(pose)),
        };
        flow_between(surface, &setup)
    }

    /// The lights (subject frame) of basis conditions weighted by `weights[c]`, for a
    /// subject standing at turntable angle `turntable` (radians): the dome's lights seen
    /// from the subject frame, `R_y(-θ)` ([`frf_core::conventions`]).
    pub fn basis_lights(&self, weights: &[f32], turntable: f32) -> Result<Vec<DirLight>> {
        if weights.len() != self.basis().len() {
            return Err(StageError::OutOfRange {
                what: "number of basis weights",
                value: format!("{} (the stage has {})", weights.len(), self.basis().len()),
            });
        }
        if let Some(w) = weights.iter().find(|w| !w.is_finite()) {
            return Err(StageError::BadConfig(format!(
                "basis weight {w} is not finite"
            )));
        }
        let subject_from_world = Rigid::rotation_y(-turntable).rotation;
        Ok(self
            .basis()
            .iter()
            .zip(weights)
            .filter(|(_, w)| **w != 0.0)
            .flat_map(|(c, &w)| {
                c.lights
                    .iter()
                    .map(move |(l, _)| l.scaled(w).rotated(subject_from_world))
            })
            .collect())
    }
}

/// The lights (subject frame) of an environment given in the subject frame.
pub fn environment_lights(env: &EnvMap, count: usize) -> Vec<DirLight> {
    env.median_cut(count)
}
