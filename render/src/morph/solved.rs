//! The solved four-way morph (docs/design.md section 4.2): each of the quad's views is
//! sampled where the point the output pixel shows actually lies in it, found by solving
//! through the view's own outgoing flows, in the quad's rectified frame
//! ([`crate::rectified`]).
//!
//! **The output.** A ray that crossed the quad's plane at `p` is seen by a camera at `p`
//! with the rectified orientation at the rectified pixel `s` of its direction (rays
//! clamped to a row: the camera on the row at `(β, γ)`, looking at the ray's point on
//! the proxy).
//!
//! **One source.** View `X` of the quad, at in-plane centre `c_X`, has flows to its
//! horizontal and vertical neighbours `Y₁`, `Y₂`. Its pixel `x` shows a point that the
//! neighbours show at `x + F_{X→Yᵢ}(x)`; in the rectified frame it moves by
//! `dᵢ(x) = H_{Yᵢ}(x + F_{X→Yᵢ}(x)) − H_X(x) = −f (c_{Yᵢ} − c_X) / Z`. Writing the output's
//! offset `p − c_X = a (c_{Y₁} − c_X) + c (c_{Y₂} − c_X)` (a 2 x 2 solve in the plane), the
//! point moves to the output by `D(x) = a d₁(x) + c d₂(x)`, exactly, at any depth. The
//! source pixel is the solution of
//!
//! ```text
//! H_X(x) + D(x) = s,
//! ```
//!
//! found by the fixed-point iteration `x ← H_X⁻¹(s − D(x))` (one step from the depth the
//! proxy gives the ray, [`PROXY_ITERATIONS`]; at most [`ITERATIONS`] from the quad's
//! fixation depth, fewer once a step is shorter than [`SETTLED_PX`]), started at the
//! depth the proxy gives the ray (its first hull voxel), else at the quad's fixation depth: that start picks, where a limb folds over another, the surface
//! the ray meets first. Each step reads the view's own two flows at its own pixel, so
//! the displacement is right where the flow changes fast (limb edges, feet), which E06's
//! formula, reading another view's flow at the output pixel, is not.
//!
//! **Visibility.** Where the view does not see the point (it is hidden there, or the
//! iteration does not settle), the last step is long; the view's bilinear weight is
//! multiplied by `exp(−(step / σ)²)` ([`SETTLE_PX`]) and the weights renormalized.
//!
//! **Properties.** At a vertex `p = c_X`, `a = c = 0`, and the output is view `X`'s pixel
//! of the ray, unwarped: the source image. On an edge of the quad (`γ = 0`, say) only
//! `A` and `B` weigh, each moved along its own row flow by the fraction of the edge
//! travelled (`a = β` for `A`): a two-way morph, solved.
//!
//! **A grid of one row** (a ring of photographs): the camera stays on the ray anywhere
//! on the row's wall, which is its frame's plane; its offset across the row `o⊥` moves
//! the point by the inverse depth the row flow measures, `f o⊥ (d₁ · f b₁) / |f b₁|²`
//! (`b₁` the baseline): a held-out photograph a few millimetres off the ring is ten pixels
//! of parallax at dinoRing's focal length.

use frf_core::grid::Neighbour;
use glam::{Vec2, Vec3};

use super::{add, quad_views};
use crate::cylinder::{Clamp, CylinderHit, bilinear_weights};
use crate::rectified::{QuadFrame, apply};
use crate::resident::ResidentPose;

