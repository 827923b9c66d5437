//! How good each ingest step is, against the virtual stage's ground truth: alpha
//! against the true coverage, registered basis images against the true images at the
//! reference instant (and what registration gains over none), their edge pixels
//! composited over black and over a bright background (and what edge decontamination
//! gains over none, [`crate::metrics::edge_band_error`]), and inter-view flow against
//! the true flow inside the matte, horizontal and vertical pairs apart. [`StageEvaluator`]
//! is the [`Evaluator`] that `frf ingest` hands to the ingest of a stage capture.

use std::path::Path;

use frf_core::grid::{Neighbour, PoseStep};
use frf_core::image::FlowImage;
use frf_ingest::evidence::{EvaluationError, Evaluator, PoseErrors, PoseEvidence};
use frf_stage::Stage;
use frf_stage::truth::flow_between;
use rayon::prelude::*;

use crate::error::Result;
use crate::metrics::{EdgeBandError, alpha_iou, alpha_mae, alpha_mask, compare, edge_band_error};

/// True alpha at least this counts as inside the matte for flow errors: the flow of a
/// pixel only partly covered is ill-defined.
const INSIDE_MATTE: f32 = 0.99;
/// Mean end-point error of `estimated` against the true flow of view `(u, v)` of `pose`
/// toward view `(u2, v2)` of `to_pose`: summed over the pixels compared, the error and
/// the true motion's length, and the pixels compared.
fn flow_epe(
    stage: &Stage,
    (pose, u, v): (u32, usize, usize),
    (to_pose, u2, v2): (u32, usize, usize),
    estimated: &FlowImage,
) -> Result<(f64, f64, usize)> {
    let (surface, alpha) = stage.reference_surface(pose, u, v)?;
    let truth = flow_between(&surface, &stage.view_setup(to_pose, u2, v2, 0.0)?);
    let (mut sum, mut motion, mut count) = (0.0f64, 0.0f64, 0usize);
    for i in 0..alpha.pixels().len() {
        let (t, e) = (truth.flow.pixels()[i], estimated.pixels()[i]);
        if alpha.pixels()[i] < INSIDE_MATTE
            || truth.occluded.pixels()[i] > 0.0
            || !frf_core::flo::is_known(t)
            || !frf_core::flo::is_known(e)
        {
            continue;
        }
        sum += (((e[0] - t[0]).powi(2) + (e[1] - t[1]).powi(2)) as f64).sqrt();
        motion += t[0].hypot(t[1]) as f64;
        count += 1;
    }
    Ok((sum, motion, count))
}

