//! `--for SCENE` of `frf stage` and `frf ingest`: the scene planned on a capture
//! ([`Plan::for_capture`]), so that only the poses, views and flows it needs are filmed
//! or ingested; and the patch of shadow maps the scene's lighting needs
//! ([`frf_render::shadow_reach`]).

use std::path::Path;

use frf_core::capture::Capture;
use frf_ingest::pipeline::Selection;
use frf_ingest::shadows::ShadowOptions;
use frf_reflectance::FieldHeader;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_scene::Scene;
use frf_scene::plan::Plan;

use crate::CliResult;

/// The largest patch of shadow maps sized for a scene's lighting, metres: a sun a few
/// degrees high would ask for tens of metres.
pub const MAX_SCENE_PATCH_M: f32 = 12.0;

/// The side of the patch of shadow maps (metres, at most [`MAX_SCENE_PATCH_M`]) that holds
/// the shadow of a standing person under the lowest shadow-making light of the scene at
/// `scene`'s lighting keys, and that light's elevation (degrees); `None` when nothing
/// lights the ground from above.
pub fn shadow_patch(scene: &Path) -> CliResult<Option<(f32, f32)>> {
    use frf_render::shadow_reach::{
        NOMINAL_SUBJECT, lowest_shadow_light_elevation, patch_side_holding, shadow_reach,
    };
    let scene = Scene::load(scene)?;
    let mut envs = Vec::new();
    for env in scene.environments() {
        envs.extend(env.load()?);
    }
    Ok(lowest_shadow_light_elevation(&envs).map(|e| {
        let side = patch_side_holding(shadow_reach(e, NOMINAL_SUBJECT));
        (side.min(MAX_SCENE_PATCH_M), e.to_degrees())
    }))
}

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
