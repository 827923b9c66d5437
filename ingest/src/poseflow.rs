//! Flow between consecutive poses of each view (issue 24: time between the captured
//! poses). A view `(u, v)` of pose `k` is camera `v` at pose `k`'s instant of walk cycle
//! `u`; the next captured pose of the same cycle is a later instant filmed by the same
//! camera, 1/30 s on per pose (past the cycle's end, the next cycle: one column on,
//! [`PoseStep::of`]). The flow between the two says how the walker moves between them,
//! which a shot between the two poses needs.
//!
//! Measured on the reference track frames (`T1`, the frame that sets each pose's instant),
//! each matted onto black with its own matte ([`crate::matte`]): both are lit alike by
//! the tracking lights, so brightness constancy holds, and neither needs the other pose's
//! registration, so each pose is ingested on its own (`frf ingest --poses P` parts merge
//! as before). Matted, the static backdrop no longer holds the subject's edges in place.
//!
//! Within a cycle the two views' cameras, seen from the subject frame, differ by the
//! turntable's turn between the instants (a third of a degree per pose): the pair is
//! matched through the plane of the turntable's axis as the inter-view flows once were
//! ([`rectified_flow`]). When the step crosses the cycle's end, the other view is the
//! next cycle's, the camera turned by a column: there the pose's hull's reprojection into
//! the turned camera ([`hull_flow`]) predicts the flow and the images refine it
//! ([`refine_flow`]), as between horizontal neighbours. Kept near the subject like the
//! inter-view flows ([`keep_near_subject`]).
//!
//! Measured on pose 0 of the perturbed small preset (poses 0 and 1: pose 0's previous
//! pose is pose 1 of the cycle before, a column away), mean end-point error inside the
//! true matte against a true motion of 2.00 px: 1.01 px on the unmatted frames, 0.78 px
//! matted, 0.62 px with the hull across the cycle's end. Carrying the set's own motion
//! (its track flows, 8 ms each way) on to the next pose's instant as a prediction gained
//! nothing within a cycle (0.49 px either way) and amplified the track flows' noise on
//! tiny captures (0.35 → 0.51 px at 32x45): not used.

use frf_core::capture::Capture;
use frf_core::grid::PoseStep;
use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_flow::FlowParams;
use frf_reflectance::hull::VoxelHull;
use rayon::prelude::*;

use crate::error::Result;
use crate::guided::{hull_flow, refine_flow, residual_search_px};
use crate::interview::{keep_near_subject, rectified_flow};
use crate::matte::{MatteInput, MatteRule, alpha as matte_alpha, premultiply};

/// The residual flow between a view and the other cycle's view warped by the hull's
/// reprojection is searched this far on the subject, metres: besides another cycle's
/// perturbation (what the inter-view flows' [`crate::guided::RESIDUAL_SEARCH_M`] allows
/// for), the walker has moved by the poses' difference of phase, a pose apart at least
/// (2 cm on average, a foot's swing several). Twice the inter-view search: 8 px at the
/// small preset's 160x224.
pub const RESIDUAL_SEARCH_M: f32 = 2.0 * crate::guided::RESIDUAL_SEARCH_M;

/// The reference track frame of view `(u, v)` of `pose`, matted onto black with the
/// matte of the frame after it (`clean`: camera `v`'s clean plates by slot).
fn matted_reference(
    capture: &Capture,
    (pose, u, v): (u32, usize, usize),
    clean: &[RgbImage],
    rule: MatteRule,
) -> Result<RgbImage> {
    let t = capture.reference_track();
    let track = capture.load_frame(pose, u, v, t.track_slot)?;
    let matte = capture.load_frame(pose, u, v, t.matte_slot)?;
    let alpha = matte_alpha(
        &MatteInput {
            track: &track,
            matte: &matte,
            matte_clean: &clean[t.matte_slot],
        },
        rule,
    )?;
    premultiply(&track, &alpha, &clean[t.track_slot])
}

/// The pose-to-pose flows of every view of `pose` that `alphas` holds (`u`-major; the
/// columns close into a ring when `wraps`) to its neighbours among `poses` (sorted), in
/// [`PoseStep::ALL`] order (`None` where the step's view was not filmed, or there is one
/// pose); `clean` holds each camera's clean plates by slot, `rule` the matte
/// rule. `each_view` is called once per view (progress, and stopping: an error it
/// returns ends the step).
#[allow(clippy::too_many_arguments)]
pub fn pose_flows(
    capture: &Capture,
    (pose, poses): (u32, &[u32]),
    wraps: bool,
    alphas: &[Option<&GrayImage>],
    guide: Option<&VoxelHull>,
    clean: &[Vec<RgbImage>],
    rule: MatteRule,
    params: &FlowParams,
    each_view: &(dyn Fn() -> Result<()> + Sync),
) -> Result<Vec<[Option<FlowImage>; 2]>> {
    let (columns, rows) = (capture.cycles(), capture.cameras().len());
    (0..columns * rows)
        .into_par_iter()
        .map(|i| {
            let mut flows: [Option<FlowImage>; 2] = Default::default();
            let Some(alpha) = alphas[i] else {
                return Ok(flows);
            };
            let (u, v) = (i / rows, i % rows);
            let mut from = None;
            for step in PoseStep::ALL {
                let Some((to_pose, to_u)) = step.of(pose, u, poses, columns, wraps) else {
                    continue;
                };
                if !capture.is_filmed(to_pose, to_u, v) {
                    continue;
                }
                if from.is_none() {
                    from = Some(matted_reference(capture, (pose, u, v), &clean[v], rule)?);
                }
                let a = from.as_ref().expect("loaded above");
                let b = matted_reference(capture, (to_pose, to_u, v), &clean[v], rule)?;
                let (from, to) = (
                    capture.subject_camera(u, v, pose),
                    capture.subject_camera(to_u, v, to_pose),
                );
                let f = match guide {
                    // Across the cycle's end the camera turned by a column: the hull's
                    // reprojection predicts the flow, the images refine it.
                    Some(hull) if to_u != u => {
                        let prior = hull_flow(hull, &from, &to, a.width(), a.height());
                        refine_flow(
                            a,
                            &b,
                            &prior,
                            params,
                            residual_search_px(RESIDUAL_SEARCH_M, &[from, to]),
                        )?
                    }
                    _ => rectified_flow(a, &b, &from, &to, params)?,
                };
                flows[step.index()] = Some(keep_near_subject(&f, alpha));
            }
            each_view()?;
            Ok(flows)
        })
        .collect()
}