/// Evaluates a pose against the stage's truth.
pub fn evaluate_pose(stage: &Stage, pose: u32, evidence: &PoseEvidence) -> Result<PoseErrors> {
    let rows = stage.cameras().len();
    // Per view: (alpha IoU, alpha MAE) and (sum, count) of flow errors, horizontal and
    // vertical.
    type ViewErrors = ((Option<f64>, f64), [(f64, usize); 4]);
    let poses = evidence.pose_flows_among;
    let per_view: Vec<ViewErrors> = (0..evidence.alphas.len())
        .into_par_iter()
        .filter(|&i| evidence.alphas[i].is_some())
        .map(|i| {
            let estimated = evidence.alphas[i].as_ref().expect("filtered");
            let (u, v) = (i / rows, i % rows);
            let (_, true_alpha) = stage.reference_surface(pose, u, v)?;
            let alpha = (
                alpha_iou(&true_alpha, estimated),
                alpha_mae(&true_alpha, estimated),
            );
            // Horizontal, vertical, pose to pose, and the true motion of the last.
            let mut epe = [(0.0, 0usize); 4];
            let columns = stage.cycles();
            for n in Neighbour::ALL {
                let (Some(f), Some((u2, v2))) = (
                    &evidence.flows[i][n.index()],
                    n.of(u, v, columns, rows, true),
                ) else {
                    continue;
                };
                let (s, _, c) = flow_epe(stage, (pose, u, v), (pose, u2, v2), f)?;
                let k = matches!(n, Neighbour::Up | Neighbour::Down) as usize;
                epe[k].0 += s;
                epe[k].1 += c;
            }
            for step in PoseStep::ALL {
                let (Some(f), Some((to_pose, u2))) = (
                    evidence
                        .pose_flows
                        .get(i)
                        .and_then(|p| p[step.index()].as_ref()),
                    step.of(pose, u, poses, columns, true),
                ) else {
                    continue;
                };
                let (s, m, c) = flow_epe(stage, (pose, u, v), (to_pose, u2, v), f)?;
                epe[2].0 += s;
                epe[2].1 += c;
                // The error of no flow at all: the true motion's length.
                epe[3].0 += m;
                epe[3].1 += c;
            }
            Ok((alpha, epe))
        })
        .collect::<Result<_>>()?;
    let sum_epe = |k: usize| {
        let (s, c) = per_view
            .iter()
            .fold((0.0, 0), |acc, p| (acc.0 + p.1[k].0, acc.1 + p.1[k].1));
        (c > 0).then(|| s / c as f64)
    };
    // Per evaluated view and condition: registered and unregistered PSNR, and the edge
    // band errors of the stored and the undecontaminated frames.
    type ImageErrors = ((f64, f64), Option<(EdgeBandError, EdgeBandError)>);
    let per_image: Vec<ImageErrors> = evidence
        .registered
        .par_iter()
        .map(|s| {
            let Some(alpha) = &evidence.alphas[s.u * rows + s.v] else {
                return Ok(Vec::new());
            };
            let mut out = Vec::new();
            for (c, (reg, unreg)) in s.basis.iter().zip(&s.unregistered).enumerate() {
                let truth = stage.true_view_image(pose, s.u, s.v, &stage.condition_lights(c)?)?;
                let subject = alpha_mask(&truth.alpha);
                let edges = edge_band_error(&truth.color, &truth.alpha, reg, alpha).zip(
                    edge_band_error(&truth.color, &truth.alpha, &s.raw_basis[c], &s.raw_alpha),
                );
                out.push((
                    (
                        compare(&truth.color, reg, Some(&subject)).psnr_db,
                        compare(&truth.color, unreg, Some(&subject)).psnr_db,
                    ),
                    edges,
                ));
            }
            Ok(out)
        })
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    let registration: Vec<(f64, f64)> = per_image
        .iter()
        .map(|p| p.0)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .collect();
    let mean = |values: &[f64]| {
        (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
    };
    let column = |k: usize| {
        registration
            .iter()
            .map(|r| [r.0, r.1][k])
            .collect::<Vec<_>>()
    };
    let ious: Vec<f64> = per_view.iter().filter_map(|p| p.0.0).collect();
    let maes: Vec<f64> = per_view.iter().map(|p| p.0.1).collect();
    let edges: Vec<(EdgeBandError, EdgeBandError)> = per_image.iter().filter_map(|p| p.1).collect();
    let edge_mean = |f: fn(&(EdgeBandError, EdgeBandError)) -> f64| {
        (!edges.is_empty()).then(|| edges.iter().map(f).sum::<f64>() / edges.len() as f64)
    };
    Ok(PoseErrors {
        alpha_iou: mean(&ious),
        alpha_mae: mean(&maes).unwrap_or(0.0),
        registration_psnr: mean(&column(0)),
        unregistered_psnr: mean(&column(1)),
        flow_epe_horizontal: sum_epe(0),
        flow_epe_vertical: sum_epe(1),
        pose_flow_epe: sum_epe(2),
        pose_flow_motion: sum_epe(3),
        registration_views: evidence.registered.len(),
        hull_iou: evidence
            .hull
            .and_then(|h| h.iou(&stage.true_occupancy(pose, h.grid()))),
        edge_band_error_dark: edge_mean(|e| e.0.dark),
        edge_band_error_bright: edge_mean(|e| e.0.bright),
        edge_band_error_dark_raw: edge_mean(|e| e.1.dark),
        edge_band_error_bright_raw: edge_mean(|e| e.1.bright),
    })
}

/// Views whose registration is evaluated: four columns spread over the turn, all cameras.
fn evaluated(u: usize, columns: usize) -> bool {
    u.is_multiple_of((columns / 4).max(1))
}

/// The judge of an ingest of a virtual-stage capture.
pub struct StageEvaluator {
    stage: Stage,
}

impl StageEvaluator {
    /// The judge of the capture in `capture_dir`, if the virtual stage wrote it (it holds
    /// the stage's configuration); `None` for any other capture.
    pub fn open_if_stage(capture_dir: &Path) -> Result<Option<Self>> {
        if !capture_dir.join(frf_stage::writer::STAGE_FILE).exists() {
            return Ok(None);
        }
        Ok(Some(Self {
            stage: frf_stage::open_stage(capture_dir)?,
        }))
    }
}

impl Evaluator for StageEvaluator {
    fn wants_unregistered(&self, u: usize, _v: usize) -> bool {
        evaluated(u, self.stage.cycles())
    }

    fn evaluate(
        &self,
        pose: u32,
        evidence: &PoseEvidence,
    ) -> std::result::Result<PoseErrors, EvaluationError> {
        Ok(evaluate_pose(&self.stage, pose, evidence)?)
    }
}
