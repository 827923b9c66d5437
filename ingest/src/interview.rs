//! Flow between neighbouring views of a pose (docs/design.md section 2.3), measured on each
//! view's registered basis images summed (the subject under the whole dome: evenly lit,
//! so brightness constancy holds across views, and far less noisy than one track frame;
//! measured on the small preset: 0.58 px instead of 0.73 px end-point error).
//!
//! With the pose's visual hull, each pair's flow is the hull's, refined on the images
//! ([`crate::guided`]); without it (`--inter-view-flow images`, or no hull), the
//! original's matching, through rectification:
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

use std::time::Instant;

use frf_core::camera::Camera;
use frf_core::grid::Neighbour;
use frf_core::image::{FlowImage, GrayImage, Image, RgbImage};
use frf_flow::FlowParams;
use rayon::prelude::*;

use frf_reflectance::hull::VoxelHull;

use crate::error::Result;
use crate::guided::guided_flow;
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

/// The views of a grid, `u`-major (`index = u * rows + v`), as the flow step needs them:
/// the image flow is measured on, its matte, and its camera seen from the subject frame
/// (`None` for a view not ingested: no flow to or from it).
pub struct GridViews<'a> {
    /// Columns.
    pub columns: usize,
    /// Rows.
    pub rows: usize,
    /// Whether the columns close into a ring.
    pub wraps: bool,
    /// Per view: the image flow is measured on.
    pub images: &'a [Option<&'a RgbImage>],
    /// Per view: its matte (flow is kept near it).
    pub alphas: &'a [Option<&'a GrayImage>],
    /// Per view: its camera, subject frame.
    pub cameras: &'a [Camera],
    /// Per view and neighbour: the flow is wanted (`None`: all); a pair is measured when
    /// either of its two directions is wanted, and kept where it is.
    pub wanted: Option<&'a [[bool; 4]]>,
    /// The pose's hull the flows are guided by ([`crate::guided`]); `None`: image
    /// matching alone ([`rectified_flow`]).
    pub hull: Option<&'a VoxelHull>,
}

/// The flows of a grid, and the thread time they took.
pub struct GridFlows {
    /// Per view, toward each neighbour ([`Neighbour::ALL`] order; `None` at the grid's
    /// edges): the measured flow averaged with the reverse one ([`symmetrize`]), kept
    /// near the subject ([`keep_near_subject`]).
    pub flows: Vec<[Option<FlowImage>; 4]>,
    /// Thread seconds spent on horizontal pairs.
    pub horizontal_seconds: f64,
    /// Thread seconds spent on vertical pairs.
    pub vertical_seconds: f64,
}

/// The flow from every view of a grid to each of its neighbours, in parallel over views:
/// each pair measured both ways, guided by the hull ([`guided_flow`]) or through
/// rectification ([`rectified_flow`]), then averaged with its reverse. `each_view` is called once per view when its raw flows are done (to
/// show progress, and to stop: an error it returns ends the step).
pub fn grid_flows(
    grid: &GridViews,
    params: &FlowParams,
    each_view: &(dyn Fn() -> Result<()> + Sync),
) -> Result<GridFlows> {
    let (columns, rows, wraps) = (grid.columns, grid.rows, grid.wraps);
    let raw: Vec<([Option<FlowImage>; 4], f64, f64)> = (0..columns * rows)
        .into_par_iter()
        .map(|i| {
            let (u, v) = (i / rows, i % rows);
            let mut flows: [Option<FlowImage>; 4] = Default::default();
            let (mut horizontal, mut vertical) = (0.0, 0.0);
            for n in Neighbour::ALL {
                let Some((u2, v2)) = n.of(u, v, columns, rows, wraps) else {
                    continue;
                };
                let j = u2 * rows + v2;
                let (Some(a), Some(b)) = (grid.images[i], grid.images[j]) else {
                    continue;
                };
                let wanted = |k: usize, m: Neighbour| grid.wanted.is_none_or(|w| w[k][m.index()]);
                if !(wanted(i, n) || wanted(j, n.opposite())) {
                    continue;
                }
                let t = Instant::now();
                let (ca, cb) = (&grid.cameras[i], &grid.cameras[j]);
                flows[n.index()] = Some(match grid.hull {
                    Some(hull) => guided_flow(a, b, ca, cb, hull, params)?,
                    None => rectified_flow(a, b, ca, cb, params)?,
                });
                let dt = t.elapsed().as_secs_f64();
                if matches!(n, Neighbour::Left | Neighbour::Right) {
                    horizontal += dt;
                } else {
                    vertical += dt;
                }
            }
            each_view()?;
            Ok((flows, horizontal, vertical))
        })
        .collect::<Result<_>>()?;
    let flows = (0..columns * rows)
        .into_par_iter()
        .map(|i| {
            let (u, v) = (i / rows, i % rows);
            let mut out: [Option<FlowImage>; 4] = Default::default();
            for n in Neighbour::ALL {
                let (Some(f), Some((u2, v2)), Some(alpha)) = (
                    &raw[i].0[n.index()],
                    n.of(u, v, columns, rows, wraps),
                    grid.alphas[i],
                ) else {
                    continue;
                };
                if grid.wanted.is_some_and(|w| !w[i][n.index()]) {
                    continue;
                }
                let back = raw[u2 * rows + v2].0[n.opposite().index()].as_ref();
                let f = back.map_or_else(|| f.clone(), |b| symmetrize(f, b));
                out[n.index()] = Some(keep_near_subject(&f, alpha));
            }
            out
        })
        .collect();
    Ok(GridFlows {
        flows,
        horizontal_seconds: raw.iter().map(|r| r.1).sum(),
        vertical_seconds: raw.iter().map(|r| r.2).sum(),
    })
}
