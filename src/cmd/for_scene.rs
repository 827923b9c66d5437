//! `--for SCENE` of `frf stage` and `frf ingest`: the scene planned on a capture
//! ([`Plan::for_capture`]), so that only the poses, views and flows it needs are filmed
//! or ingested.

use std::path::Path;

use frf_core::capture::Capture;
use frf_ingest::pipeline::Selection;
use frf_ingest::shadows::ShadowOptions;
use frf_reflectance::FieldHeader;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_render::scene::Scene;
use frf_render::scene::plan::Plan;

use crate::CliResult;

/// The plan of the scene at `scene` on `capture`: the field the capture would make
/// (the quantizer and JPEG quality do not matter to a plan; the ground patch is the one
/// ingest will make maps of).
pub fn plan(scene: &Path, capture: &Capture) -> CliResult<Plan> {
    let scene = Scene::load(scene)?;
    let mut header =
        FieldHeader::from_capture(capture, capture.poses(), LogQuantizer::new(1.0, 1.0)?, 90)?;
    header.shadows = Some(ShadowOptions::default().spec(&header.conditions));
    let cam = &capture.cameras()[0];
    Ok(Plan::for_capture(&scene, &header, (cam.width, cam.height))?)
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
