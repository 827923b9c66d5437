//! The geometry baseline of the budget: unstructured lumigraph rendering (Buehler et al.,
//! SIGGRAPH 2001) of the field's pre-lit views on a geometric proxy.
//!
//! For every pixel of the camera the proxy gives the point `P` its ray meets. Every
//! captured view that sees `P` is a candidate, penalised by the angle at `P` between its
//! ray and the camera's (`angle`) and, a little, by how much farther it stands from `P`
//! than the camera (`resolution`, relative); the [`NEIGHBOURS`] least penalised are
//! blended with weights `(1 − penalty / threshold) / penalty`, the threshold being the
//! next candidate's penalty, normalized: each view fades out before it is replaced, so
//! weights vary smoothly over the image, and a view weighs alone where the camera
//! stands on it (Buehler's epipole consistency). Each view is sampled where `P`
//! projects into it.
//!
//! Two proxies: the pose's visual hull (what the renderer has), and the stage's true
//! surface (the upper bound of any proxy). Pixels whose ray misses the proxy take the
//! depth of the nearest pixel that meets it, so that the silhouette's anti-aliased border
//! is read from the views around it.

use frf_core::camera::Camera;
use frf_core::filter::extend_nearest;
use frf_core::image::{Image, Rgba};
use frf_render::resident::ResidentPose;
use glam::Vec3;
use rayon::prelude::*;

/// Views blended per pixel (Buehler et al. use 3 to 4).
pub const NEIGHBOURS: usize = 4;
/// Weight of the relative resolution penalty against the angle, radians per unit.
pub const RESOLUTION_WEIGHT: f32 = 0.1;
/// The least penalty a weight divides by (radians): a view within 1e-6 rad of the
/// camera's ray weighs a million times its neighbours.
const PENALTY_EPS: f32 = 1e-6;

/// Per pixel of `camera`, the distance along its ray to the proxy (`None`: it misses),
/// extended to the pixels that miss from their nearest neighbour that does not; `None`
/// everywhere when no ray meets the proxy.
pub fn depths(camera: &Camera, hit: impl Fn(Vec3, Vec3) -> Option<f32> + Sync) -> Vec<Option<f32>> {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut t: Vec<Option<f32>> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let dir = camera.ray_direction(glam::Vec2::new((i % w) as f32, (i / w) as f32));
            hit(camera.centre(), dir)
        })
        .collect();
    extend_nearest(&mut t, w, h, |d| d.is_some());
    t
}

/// ULR of `resident`'s views from `camera`, on the proxy whose distances along the
/// pixels' rays are `depths` ([`depths`]); `visible(view, P)` says whether a view sees
/// the point `P`.
pub fn render(
    resident: &ResidentPose,
    camera: &Camera,
    depths: &[Option<f32>],
    visible: impl Fn(usize, Vec3) -> bool + Sync,
) -> Image<Rgba> {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let cams = &resident.geometry.cameras;
    let pixels = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let Some(t) = depths[i] else {
                return [0.0; 4];
            };
            let dir = camera.ray_direction(glam::Vec2::new((i % w) as f32, (i / w) as f32));
            let p = camera.centre() + dir * t;
            let mut candidates: Vec<(f32, usize)> = cams
                .iter()
                .enumerate()
                .map(|(k, c)| {
                    let to = p - c.centre();
                    let angle = (-dir).angle_between(-to);
                    let farther = ((to.length() - t) / to.length().max(1e-6)).max(0.0);
                    (angle + RESOLUTION_WEIGHT * farther, k)
                })
                .collect();
            candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
            let chosen: Vec<(f32, usize)> = candidates
                .into_iter()
                .filter(|&(_, k)| visible(k, p))
                .take(NEIGHBOURS + 1)
                .collect();
            if chosen.is_empty() {
                return [0.0; 4];
            }
            let threshold = if chosen.len() > NEIGHBOURS {
                chosen[NEIGHBOURS].0
            } else {
                chosen.last().map_or(1.0, |c| c.0) * 1.5 + 1e-6
            };
            let mut out = [0.0f32; 4];
            let mut total = 0.0f32;
            for &(penalty, k) in chosen.iter().take(NEIGHBOURS) {
                let weight = if threshold > 0.0 {
                    (1.0 - penalty / threshold).max(0.0) / penalty.max(PENALTY_EPS)
                } else {
                    1.0
                };
                let Some(s) = cams[k].project(p) else {
                    continue;
                };
                let px = resident.sample_prelit(k, s);
                for c in 0..4 {
                    out[c] += weight * px[c];
                }
                total += weight;
            }
            if total > 0.0 {
                out.map(|v| v / total)
            } else {
                resident.sample_prelit(
                    chosen[0].1,
                    cams[chosen[0].1].project(p).unwrap_or_default(),
                )
            }
        })
        .collect();
    Image::from_vec(w, h, pixels).expect("w*h pixels by construction")
}
