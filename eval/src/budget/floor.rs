//! The floor of every flow-based interpolation at a camera: the field's pre-lit views of
//! the quad, each carried to the camera by the stage's *true* correspondence, with the
//! true visibility, blended with the quad's bilinear weights.
//!
//! For every pixel of the camera the stage knows the point of the walker it shows and
//! where each of the quad's views shows it, and whether that view sees it
//! ([`frf_stage::Stage::truth_flow`]). A morph whose flows were exact and whose
//! visibility were right would sample each view there; what such a morph still gets
//! wrong is what resampling the views costs (bilinear filtering at sub-pixel positions),
//! shading that changes between views (specular highlights, the rim of a limb seen
//! edge-on), and points no view of the quad sees. Pixels whose centre's ray misses the
//! walker take the correspondence of the nearest pixel whose centre's does not, so that
//! the anti-aliased border of the silhouette is carried with it (as the renderer extends
//! its flows, [`frf_render::extend`]). Where no view of the quad sees a point, all of them are
//! blended, as a morph would have to.

use frf_core::camera::Camera;
use frf_core::filter::extend_nearest;
use frf_core::flo::UNKNOWN_THRESHOLD;
use frf_core::image::{Image, Rgba};
use frf_render::resident::ResidentPose;
use frf_stage::Stage;
use frf_stage::geometry::Ray;
use glam::Vec2;
use rayon::prelude::*;

/// One pixel's correspondence into one view: the flow and whether the view sees it.
type Correspondence = ([f32; 2], bool);

fn known(c: &Correspondence) -> bool {
    c.0[0].abs() < UNKNOWN_THRESHOLD && c.0[1].abs() < UNKNOWN_THRESHOLD
}

/// The floor image of `camera` (subject frame) between views `views` of `resident`
/// weighted by `weights` (see the module docs).
pub fn correspondence_floor(
    stage: &Stage,
    pose: u32,
    resident: &ResidentPose,
    camera: &Camera,
    views: [usize; 4],
    weights: [f32; 4],
) -> Image<Rgba> {
    let (surface, _) = stage.truth_surface(pose, camera);
    let (w, h) = surface.size();
    // The stage records, where a pixel's centre misses, a covered sub-sample's point:
    // its flow would be off by the sub-sample's offset.
    let actor = stage.actor(None, stage.pose_time_s(pose));
    let centre_hits: Vec<bool> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let dir = camera.ray_direction(Vec2::new((i % w) as f32, (i / w) as f32));
            let ray = Ray {
                origin: camera.centre(),
                dir,
            };
            actor.intersect(&ray, 0.0, f32::INFINITY).is_some()
        })
        .collect();
    let mut seen = vec![[0.0f32; 4]; w * h];
    let mut seen_weight = vec![0.0f32; w * h];
    let mut all = vec![[0.0f32; 4]; w * h];
    for k in 0..4 {
        if weights[k] <= 0.0 {
            continue;
        }
        let view = views[k];
        let truth = stage.truth_flow(pose, &surface, &resident.geometry.cameras[view]);
        let mut cells: Vec<Correspondence> = truth
            .flow
            .pixels()
            .iter()
            .zip(truth.occluded.pixels())
            .zip(&centre_hits)
            .map(|((f, &o), &hit)| {
                if hit {
                    (*f, o < 0.5)
                } else {
                    ([f32::INFINITY; 2], false)
                }
            })
            .collect();
        extend_nearest(&mut cells, w, h, known);
        for (i, c) in cells.iter().enumerate() {
            if !known(c) {
                continue;
            }
            let s = Vec2::new((i % w) as f32 + c.0[0], (i / w) as f32 + c.0[1]);
            let px = resident.sample_prelit(view, s);
            for ch in 0..4 {
                all[i][ch] += weights[k] * px[ch];
                if c.1 {
                    seen[i][ch] += weights[k] * px[ch];
                }
            }
            if c.1 {
                seen_weight[i] += weights[k];
            }
        }
    }
    let pixels = (0..w * h)
        .map(|i| {
            if seen_weight[i] > 0.0 {
                seen[i].map(|v| v / seen_weight[i])
            } else {
                all[i]
            }
        })
        .collect();
    Image::from_vec(w, h, pixels).expect("w*h pixels by construction")
}
