//! Mattes from track and matte frames (docs/design.md section 2.1; Einarsson et al. section 5.1).
//! In a matte frame the actor is dark and the retro-reflective floor and back-lit
//! backdrop are bright. Two rules say which pixels are foreground ([`MatteRule`]):
//!
//! - the paper's: the monochrome track frame is brighter than the matte frame after it;
//! - the default, measured better: the matte frame is darker than half its clean plate.
//!   At a silhouette pixel covering a fraction `α` of the subject, the matte frame reads
//!   about `(1 − α) C_M` (the subject is nearly black in it), so this switches at
//!   `α = ½`, where the true matte's edge is. The paper's comparison switches where
//!   `α (T_s − M_s) = (1 − α)(C_M − C_T)`: with the stage's brightnesses at `α ≈ 0.77`,
//!   eroding the matte by a fraction of a pixel all around (alpha IoU 0.962 instead of
//!   0.98+ on the small preset).
//!
//! Stray foreground elsewhere is dropped by keeping only the largest connected component
//! near the image centre, and the binary matte is blurred with a 1-pixel Gaussian,
//! modelling the sensor's and the colour interpolation's filtering, to give alpha. The
//! premultiplied foreground is `T' = T − (1 − α) C`, with `C` the clean plate lit like `T`.

use frf_core::filter::gaussian_blur;
use frf_core::image::{GrayImage, Image, RgbImage, luminance};

use crate::error::{IngestError, Result};

/// Standard deviation of the blur that turns the binary matte into alpha, pixels (the
/// paper's 1-pixel Gaussian).
pub const MATTE_BLUR_SIGMA_PX: f32 = 1.0;
/// The central region a kept component must reach: the middle half of the width and
/// the middle two thirds of the height (a walker framed as the capture cameras frame it).
const CENTRE_X: (f32, f32) = (0.25, 0.75);
const CENTRE_Y: (f32, f32) = (1.0 / 6.0, 5.0 / 6.0);

fn check_same(what: &str, a: &RgbImage, b: &RgbImage) -> Result<()> {
    if a.size() != b.size() {
        return Err(IngestError::sizes(what, a.size(), b.size()));
    }
    Ok(())
}

/// Which pixels of a track frame are foreground.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum MatteRule {
    /// The track frame is brighter than the matte frame (Einarsson et al.).
    #[cfg_attr(feature = "clap", value(name = "paper"))]
    TrackBrighterThanMatte,
    /// The matte frame is darker than half its clean plate (unbiased at silhouettes).
    #[cfg_attr(feature = "clap", value(name = "half-clean"))]
    MatteBelowHalfCleanPlate,
}

/// The frames a matte is made from: a track frame, the matte frame after it, and the
/// matte frame's clean plate.
#[derive(Debug, Clone, Copy)]
pub struct MatteInput<'a> {
    /// The track frame `T`.
    pub track: &'a RgbImage,
    /// The matte frame `M`.
    pub matte: &'a RgbImage,
    /// The clean plate of the matte frame's slot, `C_M`.
    pub matte_clean: &'a RgbImage,
}

/// The binary foreground by `rule`, restricted to the largest 4-connected component
/// that reaches the central region (empty if none does).
pub fn foreground(input: &MatteInput, rule: MatteRule) -> Result<Image<bool>> {
    check_same("track and matte frames", input.track, input.matte)?;
    check_same(
        "matte frame and its clean plate",
        input.matte,
        input.matte_clean,
    )?;
    let (w, h) = input.track.size();
    let raw: Vec<bool> = (0..w * h)
        .map(|i| {
            let m = luminance(input.matte.pixels()[i]);
            match rule {
                MatteRule::TrackBrighterThanMatte => luminance(input.track.pixels()[i]) > m,
                MatteRule::MatteBelowHalfCleanPlate => {
                    m < 0.5 * luminance(input.matte_clean.pixels()[i])
                }
            }
        })
        .collect();
    largest_central_component(&Image::from_vec(w, h, raw)?)
}

