//! The per-level solver: warping, linearisation, iteratively reweighted least squares
//! (IRLS) and successive over-relaxation (SOR), as in Black & Anandan's robust
//! framework and Sun, Roth & Black's "Classic" methods.
//!
//! At one pyramid level, with the flow `F₀` of the current warp, the energy
//!
//! `E(F) = Σ_s Σ_c ρ_D(I₂ᶜ(s + F₀) − I₁ᶜ(s) + ∇I ᶜ·(F − F₀)) + λ Σ_(s,n) [ρ_S(u_s − u_n) + ρ_S(v_s − v_n)]`
//!
//! (4-neighbour pairs, each component penalised on its own as in Black & Anandan) is
//! minimised by IRLS: the robust penalties are replaced by the quadratics through the
//! current estimate with weights ψ = ρ'(x)/x, and the resulting linear system — a 2x2
//! block per pixel coupled to its neighbours — is relaxed by block SOR, each pixel's
//! 2x2 system solved exactly. `∇Iᶜ` averages the derivatives of the warped second image
//! and of the first (Sun et al.'s blend of ½); points warped outside the second image
//! get no data term (Sun et al.), so smoothness fills them in.
//!
//! Parallelism: SOR visits the pixels in red-black (checkerboard) order, so that all
//! pixels of one colour can be updated at once — rows in parallel with rayon — while
//! remaining a true Gauss–Seidel method (convergent for any ω in (0, 2) on this
//! symmetric positive definite system; a first version that ran lexicographic SOR in
//! strips with Jacobi coupling between strips diverged at ω = 1.9). The order does not
//! depend on the thread count, so results are identical whatever the thread pool —
//! including when an outer `par_iter` over many image pairs calls the estimator
//! (rayon's work stealing composes: no oversubscription).

use frf_core::image::FlowImage;
use rayon::prelude::*;

use crate::interp::Taps;
use crate::median::median_filter;
use crate::params::Interpolation;
use crate::penalty::GncPenalty;

/// Weight of the second image's derivatives in the blended gradient (Sun et al.'s ½).
const DERIVATIVE_BLEND: f32 = 0.5;
/// The planes of both images at one pyramid level, and their spatial derivatives.
pub(crate) struct LevelImages {
    pub width: usize,
    pub height: usize,
    pub i1: Vec<Vec<f32>>,
    pub i1x: Vec<Vec<f32>>,
    pub i1y: Vec<Vec<f32>>,
    pub i2: Vec<Vec<f32>>,
    pub i2x: Vec<Vec<f32>>,
    pub i2y: Vec<Vec<f32>>,
}

/// What the solver does at one level in one GNC stage.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SolverConfig {
    pub warps: usize,
    pub irls_iterations: usize,
    pub sor_iterations: usize,
    pub omega: f32,
    pub data: GncPenalty,
    pub smoothness: GncPenalty,
    /// Smoothness weight (λ, or the quadratic λ in a quadratic stage) times the GNC mix.
    pub lambda: f32,
    pub median_radius: usize,
    pub weighted_median_radius: usize,
    pub interpolation: Interpolation,
}

/// Refines `flow` (this level's size) by `config.warps` warps.
pub(crate) fn refine_level(
    level: &LevelImages,
    flow: &mut FlowImage,
    config: &SolverConfig,
    guide: Option<&crate::weighted_median::Guide>,
) {
    let n = level.width * level.height;
    let channels = level.i1.len();
    let mut lin = vec![[0.0f32; 3]; n * channels];
    let mut weights = vec![[0.0f32; 4]; n];
    let mut coef = vec![[0.0f32; 6]; n];
    for _ in 0..config.warps {
        linearise(level, flow, config.interpolation, &mut lin);
        let base = flow.clone();
        for _ in 0..config.irls_iterations {
            smoothness_weights(level, flow, config, &mut weights);
            coefficients(level, &lin, &base, flow, &weights, config, &mut coef);
            sor_relax(
                level,
                flow,
                &coef,
                &weights,
                config.omega,
                config.sor_iterations,
            );
        }
        if config.median_radius > 0 {
            *flow = median_filter(flow, config.median_radius);
        }
        if let (Some(guide), r) = (guide, config.weighted_median_radius)
            && r > 0
        {
            *flow = crate::weighted_median::weighted_median_near_edges(flow, guide, r);
        }
    }
}

