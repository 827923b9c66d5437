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

/// Which interpolation between views.
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
}

impl Variant {
    /// All, simplest first.
    pub const ALL: [Variant; 4] = [
        Variant::Nearest,
        Variant::Linear,
        Variant::TwoWay,
        Variant::FourWay,
    ];

    /// Name in reports and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Nearest => "nearest",
            Variant::Linear => "linear",
            Variant::TwoWay => "twoway",
            Variant::FourWay => "fourway",
        }
    }

    /// Index used by the shaders.
    pub fn index(self) -> u32 {
        self as u32
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

/// The interpolated premultiplied RGBA at output pixel coordinates `s` inside the quad
/// of `hit`.
pub fn morph(pose: &ResidentPose, hit: &CylinderHit, s: Vec2, variant: Variant) -> [f32; 4] {
    let [a, b_, c, d] = quad_views(&pose.geometry, hit);
    let (beta, gamma) = (hit.beta, hit.gamma);
    let (b, g) = (1.0 - beta, 1.0 - gamma);
    let w = bilinear_weights(beta, gamma);
    let views = [a, b_, c, d];
    let mut out = [0.0f32; 4];
    match variant {
        Variant::Nearest => {
            let k = (0..4).max_by(|&i, &j| w[i].total_cmp(&w[j])).unwrap_or(0);
            out = pose.sample_prelit(views[k], s);
        }
        Variant::Linear => {
            for k in 0..4 {
                if w[k] > 0.0 {
                    add(&mut out, pose.sample_prelit(views[k], s), w[k]);
                }
            }
        }
        Variant::TwoWay => {
            let (p, q) = if gamma < 0.5 { (a, b_) } else { (c, d) };
            let fp = pose.sample_flow(q, Neighbour::Left, s);
            let fq = pose.sample_flow(p, Neighbour::Right, s);
            add(&mut out, pose.sample_prelit(p, s + beta * fp), b);
            add(&mut out, pose.sample_prelit(q, s + b * fq), beta);
        }
        Variant::FourWay => {
            let f = |view: usize, n: Neighbour| pose.sample_flow(view, n, s);
            let terms = [
                (
                    a,
                    beta * f(b_, Neighbour::Left) + gamma * f(c, Neighbour::Down),
                ),
                (
                    b_,
                    b * f(a, Neighbour::Right) + gamma * f(d, Neighbour::Down),
                ),
                (c, beta * f(d, Neighbour::Left) + g * f(a, Neighbour::Up)),
                (d, b * f(c, Neighbour::Right) + g * f(b_, Neighbour::Up)),
            ];
            for (k, (view, disp)) in terms.into_iter().enumerate() {
                if w[k] > 0.0 {
                    add(&mut out, pose.sample_prelit(view, s + disp), w[k]);
                }
            }
        }
    }
    out
}
