//! Synthetic test images shared by the integration tests: a band-limited random
//! texture that can be sampled at any sub-pixel position, so translated copies are
//! exact.

#![allow(dead_code)]

use frf_core::image::{FlowImage, GrayImage, Image, RgbImage};

/// A sum of random sinusoids, frequencies up to 0.6 rad/px (well below the 3.14 rad/px
/// Nyquist limit, so bilinear/bicubic sampling of it is accurate).
pub struct Texture {
    waves: Vec<([f32; 2], f32, [f32; 3])>,
}

impl Texture {
    /// A texture from `seed` (deterministic).
    pub fn new(seed: u64) -> Self {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) as f32) / (1u64 << 31) as f32
        };
        let waves = (0..24)
            .map(|_| {
                let angle = next() * std::f32::consts::TAU;
                let freq = 0.05 + 0.55 * next();
                let phase = next() * std::f32::consts::TAU;
                let amp = [next(), next(), next()];
                ([freq * angle.cos(), freq * angle.sin()], phase, amp)
            })
            .collect();
        Self { waves }
    }

    /// The RGB value at `(x, y)`, roughly within [0, 1].
    pub fn rgb(&self, x: f32, y: f32) -> [f32; 3] {
        let mut c = [0.5f32; 3];
        for (k, phase, amp) in &self.waves {
            let s = (k[0] * x + k[1] * y + phase).sin() * 0.04;
            for i in 0..3 {
                c[i] += amp[i] * s;
            }
        }
        c
    }

    /// A `w x h` RGB image of the texture displaced by `-d`, i.e. `I(s) = T(s − d)`.
    pub fn image(&self, w: usize, h: usize, d: [f32; 2]) -> RgbImage {
        Image::from_fn(w, h, |x, y| self.rgb(x as f32 - d[0], y as f32 - d[1]))
    }

    /// The same as one gray plane.
    pub fn gray(&self, w: usize, h: usize, d: [f32; 2]) -> GrayImage {
        self.image(w, h, d).map(|c| (c[0] + c[1] + c[2]) / 3.0)
    }
}

/// Mean end-point error against a constant flow `d`, over pixels at least `margin`
/// from the border (content that enters or leaves the frame has no correspondence).
pub fn epe_constant(flow: &FlowImage, d: [f32; 2], margin: usize) -> f32 {
    let (w, h) = flow.size();
    assert!(
        2 * margin < w.min(h),
        "margin {margin} leaves no pixel of {w}x{h}"
    );
    let mut sum = 0.0;
    let mut n = 0;
    for y in margin..h - margin {
        for x in margin..w - margin {
            let f = flow.get(x, y);
            sum += ((f[0] - d[0]).powi(2) + (f[1] - d[1]).powi(2)).sqrt();
            n += 1;
        }
    }
    sum / n as f32
}
