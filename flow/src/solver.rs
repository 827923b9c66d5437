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
use crate::sor::{PixelSystem, RedBlack};

/// Weight of the second image's derivatives in the blended gradient (Sun et al.'s ½;
/// measured: 0 or 1, i.e. one image's derivatives only, 0.191 px instead of 0.185).
const DERIVATIVE_BLEND: f32 = 0.5;

/// Both images at one pyramid level, each pixel's values packed together —
/// `[I, ∂I/∂x, ∂I/∂y]` for every channel — so that warping reads a few contiguous cache
/// lines per tap instead of one per plane (measured 15% faster warping for RGB).
pub(crate) struct LevelImages {
    pub width: usize,
    pub height: usize,
    pub channels: usize,
    /// First image, `3 · channels` values per pixel.
    pub i1: Vec<f32>,
    /// Second image, same layout.
    pub i2: Vec<f32>,
}

impl LevelImages {
    /// Packs per-channel planes and their derivatives (`[value, dx, dy]` per channel).
    pub fn pack(width: usize, height: usize, planes: &[[&[f32]; 3]], into: &mut Vec<f32>) {
        let stride = 3 * planes.len();
        into.clear();
        into.resize(width * height * stride, 0.0);
        into.par_chunks_mut(stride.max(1))
            .enumerate()
            .for_each(|(s, px)| {
                for (c, p) in planes.iter().enumerate() {
                    px[3 * c] = p[0][s];
                    px[3 * c + 1] = p[1][s];
                    px[3 * c + 2] = p[2][s];
                }
            });
    }
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
    let channels = level.channels;
    let mut lin = vec![[0.0f32; 3]; n * channels];
    let mut weights = vec![[0.0f32; 4]; n];
    let mut system = RedBlack::new(level.width, level.height);
    for _ in 0..config.warps {
        linearise(level, flow, config.interpolation, &mut lin);
        let base = flow.clone();
        for _ in 0..config.irls_iterations {
            smoothness_weights(level, flow, config, &mut weights);
            let pixel_system = |y: usize, xs: &[usize], out: &mut [PixelSystem]| {
                row_system(level, &lin, &base, flow, &weights, config, y, xs, out)
            };
            system.load(config.omega, flow.pixels(), pixel_system);
            system.sweep(config.sor_iterations);
            system.write_flow(flow.pixels_mut());
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
    let channels = level.channels;
    let stride = 3 * channels;
    let (xmax, ymax) = ((w - 1) as f32, (h - 1) as f32);
    let f = flow.pixels();
    lin.par_chunks_mut((w * channels).max(1))
        .enumerate()
        .for_each(|(y, row)| {
            let mut warped = vec![0.0f32; stride];
            for x in 0..w {
                let s = y * w + x;
                let (xs, ys) = (x as f32 + f[s][0], y as f32 + f[s][1]);
                let out = &mut row[x * channels..(x + 1) * channels];
                if !((0.0..=xmax).contains(&xs) && (0.0..=ymax).contains(&ys)) {
                    out.fill([0.0; 3]);
                    continue;
                }
                Taps::new(xs, ys, w, h, mode).sample_packed(&level.i2, stride, &mut warped);
                let first = &level.i1[s * stride..(s + 1) * stride];
                let b = DERIVATIVE_BLEND;
                for (c, o) in out.iter_mut().enumerate() {
                    let (w2, i1) = (&warped[3 * c..3 * c + 3], &first[3 * c..3 * c + 3]);
                    *o = [
                        b * w2[1] + (1.0 - b) * i1[1],
                        b * w2[2] + (1.0 - b) * i1[2],
                        w2[0] - i1[0],
                    ];
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
            // Squared differences first, then all weights of the row in one vectorised
            // pass; missing neighbours are fixed up afterwards.
            let here = &f[y * w..(y + 1) * w];
            let down = if y + 1 < h {
                &f[(y + 1) * w..(y + 2) * w]
            } else {
                here
            };
            for x in 0..w {
                let right = here[(x + 1).min(w - 1)];
                let (du_r, dv_r) = (right[0] - here[x][0], right[1] - here[x][1]);
                let (du_d, dv_d) = (down[x][0] - here[x][0], down[x][1] - here[x][1]);
                row[x] = [du_r * du_r, du_d * du_d, dv_r * dv_r, dv_d * dv_d];
            }
            let flat = row.as_flattened_mut();
            pen.weights_in_place(flat);
            flat.iter_mut().for_each(|v| *v *= lambda);
            if let Some(last) = row.last_mut() {
                last[0] = 0.0;
                last[2] = 0.0;
            }
            if y + 1 == h {
                row.iter_mut().for_each(|wt| {
                    wt[1] = 0.0;
                    wt[3] = 0.0;
                });
            }
        });
}

/// The system of the pixels `xs` of row `y`: the inverse of each pixel's 2x2 diagonal
/// block, the constant part of its right-hand side, and its pair weights.
#[allow(clippy::too_many_arguments)]
fn row_system(
    level: &LevelImages,
    lin: &[[f32; 3]],
    base: &FlowImage,
    flow: &FlowImage,
    weights: &[[f32; 4]],
    config: &SolverConfig,
    y: usize,
    xs: &[usize],
    out: &mut [PixelSystem],
) {
    let w = level.width;
    let channels = level.channels;
    let (f, f0) = (flow.pixels(), base.pixels());
    // Squared residuals of the row's pixels, then their weights in one vectorised pass.
    let mut psi: Vec<f32> = Vec::with_capacity(xs.len() * channels);
    for &x in xs {
        let s = y * w + x;
        let (du, dv) = (f[s][0] - f0[s][0], f[s][1] - f0[s][1]);
        for &[ix, iy, it] in &lin[s * channels..(s + 1) * channels] {
            let r = it + ix * du + iy * dv;
            psi.push(r * r);
        }
    }
    config.data.weights_in_place(&mut psi);
    for ((&x, o), psi) in xs
        .iter()
        .zip(out.iter_mut())
        .zip(psi.chunks_exact(channels.max(1)))
    {
        let s = y * w + x;
        let (mut a11, mut a12, mut a22, mut b1, mut b2) = (0.0f32, 0.0, 0.0, 0.0, 0.0);
        for (&[ix, iy, it], &p) in lin[s * channels..(s + 1) * channels].iter().zip(psi) {
            a11 += p * ix * ix;
            a12 += p * ix * iy;
            a22 += p * iy * iy;
            b1 += p * ix * it;
            b2 += p * iy * it;
        }
        let (u0, v0) = (f0[s][0], f0[s][1]);
        let here = weights[s];
        let left = if x > 0 { weights[s - 1] } else { [0.0; 4] };
        let up = if y > 0 { weights[s - w] } else { [0.0; 4] };
        let wu = [left[0], here[0], up[1], here[1]];
        let wv = [left[2], here[2], up[3], here[3]];
        let d11 = a11 + wu.iter().sum::<f32>();
        let d22 = a22 + wv.iter().sum::<f32>();
        let det = d11 * d22 - a12 * a12;
        // A block is singular when neither data nor smoothness constrains it
        // (textureless pixel with no neighbours, 1x1 images) or only the aperture
        // direction is constrained; relative 1e-6 is far above f32 rounding of the
        // products.
        let active = det > 1e-6 * d11 * d22 && det.is_finite() && det > 0.0;
        let inv = if active { 1.0 / det } else { 0.0 };
        *o = PixelSystem {
            inverse: [d22 * inv, -a12 * inv, d11 * inv],
            rhs: [a11 * u0 + a12 * v0 - b1, a12 * u0 + a22 * v0 - b2],
            active,
            wu,
            wv,
        };
    }
}
