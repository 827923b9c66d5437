//! How good each ingest step is, against the virtual stage's ground truth (when the
//! capture comes from it): alpha against the true coverage, registered basis images
//! against the true images at the reference instant (and what registration gains over
//! none), and inter-view flow against the true flow inside the matte, horizontal and
//! vertical pairs apart.

use frf_core::grid::Neighbour;
use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_stage::Stage;
use frf_stage::truth::flow_between;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::metrics::compare;

/// True alpha at least this counts as inside the matte for flow errors: the flow of a
/// pixel only partly covered is ill-defined.
const INSIDE_MATTE: f32 = 0.99;
/// Alpha threshold of the binary mattes compared by IoU.
const IOU_THRESHOLD: f32 = 0.5;

/// Errors of one pose against the truth.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseErrors {
    /// Intersection over union of estimated and true mattes (alpha ≥ 0.5), mean over views.
    pub alpha_iou: f64,
    /// Mean absolute alpha error over the image, mean over views.
    pub alpha_mae: f64,
    /// PSNR (dB, subject pixels, peak = the truth's brightest value) of the registered
    /// basis images against the true images at the reference instant, mean over the
    /// evaluated views and conditions.
    pub registration_psnr: f64,
    /// The same for the frames matted without registration.
    pub unregistered_psnr: f64,
    /// Mean end-point error (px) of horizontal-neighbour flow, inside the true matte where
    /// the point is visible in the neighbour.
    pub flow_epe_horizontal: f64,
    /// The same for vertical neighbours.
    pub flow_epe_vertical: f64,
    /// Views whose registration was evaluated.
    pub registration_views: usize,
}

/// Alpha IoU and MAE of one view.
pub fn alpha_errors(estimated: &GrayImage, truth: &GrayImage) -> (f64, f64) {
    let (mut inter, mut union, mut abs) = (0usize, 0usize, 0.0f64);
    for (&e, &t) in estimated.pixels().iter().zip(truth.pixels()) {
        let (a, b) = (e >= IOU_THRESHOLD, t >= IOU_THRESHOLD);
        inter += (a && b) as usize;
        union += (a || b) as usize;
        abs += (e - t).abs() as f64;
    }
    let iou = if union > 0 {
        inter as f64 / union as f64
    } else {
        1.0
    };
    (iou, abs / estimated.pixels().len().max(1) as f64)
}

/// Mean end-point error of `estimated` against the true flow of view `(u, v)` toward
/// `n`, and the pixels compared.
fn flow_epe(
    stage: &Stage,
    pose: u32,
    u: usize,
    v: usize,
    n: Neighbour,
    estimated: &FlowImage,
) -> Result<(f64, usize)> {
    let Some((u2, v2)) = n.of(u, v, stage.cycles(), stage.cameras().len(), true) else {
        return Ok((0.0, 0));
    };
    let (surface, alpha) = stage.reference_surface(pose, u, v)?;
    let truth = flow_between(&surface, &stage.view_setup(pose, u2, v2, 0.0)?);
    let (mut sum, mut count) = (0.0f64, 0usize);
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
        count += 1;
    }
    Ok((sum, count))
}

/// Alpha, flow and (on the sampled views) registration errors of a pose.
pub struct PoseEvidence<'a> {
    /// Estimated alpha per view, `u`-major.
    pub alphas: &'a [GrayImage],
    /// Estimated flows per view.
    pub flows: &'a [[Option<FlowImage>; 4]],
    /// For some views: `(u, v, registered basis, unregistered basis)`.
    pub registered: &'a [(usize, usize, Vec<RgbImage>, Vec<RgbImage>)],
}

/// Evaluates a pose against the stage's truth.
pub fn evaluate_pose(stage: &Stage, pose: u32, evidence: &PoseEvidence) -> Result<PoseErrors> {
    let rows = stage.cameras().len();
    // Per view: (alpha IoU, alpha MAE) and (sum, count) of flow errors, horizontal and
    // vertical.
    type ViewErrors = ((f64, f64), [(f64, usize); 2]);
    let per_view: Vec<ViewErrors> = (0..evidence.alphas.len())
        .into_par_iter()
        .map(|i| {
            let (u, v) = (i / rows, i % rows);
            let (_, true_alpha) = stage.reference_surface(pose, u, v)?;
            let alpha = alpha_errors(&evidence.alphas[i], &true_alpha);
            let mut epe = [(0.0, 0usize); 2];
            for n in Neighbour::ALL {
                if let Some(f) = &evidence.flows[i][n.index()] {
                    let (s, c) = flow_epe(stage, pose, u, v, n, f)?;
                    let k = matches!(n, Neighbour::Up | Neighbour::Down) as usize;
                    epe[k].0 += s;
                    epe[k].1 += c;
                }
            }
            Ok((alpha, epe))
        })
        .collect::<Result<_>>()?;
    let n = per_view.len().max(1) as f64;
    let sum_epe = |k: usize| {
        let (s, c) = per_view
            .iter()
            .fold((0.0, 0), |acc, p| (acc.0 + p.1[k].0, acc.1 + p.1[k].1));
        if c > 0 { s / c as f64 } else { 0.0 }
    };
    let registration: Vec<(f64, f64)> = evidence
        .registered
        .par_iter()
        .map(|(u, v, registered, unregistered)| {
            let mut out = Vec::new();
            for (c, (reg, unreg)) in registered.iter().zip(unregistered).enumerate() {
                let truth = stage.true_view_image(pose, *u, *v, &stage.condition_lights(c)?)?;
                out.push((
                    compare(&truth.color, reg, Some(&truth.alpha)).psnr_db,
                    compare(&truth.color, unreg, Some(&truth.alpha)).psnr_db,
                ));
            }
            Ok(out)
        })
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .collect();
    let m = registration.len().max(1) as f64;
    Ok(PoseErrors {
        alpha_iou: per_view.iter().map(|p| p.0.0).sum::<f64>() / n,
        alpha_mae: per_view.iter().map(|p| p.0.1).sum::<f64>() / n,
        registration_psnr: registration.iter().map(|r| r.0).sum::<f64>() / m,
        unregistered_psnr: registration.iter().map(|r| r.1).sum::<f64>() / m,
        flow_epe_horizontal: sum_epe(0),
        flow_epe_vertical: sum_epe(1),
        registration_views: evidence.registered.len(),
    })
}
