//! The flowed morph between the pre-lit images of a quad of the grid (docs/design.md section 4.2),
//! and the simpler interpolations it is measured against.
//!
//! With vertices `A = (u, v)`, `B = (u+1, v)`, `C = (u, v+1)`, `D = (u+1, v+1)`, bilinear
//! coordinates `(β, γ)`, `b = 1 − β`, `g = 1 − γ`, and `F_{X→Y}` the flow stored on `X`'s
//! grid toward its neighbour `Y` (pixel `s` of `X` shows the point that `Y` shows at
//! `s + F_{X→Y}(s)`):
//!
//! ```text
//! I'(s) = b g  · I_A(s + β F_{B→A}(s) + γ F_{C→A}(s))
//!       + β g  · I_B(s + b F_{A→B}(s) + γ F_{D→B}(s))
//!       + b γ  · I_C(s + β F_{D→C}(s) + g F_{A→C}(s))
//!       + β γ  · I_D(s + b F_{C→D}(s) + g F_{B→D}(s))
//! ```
//!
//! **Derivation.** Each image is displaced by the flows *into* it from its two quad
//! neighbours, weighted by how far the output has moved toward them. Take image `A`: the
//! output at `(β, γ)` sits a fraction `β` of the way toward `B` and `γ` toward `C`. A
//! point that `B` shows at `s` is shown by `A` at `s + F_{B→A}(s)`; so to see, through
//! `A`, what the output shows at `s`, `A` is sampled displaced by `β F_{B→A}(s)` toward
//! `B`'s view and `γ F_{C→A}(s)` toward `C`'s (flows are used as displacement fields in
//! the output's coordinates, first order in the motion, as in the two-way morph of
//! Einarsson et al.). The same for `B`, `C`, `D` with their own two neighbours.
//!
//! - *It returns the source image at every vertex*: at `(β, γ) = (0, 0)` only `A` has
//!   weight, and its displacement `0 · F + 0 · F` vanishes: `I' = I_A`. Likewise `B` at
//!   `(1, 0)` (displacement `b F_{A→B} + γ F_{D→B} = 0`), `C` at `(0, 1)`, `D` at `(1, 1)`.
//! - *It reduces exactly to the two-way morph on every edge*: on `γ = 0` the `C` and `D`
//!   terms have weight 0 and the others lose their `γ` displacement:
//!   `I' = b I_A(s + β F_{B→A}) + β I_B(s + b F_{A→B})`, the two-way morph of `A` and `B`.
//!   On `γ = 1`: `b I_C(s + β F_{D→C}) + β I_D(s + b F_{C→D})`, that of `C` and `D`. On
//!   `β = 0`: `g I_A(s + γ F_{C→A}) + γ I_C(s + g F_{A→C})`; on `β = 1`, `B` and `D`.
//!
//! Alpha goes through the same morph (the pre-lit images are premultiplied). Flows that
//! are unknown (outside a subject) displace by zero.

use frf_core::grid::Neighbour;
use glam::Vec2;

use crate::cylinder::{CylinderHit, bilinear_weights};
use crate::geometry::PoseGeometry;
use crate::resident::ResidentPose;

/// Flow inconsistency, pixels, at which the occlusion-aware morph weighs a source at
/// `1/e` of its bilinear weight (see [`morph`]).
pub const OCCLUSION_SIGMA_PX: f32 = 2.0;
/// The least factor a source's weight is multiplied by: the weights stay defined where
/// every source is inconsistent.
pub const OCCLUSION_FLOOR: f32 = 1e-3;

/// Which interpolation between views, and which of the renderer's refinements it uses.
///
/// Every variant looks rays beyond the grid's rows up through the geometric proxy
/// ([`crate::proxy`]). The four-way morph's ablations: `FourWayOcclusion` adds the
/// occlusion cue (measured: no gain on the stage or on real photographs, at twice the
/// cost on lavapipe; see docs/results/render.md), `FourWayNoProxy` reads rays beyond the
/// rows along their direction (the renderer before the proxy).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// The vertex of the quad with the largest weight, unwarped.
    Nearest,
    /// The four vertices blended bilinearly, unwarped.
    Linear,
    /// The two-way flowed morph along the nearer row of the quad.
    TwoWay,
    /// The four-way flowed morph.
    FourWay,
    /// Ablation: the four-way morph weighing its sources by the consistency of their
    /// flows (the occlusion cue of [`morph`]).
    FourWayOcclusion,
    /// Ablation: the four-way morph reading rays beyond the rows along their direction.
    FourWayNoProxy,
}

