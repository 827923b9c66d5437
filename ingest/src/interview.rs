//! Flow between neighbouring views of a pose (BRIEF section 3.3), measured on each
//! view's registered basis images summed (the subject under the whole dome: evenly lit,
//! so brightness constancy holds across views, and far less noisy than one track frame;
//! measured on the small preset: 0.58 px instead of 0.73 px end-point error).
//!
//! Both kinds of pair are first rectified ([`crate::rectify`]): the neighbour is warped
//! onto the reference's fronto-parallel plane through the turntable axis, flow is measured
//! there (it only has to explain the subject's relief around that plane and the actor's
//! cycle-to-cycle differences), and mapped back to true pixel coordinates. Cameras are
//! those seen from the subject frame, so that:
//!
//! - vertical neighbours `(u, v ± 1)`, different cameras of one cycle, are related by the
//!   cameras' geometry (as in the original);
//! - horizontal neighbours `(u ± 1, v)`, the same camera in consecutive cycles, are
//!   related by the turntable's turn: seen from the subject, the camera orbited by 10°.
//!   The original searched a wider range instead; rectifying as well removes most of the
//!   turn's displacement (measured: 0.61 → 0.58 px), and the search stays wide
//!   ([`FlowParams::wide_search`]) for the actor's cycle-to-cycle differences.
//!
//! Flow is stored only near the subject: inside its matte grown by [`FLOW_MARGIN_PX`]
//! (the morph samples a little outside the silhouette); elsewhere it is unknown.

use frf_core::camera::Camera;
use frf_core::image::{FlowImage, GrayImage, Image, RgbImage};
use frf_flow::FlowParams;

use crate::error::Result;
use crate::rectify::{rectify, rectifying_homography, unrectify_flow};

/// Pixels beyond the matte where flow is kept.
pub const FLOW_MARGIN_PX: usize = 3;

/// Flow between two views, through rectification; `camera_a` and `camera_b` are the
/// views' cameras as seen from the subject frame.
pub fn rectified_flow(
    a: &RgbImage,
    b: &RgbImage,
    camera_a: &Camera,
    camera_b: &Camera,
    params: &FlowParams,
) -> Result<FlowImage> {
    let h = rectifying_homography(camera_a, camera_b)?;
    let rectified = rectify(b, &h, a.width(), a.height());
    let f = frf_flow::estimate_flow(a, &rectified, &params.wide_search())?;
    Ok(unrectify_flow(&f, &h))
}

/// Forward and backward flow disagreeing by more than this (px) mark an occlusion or a
/// mismatch, where the two are not averaged.
pub const CONSISTENCY_PX: f32 = 1.0;

/// Averages a flow with its reverse: `F'(s) = ½ (F(s) − B(s + F(s)))`, with `B` the flow
/// measured the other way (bilinear), wherever the two agree to within
/// [`CONSISTENCY_PX`]; elsewhere `F` is kept. The two estimates come from separate
/// solves, so their errors partly cancel.
pub fn symmetrize(forward: &FlowImage, backward: &FlowImage) -> FlowImage {
    let w = forward.width();
    let pixels = forward
        .pixels()
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let b = backward.sample_bilinear(x + f[0], y + f[1], frf_core::image::Border::Clamp);
            let (dx, dy) = (f[0] + b[0], f[1] + b[1]);
            if (dx * dx + dy * dy).sqrt() <= CONSISTENCY_PX {
                [0.5 * (f[0] - b[0]), 0.5 * (f[1] - b[1])]
            } else {
                *f
            }
        })
        .collect();
    Image::from_vec(w, forward.height(), pixels).expect("same size as the input")
}

/// `flow` where the matte grown by [`FLOW_MARGIN_PX`] is positive, unknown elsewhere.
pub fn keep_near_subject(flow: &FlowImage, alpha: &GrayImage) -> FlowImage {
    let (w, h) = flow.size();
    let r = FLOW_MARGIN_PX as i64;
    // Grow the matte: a separable max over a (2r+1)-wide window.
    let inside: Vec<bool> = alpha.pixels().iter().map(|&a| a > 0.0).collect();
    let mut rows = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            rows[y * w + x] = (-r..=r).any(|d| {
                let xs = x as i64 + d;
                xs >= 0 && xs < w as i64 && inside[y * w + xs as usize]
            });
        }
    }
    Image::from_fn(w, h, |x, y| {
        let near = (-r..=r).any(|d| {
            let ys = y as i64 + d;
            ys >= 0 && ys < h as i64 && rows[ys as usize * w + x]
        });
        if near {
            flow.get(x, y)
        } else {
            [frf_core::flo::UNKNOWN; 2]
        }
    })
}