/// The largest 4-connected component of `mask` that reaches the central region (the
/// middle half of the width, the middle two thirds of the height); empty if none does.
pub fn largest_central_component(mask: &Image<bool>) -> Result<Image<bool>> {
    let (w, h) = mask.size();
    let raw = mask.pixels();
    // Label components by flood fill.
    let mut label = vec![u32::MAX; w * h];
    let mut sizes: Vec<usize> = Vec::new();
    let mut central: Vec<bool> = Vec::new();
    let in_centre = |x: usize, y: usize| {
        let (fx, fy) = (x as f32 / w as f32, y as f32 / h as f32);
        fx >= CENTRE_X.0 && fx <= CENTRE_X.1 && fy >= CENTRE_Y.0 && fy <= CENTRE_Y.1
    };
    let mut stack = Vec::new();
    for start in 0..w * h {
        if !raw[start] || label[start] != u32::MAX {
            continue;
        }
        let id = sizes.len() as u32;
        let (mut size, mut reaches) = (0usize, false);
        label[start] = id;
        stack.push(start);
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w, i / w);
            size += 1;
            reaches |= in_centre(x, y);
            let neighbours = [
                (x > 0).then(|| i - 1),
                (x + 1 < w).then(|| i + 1),
                (y > 0).then(|| i - w),
                (y + 1 < h).then(|| i + w),
            ];
            for j in neighbours.into_iter().flatten() {
                if raw[j] && label[j] == u32::MAX {
                    label[j] = id;
                    stack.push(j);
                }
            }
        }
        sizes.push(size);
        central.push(reaches);
    }
    let keep = (0..sizes.len())
        .filter(|&k| central[k])
        .max_by_key(|&k| sizes[k])
        .map(|k| k as u32);
    let kept = label.iter().map(|&l| Some(l) == keep).collect();
    Ok(Image::from_vec(w, h, kept)?)
}

/// Alpha of a track frame: [`foreground`] blurred by [`MATTE_BLUR_SIGMA_PX`].
pub fn alpha(input: &MatteInput, rule: MatteRule) -> Result<GrayImage> {
    let fg = foreground(input, rule)?;
    Ok(gaussian_blur(
        &fg.map(|b| if b { 1.0 } else { 0.0 }),
        MATTE_BLUR_SIGMA_PX,
    ))
}

