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
//! neighbour is estimated over a short range ([`RESIDUAL_SEARCH_M`]), and the two are
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
use frf_reflectance::hull::{Silhouette, VoxelHull, pixel_footprint_m, voxel_per_pixel};
use glam::Vec2;
use rayon::prelude::*;

use crate::error::{IngestError, Result};

/// How the flows between neighbouring views are measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
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
/// searched this far on the subject, metres ([`residual_search_px`] turns it into pixels
/// of the views at hand): the cycle-to-cycle differences move a foot by up to about 2 cm
/// (a 1.2° joint perturbation on a 0.8 m leg), and the hull errs by less than a pixel in
/// concave places. Chosen on the perturbed small preset (160x224, a pixel's footprint 9.8
/// mm on the axis): 1 px 0.38, 4 px 0.31, 8 px 0.31 px end-point error; 4 px is 0.039 m.
/// The tiny and paper sizes' check is in docs/results/ingest.md.
pub const RESIDUAL_SEARCH_M: f32 = 0.039;

/// `metres` on the turntable axis in pixels of `cameras` ([`pixel_footprint_m`]), at
/// least one; `metres` at a 1 cm footprint where the cameras give none.
pub fn residual_search_px(metres: f32, cameras: &[Camera]) -> f32 {
    (metres / pixel_footprint_m(cameras).unwrap_or(0.01)).max(1.0)
}

/// The flow hull's voxel is this fraction of a pixel's footprint on the turntable axis.
/// Measured on the small preset without perturbation (footprint 9.8 mm), the hull's own
/// flow: 0.21 px at 1 cm, 0.16 px at 5 mm, 0.15 px at 2.5 mm (twice the cost).
const VOXEL_PER_PIXEL: f32 = 0.5;
/// The band carve starts from voxels this many times larger ([`VoxelHull::carve_banded`]).
const BAND_COARSE: u32 = 4;
/// Bounds of the flow hull's voxel side, metres: finer costs memory (a 2.5 mm grid of
/// the walker's box holds about 80 million voxels); 2 cm is the coarsest hull stored.
const VOXEL_RANGE_M: (f32, f32) = (0.0025, 0.02);

