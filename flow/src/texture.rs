//! What the data term matches: the input split into planes, normalised so that the
//! brightness scale and offset of each image do not matter, and optionally reduced to
//! its texture (structure–texture decomposition) with gradient-constancy planes added.
//!
//! 1. **Channels**: every channel ([`ColorMode::Color`]) or one luminance plane
//!    ([`ColorMode::Gray`]).
//! 2. **Normalisation**, per image: each channel minus its mean, all divided by the
//!    pooled standard deviation, then scaled by [`DATA_SCALE`]. An image and any
//!    `a·I + b` of it (a > 0) give the same planes, which is what the stage's linear
//!    HDR frames need; a constant image gives zero planes (and so no data term).
//! 3. **Texture**: `T = I − w·S` with `S` the total-variation (ROF) denoised image,
//!    with w = 0.95 and θ = 1/8 of the [−1, 1] range (Wedel et al., "An improved
//!    algorithm for TV-L1 optical flow", 2009, adopted by Sun et al. 2010), computed by
//!    Chambolle & Pock's accelerated primal–dual algorithm; or a Gaussian high-pass as a
//!    cheap substitute. The texture is normalised again (step 2), as Sun et al. rescale
//!    it to [0, 255], so that λ keeps its meaning whatever the filter removed.
//! 4. **Gradient constancy** (Brox et al., ECCV 2004): `γ·∂T/∂x` and `γ·∂T/∂y` of the
//!    channel mean as two more planes, unaffected by additive brightness changes.

use frf_core::image::{GrayImage, Image, Pixel, luminance};
use rayon::prelude::*;

use crate::gradient::derivatives;
use crate::params::{ColorMode, FlowParams, TextureFilter};
use crate::pyramid::gaussian_blur;

/// Scale of the normalised planes: unit standard deviation becomes 255/4, so that ±2σ
/// spans the [0, 255] range of the 8-bit images Sun et al.'s λ values were tuned on.
pub(crate) const DATA_SCALE: f32 = 255.0 / 4.0;

/// ROF fidelity θ of the structure–texture decomposition, in units of the image's
/// standard deviation: Wedel et al. (2009) use 1/8 on images min-max scaled to
/// [−1, 1], whose standard deviation is 0.44 on average (measured: 0.27–0.56 on the
/// five Middlebury first frames), so 1/8 there is about 1/4 of a standard deviation.
const ROF_THETA: f32 = 0.25;

/// An image's planes, as [`FlowParams::color`] asks for.
pub(crate) fn split_channels<P: Pixel>(img: &Image<P>, color: ColorMode) -> Vec<GrayImage> {
    match (color, P::CHANNELS) {
        (ColorMode::Color, _) | (ColorMode::Gray, 1) => (0..P::CHANNELS)
            .map(|c| img.map(|p| p.channels()[c]))
            .collect(),
        (ColorMode::Gray, 3) => {
            vec![img.map(|p| {
                let c = p.channels();
                luminance([c[0], c[1], c[2]])
            })]
        }
        (ColorMode::Gray, n) => vec![img.map(|p| p.channels().iter().sum::<f32>() / n as f32)],
    }
}

/// Subtracts each plane's mean and divides all by their pooled standard deviation
/// (times [`DATA_SCALE`]); planes without variation become zero.
pub(crate) fn normalise(planes: &mut [GrayImage]) {
    let n: usize = planes.iter().map(|p| p.pixels().len()).sum();
    if n == 0 {
        return;
    }
    let means: Vec<f64> = planes
        .iter()
        .map(|p| p.pixels().iter().map(|&v| v as f64).sum::<f64>() / p.pixels().len() as f64)
        .collect();
    let var: f64 = planes
        .iter()
        .zip(&means)
        .map(|(p, &m)| {
            p.pixels()
                .iter()
                .map(|&v| (v as f64 - m).powi(2))
                .sum::<f64>()
        })
        .sum::<f64>()
        / n as f64;
    let std = var.sqrt();
    let magnitude = means.iter().fold(0.0f64, |a, m| a.max(m.abs()));
    // Variation below float rounding of the values themselves is no signal: treat the
    // image as constant (relative 1e-6, a few f32 ulps above rounding noise).
    let scale = if std > 1e-6 * magnitude && std > 1e-30 {
        (DATA_SCALE as f64 / std) as f32
    } else {
        0.0
    };
    for (p, &m) in planes.iter_mut().zip(&means) {
        let m = m as f32;
        p.pixels_mut()
            .par_iter_mut()
            .for_each(|v| *v = (*v - m) * scale);
    }
}