/// The interpolations proper: what [`Variant`]s compute before the refinements.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Nearest view.
    Nearest,
    /// Linear blend.
    Linear,
    /// Two-way morph.
    TwoWay,
    /// Four-way morph.
    FourWay,
}

impl Variant {
    /// The interpolations, simplest first.
    pub const ALL: [Variant; 4] = [
        Variant::Nearest,
        Variant::Linear,
        Variant::TwoWay,
        Variant::FourWay,
    ];

    /// The four-way morph's ablations.
    pub const ABLATIONS: [Variant; 2] = [Variant::FourWayOcclusion, Variant::FourWayNoProxy];

    /// Name in reports and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Nearest => "nearest",
            Variant::Linear => "linear",
            Variant::TwoWay => "twoway",
            Variant::FourWay => "fourway",
            Variant::FourWayOcclusion => "fourway-occlusion",
            Variant::FourWayNoProxy => "fourway-no-proxy",
        }
    }

    /// The interpolation it computes.
    pub fn kind(self) -> Kind {
        match self {
            Variant::Nearest => Kind::Nearest,
            Variant::Linear => Kind::Linear,
            Variant::TwoWay => Kind::TwoWay,
            _ => Kind::FourWay,
        }
    }

    /// Whether rays beyond the grid's rows are looked up through the proxy.
    pub fn uses_proxy(self) -> bool {
        self != Variant::FourWayNoProxy
    }

    /// Whether the morph weighs its sources by the consistency of their flows.
    pub fn occlusion_aware(self) -> bool {
        self == Variant::FourWayOcclusion
    }

    /// Index of the interpolation in the shaders.
    pub fn index(self) -> u32 {
        self.kind() as u32
    }

    /// The refinements as the shaders' flag bits: 1 proxy, 2 occlusion-aware.
    pub fn flags(self) -> u32 {
        self.uses_proxy() as u32 | (self.occlusion_aware() as u32) << 1
    }
}

/// The views `[A, B, C, D]` of the quad of a hit (`C = A`, `D = B` for a single row).
pub fn quad_views(geometry: &PoseGeometry, hit: &CylinderHit) -> [usize; 4] {
    let view = |u: usize, v: usize| geometry.view(u, v);
    let (u, v) = (hit.u, hit.v);
    let top = if geometry.rows > 1 { v + 1 } else { v };
    [view(u, v), view(u + 1, v), view(u, top), view(u + 1, top)]
}

fn add(acc: &mut [f32; 4], x: [f32; 4], w: f32) {
    for k in 0..4 {
        acc[k] += w * x[k];
    }
}

/// One source of a flowed morph: its view, bilinear weight, and the flows it is
/// displaced by, each `(stored on view, toward neighbour, fraction)`.
struct Source {
    view: usize,
    weight: f32,
    flows: [(usize, Neighbour, f32); 2],
}

/// A flowed morph of `sources` at `s`: each sampled displaced by its flows; weighted by
/// `weight` times, when `occlusion`, the consistency of those flows (see [`morph`]).
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

/// The interpolated premultiplied RGBA at output pixel coordinates `s` inside the quad
/// of `hit`.
///
/// **Occlusion.** Where a limb hides another in one view of the quad, the flow stored on
/// the view that sees the hidden part points at the limb in front in the other: the
/// morph samples the wrong surface there and leaves a faint copy (a ghost). The
/// occlusion-aware variant weighs each source by how well the flows it is displaced by
/// agree with the flows back: for a displacement `F_{X→Y}(s)` into source `Y`, the
/// inconsistency `e = |F_{X→Y}(s) + F_{Y→X}(s + F_{X→Y}(s))|` is zero where the point is
/// seen by both and large where `Y` does not see it; scaled by the fraction of the flow
/// used, the source's weight is multiplied by `exp(−Σ (fraction e)² / σ²)`
/// ([`OCCLUSION_SIGMA_PX`]) and the weights renormalized. At a vertex, and wherever the
/// flows agree, this is the plain morph.
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
        Kind::FourWay => {
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
