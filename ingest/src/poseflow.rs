//! Flow between consecutive poses of each view (issue 24: time between the captured
//! poses). A view `(u, v)` of pose `k` is camera `v` at pose `k`'s instant of walk cycle
//! `u`; the next captured pose of the same cycle is a later instant filmed by the same
//! camera, 1/30 s on per pose (past the cycle's end, the next cycle: one column on,
//! [`PoseStep::of`]). The flow between the two says how the walker moves between them,
//! which a shot between the two poses needs.
//!
//! Measured on the reference track frames (`T1`, the frame that sets each pose's instant):
//! both are lit alike by the tracking lights, so brightness constancy holds, and neither
//! needs the other pose's registration, so each pose is ingested on its own (`frf ingest
//! --poses P` parts merge as before). The two views' cameras, seen from the subject
//! frame, differ by the turntable's turn between the instants (a third of a degree per
//! pose): the pair is rectified as the inter-view flows are ([`rectified_flow`]). Kept
//! near the subject like them ([`keep_near_subject`]).

use frf_core::capture::Capture;
use frf_core::grid::PoseStep;
use frf_core::image::{FlowImage, GrayImage};
use frf_flow::FlowParams;
use rayon::prelude::*;

use crate::error::Result;
use crate::interview::{keep_near_subject, rectified_flow};

/// The pose-to-pose flows of every view of `pose` that `alphas` holds (`u`-major; the
/// columns close into a ring when `wraps`), in
/// [`PoseStep::ALL`] order (`None` where the step's view was not filmed, or the capture
/// holds one pose). `each_view` is called once per view (progress, and stopping: an error
/// it returns ends the step).
pub fn pose_flows(
    capture: &Capture,
    pose: u32,
    wraps: bool,
    alphas: &[Option<&GrayImage>],
    params: &FlowParams,
    each_view: &(dyn Fn() -> Result<()> + Sync),
) -> Result<Vec<[Option<FlowImage>; 2]>> {
    let (columns, rows) = (capture.cycles(), capture.cameras().len());
    let slot = capture.reference_track().track_slot;
    let mut poses = capture.poses().to_vec();
    poses.sort_unstable();
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
                let Some((to_pose, to_u)) = step.of(pose, u, &poses, columns, wraps) else {
                    continue;
                };
                if !capture.is_filmed(to_pose, to_u, v) {
                    continue;
                }
                if from.is_none() {
                    from = Some(capture.load_frame(pose, u, v, slot)?);
                }
                let a = from.as_ref().expect("loaded above");
                let b = capture.load_frame(to_pose, to_u, v, slot)?;
                let f = rectified_flow(
                    a,
                    &b,
                    &capture.subject_camera(u, v, pose),
                    &capture.subject_camera(to_u, v, to_pose),
                    params,
                )?;
                flows[step.index()] = Some(keep_near_subject(&f, alpha));
            }
            each_view()?;
            Ok(flows)
        })
        .collect()
}
