//! The cameras' sensor: photon shot noise and read noise, then 12-bit quantization
//! (the original's Phantom 7.1 raw depth), clipping at full scale. Noise is drawn from
//! the counter-based RNG keyed by the frame and pixel, so it is reproducible.

use frf_core::image::{Image, RgbImage};

use crate::rng::{gaussian, hash};

/// Full-well capacity, electrons at linear 1.0, and read noise, electrons RMS: typical
/// of high-speed CMOS sensors of the original's era (SNR ≈ 50 at mid-gray).
const FULL_WELL_ELECTRONS: f32 = 8000.0;
const READ_NOISE_ELECTRONS: f32 = 10.0;
/// Bits per sample of the raw data.
pub const BITS: u32 = 12;
/// The largest raw code.
pub const MAX_CODE: f32 = ((1u32 << BITS) - 1) as f32;

/// Exposes a linear image: adds noise (if `noise`), quantizes to 12 bits and clips to
/// `[0, 1]`. `key` identifies the frame; `noise_scale` scales the noise (e.g. 1/4 for
/// clean plates averaged over 16 frames).
pub fn expose(linear: &RgbImage, key: u64, noise: bool, noise_scale: f32) -> RgbImage {
    let w = linear.width();
    let pixels = linear
        .pixels()
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let mut out = *p;
            for (c, v) in out.iter_mut().enumerate() {
                let mut x = v.max(0.0);
                if noise {
                    let sigma = (x * FULL_WELL_ELECTRONS + READ_NOISE_ELECTRONS.powi(2)).sqrt()
                        / FULL_WELL_ELECTRONS;
                    x += sigma
                        * noise_scale
                        * gaussian(hash(&[key, (i % w) as u64, (i / w) as u64, c as u64]));
                }
                *v = (x.clamp(0.0, 1.0) * MAX_CODE).round() / MAX_CODE;
            }
            out
        })
        .collect();
    Image::from_vec(linear.width(), linear.height(), pixels).expect("same size as input")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantizes_to_12_bits_and_clips() {
        let img = Image::from_vec(3, 1, vec![[0.5; 3], [2.0; 3], [-1.0; 3]]).unwrap();
        let out = expose(&img, 1, false, 1.0);
        assert_eq!(out.get(1, 0), [1.0; 3]);
        assert_eq!(out.get(2, 0), [0.0; 3]);
        let code = out.get(0, 0)[0] * MAX_CODE;
        assert!((code - code.round()).abs() < 1e-3);
    }

    #[test]
    fn noise_has_the_stated_strength() {
        let img = Image::new(200, 200, [0.25f32; 3]);
        let out = expose(&img, 9, true, 1.0);
        let n = out.pixels().len() as f32;
        let mean = out.pixels().iter().map(|p| p[1]).sum::<f32>() / n;
        let var = out
            .pixels()
            .iter()
            .map(|p| (p[1] - mean).powi(2))
            .sum::<f32>()
            / n;
        let expected = (0.25 * FULL_WELL_ELECTRONS + READ_NOISE_ELECTRONS.powi(2)).sqrt()
            / FULL_WELL_ELECTRONS;
        assert!((mean - 0.25).abs() < 3e-4);
        assert!(
            (var.sqrt() / expected - 1.0).abs() < 0.05,
            "{} vs {expected}",
            var.sqrt()
        );
    }
}