/// The ROF (total-variation) denoised `f`: the minimiser of `TV(u) + |u − f|² / 2θ`,
/// by the accelerated primal–dual algorithm of Chambolle & Pock (J. Math. Imaging
/// Vis. 2011, Algorithm 2, using the 1/θ-strong convexity of the fidelity term), which
/// converges as O(1/N²) where Chambolle's 2004 projection converges as O(1/N): the flow
/// error on Middlebury is within 0.003 px of its 100-iteration value after 25 iterations
/// (measured). `theta` is in the units of `f`.
pub(crate) fn rof_structure(f: &GrayImage, theta: f32, iterations: usize) -> GrayImage {
    let (w, h) = f.size();
    let fp = f.pixels();
    let mut u = fp.to_vec();
    let mut ubar = fp.to_vec();
    let mut px = vec![0.0f32; w * h];
    let mut py = vec![0.0f32; w * h];
    // τσL² ≤ 1 with L² = 8, the squared norm of the forward-difference gradient.
    let (mut tau, mut sigma) = (0.35f32, 0.35f32);
    let gamma = 1.0 / theta;
    let rw = w.max(1);
    let zeros = vec![0.0f32; w];
    for _ in 0..iterations {
        // Dual ascent and projection onto the unit ball: p ← Π(p + σ∇ū). The last
        // column's px and last row's py stay zero (no forward difference there). Edge
        // cases sit outside the loops so that the row loops vectorise.
        px.par_chunks_mut(rw)
            .zip(py.par_chunks_mut(rw))
            .enumerate()
            .for_each(|(y, (rx, ry))| {
                let row = &ubar[y * w..(y + 1) * w];
                let next = if y + 1 < h {
                    &ubar[(y + 1) * w..(y + 2) * w]
                } else {
                    row
                };
                let n = w - 1;
                let cells = rx[..n].iter_mut().zip(&mut ry[..n]);
                let grads = row[..n].iter().zip(&row[1..]).zip(&next[..n]);
                for ((qx, qy), ((&here, &right), &below)) in cells.zip(grads) {
                    let (ax, ay) = (*qx + sigma * (right - here), *qy + sigma * (below - here));
                    let norm = (ax * ax + ay * ay).sqrt().max(1.0);
                    *qx = ax / norm;
                    *qy = ay / norm;
                }
                let ay = ry[n] + sigma * (next[n] - row[n]);
                ry[n] = ay / ay.abs().max(1.0);
            });
        // Primal step: u ← (u + τ div p + (τ/θ) f) / (1 + τ/θ), then extrapolation;
        // div p = px(x) − px(x − 1) + py(y) − py(y − 1), zero outside the image.
        let step = 1.0 / (1.0 + tau / theta);
        let rho = 1.0 / (1.0 + 2.0 * gamma * tau).sqrt();
        let fidelity = tau / theta;
        u.par_chunks_mut(rw)
            .zip(ubar.par_chunks_mut(rw))
            .enumerate()
            .for_each(|(y, (ru, rb))| {
                let (pxr, pyr) = (&px[y * w..(y + 1) * w], &py[y * w..(y + 1) * w]);
                let pyu = if y > 0 {
                    &py[(y - 1) * w..y * w]
                } else {
                    &zeros[..]
                };
                let fr = &fp[y * w..(y + 1) * w];
                let update = |old: &mut f32, bar: &mut f32, div: f32, f: f32| {
                    let new = (*old + tau * div + fidelity * f) * step;
                    *bar = new + rho * (new - *old);
                    *old = new;
                };
                update(&mut ru[0], &mut rb[0], pxr[0] + pyr[0] - pyu[0], fr[0]);
                let cells = ru[1..].iter_mut().zip(&mut rb[1..]);
                let divs = pxr[1..]
                    .iter()
                    .zip(&pxr[..w - 1])
                    .zip(pyr[1..].iter().zip(&pyu[1..]));
                for (((old, bar), ((&a, &b), (&c, &d))), &f) in cells.zip(divs).zip(&fr[1..]) {
                    update(old, bar, a - b + c - d, f);
                }
            });
        tau *= rho;
        sigma /= rho;
    }
    Image::from_vec(w, h, u).unwrap_or_else(|_| Image::new(w, h, 0.0))
}

