//! The flowed morphs of Einarsson et al. (EGSR 2006), kept as variants so that what the
//! solved morph ([`super::solved`]) gains is always measured beside them
//! (docs/design.md section 4.2).
//!
//! With vertices `A = (u, v)`, `B = (u+1, v)`, `C = (u, v+1)`, `D = (u+1, v+1)`, bilinear
//! coordinates `(β, γ)`, `b = 1 − β`, `g = 1 − γ`, and `F_{X→Y}` the flow stored on `X`'s
//! grid toward its neighbour `Y`:
//!
//! ```text
//! I'(s) = b g  · I_A(s + β F_{B→A}(s) + γ F_{C→A}(s))
//!       + β g  · I_B(s + b F_{A→B}(s) + γ F_{D→B}(s))
//!       + b γ  · I_C(s + β F_{D→C}(s) + g F_{A→C}(s))
//!       + β γ  · I_D(s + b F_{C→D}(s) + g F_{B→D}(s))
//! ```
//!
//! Each image is displaced by the flows *into* it from its two quad neighbours, read at
//! the output pixel `s` of the camera interpolated at `(β, γ)`: first order in the
//! motion, and wrong wherever the flow changes within the displacement (limb edges,
//! feet), which doubles them. It returns the source image at every vertex and reduces to
//! the two-way morph `b I_A(s + β F_{B→A}) + β I_B(s + b F_{A→B})` on every edge (tested in
//! `render/tests/cpu_reference.rs`).
//!
//! **Occlusion cue** (the `fourway-occlusion` ablation): each source is weighed by how
//! well the flows it is displaced by agree with the flows back: for a displacement
//! `F_{X→Y}(s)` into source `Y`, `e = |F_{X→Y}(s) + F_{Y→X}(s + F_{X→Y}(s))|`, scaled by the
//! fraction of the flow used, multiplies the source's weight by `exp(−Σ (fraction e)² /
//! σ²)` ([`OCCLUSION_SIGMA_PX`]), and the weights are renormalized.

use frf_core::grid::Neighbour;
use glam::{Vec2, Vec3};

use super::{Kind, Variant, add, quad_views};
use crate::cylinder::{Clamp, CylinderHit, bilinear_weights, interpolate_camera};
use crate::geometry::PoseGeometry;
use crate::resident::ResidentPose;

/// Flow inconsistency, pixels, at which the occlusion cue weighs a source at `1/e` of
/// its bilinear weight.
pub const OCCLUSION_SIGMA_PX: f32 = 2.0;
/// The least factor a source's weight is multiplied by: the weights stay defined where
/// every source is inconsistent.
pub const OCCLUSION_FLOOR: f32 = 1e-3;

/// One source of a flowed morph: its view, bilinear weight, and the flows it is
/// displaced by, each `(stored on view, toward neighbour, fraction)`.
struct Source {
    view: usize,
    weight: f32,
    flows: [(usize, Neighbour, f32); 2],
}

/// A flowed morph of `sources` at `s`: each sampled displaced by its flows; weighted by
/// `weight` times, when `occlusion`, the consistency of those flows.
fn flowed(pose: &ResidentPose, sources: &[Source], s: Vec2, occlusion: bool) -> [f32; 4] {
    let mut out = [0.0f32; 4];
    let mut total = 0.0f32;
    for src in sources.iter().filter(|src| src.weight > 0.0) {
        let mut disp = Vec2::ZERO;
        let mut err2 = 0.0f32;
        for &(view, n, frac) in &src.flows {
            if frac == 0.0 {
                continue;
            }
            let f = pose.sample_flow(view, n, s);
            disp += frac * f;
            if occlusion {
                let back = pose.sample_flow(src.view, n.opposite(), s + f);
                err2 += (frac * (f + back)).length_squared();
            }
        }
        let w = src.weight * confidence(err2);
        add(&mut out, pose.sample_prelit(src.view, s + disp), w);
        total += w;
    }
    if occlusion && total > 0.0 {
        out.iter_mut().for_each(|c| *c /= total);
    }
    out
}

/// The occlusion cue's factor for a squared, fraction-weighted flow inconsistency.
pub fn confidence(err2: f32) -> f32 {
    (-err2 / (OCCLUSION_SIGMA_PX * OCCLUSION_SIGMA_PX))
        .exp()
        .max(OCCLUSION_FLOOR)
}

