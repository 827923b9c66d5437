//! Signed logarithmic 8-bit quantization of flow components (docs/design.md section 3.1): fine steps
//! near zero, coarse ones for large displacements, saturating (never wrapping) beyond
//! the largest flow of the data set.
//!
//! With scale `s` and range `M`, a component `x` maps to the code
//! `q = sign(x) · round(127 · ln(1 + |x|/s) / ln(1 + M/s))`, clamped to `±127`, and back
//! to `x' = sign(q) · s · ((1 + M/s)^(|q|/127) − 1)`. Code `−128` means unknown flow.
//! For `|x| ≤ M` the error is at most `(s + |x|) · (e^{k/2} − 1)` with
//! `k = ln(1 + M/s) / 127` ([`LogQuantizer::error_bound`]): a constant relative error
//! for large flow, a constant absolute one (`≈ s·k/2`) near zero.
//!
//! Both parameters are chosen from the data ([`LogQuantizer::fit`]): `M` is the largest
//! known magnitude, and `s` minimizes the mean error bound over the data's magnitudes.

use serde::{Deserialize, Serialize};

use crate::error::Result;

/// The code for unknown flow.
pub const UNKNOWN_CODE: i8 = i8::MIN;
/// The largest code magnitude.
const MAX_CODE: f32 = 127.0;

/// Parameters of the signed logarithmic quantizer.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LogQuantizer {
    /// Scale `s`, pixels: below it steps are nearly uniform.
    pub scale: f32,
    /// Range `M`, pixels: the largest magnitude represented exactly (larger saturates).
    pub range: f32,
}

impl LogQuantizer {
    /// A quantizer, checked: both parameters finite and positive, and their ratio within
    /// `f32` (else the step `ln(1 + M/s) / 127` is infinite or zero, and every code
    /// decodes to infinity, or every value, 0 included, encodes to the extreme code).
    pub fn new(scale: f32, range: f32) -> Result<Self> {
        if !(scale.is_finite() && range.is_finite() && scale > 0.0 && range > 0.0) {
            return Err(frf_core::BadArgument::new(
                "flow quantizer (scale s, range M)",
                format!("s = {scale}, M = {range}"),
                "finite and positive",
            )
            .into());
        }
        let q = Self { scale, range };
        let k = q.k();
        if !(k.is_finite() && k > 0.0) {
            return Err(frf_core::BadArgument::new(
                "flow quantizer M / s",
                range / scale,
                "a ratio f32 can hold (range and scale closer together)",
            )
            .into());
        }
        Ok(q)
    }

    fn k(&self) -> f32 {
        (self.range / self.scale).ln_1p() / MAX_CODE
    }

    /// The code of one component; non-finite values and magnitudes above `1e9` (the
    /// Middlebury unknown marker) give [`UNKNOWN_CODE`].
    #[inline]
    pub fn encode(&self, x: f32) -> i8 {
        if !x.is_finite() || x.abs() > frf_core::flo::UNKNOWN_THRESHOLD {
            return UNKNOWN_CODE;
        }
        let q = ((x.abs() / self.scale).ln_1p() / self.k())
            .round()
            .min(MAX_CODE);
        (q.copysign(x)) as i8
    }

    /// The value of a code; [`UNKNOWN_CODE`] gives [`frf_core::flo::UNKNOWN`].
    #[inline]
    pub fn decode(&self, q: i8) -> f32 {
        if q == UNKNOWN_CODE {
            return frf_core::flo::UNKNOWN;
        }
        let m = self.scale * ((q.unsigned_abs() as f32) * self.k()).exp_m1();
        if q < 0 { -m } else { m }
    }

    /// Largest error `|x − decode(encode(x))|` for `|x| ≤ M`.
    pub fn error_bound(&self, x: f32) -> f32 {
        (self.scale + x.abs()) * (self.k() / 2.0).exp_m1()
    }