/// Fixed-point steps per source at most. From the proxy's depth the first step lands
/// within a few tenths of a pixel and each step shrinks the error by the flow's gradient
/// (about 0.1 on a limb). Measured at 16 quad centres of the small preset's zero-
/// perturbation capture (subject PSNR, oracle / ingested field): 2 steps 32.30 / 29.60 dB,
/// 3 steps 32.45 / 29.51 dB, 4 steps 32.42 dB (oracle), at 2/3 the cost of 3 on lavapipe.
pub const ITERATIONS: usize = 2;
/// Fixed-point steps per source that start from the depth the proxy gives the ray (a
/// pose with a visual hull): a ray of the subject starts on the hull, whose depth is the
/// surface's to within its voxels, and from there one step lands where a second moves it
/// by hundredths of a pixel; a ray that misses the hull sees nothing of the subject.
/// Chosen on seed 7's pose 0 (oracle / ingested field, 16 quad centres, one step against
/// two: sky 32.85 / 31.89 against 32.90 / 31.74, Pisa 32.28 / 30.95 against 32.18 /
/// 30.74, Grace 31.11 / 30.36 against 31.05 / 30.26; the six camera paths' mean 30.58 /
/// 30.37 against 30.56 / 30.29), reported on pose 12 (oracle: sky 31.35 against 31.39,
/// Pisa 32.16 against 32.10, the paths' mean 29.57 against 29.53); the four-way pass
/// 11-15 % cheaper on lavapipe (docs/results/render.md). Without a proxy the solve starts
/// at the quad's fixation depth and takes [`ITERATIONS`]: one step from there cost a
/// ring of photographs without a hull 0.58 dB (dinoSparseRing, every other view held
/// out: 17.82 -> 17.24 dB).
pub const PROXY_ITERATIONS: usize = 1;
/// A fixed-point step shorter than this (pixels) ends the iteration: the solution has
/// settled far below the resolution of the stored flows.
pub const SETTLED_PX: f32 = 0.01;
/// Length of the last fixed-point step, pixels, at which a source's weight falls to
/// `1/e`. A settled solution moves by hundredths of a pixel; one that alternates between
/// two surfaces by several. Measured (16 quad centres of the small zero-perturbation
/// capture, oracle / ingested; the perturbed capture's path suite): 0.5 px 32.30 /
/// 29.60 / 25.98 dB, 1 px 32.43 / 29.58 / 26.00, 2 px 32.51 / 29.52 / 26.01, 4 px
/// 32.46 / 29.49 / 26.01; below 2 px neighbouring pixels at an occlusion boundary pick
/// different sources and the boundary breaks into speckles.
pub const SETTLE_PX: f32 = 2.0;
/// The least factor a source's weight is multiplied by, so that the weights stay
/// defined where no source settles.
pub const SETTLE_FLOOR: f32 = 1e-3;

/// Where the output camera is and what the pixel's ray looks at.
#[derive(Debug, Clone, Copy)]
pub struct Output {
    /// Its centre in the quad's plane.
    pub centre: Vec2,
    /// The rectified pixel of the ray.
    pub s: Vec2,
    /// Inverse depth (1/m, along the plane's normal) the solve starts from.
    pub inverse_depth: f32,
    /// Fixed-point steps at most: [`PROXY_ITERATIONS`] from the proxy's depth,
    /// [`ITERATIONS`] from the quad's fixation depth.
    pub steps: usize,
}

/// The output camera of a ray that crossed the quad of `frame` at `hit` (see the module
/// docs); `None` where the ray does not look into the quad's inner side.
pub fn output(
    pose: &ResidentPose,
    frame: &QuadFrame,
    hit: &CylinderHit,
    origin: Vec3,
    dir: Vec3,
    proxy: bool,
) -> Option<Output> {
    let g = &pose.geometry;
    let point = if proxy {
        g.proxy.point(origin, dir)
    } else {
        None
    };
    let (centre, s) = match hit.clamped {
        // Inside the grid, and anywhere on a grid of one row (whose wall is its frame's
        // plane): the camera at the ray's crossing of the plane, on the ray.
        _ if hit.clamped == Clamp::None || g.rows == 1 => {
            (hit.point, frame.project_direction(dir)?)
        }
        _ => {
            let views = quad_views(g, hit);
            let w = bilinear_weights(hit.beta, hit.gamma);
            let c: Vec3 = (0..4).map(|k| g.cameras[views[k]].centre() * w[k]).sum();
            let s = match point {
                Some(p) => frame.project_direction(p - c)?,
                None => frame.project_direction(dir)?,
            };
            (c, s)
        }
    };
    let plane = frame.to_plane(centre);
    let from_point = point
        .map(|p| 1.0 / (frame.to_plane(p).z - plane.z))
        .filter(|v| v.is_finite() && *v > 0.0);
    Some(Output {
        centre: plane.truncate(),
        s,
        inverse_depth: from_point.unwrap_or(1.0 / frame.fixation_depth),
        steps: match from_point {
            Some(_) => PROXY_ITERATIONS,
            None => ITERATIONS,
        },
    })
}