/// The premultiplied foreground `T − (1 − α) C`, clamped at zero (noise and the
/// actor's shadow, absent from the clean plate, would otherwise go negative), and zero
/// where alpha is zero: a premultiplied colour cannot exceed its coverage, and what
/// `T − C` leaves in the background is sensor noise, which would otherwise cost the
/// image codec most of its bits.
pub fn premultiply(frame: &RgbImage, alpha: &GrayImage, clean: &RgbImage) -> Result<RgbImage> {
    check_same("frame and clean plate", frame, clean)?;
    if !frame.same_size(alpha) {
        return Err(IngestError::sizes("the alpha", frame.size(), alpha.size()));
    }
    let pixels = frame
        .pixels()
        .iter()
        .zip(alpha.pixels())
        .zip(clean.pixels())
        .map(|((f, &a), c)| {
            if a <= 0.0 {
                [0.0; 3]
            } else {
                [0, 1, 2].map(|k| (f[k] - (1.0 - a) * c[k]).max(0.0))
            }
        })
        .collect();
    Ok(Image::from_vec(frame.width(), frame.height(), pixels)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dark disc on a bright background in the matte frame, lit in the track frame,
    /// with a stray bright speck in a corner; and the matte frame's clean plate.
    fn frames() -> (RgbImage, RgbImage, RgbImage) {
        let disc =
            |x: usize, y: usize| (x as f32 - 20.0).powi(2) + (y as f32 - 30.0).powi(2) < 100.0;
        let speck = |x: usize, y: usize| x < 2 && y < 2;
        let track = Image::from_fn(40, 60, |x, y| {
            if disc(x, y) || speck(x, y) {
                [0.5; 3]
            } else {
                [0.05; 3]
            }
        });
        let matte = Image::from_fn(40, 60, |x, y| {
            if disc(x, y) || speck(x, y) {
                [0.01; 3]
            } else {
                [0.7; 3]
            }
        });
        (track, matte, Image::new(40, 60, [0.7; 3]))
    }

    fn input(f: &(RgbImage, RgbImage, RgbImage)) -> MatteInput<'_> {
        MatteInput {
            track: &f.0,
            matte: &f.1,
            matte_clean: &f.2,
        }
    }

    #[test]
    fn keeps_the_central_component_and_blurs_it() {
        let f = frames();
        for rule in [
            MatteRule::TrackBrighterThanMatte,
            MatteRule::MatteBelowHalfCleanPlate,
        ] {
            let fg = foreground(&input(&f), rule).unwrap();
            assert!(fg.get(20, 30));
            assert!(!fg.get(0, 0), "the stray corner speck must go");
            let count = fg.pixels().iter().filter(|&&b| b).count();
            assert!(
                (count as f32 - std::f32::consts::PI * 100.0).abs() < 30.0,
                "{count}"
            );
        }
        let a = alpha(&input(&f), MatteRule::TrackBrighterThanMatte).unwrap();
        assert!((a.get(20, 30) - 1.0).abs() < 1e-4);
        assert!(a.get(0, 0) < 1e-4);
        // The edge is soft: some pixels strictly between 0 and 1.
        assert!(a.pixels().iter().any(|&v| v > 0.2 && v < 0.8));
    }

    #[test]
    fn the_half_clean_plate_rule_finds_the_half_covered_edge() {
        // A vertical edge: column 10 is half covered (matte frame half as bright).
        let track = Image::from_fn(20, 20, |x, _| {
            [if x < 10 {
                0.4
            } else if x == 10 {
                0.2
            } else {
                0.02
            }; 3]
        });
        let matte = Image::from_fn(20, 20, |x, _| {
            [if x < 10 {
                0.0
            } else if x == 10 {
                0.34
            } else {
                0.7
            }; 3]
        });
        let clean = Image::new(20, 20, [0.7f32; 3]);
        let f = (track, matte, clean);
        let half = foreground(&input(&f), MatteRule::MatteBelowHalfCleanPlate).unwrap();
        assert!(half.get(10, 10) && !half.get(11, 10));
        // The paper's rule, with these brightnesses, drops the half-covered column.
        let paper = foreground(&input(&f), MatteRule::TrackBrighterThanMatte).unwrap();
        assert!(!paper.get(10, 10) && paper.get(9, 10));
    }

    #[test]
    fn premultiplied_foreground_removes_the_background() {
        let f = frames();
        let a = alpha(&input(&f), MatteRule::TrackBrighterThanMatte).unwrap();
        let (track, clean) = (&f.0, Image::new(40, 60, [0.05f32; 3]));
        let p = premultiply(track, &a, &clean).unwrap();
        assert!(p.get(39, 59)[0].abs() < 1e-6);
        assert!((p.get(20, 30)[0] - 0.5).abs() < 1e-4);
        assert!(p.pixels().iter().all(|c| c.iter().all(|&v| v >= 0.0)));
    }

    #[test]
    fn nothing_in_the_centre_gives_an_empty_matte_and_sizes_must_agree() {
        let f = (
            Image::new(20, 20, [0.0f32; 3]),
            Image::new(20, 20, [1.0f32; 3]),
            Image::new(20, 20, [1.0f32; 3]),
        );
        for rule in [
            MatteRule::TrackBrighterThanMatte,
            MatteRule::MatteBelowHalfCleanPlate,
        ] {
            assert!(
                foreground(&input(&f), rule)
                    .unwrap()
                    .pixels()
                    .iter()
                    .all(|&b| !b)
            );
        }
        let g = (f.0.clone(), Image::new(21, 20, [1.0f32; 3]), f.2.clone());
        let e = foreground(&input(&g), MatteRule::TrackBrighterThanMatte)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("track and matte frames: expected 20x20, got 21x20"),
            "{e}"
        );
    }
}
