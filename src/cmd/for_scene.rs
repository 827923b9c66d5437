//! `--for SCENE` of `frf stage` and `frf ingest`: the scene planned on a capture
//! ([`Plan::for_capture`]), so that only the poses, views and flows it needs are filmed
//! or ingested (the patch of shadow maps its lighting needs: [`Scene::shadow_patch`]).

use std::path::Path;

use frf_core::capture::Capture;
use frf_ingest::pipeline::Selection;
use frf_ingest::shadows::ShadowOptions;
use frf_reflectance::FieldHeader;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_scene::Scene;
use frf_scene::plan::Plan;

use crate::CliResult;

/// The plan of the scene at `scene` on `capture`: the field the capture would make
/// (the quantizer and JPEG quality do not matter to a plan) with shadow maps of `shadows`
/// (the ingest's; the original's patch when `None`).
pub fn plan(scene: &Path, capture: &Capture, shadows: Option<&ShadowOptions>) -> CliResult<Plan> {
    let scene = Scene::load(scene)?;
    let mut header =
        FieldHeader::from_capture(capture, capture.poses(), LogQuantizer::new(1.0, 1.0)?, 90)?;
    let default = ShadowOptions::default();
    header.shadows = Some(shadows.unwrap_or(&default).spec(&header.conditions));
    let cam = &capture.cameras()[0];
    Ok(Plan::for_capture(&scene, &header, (cam.width, cam.height))?)
}

/// The views and flows of `plan`, for ingest.
pub fn selection(plan: &Plan) -> Selection {
    Selection::of(
        plan.poses
            .iter()
            .map(|p| (p.pose, &p.views[..], &p.flows[..])),
    )
}
