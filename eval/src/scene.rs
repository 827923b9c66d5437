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
//! - **Edge band**: pixels whose true alpha lies in (0.05, 0.95) ([`EDGE_BAND`]); the
//!   subject over black and over a bright background, estimate against truth, mean
//!   absolute error relative to the truth's mean subject colour ([`edge_band_error`]).

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgb, Rgba};
use frf_core::light::DirLight;
use frf_render::composite::{Backdrop, compose, over};
use frf_render::shadow::RelitShadow;
use frf_stage::Stage;
use frf_stage::ground::relative_irradiance;
use glam::Vec3;
use serde::Serialize;

use crate::error::Result;
use crate::metrics::{SUBJECT_ALPHA, psnr};

/// The edge band: true alpha strictly between these (partly covered pixels).
pub const EDGE_BAND: (f32, f32) = (0.05, 0.95);

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

/// The edge-band error of a rendered subject against the true one, composited over a
/// uniform `background`: mean over the band's pixels and channels of
/// `|test over bg − truth over bg|`, divided by the truth's mean colour over its subject
/// (alpha ≥ ½), so that the figure does not depend on exposure. `None` when the band is
/// empty.
pub fn edge_band_error(truth: &Image<Rgba>, test: &Image<Rgba>, background: Rgb) -> Option<f64> {
    let bg = [background[0], background[1], background[2], 1.0];
    let (mut err, mut n) = (0.0f64, 0usize);
    let (mut level, mut m) = (0.0f64, 0usize);
    for (t, e) in truth.pixels().iter().zip(test.pixels()) {
        if t[3] >= SUBJECT_ALPHA {
            level += (t[0] + t[1] + t[2]) as f64 / 3.0;
            m += 1;
        }
        if t[3] > EDGE_BAND.0 && t[3] < EDGE_BAND.1 {
            let (a, b) = (over(*e, bg, [1.0; 3], false), over(*t, bg, [1.0; 3], false));
            err += (0..3).map(|c| (a[c] - b[c]).abs() as f64).sum::<f64>() / 3.0;
            n += 1;
        }
    }
    (n > 0 && m > 0 && level > 0.0).then(|| (err / n as f64) / (level / m as f64))
}

/// A bright background for edge-band errors: the truth's 99th-percentile subject colour
/// (grey), bright enough that backdrop light left in the edges shows against it, and
/// unaffected by a few specular glints.
pub fn bright_background(truth: &Image<Rgba>) -> Rgb {
    let mut values: Vec<f32> = truth
        .pixels()
        .iter()
        .filter(|p| p[3] >= SUBJECT_ALPHA)
        .map(|p| (p[0] + p[1] + p[2]) / (3.0 * p[3]))
        .collect();
    if values.is_empty() {
        return [1.0; 3];
    }
    values.sort_by(f32::total_cmp);
    [values[(values.len() - 1) * 99 / 100]; 3]
}

/// Scores of the scene at a set of cameras.
#[derive(Debug, Clone, Serialize)]
pub struct SceneScore {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_edge_band_error_sees_backdrop_light_left_in_the_edges() {
        // A disc of colour 0.5 with a soft edge; the test leaves 0.2 of backdrop light in
        // the partly covered pixels (what a wrong matte leaves).
        let truth = Image::from_fn(40, 40, |x, y| {
            let r = ((x as f32 - 20.0).powi(2) + (y as f32 - 20.0).powi(2)).sqrt();
            let a = (12.0 - r).clamp(0.0, 1.0);
            [0.5 * a, 0.5 * a, 0.5 * a, a]
        });
        let fringe = truth.map(|p| {
            if p[3] > 0.05 && p[3] < 0.95 {
                [p[0] + 0.2, p[1] + 0.2, p[2] + 0.2, p[3]]
            } else {
                p
            }
        });
        assert_eq!(edge_band_error(&truth, &truth, [0.0; 3]), Some(0.0));
        let dark = edge_band_error(&truth, &fringe, [0.0; 3]).unwrap();
        // 0.2 in every band pixel, against a mean subject colour of about 0.5.
        assert!((dark - 0.4).abs() < 0.05, "{dark}");
        assert_eq!(bright_background(&truth), [0.5; 3]);
        let nothing = Image::new(8, 8, [0.0f32; 4]);
        assert_eq!(edge_band_error(&nothing, &nothing, [1.0; 3]), None);
    }
}
