//! `--for SCENE` of `frf stage` and `frf ingest`: the plan of a scene on a capture (its
//! grid, cameras, basis and poses), so that only the poses, views and flows the scene
//! needs are filmed or ingested.

use std::path::Path;

use frf_core::capture::Capture;
use frf_core::manifest::FilmedSpec;
use frf_ingest::pipeline::Selection;
use frf_reflectance::FieldHeader;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_render::scene::Scene;
use frf_render::scene::plan::Plan;

use crate::CliResult;

/// The plan of the scene at `scene` on `capture` (every frame of the scene, at the
/// scene's size or the capture's image size).
pub fn plan(scene: &Path, capture: &Capture) -> CliResult<Plan> {
    let scene = Scene::load(scene)?;
    // The quantizer and JPEG quality do not matter to a plan.
    let header = FieldHeader::from_capture(capture, capture.poses(), LogQuantizer::new(1.0, 1.0)?, 90)?;
    let cam = &capture.cameras()[0];
    let size = scene.size.unwrap_or((cam.width, cam.height));
    let frames = scene.shot_frames(0..scene.frame_times().len(), size)?;
    Ok(Plan::from_header(&scene, &header, &frames)?)
}

/// The views and flows of `plan`, for ingest.
pub fn selection(plan: &Plan) -> Selection {
    Selection {
        views: plan.poses.iter().map(|p| (p.pose, p.views.clone())).collect(),
        flows: plan.poses.iter().map(|p| (p.pose, p.flows.clone())).collect(),
    }
}

/// The views of `plan` to film, for the stage (`rows` cameras per column).
pub fn filmed(plan: &Plan, rows: usize) -> Vec<FilmedSpec> {
    plan.poses
        .iter()
        .map(|p| FilmedSpec {
            pose: p.pose,
            views: p
                .views
                .iter()
                .enumerate()
                .filter(|(_, v)| **v)
                .map(|(i, _)| [(i / rows) as u32, (i % rows) as u32])
                .collect(),
        })
        .collect()
}

/// A line for people: what the plan keeps.
pub fn summary(plan: &Plan) -> String {
    let c = &plan.counts;
    format!(
        "for the scene: {} of {} poses ({:?}), {} of {} views, {} flows",
        c.poses_used,
        c.poses_total,
        plan.poses.iter().map(|p| p.pose).collect::<Vec<_>>(),
        c.views_used,
        c.views_total,
        c.flows_used
    )
}