/// Applies [`FlowParams::texture`] and adds the gradient planes; `planes` are
/// normalised already.
pub(crate) fn texture_planes(mut planes: Vec<GrayImage>, params: &FlowParams) -> Vec<GrayImage> {
    match params.texture {
        TextureFilter::None => {}
        TextureFilter::Rof { weight, iterations } => {
            for p in planes.iter_mut() {
                // θ is stated for unit standard deviation; the planes carry DATA_SCALE.
                let s = rof_structure(p, ROF_THETA * DATA_SCALE, iterations);
                subtract_scaled(p, &s, weight);
            }
        }
        TextureFilter::Gaussian { weight, sigma } => {
            for p in planes.iter_mut() {
                let s = gaussian_blur(p, sigma);
                subtract_scaled(p, &s, weight);
            }
        }
    }
    if params.texture != TextureFilter::None {
        normalise(&mut planes);
    }
    if params.gradient_weight > 0.0 && !planes.is_empty() {
        let (w, h) = planes[0].size();
        let k = planes.len() as f32;
        let mean = Image::from_fn(w, h, |x, y| {
            planes.iter().map(|p| p.get(x, y)).sum::<f32>() / k
        });
        let (dx, dy) = derivatives(&mean);
        let g = params.gradient_weight;
        planes.push(dx.map(|v| v * g));
        planes.push(dy.map(|v| v * g));
    }
    planes
}

fn subtract_scaled(p: &mut GrayImage, s: &GrayImage, weight: f32) {
    p.pixels_mut()
        .par_iter_mut()
        .zip(s.pixels().par_iter())
        .for_each(|(v, &s)| *v -= weight * s);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalisation_removes_gain_and_offset() {
        let img = Image::from_fn(9, 6, |x, y| ((x * 7 + y * 3) % 5) as f32 * 0.1);
        let mut a = vec![img.clone()];
        let mut b = vec![img.map(|v| 3.0 * v + 0.2)];
        normalise(&mut a);
        normalise(&mut b);
        for (p, q) in a[0].pixels().iter().zip(b[0].pixels()) {
            assert!((p - q).abs() < 1e-3, "{p} vs {q}");
        }
        let mut constant = vec![Image::new(4, 4, 0.7f32)];
        normalise(&mut constant);
        assert!(constant[0].pixels().iter().all(|&v| v == 0.0));
    }

    #[test]
    fn rof_keeps_a_step_and_removes_fine_texture() {
        // A step edge plus a ±1 checkerboard: the structure keeps the step (TV does not
        // blur edges) and drops most of the checkerboard.
        let f = Image::from_fn(32, 32, |x, y| {
            (if x < 16 { 0.0 } else { 40.0 }) + if (x + y) % 2 == 0 { 1.0 } else { -1.0 }
        });
        let s = rof_structure(&f, 4.0, 100);
        assert!((s.get(4, 16) - 0.0).abs() < 0.6 && (s.get(27, 16) - 40.0).abs() < 0.6);
        assert!(s.get(15, 16) < 5.0 && s.get(16, 16) > 35.0);
    }
}
