//! Image error measures used in every report: PSNR over a mask with a stated peak, and
//! mean absolute error. For linear HDR images the peak is the reference's brightest
//! channel value inside the mask, so that the figure does not depend on exposure.

use frf_core::image::{GrayImage, RgbImage};

/// Pixels with alpha at least this much count as subject in masked measures.
pub const SUBJECT_ALPHA: f32 = 0.5;

/// Error of `test` against `reference` over the pixels where `mask` (if any) is at least
/// [`SUBJECT_ALPHA`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageError {
    /// Peak signal-to-noise ratio, dB, with the peak stated in `peak`.
    pub psnr_db: f64,
    /// Mean absolute error per channel, relative to the reference's mean.
    pub relative_mae: f64,
    /// The peak used: the reference's largest channel value inside the mask.
    pub peak: f64,
    /// Pixels compared.
    pub pixels: usize,
}

/// Compares two equally sized images.
pub fn compare(reference: &RgbImage, test: &RgbImage, mask: Option<&GrayImage>) -> ImageError {
    let (mut se, mut ae, mut sum, mut peak, mut n) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0usize);
    for (i, (r, t)) in reference.pixels().iter().zip(test.pixels()).enumerate() {
        if mask.is_some_and(|m| m.pixels()[i] < SUBJECT_ALPHA) {
            continue;
        }
        for c in 0..3 {
            let (r, t) = (r[c] as f64, t[c] as f64);
            se += (r - t).powi(2);
            ae += (r - t).abs();
            sum += r.abs();
            peak = peak.max(r);
        }
        n += 1;
    }
    let samples = (3 * n).max(1) as f64;
    let mse = se / samples;
    ImageError {
        psnr_db: if mse > 0.0 && peak > 0.0 {
            10.0 * (peak * peak / mse).log10()
        } else {
            f64::INFINITY
        },
        relative_mae: if sum > 0.0 { ae / sum } else { 0.0 },
        peak,
        pixels: n,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use frf_core::image::Image;

    #[test]
    fn psnr_of_a_known_error() {
        let a = Image::new(10, 10, [1.0f32, 0.5, 0.25]);
        let b = a.map(|p| p.map(|v| v + 0.01));
        let e = compare(&a, &b, None);
        // MSE 1e-4 with peak 1: 40 dB.
        assert!((e.psnr_db - 40.0).abs() < 1e-4, "{}", e.psnr_db);
        assert_eq!(e.pixels, 100);
        let mask = Image::from_fn(10, 10, |x, _| if x < 5 { 1.0 } else { 0.0 });
        assert_eq!(compare(&a, &b, Some(&mask)).pixels, 50);
        assert!(compare(&a, &a, None).psnr_db.is_infinite());
    }
}