/// The flow hull's voxel side for these cameras: [`VOXEL_PER_PIXEL`] of the smallest
/// pixel footprint on the turntable axis, within [`VOXEL_RANGE_M`].
pub fn flow_hull_voxel_m(cameras: &[Camera]) -> f32 {
    voxel_per_pixel(cameras, VOXEL_PER_PIXEL, VOXEL_RANGE_M)
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
/// images over [`RESIDUAL_SEARCH_M`] ([`refine_flow`]).
pub fn guided_flow(
    a: &RgbImage,
    b: &RgbImage,
    camera_a: &Camera,
    camera_b: &Camera,
    hull: &VoxelHull,
    params: &FlowParams,
) -> Result<FlowImage> {
    if !a.same_size(b) {
        return Err(IngestError::sizes("the view matched", a.size(), b.size()));
    }
    let (w, h) = a.size();
    let prior = hull_flow(hull, camera_a, camera_b, w, h);
    if prior.pixels().first().is_none_or(|f| !is_known(*f)) {
        return Err(IngestError::Degenerate(
            "no ray of the view meets the pose's hull: it cannot guide the flow".into(),
        ));
    }
    let search = residual_search_px(RESIDUAL_SEARCH_M, &[*camera_a, *camera_b]);
    refine_flow(a, b, &prior, params, search)
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
    if !a.same_size(b) {
        return Err(IngestError::sizes("the view matched", a.size(), b.size()));
    }
    if !a.same_size(prior) {
        return Err(IngestError::sizes("the prior flow", a.size(), prior.size()));
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

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    const CENTRE: Vec3 = Vec3::new(0.0, 1.0, 0.0);
    const RADIUS: f32 = 0.3;

    /// Where the ray of `camera` through pixel `s` meets the sphere first.
    fn on_sphere(camera: &Camera, s: Vec2) -> Option<Vec3> {
        let dir = camera.ray_direction(s);
        let oc = camera.centre() - CENTRE;
        let b = oc.dot(dir);
        let disc = b * b - (oc.length_squared() - RADIUS * RADIUS);
        (disc >= 0.0).then(|| camera.centre() + dir * (-b - disc.sqrt()))
    }

    /// A sphere seen by `n` cameras on a ring, at three heights, and their mattes.
    fn ring(n: usize, size: u32) -> Vec<(Camera, GrayImage)> {
        (0..n)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / n as f32;
                let eye = CENTRE + Vec3::new(a.sin() * 4.0, 0.6 * (i % 3) as f32, a.cos() * 4.0);
                let cam = Camera::look_at(eye, CENTRE, Vec3::Y, 0.5, size, size).unwrap();
                let alpha = Image::from_fn(size as usize, size as usize, |x, y| {
                    f32::from(u8::from(
                        on_sphere(&cam, Vec2::new(x as f32, y as f32)).is_some(),
                    ))
                });
                (cam, alpha)
            })
            .collect()
    }

    #[test]
    fn the_residual_search_is_a_distance_on_the_subject() {
        // The stage's cameras: 4.5 m away, 27.5° vertical field of view.
        let camera = |h: u32| {
            let eye = Vec3::new(0.0, 0.9, 4.5);
            let (target, fov) = (Vec3::new(0.0, 0.9, 0.0), 27.5f32.to_radians());
            Camera::look_at(eye, target, Vec3::Y, fov, h * 5 / 7, h).unwrap()
        };
        let at = |h: u32| residual_search_px(RESIDUAL_SEARCH_M, &[camera(h)]);
        // What it was chosen as at the small preset, and the same metres at the others.
        let (tiny, small, paper) = (at(90), at(224), at(448));
        assert!((3.9..=4.0).contains(&small), "{small}");
        assert!((small / paper - 0.5).abs() < 1e-3, "{small} {paper}");
        assert!((tiny / small - 90.0 / 224.0).abs() < 1e-3, "{tiny} {small}");
        // Never below a pixel.
        assert_eq!(residual_search_px(1e-6, &[camera(224)]), 1.0);
    }

    #[test]
    fn the_hull_flow_of_a_sphere_is_its_reprojection() {
        let views = ring(24, 160);
        let cameras: Vec<Camera> = views.iter().map(|v| v.0).collect();
        let mattes: Vec<&GrayImage> = views.iter().map(|v| &v.1).collect();
        let voxel = flow_hull_voxel_m(&cameras);
        // Half of a pixel's footprint 4 m away: 4 m / 326 px / 2.
        assert!(
            (voxel - 0.5 * 4.0 / cameras[0].intrinsics.fx).abs() < 1e-4,
            "{voxel}"
        );
        let hull = flow_hull(&cameras, &mattes, 0).unwrap().unwrap();
        // Neighbours on the ring, 15 degrees apart, and a view from the other height.
        for (a, b) in [(0, 1), (5, 6), (0, 2)] {
            let (ca, cb) = (&cameras[a], &cameras[b]);
            let flow = hull_flow(&hull, ca, cb, 160, 160);
            // What the images alone were matched from: the plane through the axis.
            let plane = crate::rectify::rectifying_homography(ca, cb).unwrap();
            let (mut sum, mut plane_sum, mut count) = (0.0f32, 0.0f32, 0);
            for y in 0..160 {
                for x in 0..160 {
                    let s = Vec2::new(x as f32, y as f32);
                    // Inside the silhouette by a pixel: the hull's rim is a voxel wide.
                    let inside = [(-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0)]
                        .iter()
                        .all(|d| on_sphere(ca, s + Vec2::from(*d)).is_some());
                    let Some(p) = on_sphere(ca, s).filter(|_| inside) else {
                        continue;
                    };
                    let truth = cb.project(p).unwrap() - s;
                    let f = flow.get(x, y);
                    sum += (Vec2::new(f[0], f[1]) - truth).length();
                    plane_sum += (plane.apply(s) - s - truth).length();
                    count += 1;
                }
            }
            let (epe, plane_epe) = (sum / count as f32, plane_sum / count as f32);
            eprintln!(
                "views {a} -> {b}: hull flow EPE {epe:.3} px, the axis plane's {plane_epe:.3} px, \
                 over {count} px"
            );
            // A visual hull of 24 views is a little fat where no view sees the sphere's
            // outline (top and bottom: the views rise to 17 degrees only): measured 0.15
            // to 0.28 px, where the plane errs by 5 to 10 px.
            assert!(
                count > 1000 && epe < 0.3 && epe < 0.04 * plane_epe,
                "views {a} -> {b}: EPE {epe} over {count} px, the plane's {plane_epe}"
            );
        }
        // Rays that miss the hull take the nearest flow: the whole image is known.
        let flow = hull_flow(&hull, &cameras[0], &cameras[1], 160, 160);
        assert!(
            flow.pixels()
                .iter()
                .all(|f| is_known(*f) && f[0].is_finite())
        );
    }

    #[test]
    fn the_prior_is_refined_to_the_images_motion() {
        // A smooth pattern moved by a known sub-pixel shift; a prior that is off by
        // 1.5 px is brought back by the images.
        let pattern = |x: f32, y: f32| {
            let v = 0.5 + 0.2 * (0.37 * x).sin() * (0.29 * y).cos() + 0.1 * (0.11 * (x + y)).sin();
            [v, v * 0.8, v * 0.6]
        };
        let shift = Vec2::new(1.3, -0.6);
        let a = Image::from_fn(64, 64, |x, y| pattern(x as f32, y as f32));
        let b = Image::from_fn(64, 64, |x, y| {
            pattern(x as f32 - shift.x, y as f32 - shift.y)
        });
        let prior = Image::new(64, 64, [shift.x + 1.5, shift.y]);
        let params = FlowParams::preset(frf_flow::Preset::Balanced);
        let f = refine_flow(&a, &b, &prior, &params, 4.0).unwrap();
        let (mut sum, mut count) = (0.0, 0);
        for y in 8..56 {
            for x in 8..56 {
                let g = f.get(x, y);
                sum += (Vec2::new(g[0], g[1]) - shift).length();
                count += 1;
            }
        }
        let epe = sum / count as f32;
        assert!(epe < 0.05, "EPE {epe}");
        let e = refine_flow(&a, &b, &Image::new(3, 3, [0.0; 2]), &params, 4.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("the prior flow") && e.contains("got 3x3"), "{e}");
    }
}
