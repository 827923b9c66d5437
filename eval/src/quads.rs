//! `frf eval FIELD --capture C --env E`: cameras at the centres of grid quads, every
//! variant scored against the stage's truth ([`crate::views`]), beside the renderer at
//! the captured views (the error of relighting and storage alone), and with a scene
//! (`--shadows`) the hull, the relit shadow, composites and matte edges
//! ([`crate::scene::score_scene`]).

use std::path::{Path, PathBuf};

use frf_core::env::EnvMap;
use frf_core::io::write_png8_srgba;
use frf_core::light::DirLight;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_render::composite::GroundLook;
use frf_render::geometry::PoseGeometry;
use frf_render::morph::Variant;
use frf_render::renderer::Renderer;
use frf_stage::Stage;
use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::scene::{SceneScore, score_scene};
use crate::views::{
    ReportHeader, VariantScore, between_view_cameras, evaluate, grid_view_cameras, truth_frames,
};
use frf_core::progress::Progress;

/// What `frf eval --json` prints at quad centres.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct QuadsReport {
    /// What was rendered, and how the truth was made.
    #[serde(flatten)]
    pub header: ReportHeader,
    /// The cameras' names.
    pub cameras: Vec<String>,
    /// Each variant.
    pub variants: Vec<VariantScore>,
    /// The four-way renderer at captured cameras: the error of relighting and storage.
    pub at_captured_views: VariantScore,
    /// With a scene: its scores.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub scene: Option<SceneScore>,
}

/// What to evaluate.
pub struct QuadsOptions<'a> {
    /// The field's path, the capture's and the environment's name, for the report.
    pub names: (PathBuf, PathBuf, String),
    /// Cameras (quads).
    pub cameras: usize,
    /// Variants.
    pub variants: &'a [Variant],
    /// The environment and its median-cut lights of the truth.
    pub env: &'a EnvMap,
    /// The truth's lights, and how many were asked for (the report's `truth_lights`).
    pub lights: &'a [DirLight],
    /// Median-cut lights asked for.
    pub light_count: usize,
    /// Write each camera's truth and renders as PNGs here.
    pub images: Option<&'a Path>,
    /// Score the scene too, composited over the environment with this ground.
    pub scene: Option<GroundLook>,
}

/// Evaluates pose `pose` of `field` (resident on `renderer`, whose geometry is
/// `geometry`) at quad centres (see the module docs).
#[allow(clippy::too_many_arguments)]
pub fn evaluate_quads<R: ReadAt>(
    field: &FieldFile<R>,
    geometry: &PoseGeometry,
    renderer: &mut Renderer,
    stage: &Stage,
    pose: u32,
    options: &QuadsOptions,
    progress: &dyn Progress,
) -> Result<QuadsReport> {
    let cameras = between_view_cameras(geometry, options.cameras)?;
    let at_views = grid_view_cameras(geometry, options.cameras)?;
    let all: Vec<_> = cameras.iter().chain(&at_views).map(|c| c.camera).collect();
    progress.phase("truth frames", all.len());
    let (mut truths, seconds) = truth_frames(stage, pose, &all, options.lights, progress)?;
    progress.finish();
    let truths_at_views = truths.split_off(cameras.len());
    if let Some(dir) = options.images {
        for (i, t) in truths.iter().enumerate() {
            write_png8_srgba(&dir.join(format!("camera{i:02}_truth.png")), t, 1.0)?;
        }
    }
    progress.phase("rendered frames", cameras.len() * options.variants.len());
    let variants = evaluate(
        renderer,
        &cameras,
        &truths,
        options.variants,
        &mut |i, v, img| {
            progress.step();
            if let Some(dir) = options.images {
                write_png8_srgba(
                    &dir.join(format!("camera{i:02}_{}.png", v.name())),
                    img,
                    1.0,
                )?;
            }
            Ok(())
        },
    )?;
    progress.finish();
    let mut floor = evaluate(
        renderer,
        &at_views,
        &truths_at_views,
        &[Variant::FourWay],
        &mut |_, _, _| Ok(()),
    )?
    .remove(0);
    floor.name = "at the captured views".into();
    let scene = match options.scene {
        Some(ground) => Some(score_scene(
            field,
            renderer,
            stage,
            pose,
            (&cameras, &truths),
            &at_views,
            options.env,
            options.lights,
            ground,
            options.images,
            progress,
        )?),
        None => None,
    };
    let (field_name, capture, env) = options.names.clone();
    Ok(QuadsReport {
        header: ReportHeader {
            field: field_name,
            capture,
            env,
            pose,
            device: renderer.device(),
            truth_lights: options.light_count,
            truth_seconds_per_frame: seconds / all.len().max(1) as f64,
        },
        cameras: cameras.iter().map(|c| c.name.clone()).collect(),
        variants,
        at_captured_views: floor,
        scene,
    })
}
impl QuadsReport {
    /// The scene's scores in a line for a person (`None` without them); `extent_m`: the
    /// side of the field's patch of shadow maps.
    pub fn scene_line(&self, extent_m: f32) -> Option<String> {
        let s = self.scene.as_ref()?;
        let f = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{v:.4}"));
        Some(format!(
            "scene: hull IoU {}, shadow MAE {} (relit maps against the true relative irradiance, {} m \
             patch; traced against the hull instead: {}), composite PSNR {:.2} dB (four-way, over the environment), edge-band \
             error {} over black / {} over bright (at the captured views)",
            f(s.hull_iou),
            f(s.shadow_mae),
            extent_m,
            f(s.shadow_mae_traced),
            s.psnr_composite,
            f(s.edge_band_mae_dark),
            f(s.edge_band_mae_bright)
        ))
    }
}