    /// Chooses `M` as the largest known magnitude among `values` and `s` to minimize the
    /// mean error bound over them (golden-section search on `ln s`). Returns a default
    /// (`s = 0.25`, `M = 1`) when nothing is known.
    pub fn fit(values: impl Iterator<Item = f32>) -> Self {
        let mut mags: Vec<f32> = values
            .filter(|v| v.is_finite() && v.abs() <= frf_core::flo::UNKNOWN_THRESHOLD)
            .map(f32::abs)
            .collect();
        let range = mags.iter().copied().fold(0.0, f32::max);
        if range <= 0.0 {
            return Self {
                scale: 0.25,
                range: 1.0,
            };
        }
        // A subsample of at most 65 536 magnitudes is plenty to place the minimum.
        if mags.len() > 65_536 {
            let stride = mags.len() / 65_536;
            mags = mags.into_iter().step_by(stride).collect();
        }
        let cost = |log_s: f32| {
            let q = Self {
                scale: log_s.exp(),
                range,
            };
            mags.iter().map(|&m| q.error_bound(m)).sum::<f32>()
        };
        let (mut a, mut b) = ((range * 1e-3).ln(), range.ln());
        let phi = 0.618_034;
        for _ in 0..60 {
            let c = b - phi * (b - a);
            let d = a + phi * (b - a);
            if cost(c) < cost(d) {
                b = d;
            } else {
                a = c;
            }
        }
        Self {
            scale: ((a + b) / 2.0).exp(),
            range,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn error_is_within_the_bound(x in -60.0f32..60.0, s in 0.05f32..5.0, m in 1.0f32..80.0) {
            let q = LogQuantizer::new(s, m).unwrap();
            let back = q.decode(q.encode(x));
            if x.abs() <= m {
                // 1e-5 relative slack for f32 rounding of exp/ln.
                prop_assert!((back - x).abs() <= q.error_bound(x) * 1.0001 + 1e-5,
                    "x {} back {} bound {}", x, back, q.error_bound(x));
            } else {
                // Saturates toward the range, never wraps.
                prop_assert!((back.abs() - m).abs() <= 1e-3 * m && back.signum() == x.signum());
            }
        }

        #[test]
        fn codes_are_monotonic(a in -50.0f32..50.0, b in -50.0f32..50.0) {
            let q = LogQuantizer::new(0.5, 30.0).unwrap();
            if a <= b {
                prop_assert!(q.encode(a) <= q.encode(b));
            }
        }
    }

    #[test]
    fn steps_are_fine_near_zero_and_coarse_far_away() {
        let q = LogQuantizer::new(0.5, 32.0).unwrap();
        let near = q.decode(1) - q.decode(0);
        let far = q.decode(127) - q.decode(126);
        assert!(near < 0.02 && far > 0.5, "{near} {far}");
        assert_eq!(q.encode(f32::NAN), UNKNOWN_CODE);
        assert_eq!(q.encode(1e10), UNKNOWN_CODE);
        assert_eq!(q.decode(UNKNOWN_CODE), frf_core::flo::UNKNOWN);
        assert_eq!(q.encode(0.0), 0);
        let e = LogQuantizer::new(0.0, 1.0).unwrap_err().to_string();
        assert!(
            e.contains("s = 0, M = 1: expected finite and positive"),
            "{e}"
        );
        let e = LogQuantizer::new(1.0, f32::INFINITY)
            .unwrap_err()
            .to_string();
        assert!(e.contains("s = 1, M = inf"), "{e}");
    }

    #[test]
    fn fitted_scale_beats_fixed_choices() {
        // Mostly small flow with a few large displacements.
        let values: Vec<f32> = (0..10_000)
            .map(|i| {
                if i % 100 == 0 {
                    18.0
                } else {
                    (i % 37) as f32 * 0.05 - 0.9
                }
            })
            .collect();
        let fitted = LogQuantizer::fit(values.iter().copied());
        assert_eq!(fitted.range, 18.0);
        let mean_err = |q: &LogQuantizer| {
            values
                .iter()
                .map(|&v| (q.decode(q.encode(v)) - v).abs())
                .sum::<f32>()
                / values.len() as f32
        };
        for s in [0.01, 0.1, 2.0, 10.0] {
            let other = LogQuantizer::new(s, 18.0).unwrap();
            assert!(mean_err(&fitted) <= mean_err(&other) * 1.05, "s = {s}");
        }
    }
}
