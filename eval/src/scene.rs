//! The subject in a scene, judged against the virtual stage's truth: the relit shadow
//! against the true relative irradiance of the ground, the composite against the true
//! composite, and the subject's matte edges over dark and bright backgrounds.
//!
//! - **Shadow**: the renderer's relit shadow (its maps relit with the environment's
//!   coefficients) against the stage's true relative irradiance at the same texel
//!   centres under the environment's median-cut lights ([`frf_stage::ground`]); mean
//!   absolute error over the ground patch and the three channels.
//! - **Composite**: the true composite is built by the product's own compositing
//!   ([`frf_render::composite::compose`]) from the true subject and the true relative
//!   irradiance at every pixel's ground point (traced against the walker itself, not a
//!   grid), over the same backdrop; PSNR over the whole frame.
//! - **Edge band**: pixels whose true alpha lies in (0.05, 0.95); the subject over black
//!   and over a bright background, estimate against truth
//!   ([`crate::metrics::edge_band_error`]).

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgba};
use frf_core::light::DirLight;
use frf_render::composite::{Backdrop, compose};
use frf_render::shadow::RelitShadow;
use frf_stage::Stage;
use frf_stage::ground::relative_irradiance;
use glam::Vec3;
use serde::Serialize;

use crate::error::Result;
use crate::metrics::psnr;

/// Mean absolute error of a relit shadow against the stage's true relative irradiance of
/// the same ground texels, pose `pose`, under `lights` (subject frame).
pub fn shadow_error(relit: &RelitShadow, stage: &Stage, pose: u32, lights: &[DirLight]) -> f64 {
    let truth = stage.true_ground_shadow(pose, lights, &relit.ground);
    let n = truth.pixels().len().max(1) as f64;
    relit
        .image
        .pixels()
        .iter()
        .zip(truth.pixels())
        .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs() as f64).sum::<f64>() / 3.0)
        .sum::<f64>()
        / n
}

/// The true composite of `truth_subject` (the stage's true frame from `camera`) over
/// `backdrop`, its ground darkened by the walker's true shadow under `lights`.
pub fn true_composite(
    stage: &Stage,
    pose: u32,
    camera: &Camera,
    truth_subject: Image<Rgba>,
    lights: &[DirLight],
    backdrop: &Backdrop,
) -> Result<Image<Rgba>> {
    let actor = stage.true_actor(pose);
    let shadow = |p: Vec3| relative_irradiance(&actor, lights, p);
    Ok(compose(truth_subject, camera, backdrop, &shadow)?.0)
}

/// PSNR (dB) of a composite against the true one, over the whole frame.
pub fn composite_psnr(truth: &Image<Rgba>, test: &Image<Rgba>) -> f64 {
    psnr(truth, test, None)
}

/// Scores of the scene at a set of cameras.
#[derive(Debug, Clone, Serialize)]
pub struct SceneScore {
    /// Intersection over union of the pose's visual hull with the true body (`None`
    /// when the field has no hull).
    pub hull_iou: Option<f64>,
    /// [`shadow_error`] of the relit shadow (`None` when the field has no maps).
    pub shadow_mae: Option<f64>,
    /// [`shadow_error`] of the ablation: the environment's lights traced against the
    /// pose's visual hull ([`frf_render::shadow::traced_shadow`]).
    pub shadow_mae_traced: Option<f64>,
    /// Mean [`composite_psnr`] over the cameras, dB.
    pub psnr_composite: f64,
    /// Seconds to set the scene up: the backdrop made resident and the shadow relit.
    pub scene_seconds: f64,
    /// Seconds to trace the ablation's shadow against the hull (CPU).
    pub traced_seconds: Option<f64>,
    /// Mean seconds per composited frame (subject, shadow, backdrop, readback).
    pub seconds_per_composite: f64,
    /// Mean edge-band error over black, at the captured views.
    pub edge_band_mae_dark: Option<f64>,
    /// Mean edge-band error over the bright background, at the captured views.
    pub edge_band_mae_bright: Option<f64>,
    /// The mean of the two: the figure the shadow work is judged on.
    pub edge_band_mae: Option<f64>,
    /// PSNR per camera.
    pub psnr_composite_per_camera: Vec<f64>,
}

/// The mean of the values that exist, if any.
pub fn mean_of(values: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let v: Vec<f64> = values.flatten().collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}
