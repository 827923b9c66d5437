//! What an ingest hands to whoever can judge it against a ground truth, and the figures
//! it records in its report when someone does. Ingest itself knows no truth: the
//! virtual stage's judge lives in `frf-eval`, and a real capture has none.

use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_reflectance::hull::VoxelHull;
use serde::{Deserialize, Serialize};

/// Errors of one pose against a ground truth.
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
    /// Intersection over union of the visual hull's voxels with the true occupancy of
    /// the same grid (`None` without a hull).
    #[serde(default)]
    pub hull_iou: Option<f64>,
}

/// One pose's intermediate results, as ingest computed them.
pub struct PoseEvidence<'a> {
    /// Estimated alpha per view, `u`-major.
    pub alphas: &'a [GrayImage],
    /// Estimated flows per view, in [`frf_core::grid::Neighbour::ALL`] order.
    pub flows: &'a [[Option<FlowImage>; 4]],
    /// For the views the evaluator asked for ([`Evaluator::wants_unregistered`]):
    /// `(u, v, registered basis, the same frames matted without registration)`.
    pub registered: &'a [(usize, usize, Vec<RgbImage>, Vec<RgbImage>)],
    /// The pose's visual hull, when ingest carved one.
    pub hull: Option<&'a VoxelHull>,
}

/// Errors an evaluator may return (its own error type, boxed).
pub type EvaluationError = Box<dyn std::error::Error + Send + Sync>;

/// Someone who can judge an ingest against a ground truth.
pub trait Evaluator: Sync {
    /// Whether ingest should keep view `(u, v)`'s basis frames matted without
    /// registration, to measure what registration gains.
    fn wants_unregistered(&self, u: usize, v: usize) -> bool;
    /// The errors of pose `pose` from its evidence.
    fn evaluate(
        &self,
        pose: u32,
        evidence: &PoseEvidence,
    ) -> std::result::Result<PoseErrors, EvaluationError>;
}
