//! What `frf render` says before drawing a shot: the field, frames, size and device with
//! what the plan reads of the field; where the shadow comes from; a shadow the field's
//! maps cannot hold; the poses that stand in for ones the field lacks.

use std::path::Path;

use frf_reflectance::container::ReadAt;

use crate::Scene;
use crate::error::Result;
use crate::plan_report::shadow_words;
use crate::shot::Shot;

/// The lines said before `shot` draws `frames` of the shot's `total` from the field at
/// `field_path`, at `size`; `traced_lights`: the lights a traced shadow is cast by.
pub fn shot_preamble<R: ReadAt>(
    scene: &Scene,
    shot: &mut Shot<'_, R>,
    field_path: &Path,
    (frames, total, size): (usize, usize, (u32, u32)),
    traced_lights: usize,
) -> Result<Vec<String>> {
    let c = &shot.plan().counts;
    let mut lines = vec![format!(
        "{}: {} of {} frames, {}x{}, {}; plan: {} of {} poses, {} of {} views, {} of {} flows, {} of {} conditions, {:.2} of {:.2} MB{}",
        field_path.display(),
        frames,
        total,
        size.0,
        size.1,
        shot.device(),
        c.poses_used,
        c.poses_total,
        c.views_used,
        c.views_total,
        c.flows_used,
        c.flows_total,
        c.conditions_used,
        c.conditions_total,
        c.bytes_read as f64 / 1e6,
        c.bytes_total as f64 / 1e6,
        if shot.planned() {
            ""
        } else {
            " (--no-plan: everything is read)"
        }
    )];
    let header = shot.field().header();
    let words = shadow_words(scene, shot.plan(), header, traced_lights);
    lines.push(format!("shadow: {words}"));
    if let Some(r) = shot.shadow_reach()?.filter(|r| r.cut()) {
        lines.push(format!(
            "warning: the lights that make the shadow are as low as {:.0}°: it reaches {:.1} m \
             from the walker, past the field's {:.1} m patch of shadow maps (they fade out from \
             {:.1} m): ingest with --shadow-extent {:.0} (or --for this scene) to hold it whole",
            r.elevation_deg,
            r.reach_m,
            r.patch_side_m,
            0.5 * r.patch_side_m * frf_render::shadow::EDGE_FADE_FROM,
            r.side_needed_m().ceil()
        ));
    }
    for (wanted, held) in &shot.plan().poses_substituted {
        lines.push(format!(
            "pose {wanted} is not in the field: pose {held} stands in for it (render.json: poses_substituted)"
        ));
    }
    Ok(lines)
}
