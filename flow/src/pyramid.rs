//! Image pyramids for coarse-to-fine estimation: Gaussian anti-aliasing, bilinear
//! resampling under the pixel-centre convention, the choice of the number of levels, and
//! flow-field resizing between levels.
//!
//! Each level is the previous one blurred with a Gaussian of σ = 1/√(2·ratio) and
//! resampled by `ratio` (Sun et al.'s anti-aliasing rule; σ = 1 for ratio 0.5). A pixel
//! centre `x` of a level of width `w` sits at `(x + ½)·(w'/w) − ½` in a level of width
//! `w'` (pixel centres at integer coordinates, [`frf_core::conventions`]); flow
//! components scale by `w'/w` and `h'/h`.

use frf_core::image::{FlowImage, GrayImage, Image, Pixel};
use rayon::prelude::*;

use crate::params::FlowParams;

/// A pyramid level's displacement reach: one linearisation recovers about one pixel,
/// so the coarsest level must shrink the largest displacement to about this
/// (the classical rule of thumb for gradient-based flow, e.g. Bouguet's pyramidal LK).
const COARSE_REACH_PX: f32 = 1.0;

/// Sizes `(width, height)` of the pyramid levels, finest (the input) first.
pub(crate) fn level_sizes(width: usize, height: usize, params: &FlowParams) -> Vec<(usize, usize)> {
    let r = params.pyramid_ratio as f64;
    let size_at = |n: i32| {
        let f = r.powi(n);
        (
            ((width as f64 * f).round() as usize).max(1),
            ((height as f64 * f).round() as usize).max(1),
        )
    };
    let mut sizes = vec![(width, height)];
    let mut displacement = params.max_displacement_px;
    loop {
        let next = size_at(sizes.len() as i32);
        let reached = displacement <= COARSE_REACH_PX;
        let too_small = next.0.min(next.1) < params.min_level_px;
        // Levels below the finest solved one are always built (they feed the rest).
        let needed_for_finest = sizes.len() <= params.finest_level;
        if too_small || (reached && !needed_for_finest) || next == *sizes.last().unwrap_or(&next) {
            break;
        }
        sizes.push(next);
        displacement *= params.pyramid_ratio;
    }
    sizes
}

/// A normalised Gaussian kernel of standard deviation `sigma`, radius `ceil(2σ)`
/// (95% of the mass; the tail changes the anti-aliasing imperceptibly).
pub(crate) fn gaussian_kernel(sigma: f32) -> Vec<f32> {
    let radius = (2.0 * sigma).ceil().max(1.0) as i32;
    let mut k: Vec<f32> = (-radius..=radius)
        .map(|i| (-(i * i) as f32 / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f32 = k.iter().sum();
    k.iter_mut().for_each(|v| *v /= sum);
    k
}

/// Separable convolution with `kernel` (odd length) along x then y, edges clamped.
pub(crate) fn convolve_separable(img: &GrayImage, kernel: &[f32]) -> GrayImage {
    let (w, h) = img.size();
    let radius = (kernel.len() / 2) as isize;
    let src = img.pixels();
    let mut tmp = vec![0.0f32; w * h];
    tmp.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            let s = &src[y * w..(y + 1) * w];
            for (x, out) in row.iter_mut().enumerate() {
                let mut acc = 0.0;
                for (k, &kv) in kernel.iter().enumerate() {
                    let xi = (x as isize + k as isize - radius).clamp(0, w as isize - 1) as usize;
                    acc += kv * s[xi];
                }
                *out = acc;
            }
        });
    let mut out = vec![0.0f32; w * h];
    out.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            row.fill(0.0);
            for (k, &kv) in kernel.iter().enumerate() {
                let yi = (y as isize + k as isize - radius).clamp(0, h as isize - 1) as usize;
                let s = &tmp[yi * w..(yi + 1) * w];
                for (o, &v) in row.iter_mut().zip(s) {
                    *o += kv * v;
                }
            }
        });
    Image::from_vec(w, h, out).unwrap_or_else(|_| Image::new(w, h, 0.0))
}

/// Gaussian blur with standard deviation `sigma` (pixels); `sigma ≤ 0` copies.
pub(crate) fn gaussian_blur(img: &GrayImage, sigma: f32) -> GrayImage {
    if sigma <= 0.0 {
        return img.clone();
    }
    convolve_separable(img, &gaussian_kernel(sigma))
}

/// Bilinear taps `(i0, i1, t)` of every output position of a `from → to` resampling
/// along one axis (pixel centres at integers, edges clamped).
fn axis_taps(from: usize, to: usize) -> Vec<(usize, usize, f32)> {
    let scale = from as f32 / to as f32;
    (0..to)
        .map(|i| {
            let p = ((i as f32 + 0.5) * scale - 0.5).clamp(0.0, (from - 1) as f32);
            let i0 = p as usize; // p ≥ 0: truncation is the floor.
            let i1 = (i0 + 1).min(from - 1);
            (i0, i1, p - i0 as f32)
        })
        .collect()
}

