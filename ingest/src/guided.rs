//! Inter-view flow guided by the pose's geometry (docs/design.md section 2.3).
//!
//! The capture's cameras are calibrated, and every view of a pose sees the same walker
//! (up to the small cycle-to-cycle differences of consecutive cycles): the flow between
//! two views is, to first order, the reprojection of the walker's surface. The visual
//! hull carved from the pose's mattes is that surface wherever the walker is convex,
//! and its flow ([`hull_flow`]) is far more exact than what image matching finds on
//! these images. Measured on the small preset without perturbation (seven pairs, inside
//! the true matte): image matching 0.69 px end-point error, almost all of it along the
//! epipolar lines (0.66 px; 0.10 px across them), i.e. in depth; even started from the
//! true flow the matcher drifts to 0.42 px, the images themselves disagreeing with the
//! truth at that level (shading seen from another direction, resampling); the hull's
//! flow 0.33 px at 2 cm voxels, 0.21 at 1 cm, 0.16 at 5 mm.
//!
//! What the hull cannot know is how the walker of one cycle differs from the next's
//! (horizontal neighbours are consecutive cycles), and where it is concave. So the
//! flow is the hull's, refined on the images ([`guided_flow`]): the neighbour is warped
//! onto the view by the hull's flow, the residual flow between the view and the warped
//! neighbour is estimated over a short range ([`RESIDUAL_SEARCH_PX`]), and the two are
//! composed. On the perturbed small preset: 0.65 px by image matching (through the
//! plane of the turntable's axis, [`crate::rectify`]), 0.72 px by the hull alone, 0.31
//! px guided.
//!
//! The hull is carved for the flow at half a pixel's footprint on the turntable's axis
//! ([`flow_hull_voxel_m`]: 5 mm at 160x224, 2.5 mm at 320x448) in a narrow band
//! ([`VoxelHull::carve_banded`]), finer than the hull stored for shadows.

use frf_core::camera::Camera;
use frf_core::filter::extend_nearest;
use frf_core::flo::{UNKNOWN, is_known};
use frf_core::image::{Border, FlowImage, GrayImage, Image, RgbImage};
use frf_flow::FlowParams;
use frf_reflectance::hull::{Silhouette, VoxelHull};
use glam::Vec2;
use rayon::prelude::*;

use crate::error::{IngestError, Result};

/// How the flows between neighbouring views are measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InterViewFlow {
    /// Image matching guided by the pose's visual hull ([`guided_flow`]).
    #[default]
    Hull,
    /// Image matching alone, through the plane of the turntable's axis (the inter-view
    /// module's `rectified_flow`), as before the hull guided it.
    Images,
}

impl InterViewFlow {
    /// Its name on the command line and in part settings.
    pub fn name(self) -> &'static str {
        match self {
            Self::Hull => "hull",
            Self::Images => "images",
        }
    }
}

/// The residual flow between a view and its neighbour warped by the hull's flow is
/// searched over this many pixels: the cycle-to-cycle differences move a foot by up to
/// about 2 px at 160x224 (a 1.2° joint perturbation on a 0.8 m leg), and the hull errs by
/// less than a pixel in concave places. Measured on the perturbed small preset: 1 px
/// 0.38, 4 px 0.31, 8 px 0.31 px end-point error.
pub const RESIDUAL_SEARCH_PX: f32 = 4.0;

/// The flow hull's voxel is this fraction of a pixel's footprint on the turntable axis.
/// Measured on the small preset without perturbation (footprint 9.8 mm), the hull's own
/// flow: 0.21 px at 1 cm, 0.16 px at 5 mm, 0.15 px at 2.5 mm (twice the cost).
const VOXEL_PER_PIXEL: f32 = 0.5;
/// The band carve starts from voxels this many times larger ([`VoxelHull::carve_banded`]).
const BAND_COARSE: u32 = 4;
/// Bounds of the flow hull's voxel side, metres: finer costs memory (a 2.5 mm grid of
/// the walker's box holds about 80 million voxels), coarser is the shadow hull's.
const VOXEL_RANGE_M: (f32, f32) = (0.0025, 0.02);

/// The flow hull's voxel side for these cameras: [`VOXEL_PER_PIXEL`] of the smallest
/// pixel footprint on the turntable axis, within [`VOXEL_RANGE_M`].
pub fn flow_hull_voxel_m(cameras: &[Camera]) -> f32 {
    let footprint = cameras
        .iter()
        .map(|c| (c.centre() - c.axis_point()).length() / c.intrinsics.fx.max(c.intrinsics.fy))
        .filter(|f| f.is_finite() && *f > 0.0)
        .fold(f32::INFINITY, f32::min);
    if !footprint.is_finite() {
        return VOXEL_RANGE_M.1;
    }
    (footprint * VOXEL_PER_PIXEL).clamp(VOXEL_RANGE_M.0, VOXEL_RANGE_M.1)
}

