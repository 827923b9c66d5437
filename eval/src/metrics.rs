//! Image error measures, in one place for every report of the project.
//!
//! **Regions.** Every measure takes an optional mask of pixels (`None`: the whole image).
//! The masks used in reports are built here, with their rule in their name:
//! - [`alpha_mask`]: pixels where one alpha image is at least [`SUBJECT_ALPHA`] (the
//!   subject of a truth image: ingest and storage figures);
//! - [`subject_mask`]: pixels where *either* of two RGBA images has alpha at least
//!   [`SUBJECT_ALPHA`] (rendered frames: a renderer that drops or invents part of the
//!   subject is charged for it);
//! - the edge band of [`edge_band_error`]: pixels whose true alpha lies strictly inside
//!   [`EDGE_BAND`] (partly covered silhouette pixels).
//!
//! **PSNR** is over the colour channels (the first three), in linear light, with the
//! peak stated: the reference's largest colour value inside the region, so that the
//! figure does not depend on exposure. **SSIM** (Wang et al. 2004) is on Rec. 709
//! luminance with a Gaussian window of σ = 1.5 px (11 x 11, edges clamped), K1 = 0.01,
//! K2 = 0.03 and the reference's peak in the region as dynamic range; the SSIM of a
//! region is the mean of the SSIM map over it.

use frf_core::filter::gaussian_blur;
use frf_core::image::{GrayImage, Image, RgbImage, Rgba, luminance};

/// Alpha at least this much counts as subject in masked measures (half covered).
pub const SUBJECT_ALPHA: f32 = 0.5;
/// True alpha strictly between these bounds makes a pixel part of the edge band.
pub const EDGE_BAND: (f32, f32) = (0.05, 0.95);
/// The bright background of [`edge_band_error`] is this percentile of the truth's
/// subject values.
pub const BRIGHT_PERCENTILE: f64 = 0.99;

/// Composite error over the edge band ([`edge_band_error`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeBandError {
    /// Over black (the premultiplied colour itself), relative to the truth's mean subject
    /// value.
    pub dark: f64,
    /// Over the bright level `bright`, relative to the same.
    pub bright: f64,
    /// The bright background's level: the truth's [`BRIGHT_PERCENTILE`] subject value.
    pub bright_level: f64,
    /// Pixels in the band.
    pub pixels: usize,
}

/// The error of an estimated premultiplied image and its alpha, composited over black
/// and over a bright background, against the truth composited the same way, over the
/// pixels whose true alpha is strictly inside [`EDGE_BAND`]: over a background `b` the
/// composite is `F + (1 − α) b`; over black only `F` counts, over a bright background
/// the estimate's alpha error too. The bright level is the [`BRIGHT_PERCENTILE`] of the
/// truth's colour values over its subject (true alpha ≥ [`SUBJECT_ALPHA`]). Both errors
/// are the mean absolute error per channel relative to the truth's mean colour value
/// over its subject, so that they do not depend on exposure. `None` when the band or the
/// subject is empty, or the truth's subject is black.
pub fn edge_band_error(
    true_colour: &RgbImage,
    true_alpha: &GrayImage,
    colour: &RgbImage,
    alpha: &GrayImage,
) -> Option<EdgeBandError> {
    let mut subject: Vec<f32> = true_colour
        .pixels()
        .iter()
        .zip(true_alpha.pixels())
        .filter(|(_, a)| **a >= SUBJECT_ALPHA)
        .flat_map(|(c, _)| *c)
        .collect();
    if subject.is_empty() {
        return None;
    }
    let mean = subject.iter().map(|&v| v as f64).sum::<f64>() / subject.len() as f64;
    if !mean.is_finite() || mean <= 0.0 {
        return None;
    }
    subject.sort_by(f32::total_cmp);
    let b = subject[((subject.len() - 1) as f64 * BRIGHT_PERCENTILE).round() as usize] as f64;
    let (mut dark, mut bright, mut pixels) = (0.0f64, 0.0f64, 0usize);
    for i in 0..true_alpha.pixels().len() {
        let ta = true_alpha.pixels()[i];
        if !(ta > EDGE_BAND.0 && ta < EDGE_BAND.1) {
            continue;
        }
        let (tc, c) = (true_colour.pixels()[i], colour.pixels()[i]);
        let a = alpha.pixels()[i] as f64;
        for k in 0..3 {
            let (t, e) = (tc[k] as f64, c[k] as f64);
            dark += (e - t).abs();
            bright += ((e + (1.0 - a) * b) - (t + (1.0 - ta as f64) * b)).abs();
        }
        pixels += 1;
    }
    (pixels > 0).then(|| {
        let n = (3 * pixels) as f64 * mean;
        EdgeBandError {
            dark: dark / n,
            bright: bright / n,
            bright_level: b,
            pixels,
        }
    })
}