/// `lin[s·C + c] = [∂x, ∂y, ∂t]` of channel `c` at pixel `s`, linearised at `flow`.
fn linearise(level: &LevelImages, flow: &FlowImage, mode: Interpolation, lin: &mut [[f32; 3]]) {
    let (w, h) = (level.width, level.height);
    let channels = level.i1.len();
    let (xmax, ymax) = ((w - 1) as f32, (h - 1) as f32);
    let f = flow.pixels();
    lin.par_chunks_mut((w * channels).max(1))
        .enumerate()
        .for_each(|(y, row)| {
            for x in 0..w {
                let s = y * w + x;
                let (xs, ys) = (x as f32 + f[s][0], y as f32 + f[s][1]);
                let out = &mut row[x * channels..(x + 1) * channels];
                if !((0.0..=xmax).contains(&xs) && (0.0..=ymax).contains(&ys)) {
                    out.fill([0.0; 3]);
                    continue;
                }
                let taps = Taps::new(xs, ys, w, h, mode);
                for (c, o) in out.iter_mut().enumerate() {
                    let b = DERIVATIVE_BLEND;
                    let ix = b * taps.sample(&level.i2x[c]) + (1.0 - b) * level.i1x[c][s];
                    let iy = b * taps.sample(&level.i2y[c]) + (1.0 - b) * level.i1y[c][s];
                    let it = taps.sample(&level.i2[c]) - level.i1[c][s];
                    *o = [ix, iy, it];
                }
            }
        });
}

/// `weights[s] = λ·[ψ(Δu→), ψ(Δu↓), ψ(Δv→), ψ(Δv↓)]` for the pairs to the right and
/// below; zero where there is no such neighbour.
fn smoothness_weights(
    level: &LevelImages,
    flow: &FlowImage,
    config: &SolverConfig,
    weights: &mut [[f32; 4]],
) {
    let (w, h) = (level.width, level.height);
    let f = flow.pixels();
    let pen = config.smoothness;
    let lambda = config.lambda;
    weights
        .par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let s = y * w + x;
                let mut wt = [0.0f32; 4];
                if x + 1 < w {
                    let du = f[s + 1][0] - f[s][0];
                    let dv = f[s + 1][1] - f[s][1];
                    wt[0] = lambda * pen.weight_sq(du * du);
                    wt[2] = lambda * pen.weight_sq(dv * dv);
                }
                if y + 1 < h {
                    let du = f[s + w][0] - f[s][0];
                    let dv = f[s + w][1] - f[s][1];
                    wt[1] = lambda * pen.weight_sq(du * du);
                    wt[3] = lambda * pen.weight_sq(dv * dv);
                }
                *out = wt;
            }
        });
}

/// Per pixel, the inverse of its 2x2 diagonal block `[m11, m12, m22]`, the constant
/// part of the right-hand side `[c1, c2]`, and 1 if the block is invertible (else 0:
/// the pixel keeps its value).
#[allow(clippy::too_many_arguments)]
fn coefficients(
    level: &LevelImages,
    lin: &[[f32; 3]],
    base: &FlowImage,
    flow: &FlowImage,
    weights: &[[f32; 4]],
    config: &SolverConfig,
    coef: &mut [[f32; 6]],
) {
    let w = level.width;
    let channels = level.i1.len();
    let (f, f0) = (flow.pixels(), base.pixels());
    let pen = config.data;
    coef.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let s = y * w + x;
                let (du, dv) = (f[s][0] - f0[s][0], f[s][1] - f0[s][1]);
                let (mut a11, mut a12, mut a22, mut b1, mut b2) = (0.0f32, 0.0, 0.0, 0.0, 0.0);
                for &[ix, iy, it] in &lin[s * channels..(s + 1) * channels] {
                    let r = it + ix * du + iy * dv;
                    let psi = pen.weight_sq(r * r);
                    a11 += psi * ix * ix;
                    a12 += psi * ix * iy;
                    a22 += psi * iy * iy;
                    b1 += psi * ix * it;
                    b2 += psi * iy * it;
                }
                let (u0, v0) = (f0[s][0], f0[s][1]);
                let c1 = a11 * u0 + a12 * v0 - b1;
                let c2 = a12 * u0 + a22 * v0 - b2;
                let wt = weights[s];
                let (mut su, mut sv) = (wt[0] + wt[1], wt[2] + wt[3]);
                if x > 0 {
                    su += weights[s - 1][0];
                    sv += weights[s - 1][2];
                }
                if y > 0 {
                    su += weights[s - w][1];
                    sv += weights[s - w][3];
                }
                let (d11, d22) = (a11 + su, a22 + sv);
                let det = d11 * d22 - a12 * a12;
                // A block is singular when neither data nor smoothness constrains it
                // (textureless pixel with no neighbours, 1x1 images) or only the
                // aperture direction is constrained; relative 1e-6 is far above f32
                // rounding of the products.
                *out = if det > 1e-6 * d11 * d22 && det.is_finite() && det > 0.0 {
                    let inv = 1.0 / det;
                    [d22 * inv, -a12 * inv, d11 * inv, c1, c2, 1.0]
                } else {
                    [0.0; 6]
                };
            }
        });
}