/// The pixel of the interpolated camera of `hit` through which the ray `origin + t dir`
/// passes, or `None` if it points behind that camera.
///
/// Inside the grid the camera sits at the hit, on the ray, and the ray's direction says
/// where it crosses its image. A ray clamped to a row is, with `proxy`, looked up where
/// its point on the subject ([`crate::proxy::Proxy::point`]) projects into the camera
/// interpolated on the row itself (docs/design.md section 4.3); without it (or without a
/// point), along its direction from the hit on the wall.
pub fn source_pixel(
    geometry: &PoseGeometry,
    hit: &CylinderHit,
    origin: Vec3,
    dir: Vec3,
    proxy: bool,
) -> Option<Vec2> {
    let views = quad_views(geometry, hit);
    let cams = views.map(|i| &geometry.cameras[i]);
    let on_row = (proxy && hit.clamped != Clamp::None)
        .then(|| geometry.proxy.point(origin, dir))
        .flatten()
        .map(|p| {
            let w = bilinear_weights(hit.beta, hit.gamma);
            let centre: Vec3 = (0..4).map(|k| cams[k].centre() * w[k]).sum();
            (p - centre, centre)
        });
    let (ray, centre) = on_row.unwrap_or((dir, hit.point));
    let cam = interpolate_camera(cams, hit.beta, hit.gamma, centre);
    let dc = cam.world_from_camera.rotation.transpose() * ray;
    if dc.z <= 1e-6 * ray.length() {
        return None;
    }
    let k = &cam.intrinsics;
    Some(Vec2::new(
        k.fx * dc.x / dc.z + k.cx,
        k.fy * dc.y / dc.z + k.cy,
    ))
}

/// The interpolated premultiplied RGBA at pixel `s` of the camera interpolated at the
/// hit, by `variant`'s interpolation of the images as they are read at `s` (nearest,
/// linear blend) or displaced by the flows read there (two-way, E06's four-way; the
/// solved morph's variants, which [`super::shade`] sends to [`super::solved`], get
/// E06's four-way here).
pub fn morph(pose: &ResidentPose, hit: &CylinderHit, s: Vec2, variant: Variant) -> [f32; 4] {
    let [a, b_, c, d] = quad_views(&pose.geometry, hit);
    let (beta, gamma) = (hit.beta, hit.gamma);
    let (b, g) = (1.0 - beta, 1.0 - gamma);
    let w = bilinear_weights(beta, gamma);
    let views = [a, b_, c, d];
    let occlusion = variant.occlusion_aware();
    let mut out = [0.0f32; 4];
    match variant.kind() {
        Kind::Nearest => {
            let k = (0..4).max_by(|&i, &j| w[i].total_cmp(&w[j])).unwrap_or(0);
            out = pose.sample_prelit(views[k], s);
        }
        Kind::Linear => {
            for k in 0..4 {
                if w[k] > 0.0 {
                    add(&mut out, pose.sample_prelit(views[k], s), w[k]);
                }
            }
        }
        Kind::TwoWay => {
            let (p, q) = if gamma < 0.5 { (a, b_) } else { (c, d) };
            let none = (p, Neighbour::Up, 0.0);
            let sources = [
                Source {
                    view: p,
                    weight: b,
                    flows: [(q, Neighbour::Left, beta), none],
                },
                Source {
                    view: q,
                    weight: beta,
                    flows: [(p, Neighbour::Right, b), none],
                },
            ];
            out = flowed(pose, &sources, s, occlusion);
        }
        Kind::FourWayE06 | Kind::FourWay => {
            use Neighbour::{Down, Left, Right, Up};
            let sources = [
                Source {
                    view: a,
                    weight: w[0],
                    flows: [(b_, Left, beta), (c, Down, gamma)],
                },
                Source {
                    view: b_,
                    weight: w[1],
                    flows: [(a, Right, b), (d, Down, gamma)],
                },
                Source {
                    view: c,
                    weight: w[2],
                    flows: [(d, Left, beta), (a, Up, g)],
                },
                Source {
                    view: d,
                    weight: w[3],
                    flows: [(c, Right, b), (b_, Up, g)],
                },
            ];
            out = flowed(pose, &sources, s, occlusion);
        }
    }
    out
}