/// [`edge_band_error`] of premultiplied RGBA images (a rendered subject against the true
/// one).
pub fn edge_band_error_rgba(truth: &Image<Rgba>, test: &Image<Rgba>) -> Option<EdgeBandError> {
    let rgb = |i: &Image<Rgba>| i.map(|p| [p[0], p[1], p[2]]);
    edge_band_error(&rgb(truth), &alpha_of(truth), &rgb(test), &alpha_of(test))
}

/// Colour error of a test image against a reference over a region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageError {
    /// Peak signal-to-noise ratio, dB, with the peak stated in `peak`; infinite when the
    /// images are equal over the region.
    pub psnr_db: f64,
    /// Mean absolute error per channel, relative to the reference's mean.
    pub relative_mae: f64,
    /// The peak used: the reference's largest colour value inside the region.
    pub peak: f64,
    /// Pixels compared.
    pub pixels: usize,
}

/// Compares the colour channels (the first three) of two equally sized images over the
/// pixels where `mask` holds (all pixels when `None`).
pub fn compare<P: Copy + AsRef<[f32]>>(
    reference: &Image<P>,
    test: &Image<P>,
    mask: Option<&[bool]>,
) -> ImageError {
    let (mut se, mut ae, mut sum, mut peak, mut n) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0usize);
    for (i, (r, t)) in reference.pixels().iter().zip(test.pixels()).enumerate() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        let (r, t) = (r.as_ref(), t.as_ref());
        for c in 0..3 {
            let (r, t) = (r[c] as f64, t[c] as f64);
            se += (r - t).powi(2);
            ae += (r - t).abs();
            sum += r.abs();
            peak = peak.max(r);
        }
        n += 1;
    }
    let mse = se / (3 * n).max(1) as f64;
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

/// PSNR (dB) of the colour of `test` against `reference` over `mask` ([`compare`]).
pub fn psnr<P: Copy + AsRef<[f32]>>(
    reference: &Image<P>,
    test: &Image<P>,
    mask: Option<&[bool]>,
) -> f64 {
    compare(reference, test, mask).psnr_db
}

/// Pixels where `alpha` is at least [`SUBJECT_ALPHA`].
pub fn alpha_mask(alpha: &GrayImage) -> Vec<bool> {
    alpha.pixels().iter().map(|&a| a >= SUBJECT_ALPHA).collect()
}

/// Pixels where either image's alpha is at least [`SUBJECT_ALPHA`].
pub fn subject_mask(reference: &Image<Rgba>, test: &Image<Rgba>) -> Vec<bool> {
    reference
        .pixels()
        .iter()
        .zip(test.pixels())
        .map(|(r, t)| r[3] >= SUBJECT_ALPHA || t[3] >= SUBJECT_ALPHA)
        .collect()
}