/// Bilinear resampling of `img` to `width x height` (edges clamped), no anti-aliasing.
/// The taps are computed once per row and column (the per-pixel sampler of
/// `frf-core` measured 6% of the fast preset's time here).
pub(crate) fn resample<P: Pixel>(img: &Image<P>, width: usize, height: usize) -> Image<P> {
    if img.pixels().is_empty() || width == 0 || height == 0 {
        return Image::new(width, height, P::zero());
    }
    let xt = axis_taps(img.width(), width);
    let yt = axis_taps(img.height(), height);
    let src = img.pixels();
    let sw = img.width();
    let mut out = vec![P::zero(); width * height];
    out.par_chunks_mut(width)
        .zip(yt.par_iter())
        .for_each(|(row, &(y0, y1, fy))| {
            let (r0, r1) = (&src[y0 * sw..(y0 + 1) * sw], &src[y1 * sw..(y1 + 1) * sw]);
            for (o, &(x0, x1, fx)) in row.iter_mut().zip(&xt) {
                let top = r0[x0].add_scaled(r0[x1], fx).add_scaled(r0[x0], -fx);
                let bottom = r1[x0].add_scaled(r1[x1], fx).add_scaled(r1[x0], -fx);
                *o = top.add_scaled(bottom, fy).add_scaled(top, -fy);
            }
        });
    Image::from_vec(width, height, out).unwrap_or_else(|_| Image::new(width, height, P::zero()))
}

/// One pyramid step: anti-alias for `ratio`, then resample to `width x height`.
pub(crate) fn downsample(img: &GrayImage, width: usize, height: usize, ratio: f32) -> GrayImage {
    let sigma = 1.0 / (2.0 * ratio).sqrt();
    resample(&gaussian_blur(img, sigma), width, height)
}

/// A flow field resized to `width x height`, its components rescaled to the new
/// pixel size.
pub(crate) fn resize_flow(flow: &FlowImage, width: usize, height: usize) -> FlowImage {
    if flow.size() == (width, height) {
        return flow.clone();
    }
    let fx = width as f32 / flow.width() as f32;
    let fy = height as f32 / flow.height() as f32;
    let mut out = resample(flow, width, height);
    out.pixels_mut().par_iter_mut().for_each(|p| {
        p[0] *= fx;
        p[1] *= fy;
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::Preset;

    #[test]
    fn levels_stop_at_min_size_and_at_reach() {
        let mut p = FlowParams::preset(Preset::Balanced);
        p.pyramid_ratio = 0.5;
        p.min_level_px = 16;
        p.max_displacement_px = 1000.0;
        let sizes = level_sizes(640, 480, &p);
        assert_eq!(sizes.last(), Some(&(40, 30)));
        assert_eq!(sizes.len(), 5);
        // 4 px of motion: two halvings bring it to 1 px.
        p.max_displacement_px = 4.0;
        assert_eq!(level_sizes(640, 480, &p).len(), 3);
        // Tiny images get a single level.
        assert_eq!(level_sizes(1, 1, &p), vec![(1, 1)]);
        assert_eq!(level_sizes(3, 5, &p), vec![(3, 5)]);
    }

    #[test]
    fn resampling_keeps_a_linear_ramp_aligned() {
        // A ramp f(x) = x at the fine level must read (x + ½)·2 − ½ at coarse pixel x.
        let fine = Image::from_fn(16, 4, |x, _| x as f32);
        let coarse = resample(&fine, 8, 2);
        for x in 1..7 {
            let expected = (x as f32 + 0.5) * 2.0 - 0.5;
            assert!((coarse.get(x, 1) - expected).abs() < 1e-5);
        }
    }

    #[test]
    fn blur_preserves_constants_and_mass() {
        let img = Image::new(9, 7, 0.25f32);
        let b = gaussian_blur(&img, 1.3);
        assert!(b.pixels().iter().all(|&v| (v - 0.25).abs() < 1e-6));
        let k = gaussian_kernel(1.0);
        assert_eq!(k.len(), 5);
        assert!((k.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn resized_flow_scales_its_components() {
        let flow = Image::new(8, 6, [2.0f32, -1.0]);
        let half = resize_flow(&flow, 4, 3);
        assert!(
            half.pixels()
                .iter()
                .all(|p| (p[0] - 1.0).abs() < 1e-6 && (p[1] + 0.5).abs() < 1e-6)
        );
    }
}
