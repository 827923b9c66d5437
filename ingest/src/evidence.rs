//! What an ingest hands to whoever can judge it against a ground truth, and the figures
//! it records in its report when someone does. Ingest itself knows no truth: the
//! virtual stage's judge lives in `frf-eval`, and a real capture has none.

use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_reflectance::hull::VoxelHull;
use serde::{Deserialize, Serialize};

/// Errors of one pose against a ground truth.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseErrors {
    /// Intersection over union of estimated and true mattes (alpha ≥ 0.5), mean over the
    /// views where either matte holds a pixel (`None`: no view does, nothing measured).
    pub alpha_iou: Option<f64>,
    /// Mean absolute alpha error over the image, mean over views.
    pub alpha_mae: f64,
    /// PSNR (dB, subject pixels, peak = the truth's brightest value) of the registered
    /// basis images against the true images at the reference instant, mean over the
    /// evaluated views and conditions (`None`: no view was evaluated, or none holds a
    /// subject pixel).
    pub registration_psnr: Option<f64>,
    /// The same for the frames matted without registration.
    pub unregistered_psnr: Option<f64>,
    /// Mean end-point error (px) of horizontal-neighbour flow, inside the true matte where
    /// the point is visible in the neighbour (`None`: no such pixel, as in a capture too
    /// small for any pixel to lie wholly inside the subject).
    pub flow_epe_horizontal: Option<f64>,
    /// The same for vertical neighbours.
    pub flow_epe_vertical: Option<f64>,
    /// The same for the flows to the next and previous captured pose of each view
    /// (`None` where there are none).
    #[serde(default)]
    pub pose_flow_epe: Option<f64>,
    /// The mean length of the true motion over the same pixels (the error of no flow).
    #[serde(default)]
    pub pose_flow_motion: Option<f64>,
    /// Views whose registration was evaluated.
    pub registration_views: usize,
    /// Intersection over union of the visual hull's voxels with the true occupancy of
    /// the same grid (`None` without a hull, or when both are empty).
    #[serde(default)]
    pub hull_iou: Option<f64>,
    /// Error over the edge band (true alpha strictly between 0.05 and 0.95) of the
    /// registered basis images composited over black, against the truth composited the
    /// same way: mean absolute error per channel relative to the truth's mean subject
    /// value, mean over the evaluated views and conditions. `None` where not measured
    /// (no evaluated view, or a part written before the figure existed).
    #[serde(default)]
    pub edge_band_error_dark: Option<f64>,
    /// The same composited over a bright background (the truth's 99th-percentile subject
    /// value), which also shows the error of alpha: `F + (1 − α) b`.
    #[serde(default)]
    pub edge_band_error_bright: Option<f64>,
    /// [`Self::edge_band_error_dark`] of the frames before edge decontamination (matted
    /// with the blurred binary matte).
    #[serde(default)]
    pub edge_band_error_dark_raw: Option<f64>,
    /// [`Self::edge_band_error_bright`] of the frames before edge decontamination.
    #[serde(default)]
    pub edge_band_error_bright_raw: Option<f64>,
}

/// A view whose registration and edges the evaluator asked to see
/// ([`Evaluator::wants_unregistered`]).
pub struct SampledView {
    /// Column.
    pub u: usize,
    /// Camera.
    pub v: usize,
    /// Registered basis images as stored (their alpha is the view's in
    /// [`PoseEvidence::alphas`]).
    pub basis: Vec<RgbImage>,
    /// The same frames matted without registration (same edge treatment).
    pub unregistered: Vec<RgbImage>,
    /// The registered frames before edge decontamination.
    pub raw_basis: Vec<RgbImage>,
    /// The alpha they were matted with (the blurred binary matte).
    pub raw_alpha: GrayImage,
}

/// One pose's intermediate results, as ingest computed them.
pub struct PoseEvidence<'a> {
    /// Estimated alpha per view, `u`-major (`None`: the view was not ingested).
    pub alphas: &'a [Option<GrayImage>],
    /// Estimated flows per view, in [`frf_core::grid::Neighbour::ALL`] order.
    pub flows: &'a [[Option<FlowImage>; 4]],
    /// Estimated pose-to-pose flows per view, in [`frf_core::grid::PoseStep::ALL`] order.
    pub pose_flows: &'a [[Option<FlowImage>; 2]],
    /// The poses among which they lead to the next and the previous (sorted).
    pub pose_flows_among: &'a [u32],
    /// The views the evaluator asked for ([`Evaluator::wants_unregistered`]).
    pub registered: &'a [SampledView],
    /// The pose's visual hull, when ingest carved one.
    pub hull: Option<&'a VoxelHull>,
}

/// Errors an evaluator may return (its own error type, boxed).
pub type EvaluationError = Box<dyn std::error::Error + Send + Sync>;

/// Someone who can judge an ingest against a ground truth.
pub trait Evaluator: Sync {
    /// Whether ingest should keep view `(u, v)`'s basis frames matted without
    /// registration and without edge decontamination ([`SampledView`]), to measure what
    /// each gains.
    fn wants_unregistered(&self, u: usize, v: usize) -> bool;
    /// The errors of pose `pose` from its evidence.
    fn evaluate(
        &self,
        pose: u32,
        evidence: &PoseEvidence,
    ) -> std::result::Result<PoseErrors, EvaluationError>;
}
