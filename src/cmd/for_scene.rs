//! `--for SCENE` of `frf stage` and `frf ingest`: the plan of a scene on a capture (its
//! grid, cameras, basis and poses), so that only the poses, views and flows the scene
//! needs are filmed or ingested.

use std::path::Path;

use frf_core::capture::Capture;
use frf_core::manifest::FilmedSpec;
use frf_ingest::pipeline::Selection;
use frf_ingest::shadows::ShadowOptions;
use frf_reflectance::FieldHeader;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_render::scene::plan::Plan;
use frf_render::scene::{Scene, ShadowSpec};

use crate::CliResult;

/// Every [`HULL_RING_STEP`]-th column of the middle row is filmed and ingested for a
/// scene that draws a shadow, whether its camera sees them or not: the visual hull the
/// shadow maps are traced from needs silhouettes from all around. Measured on the demo
/// scene (small preset, 10 poses), hull IoU against the true body: 0.57 from the 29
/// views per pose a wider camera move reached alone, 0.79 with a ring every 40 degrees
/// (0.84 from all 108 views).
pub const HULL_RING_STEP: usize = 6;

/// The plan of the scene at `scene` on `capture` (every frame of the scene, at the
/// scene's size or the capture's image size), with the hull's ring of views when the
/// scene draws a shadow.
pub fn plan(scene: &Path, capture: &Capture) -> CliResult<Plan> {
    let scene = Scene::load(scene)?;
    // The quantizer and JPEG quality do not matter to a plan; the ground patch is the
    // one ingest will make maps of.
    let mut header =
        FieldHeader::from_capture(capture, capture.poses(), LogQuantizer::new(1.0, 1.0)?, 90)?;
    header.shadows = Some(ShadowOptions::default().spec(&header.conditions));
    let cam = &capture.cameras()[0];
    let size = scene.size.unwrap_or((cam.width, cam.height));
    let frames = scene.shot_frames(0..scene.frame_times().len(), size)?;
    let mut plan = Plan::from_header(&scene, &header, &frames)?;
    if plan.ground_seen && scene.shadow != ShadowSpec::None {
        let (columns, rows) = (header.columns, header.rows);
        for p in &mut plan.poses {
            for u in (0..columns).step_by(HULL_RING_STEP) {
                p.views[u * rows + rows / 2] = true;
            }
        }
        plan.counts.views_used = plan
            .poses
            .iter()
            .map(|p| p.views.iter().filter(|&&v| v).count())
            .sum();
    }
    Ok(plan)
}

/// The views and flows of `plan`, for ingest.
pub fn selection(plan: &Plan) -> Selection {
    Selection {
        views: plan
            .poses
            .iter()
            .map(|p| (p.pose, p.views.clone()))
            .collect(),
        flows: plan
            .poses
            .iter()
            .map(|p| (p.pose, p.flows.clone()))
            .collect(),
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