/// `sweeps` red-black block-SOR sweeps over `flow` (see the module documentation).
fn sor_relax(
    level: &LevelImages,
    flow: &mut FlowImage,
    coef: &[[f32; 6]],
    weights: &[[f32; 4]],
    omega: f32,
    sweeps: usize,
) {
    let (w, h) = (level.width, level.height);
    // Rows of each parity in their own array: a half-pass updates one colour in the rows
    // of one parity and only reads the other parity's rows (its vertical neighbours).
    let f = flow.pixels();
    let mut rows: [Vec<[f32; 2]>; 2] = std::array::from_fn(|parity| {
        (parity..h)
            .step_by(2)
            .flat_map(|y| f[y * w..(y + 1) * w].iter().copied())
            .collect()
    });
    let relax = HalfPass {
        w,
        h,
        coef,
        weights,
        omega,
    };
    for _ in 0..sweeps {
        for colour in 0..2 {
            let [even, odd] = &mut rows;
            relax.run(even, odd, 0, colour);
            relax.run(odd, even, 1, colour);
        }
    }
    let out = flow.pixels_mut();
    for (parity, data) in rows.iter().enumerate() {
        for (k, row) in data.chunks(w).enumerate() {
            let y = 2 * k + parity;
            out[y * w..(y + 1) * w].copy_from_slice(row);
        }
    }
}

/// What one half-pass of red-black SOR needs.
struct HalfPass<'a> {
    w: usize,
    h: usize,
    coef: &'a [[f32; 6]],
    weights: &'a [[f32; 4]],
    omega: f32,
}

impl HalfPass<'_> {
    /// Updates the pixels of `colour` ((x + y) mod 2) in the rows of `parity`, stored in
    /// `mine`; `other` holds the rows of the other parity.
    fn run(&self, mine: &mut [[f32; 2]], other: &[[f32; 2]], parity: usize, colour: usize) {
        let (w, h) = (self.w, self.h);
        let (coef, weights, omega) = (self.coef, self.weights, self.omega);
        mine.par_chunks_mut(w.max(1))
            .with_min_len(4)
            .enumerate()
            .for_each(|(k, row)| {
                let y = 2 * k + parity;
                // Rows y − 1 and y + 1 have the other parity, at index (y ∓ 1) / 2 there.
                let above = (y > 0).then(|| &other[(y - 1) / 2 * w..][..w]);
                let below = (y + 1 < h).then(|| &other[(y + 1) / 2 * w..][..w]);
                let crow = &coef[y * w..(y + 1) * w];
                let wrow = &weights[y * w..(y + 1) * w];
                let wup = (y > 0).then(|| &weights[(y - 1) * w..y * w]);
                for x in ((colour + y) % 2..w).step_by(2) {
                    let c = crow[x];
                    if c[5] == 0.0 {
                        continue;
                    }
                    let wt = wrow[x];
                    let (mut su, mut sv) = (c[3], c[4]);
                    if x + 1 < w {
                        let n = row[x + 1];
                        su += wt[0] * n[0];
                        sv += wt[2] * n[1];
                    }
                    if x > 0 {
                        let wl = wrow[x - 1];
                        let n = row[x - 1];
                        su += wl[0] * n[0];
                        sv += wl[2] * n[1];
                    }
                    if let Some(b) = below {
                        let n = b[x];
                        su += wt[1] * n[0];
                        sv += wt[3] * n[1];
                    }
                    if let (Some(a), Some(wu)) = (above, wup) {
                        let n = a[x];
                        su += wu[x][1] * n[0];
                        sv += wu[x][3] * n[1];
                    }
                    let un = c[0] * su + c[1] * sv;
                    let vn = c[1] * su + c[2] * sv;
                    let p = &mut row[x];
                    p[0] += omega * (un - p[0]);
                    p[1] += omega * (vn - p[1]);
                }
            });
    }
}
