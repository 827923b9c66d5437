//! Image quality of rendered frames against a reference: PSNR (peak = the reference's
//! largest value in the region), SSIM (Wang et al. 2004: Gaussian window σ = 1.5 px
//! truncated at 11 x 11, K1 = 0.01, K2 = 0.03, dynamic range = the reference's peak) on
//! Rec. 709 luminance, and mean absolute alpha error. Regions are masks of pixels; the
//! SSIM of a region is the mean of the SSIM map over it.

use frf_core::filter::gaussian_blur;
use frf_core::image::{GrayImage, Image, Rgba};

/// Rec. 709 luminance of linear RGB.
fn luminance(p: &[f32]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// PSNR (dB) of the colour of `test` against `reference` over pixels where `mask` holds
/// (all pixels when `None`); infinite when they are equal.
pub fn psnr(reference: &Image<Rgba>, test: &Image<Rgba>, mask: Option<&[bool]>) -> f64 {
    let (mut se, mut peak, mut n) = (0.0f64, 0.0f64, 0usize);
    for (i, (r, t)) in reference.pixels().iter().zip(test.pixels()).enumerate() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        for c in 0..3 {
            se += (r[c] as f64 - t[c] as f64).powi(2);
            peak = peak.max(r[c] as f64);
        }
        n += 1;
    }
    let mse = se / (3 * n).max(1) as f64;
    if mse > 0.0 && peak > 0.0 {
        10.0 * (peak * peak / mse).log10()
    } else {
        f64::INFINITY
    }
}

/// The SSIM window: a Gaussian of σ = 1.5 px, truncated at radius 5 (11 x 11), edges
/// clamped.
fn blur(img: &GrayImage) -> GrayImage {
    gaussian_blur(img, 1.5)
}

/// Mean SSIM of the luminance of `test` against `reference` over `mask` (all pixels when
/// `None`); 1 for identical images.
pub fn ssim(reference: &Image<Rgba>, test: &Image<Rgba>, mask: Option<&[bool]>) -> f64 {
    let (w, h) = reference.size();
    let x = Image::from_fn(w, h, |i, j| luminance(&reference.get(i, j)));
    let y = Image::from_fn(w, h, |i, j| luminance(&test.get(i, j)));
    let peak = x
        .pixels()
        .iter()
        .enumerate()
        .filter(|(i, _)| mask.is_none_or(|m| m[*i]))
        .map(|(_, &v)| v)
        .fold(0.0f32, f32::max)
        .max(1e-6);
    let (c1, c2) = ((0.01 * peak).powi(2), (0.03 * peak).powi(2));
    let product =
        |a: &GrayImage, b: &GrayImage| Image::from_fn(w, h, |i, j| a.get(i, j) * b.get(i, j));
    let (mx, my) = (blur(&x), blur(&y));
    let (sxx, syy, sxy) = (
        blur(&product(&x, &x)),
        blur(&product(&y, &y)),
        blur(&product(&x, &y)),
    );
    let (mut sum, mut n) = (0.0f64, 0usize);
    for i in 0..w * h {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        let (a, b) = (mx.pixels()[i], my.pixels()[i]);
        let var_x = (sxx.pixels()[i] - a * a).max(0.0);
        let var_y = (syy.pixels()[i] - b * b).max(0.0);
        let cov = sxy.pixels()[i] - a * b;
        let s =
            ((2.0 * a * b + c1) * (2.0 * cov + c2)) / ((a * a + b * b + c1) * (var_x + var_y + c2));
        sum += s as f64;
        n += 1;
    }
    if n == 0 { 1.0 } else { sum / n as f64 }
}

/// Mean absolute difference of alpha over the whole frame.
pub fn alpha_mae(reference: &Image<Rgba>, test: &Image<Rgba>) -> f64 {
    let n = reference.pixels().len().max(1) as f64;
    reference
        .pixels()
        .iter()
        .zip(test.pixels())
        .map(|(r, t)| (r[3] - t[3]).abs() as f64)
        .sum::<f64>()
        / n
}

/// The subject: pixels where either image's alpha is at least one half.
pub fn subject_mask(reference: &Image<Rgba>, test: &Image<Rgba>) -> Vec<bool> {
    reference
        .pixels()
        .iter()
        .zip(test.pixels())
        .map(|(r, t)| r[3] >= 0.5 || t[3] >= 0.5)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern(seed: usize) -> Image<Rgba> {
        Image::from_fn(40, 30, |x, y| {
            let v = (((x * 7 + y * 13 + seed) % 17) as f32) / 17.0;
            [v, 0.5 * v, 0.2, if x > 10 { 1.0 } else { 0.0 }]
        })
    }

    #[test]
    fn identical_images_score_perfectly_and_damage_lowers_the_scores() {
        let a = pattern(0);
        assert_eq!(psnr(&a, &a, None), f64::INFINITY);
        assert!((ssim(&a, &a, None) - 1.0).abs() < 1e-6);
        assert_eq!(alpha_mae(&a, &a), 0.0);
        let b = pattern(5);
        let s = ssim(&a, &b, None);
        assert!(s < 0.5, "a different texture: SSIM {s}");
        // A uniform offset of 1 % of the peak: PSNR 40 dB on the colour channels.
        let mut c = a.clone();
        c.pixels_mut()
            .iter_mut()
            .for_each(|p| p[0] += 0.01 * 16.0 / 17.0);
        let p = psnr(&a, &c, None);
        let expected = 10.0 * (3.0 / (0.01f64).powi(2)).log10();
        assert!((p - expected).abs() < 0.05, "{p} vs {expected}");
        let mask = subject_mask(&a, &a);
        assert_eq!(mask.iter().filter(|&&m| m).count(), 29 * 30);
        let mut d = a.clone();
        d.pixels_mut().iter_mut().for_each(|p| p[3] = 1.0);
        assert!((alpha_mae(&a, &d) - 11.0 / 40.0).abs() < 1e-6);
    }
}
