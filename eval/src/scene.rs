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

use std::path::Path;
use std::time::Instant;

use frf_core::camera::Camera;
use frf_core::env::EnvMap;
use frf_core::image::{Image, Rgba};
use frf_core::io::{rgba_from, write_png8_srgb};
use frf_core::light::DirLight;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_render::composite::{Backdrop, GroundLook, compose};
use frf_render::morph::Variant;
use frf_render::renderer::{Renderer, SceneShadow};
use frf_render::shadow::{RelitShadow, ShadowMaps, traced_shadow};
use frf_stage::Stage;
use frf_stage::ground::relative_irradiance;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::error::{EvalError, Result};
use crate::metrics::{edge_band_error_rgba, psnr};
use crate::storage::env_lights_for_view;
use crate::views::EvalCamera;
use frf_core::progress::Progress;

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
#[derive(Debug, Clone, Serialize, Deserialize)]
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

/// Median-cut lights of the traced-shadow ablation (as `frf render --shadow traced`).
pub const TRACED_LIGHTS: usize = 256;

/// Scores the scene of pose `pose` (`renderer` holds it): the hull against the true
/// body, the relit shadow (and the ablation traced against the hull) against the true
/// relative irradiance, composites over the environment `env` with `ground` at the
/// `(cameras, truths)` against true composites, and matte edges at the captured-view
/// cameras `at_views`; the relit and the true shadow are written to `images` if given.
#[allow(clippy::too_many_arguments)]
pub fn score_scene<R: ReadAt>(
    field: &FieldFile<R>,
    renderer: &mut Renderer,
    stage: &Stage,
    pose: u32,
    (cameras, truths): (&[EvalCamera], &[Image<Rgba>]),
    at_views: &[EvalCamera],
    env: &EnvMap,
    lights: &[DirLight],
    ground: GroundLook,
    images: Option<&Path>,
    progress: &dyn Progress,
) -> Result<SceneScore> {
    let backdrop = Backdrop::environment(env.clone(), ground);
    let maps = ShadowMaps::load(field, pose)?.map(std::sync::Arc::new);
    // The ablation first: the environment's lights traced against the hull.
    let hull = field.hull(pose)?;
    let hull_iou = hull
        .as_ref()
        .and_then(|h| h.iou(&stage.true_occupancy(pose, h.grid())));
    let (shadow_mae_traced, traced_seconds) = match (hull, &maps) {
        (Some(hull), Some(m)) => {
            let t = Instant::now();
            let traced = traced_shadow(&hull, &env.median_cut(TRACED_LIGHTS), m.spec.ground);
            let seconds = t.elapsed().as_secs_f64();
            (
                Some(shadow_error(&traced, stage, pose, lights)),
                Some(seconds),
            )
        }
        _ => (None, None),
    };
    let t = Instant::now();
    renderer.set_scene(
        backdrop.clone(),
        maps.clone().map_or(SceneShadow::None, SceneShadow::Maps),
    )?;
    let scene_seconds = t.elapsed().as_secs_f64();
    let relit = renderer.relit_shadow()?;
    let shadow_mae = relit.as_ref().map(|r| shadow_error(r, stage, pose, lights));
    if let (Some(dir), Some(r)) = (images, &relit) {
        let truth = stage.true_ground_shadow(pose, lights, &r.ground);
        write_png8_srgb(&dir.join("shadow_relit.png"), &r.image, 1.0)?;
        write_png8_srgb(&dir.join("shadow_truth.png"), &truth, 1.0)?;
    }
    progress.phase("composites", cameras.len());
    let mut composite_seconds = 0.0;
    let psnrs = cameras
        .iter()
        .zip(truths)
        .map(|(c, truth)| {
            let t = Instant::now();
            let frame = renderer.render_frame(&c.camera, Variant::FourWay, false)?;
            composite_seconds += t.elapsed().as_secs_f64();
            let t = true_composite(stage, pose, &c.camera, truth.clone(), lights, &backdrop)?;
            progress.step();
            Ok(composite_psnr(&t, &frame.composite))
        })
        .collect::<Result<Vec<f64>>>()?;
    progress.finish();
    let mut dark = Vec::new();
    let mut bright = Vec::new();
    for c in at_views {
        // The walker of that view's cycle as filmed, lit as the renderer relit it.
        let (u, v) = c
            .view
            .ok_or_else(|| EvalError::Misuse("a captured-view camera without its view".into()))?;
        let t = stage.true_view_image(pose, u, v, &env_lights_for_view(stage, lights, pose, u))?;
        let truth = &rgba_from(&t.color, &t.alpha)?;
        let (img, _) = renderer.render(&c.camera, Variant::FourWay)?;
        let e = edge_band_error_rgba(truth, &img);
        dark.push(e.map(|e| e.dark));
        bright.push(e.map(|e| e.bright));
    }
    let (dark, bright) = (mean_of(dark.into_iter()), mean_of(bright.into_iter()));
    Ok(SceneScore {
        hull_iou,
        shadow_mae,
        shadow_mae_traced,
        psnr_composite: psnrs.iter().sum::<f64>() / psnrs.len().max(1) as f64,
        scene_seconds,
        traced_seconds,
        seconds_per_composite: composite_seconds / psnrs.len().max(1) as f64,
        edge_band_mae_dark: dark,
        edge_band_mae_bright: bright,
        edge_band_mae: mean_of([dark, bright].into_iter()),
        psnr_composite_per_camera: psnrs,
    })
}