/// Mean SSIM of the luminance of `test` against `reference` over `mask` (all pixels when
/// `None`); 1 for identical images.
pub fn ssim<P: Copy + AsRef<[f32]>>(
    reference: &Image<P>,
    test: &Image<P>,
    mask: Option<&[bool]>,
) -> f64 {
    let (w, h) = reference.size();
    let lum = |p: P| {
        let c = p.as_ref();
        luminance([c[0], c[1], c[2]])
    };
    let x = reference.map(lum);
    let y = test.map(lum);
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
    let blur = |img: &GrayImage| gaussian_blur(img, 1.5);
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

/// Mean absolute difference of two alpha images over the whole frame.
pub fn alpha_mae(reference: &GrayImage, test: &GrayImage) -> f64 {
    let n = reference.pixels().len().max(1) as f64;
    reference
        .pixels()
        .iter()
        .zip(test.pixels())
        .map(|(r, t)| (r - t).abs() as f64)
        .sum::<f64>()
        / n
}

/// A reference alpha this close to [`SUBJECT_ALPHA`] is on neither side of it for
/// [`alpha_iou`]. The stage's true alpha is the coverage of 2x2 sub-samples, blurred by
/// the lens: an edge anywhere within a quarter pixel of a pixel's centre covers two of
/// its four sub-samples, so along the silhouette many true alphas are ½ give or take
/// the blur's rounding, and a threshold at ½ splits them by chance. On the perturbed
/// small preset's estimated mattes 82 % of the pixels on opposite sides were such ties
/// (true alpha within 0.01 of ½).
pub const AMBIGUOUS_ALPHA: f32 = 0.01;

/// Intersection over union of the binary mattes `alpha ≥ SUBJECT_ALPHA` of two alpha
/// images, leaving out the pixels whose reference is within [`AMBIGUOUS_ALPHA`] of the
/// threshold (`None` when both are empty: there is nothing to measure).
pub fn alpha_iou(reference: &GrayImage, test: &GrayImage) -> Option<f64> {
    let (mut inter, mut union) = (0usize, 0usize);
    for (&r, &t) in reference.pixels().iter().zip(test.pixels()) {
        if (r - SUBJECT_ALPHA).abs() < AMBIGUOUS_ALPHA {
            continue;
        }
        let (a, b) = (r >= SUBJECT_ALPHA, t >= SUBJECT_ALPHA);
        inter += (a && b) as usize;
        union += (a || b) as usize;
    }
    (union > 0).then(|| inter as f64 / union as f64)
}

/// Columns of subject a pair of rows needs for [`max_row_jump`] to count it.
const ROW_JUMP_MIN_COLUMNS: usize = 3;

/// The largest jump between neighbouring rows of a frame's subject: per pair of rows,
/// the mean over the columns where both rows' alpha is at least ½ of the largest
/// absolute difference of their premultiplied RGBA channels; the largest over the pairs
/// with at least three such columns. A seam across the subject (a tear where the image
/// above a row comes from elsewhere than the image below it) is a jump far larger than
/// the true image's between any two of its rows; the true image sets the scale.
pub fn max_row_jump(img: &Image<Rgba>) -> f64 {
    let (w, h) = (img.width(), img.height());
    let mut worst = 0.0f64;
    for y in 1..h {
        let (mut sum, mut n) = (0.0f64, 0usize);
        for x in 0..w {
            let (a, b) = (img.get(x, y - 1), img.get(x, y));
            if a[3] < 0.5 || b[3] < 0.5 {
                continue;
            }
            let d = (0..4).map(|c| (a[c] - b[c]).abs()).fold(0.0f32, f32::max);
            sum += d as f64;
            n += 1;
        }
        if n >= ROW_JUMP_MIN_COLUMNS {
            worst = worst.max(sum / n as f64);
        }
    }
    worst
}

/// The alpha channel of an RGBA image.
pub fn alpha_of(img: &Image<Rgba>) -> GrayImage {
    img.map(|p| p[3])
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
    fn edge_band_error_of_a_known_fringe() {
        // A subject of colour 0.2 in columns 0-4 whose column 5 is half covered (the
        // band), with one bright pixel of 1.0: its three values are the top 1 % of the
        // 3 x 60 subject values (alpha >= 0.5: columns 0-5).
        let true_alpha = Image::from_fn(10, 10, |x, _| match x {
            0..5 => 1.0,
            5 => 0.5,
            _ => 0.0,
        });
        let true_colour = Image::from_fn(10, 10, |x, y| {
            if x == 0 && y == 0 {
                [1.0; 3]
            } else {
                [0.2 * true_alpha.get(x, y); 3]
            }
        });
        assert!(
            edge_band_error(&true_colour, &true_alpha, &true_colour, &true_alpha)
                .is_some_and(|e| e.dark == 0.0 && e.bright == 0.0 && e.pixels == 10)
        );
        // The estimate's band pixels carry 0.1 of backdrop light and alpha 0.7.
        let mut colour = true_colour.clone();
        let mut alpha = true_alpha.clone();
        for y in 0..10 {
            colour.set(5, y, [0.2; 3]);
            alpha.set(5, y, 0.7);
        }
        let e = edge_band_error(&true_colour, &true_alpha, &colour, &alpha).unwrap();
        let mean = (49.0 * 0.2 + 1.0 + 10.0 * 0.1) / 60.0;
        assert_eq!(e.bright_level, 1.0);
        assert!((e.dark - 0.1 / mean).abs() < 1e-6, "{e:?}");
        // Over 1.0: 0.2 + 0.3 against 0.1 + 0.5.
        assert!((e.bright - 0.1 / mean).abs() < 1e-6, "{e:?}");
        assert!(edge_band_error(&true_colour, &true_alpha.map(|_| 0.0), &colour, &alpha).is_none());
    }

    #[test]
    fn psnr_of_a_known_error_over_a_region() {
        let a = Image::new(10, 10, [1.0f32, 0.5, 0.25]);
        let b = a.map(|p| p.map(|v| v + 0.01));
        let e = compare(&a, &b, None);
        // MSE 1e-4 with peak 1: 40 dB.
        assert!((e.psnr_db - 40.0).abs() < 1e-4, "{}", e.psnr_db);
        assert_eq!(e.pixels, 100);
        let half = alpha_mask(&Image::from_fn(
            10,
            10,
            |x, _| if x < 5 { 1.0 } else { 0.0 },
        ));
        assert_eq!(compare(&a, &b, Some(&half)).pixels, 50);
        assert!(compare(&a, &a, None).psnr_db.is_infinite());
    }

    #[test]
    fn identical_images_score_perfectly_and_damage_lowers_the_scores() {
        let a = pattern(0);
        assert_eq!(psnr(&a, &a, None), f64::INFINITY);
        assert!((ssim(&a, &a, None) - 1.0).abs() < 1e-6);
        assert_eq!(alpha_mae(&alpha_of(&a), &alpha_of(&a)), 0.0);
        let b = pattern(5);
        let s = ssim(&a, &b, None);
        assert!(s < 0.5, "a different texture: SSIM {s}");
        // A uniform offset of 1 % of the peak on one of three channels: 10 log10(3 / 1e-4).
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
        assert!((alpha_mae(&alpha_of(&a), &alpha_of(&d)) - 11.0 / 40.0).abs() < 1e-6);
        // 29 of 40 columns are subject in a, all of them in d.
        assert!((alpha_iou(&alpha_of(&a), &alpha_of(&d)).unwrap() - 29.0 / 40.0).abs() < 1e-9);
    }

    #[test]
    fn a_true_alpha_of_one_half_is_on_neither_side() {
        // Columns 0-3 covered, column 4 half covered (a tie), 5-9 empty.
        let truth = Image::from_fn(10, 4, |x, _| match x {
            0..4 => 1.0,
            4 => 0.5,
            _ => 0.0,
        });
        // Either reading of the tie scores the same; a miss beside it counts.
        let wider = Image::from_fn(10, 4, |x, _| if x <= 4 { 0.9 } else { 0.0 });
        let narrower = Image::from_fn(10, 4, |x, _| if x < 4 { 0.9 } else { 0.1 });
        assert_eq!(alpha_iou(&truth, &wider), Some(1.0));
        assert_eq!(alpha_iou(&truth, &narrower), Some(1.0));
        let eroded = Image::from_fn(10, 4, |x, _| if x < 3 { 0.9 } else { 0.0 });
        assert_eq!(alpha_iou(&truth, &eroded), Some(0.75));
    }
}