/// The hull the flows are guided by, carved from the views' mattes (cameras in the
/// subject frame) allowing `misses` views to disagree; `None` when nothing survives.
pub fn flow_hull(
    cameras: &[Camera],
    alphas: &[&GrayImage],
    misses: usize,
) -> Result<Option<VoxelHull>> {
    let views: Vec<Silhouette> = cameras
        .iter()
        .zip(alphas)
        .map(|(camera, alpha)| Silhouette { camera, alpha })
        .collect();
    let hull = VoxelHull::carve_banded(&views, flow_hull_voxel_m(cameras), BAND_COARSE, misses)?;
    Ok((hull.count() > 0).then_some(hull))
}

/// The flow from view `a` to view `b` (cameras in the subject frame, images `width x
/// height`) that the hull's surface implies: at each pixel of `a`, the point where its
/// ray first meets the hull (the middle of the first occupied voxel along it), projected
/// into `b`. Pixels whose ray misses the hull take the flow of the nearest one that meets
/// it; with no pixel meeting it, the flow is unknown everywhere.
pub fn hull_flow(
    hull: &VoxelHull,
    a: &Camera,
    b: &Camera,
    width: usize,
    height: usize,
) -> FlowImage {
    let half_voxel = 0.5 * hull.grid().voxel_m;
    let mut flow: Vec<[f32; 2]> = (0..width * height)
        .into_par_iter()
        .map(|i| {
            let s = Vec2::new((i % width) as f32, (i / width) as f32);
            let dir = a.ray_direction(s);
            hull.first_hit(a.centre(), dir)
                .and_then(|t| b.project(a.centre() + dir * (t + half_voxel)))
                .map_or([UNKNOWN; 2], |p| [p.x - s.x, p.y - s.y])
        })
        .collect();
    extend_nearest(&mut flow, width, height, |f| is_known(*f));
    Image::from_vec(width, height, flow).expect("width x height values")
}

/// The flow from image `a` to image `b` (views with cameras `camera_a` and `camera_b`,
/// subject frame) guided by `hull` (see the module docs): the hull's flow refined on the
/// images over [`RESIDUAL_SEARCH_PX`] ([`refine_flow`]).
pub fn guided_flow(
    a: &RgbImage,
    b: &RgbImage,
    camera_a: &Camera,
    camera_b: &Camera,
    hull: &VoxelHull,
    params: &FlowParams,
) -> Result<FlowImage> {
    if !a.same_size(b) {
        return Err(IngestError::BadParameter(format!(
            "views of {}x{} and {}x{} cannot be matched",
            a.width(),
            a.height(),
            b.width(),
            b.height()
        )));
    }
    let (w, h) = a.size();
    let prior = hull_flow(hull, camera_a, camera_b, w, h);
    if prior.pixels().first().is_none_or(|f| !is_known(*f)) {
        return Err(IngestError::BadParameter(
            "no ray of the view meets the pose's hull: it cannot guide the flow".into(),
        ));
    }
    refine_flow(a, b, &prior, params, RESIDUAL_SEARCH_PX)
}

/// The flow from image `a` to image `b` that `prior` predicts, refined on the images:
/// `b` warped onto `a` by the prior `P` (bicubic), the residual `r` from `a` to the
/// warped `b` estimated with `params` over `search_px`, and `F(s) = r(s) + P(s + r(s))`.
/// The residual's smoothness then holds the prior's shape where the images say little,
/// instead of flattening the flow itself.
pub fn refine_flow(
    a: &RgbImage,
    b: &RgbImage,
    prior: &FlowImage,
    params: &FlowParams,
    search_px: f32,
) -> Result<FlowImage> {
    if !(a.same_size(b) && a.same_size(prior)) {
        return Err(IngestError::BadParameter(format!(
            "views of {}x{} and {}x{} and a prior of {}x{} cannot be matched",
            a.width(),
            a.height(),
            b.width(),
            b.height(),
            prior.width(),
            prior.height()
        )));
    }
    let (w, h) = a.size();
    let warped = Image::from_fn(w, h, |x, y| {
        let f = prior.get(x, y);
        b.sample_bicubic(x as f32 + f[0], y as f32 + f[1], Border::Zero)
    });
    let residual = frf_flow::estimate_flow(
        a,
        &warped,
        &FlowParams {
            max_displacement_px: search_px,
            ..*params
        },
    )?;
    Ok(Image::from_fn(w, h, |x, y| {
        let r = residual.get(x, y);
        let p = prior.sample_bilinear(x as f32 + r[0], y as f32 + r[1], Border::Clamp);
        [r[0] + p[0], r[1] + p[1]]
    }))
}