/// The flows of vertex `k` of a quad `[A, B, C, D]` toward its horizontal and vertical
/// partners (`k ^ 1`, `k ^ 2`).
pub fn partner_flows(k: usize) -> (Neighbour, Neighbour) {
    let h = if k.is_multiple_of(2) {
        Neighbour::Right
    } else {
        Neighbour::Left
    };
    let v = if k < 2 {
        Neighbour::Up
    } else {
        Neighbour::Down
    };
    (h, v)
}

/// The fractions `(a, c)` of vertex `k`'s baselines to its horizontal and vertical
/// partners that carry it to the in-plane point `to`; `c = 0` without a vertical partner.
pub fn fractions(frame: &QuadFrame, k: usize, vertical: bool, to: Vec2) -> (f32, f32) {
    let o = to - frame.centres[k];
    let b1 = frame.centres[k ^ 1] - frame.centres[k];
    let b2 = frame.centres[k ^ 2] - frame.centres[k];
    let det = b1.perp_dot(b2);
    if vertical && det.abs() > 1e-9 {
        (o.perp_dot(b2) / det, b1.perp_dot(o) / det)
    } else {
        (o.dot(b1) / b1.length_squared().max(1e-12), 0.0)
    }
}

/// Solves for the pixel of vertex `k` that shows the output's point (see the module
/// docs): the pixel, and the length of the last fixed-point step.
pub fn solve(
    pose: &ResidentPose,
    frame: &QuadFrame,
    views: &[usize; 4],
    k: usize,
    out: &Output,
) -> (Vec2, f32) {
    let (h, v) = (k ^ 1, k ^ 2);
    let vertical = views[v] != views[k];
    let (a, c) = fractions(frame, k, vertical, out.centre);
    let (to_h, to_v) = partner_flows(k);
    let view = views[k];
    // Without a vertical partner the output may stand off the row: its offset across the
    // row moves the point by the same inverse depth the row's flow measures.
    let (across, along) = if vertical {
        (Vec2::ZERO, Vec2::ZERO)
    } else {
        let o = out.centre - frame.centres[k];
        let off = o - (frame.centres[h] - frame.centres[k]) * a;
        let along = frame.parallax(frame.centres[k], frame.centres[h]);
        (
            frame.parallax(Vec2::ZERO, off),
            along / along.length_squared().max(1e-12),
        )
    };
    // `here` is `H_X(x)`; after a step it is `s − D` by construction.
    let displacement = |x: Vec2, here: Vec2| {
        let mut d = Vec2::ZERO;
        if a != 0.0 || across != Vec2::ZERO {
            let f = pose.sample_flow(view, to_h, x);
            let d_h = apply(&frame.to_rectified[h], x + f) - here;
            d += a * d_h + across * d_h.dot(along);
        }
        if c != 0.0 {
            let f = pose.sample_flow(view, to_v, x);
            d += c * (apply(&frame.to_rectified[v], x + f) - here);
        }
        d
    };
    let mut here = out.s + frame.parallax(frame.centres[k], out.centre) * out.inverse_depth;
    let mut x = apply(&frame.from_rectified[k], here);
    let mut step = 0.0;
    for _ in 0..out.steps {
        here = out.s - displacement(x, here);
        let next = apply(&frame.from_rectified[k], here);
        step = (next - x).length();
        x = next;
        if step < SETTLED_PX {
            break;
        }
    }
    (x, step)
}

/// The solved four-way morph of the ray `origin + t dir` that crossed the cylinder at
/// `hit`; `None` where it sees nothing.
pub fn shade(
    pose: &ResidentPose,
    hit: &CylinderHit,
    origin: Vec3,
    dir: Vec3,
    proxy: bool,
) -> Option<[f32; 4]> {
    let g = &pose.geometry;
    let frame = g.quad_frame(hit)?;
    let out = output(pose, frame, hit, origin, dir, proxy)?;
    let views = quad_views(g, hit);
    let w = bilinear_weights(hit.beta, hit.gamma);
    let mut acc = [0.0f32; 4];
    let mut total = 0.0f32;
    for k in 0..4 {
        if w[k] <= 0.0 {
            continue;
        }
        let (x, step) = solve(pose, frame, &views, k, &out);
        let wk = w[k] * (-(step / SETTLE_PX).powi(2)).exp().max(SETTLE_FLOOR);
        add(&mut acc, pose.sample_prelit(views[k], x), wk);
        total += wk;
    }
    if total > 0.0 {
        acc.iter_mut().for_each(|c| *c /= total);
    }
    Some(acc)
}
