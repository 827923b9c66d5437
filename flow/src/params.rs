//! The estimator's parameters, [`FlowParams`], and their validation. Every field says
//! what it controls; [`crate::presets`] holds the measured presets built from them.

use crate::error::{FlowError, Result};
use crate::penalty::Penalty;

/// Which image channels the data term compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColorMode {
    /// One channel: Rec. 709 luminance of 3-channel images, the channel mean of others.
    Gray,
    /// Every channel of the input, each with its own robust data term.
    Color,
}

/// How the input is filtered before matching, to make the data term insensitive to
/// shading and brightness changes (see `texture.rs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TextureFilter {
    /// Match the normalised intensities themselves.
    None,
    /// Structure–texture decomposition (Wedel et al. 2009, used by Sun et al. 2010):
    /// match `I − weight · ROF(I)`, the total-variation (ROF) denoised image being the
    /// "structure".
    Rof {
        /// Fraction of the structure removed (0.95 in Sun et al.).
        weight: f32,
        /// Iterations of Chambolle's projection algorithm (100 in Sun et al.).
        iterations: usize,
    },
    /// A cheap stand-in: match `I − weight · G_σ ∗ I`, a Gaussian high-pass.
    Gaussian {
        /// Fraction of the low-pass removed.
        weight: f32,
        /// Standard deviation of the Gaussian, in pixels of the finest solved level.
        sigma: f32,
    },
}

/// How the second image and its derivatives are sampled at `s + F(s)` when warping.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// 2x2 bilinear.
    Bilinear,
    /// 4x4 Keys cubic convolution (a = −0.5), as MATLAB's `interp2(..., 'cubic')`
    /// that Sun et al. found better than bilinear.
    Bicubic,
}

/// Parameters of [`crate::estimate_flow`]. Start from [`FlowParams::preset`]; the
/// fields are public so that sweeps can vary one knob at a time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowParams {
    /// Size ratio between successive pyramid levels, in (0.3, 0.95).
    pub pyramid_ratio: f32,
    /// The coarsest level keeps at least this many pixels on its shorter side (≥ 2).
    pub min_level_px: usize,
    /// The largest displacement expected, in pixels at full resolution: the pyramid
    /// gets enough levels to shrink it to about one pixel at the coarsest level (the
    /// reach of one linearisation), within the limit of `min_level_px`.
    pub max_displacement_px: f32,
    /// The finest level solved (0 = full resolution); the flow of a coarser finest
    /// level is upsampled bilinearly to full resolution.
    pub finest_level: usize,
    /// Warps (re-linearisations) per pyramid level.
    pub warps: usize,
    /// IRLS re-weightings per warp.
    pub irls_iterations: usize,
    /// SOR sweeps per IRLS re-weighting.
    pub sor_iterations: usize,
    /// SOR relaxation factor ω, in (0, 2).
    pub sor_omega: f32,
    /// Penalty of the brightness (texture) constancy residual.
    pub data_penalty: Penalty,
    /// Penalty of the flow differences between 4-neighbours, per component.
    pub smoothness_penalty: Penalty,
    /// Weight λ of the smoothness term against the data term (robust stages).
    pub lambda: f32,
    /// Weight of the smoothness term in the quadratic (first) GNC stage.
    pub lambda_quadratic: f32,
    /// Graduated non-convexity stages: 1 = robust only; 2 = quadratic, robust;
    /// 3 = quadratic, half-way blend, robust.
    pub gnc_stages: usize,
    /// Finest pyramid levels re-run by GNC stages after the first (which runs them all).
    pub gnc_levels: usize,
    /// Whether the quadratic GNC stage runs down to the finest level (Sun et al.) or
    /// stops where the robust stages take over (cheaper).
    pub quadratic_to_finest: bool,
    /// Radius of the median filter applied to the flow after every warp (0: off,
    /// 2: Sun et al.'s 5x5).
    pub median_radius: usize,
    /// Radius of the edge-aware weighted median applied near motion boundaries after
    /// every warp at the finest levels (0: off); Classic+NL's non-local term.
    pub weighted_median_radius: usize,
    /// Which channels are matched.
    pub color: ColorMode,
    /// Input filtering before matching.
    pub texture: TextureFilter,
    /// Weight of two extra gradient-constancy channels (`∂I/∂x`, `∂I/∂y` of the
    /// filtered luminance; Brox et al. 2004); 0 = off.
    pub gradient_weight: f32,
    /// Sampling of the second image when warping.
    pub interpolation: Interpolation,
}

/// Bounds a caller may not leave: beyond them the estimator would allocate or loop
/// absurdly, or the solver would diverge.
pub(crate) mod limits {
    /// Most warps, IRLS or SOR iterations per level (an order of magnitude above the
    /// largest preset).
    pub const MAX_ITERATIONS: usize = 1000;
    /// Largest median radius (a 41x41 window).
    pub const MAX_MEDIAN_RADIUS: usize = 20;
    /// Largest displacement the pyramid is asked to reach, in pixels.
    pub const MAX_DISPLACEMENT_PX: f32 = 4096.0;
    /// Most ROF iterations.
    pub const MAX_ROF_ITERATIONS: usize = 10_000;
}

impl FlowParams {
    /// Checks every field; returns the first one out of range.
    pub fn validate(&self) -> Result<()> {
        use limits::*;
        let finite_pos = |v: f32| v.is_finite() && v > 0.0;
        if !(self.pyramid_ratio > 0.3 && self.pyramid_ratio < 0.95) {
            return Err(FlowError::parameter(
                "pyramid_ratio",
                self.pyramid_ratio,
                "between 0.3 and 0.95",
            ));
        }
        if self.min_level_px < 2 {
            return Err(FlowError::parameter(
                "min_level_px",
                self.min_level_px,
                "at least 2",
            ));
        }
        if !(finite_pos(self.max_displacement_px)
            && self.max_displacement_px <= MAX_DISPLACEMENT_PX)
        {
            return Err(FlowError::parameter(
                "max_displacement_px",
                self.max_displacement_px,
                "positive and at most 4096",
            ));
        }
        if self.finest_level > 8 {
            return Err(FlowError::parameter(
                "finest_level",
                self.finest_level,
                "0 to 8",
            ));
        }
        for (name, v) in [
            ("warps", self.warps),
            ("irls_iterations", self.irls_iterations),
            ("sor_iterations", self.sor_iterations),
        ] {
            if v == 0 || v > MAX_ITERATIONS {
                return Err(FlowError::parameter(name, v, "1 to 1000"));
            }
        }
        if !(self.sor_omega > 0.0 && self.sor_omega < 2.0) {
            return Err(FlowError::parameter(
                "sor_omega",
                self.sor_omega,
                "in (0, 2)",
            ));
        }
        if !self.data_penalty.is_valid() {
            return Err(FlowError::parameter(
                "data_penalty",
                format!("{:?}", self.data_penalty),
                "finite positive scale, exponent in (0, 1]",
            ));
        }
        if !self.smoothness_penalty.is_valid() {
            return Err(FlowError::parameter(
                "smoothness_penalty",
                format!("{:?}", self.smoothness_penalty),
                "finite positive scale, exponent in (0, 1]",
            ));
        }
        if !finite_pos(self.lambda) {
            return Err(FlowError::parameter(
                "lambda",
                self.lambda,
                "finite and positive",
            ));
        }
        if !finite_pos(self.lambda_quadratic) {
            return Err(FlowError::parameter(
                "lambda_quadratic",
                self.lambda_quadratic,
                "finite and positive",
            ));
        }
        if !(1..=3).contains(&self.gnc_stages) {
            return Err(FlowError::parameter(
                "gnc_stages",
                self.gnc_stages,
                "1, 2 or 3",
            ));
        }
        if self.gnc_levels == 0 {
            return Err(FlowError::parameter(
                "gnc_levels",
                self.gnc_levels,
                "at least 1",
            ));
        }
        if self.median_radius > MAX_MEDIAN_RADIUS {
            return Err(FlowError::parameter(
                "median_radius",
                self.median_radius,
                "0 to 20",
            ));
        }
        if self.weighted_median_radius > MAX_MEDIAN_RADIUS {
            return Err(FlowError::parameter(
                "weighted_median_radius",
                self.weighted_median_radius,
                "0 to 20",
            ));
        }
        if !(self.gradient_weight.is_finite() && self.gradient_weight >= 0.0) {
            return Err(FlowError::parameter(
                "gradient_weight",
                self.gradient_weight,
                "finite and non-negative",
            ));
        }
        match self.texture {
            TextureFilter::None => {}
            TextureFilter::Rof { weight, iterations } => {
                if !(0.0..=1.0).contains(&weight) {
                    return Err(FlowError::parameter("texture.weight", weight, "in [0, 1]"));
                }
                if iterations == 0 || iterations > MAX_ROF_ITERATIONS {
                    return Err(FlowError::parameter(
                        "texture.iterations",
                        iterations,
                        "1 to 10000",
                    ));
                }
            }
            TextureFilter::Gaussian { weight, sigma } => {
                if !(0.0..=1.0).contains(&weight) {
                    return Err(FlowError::parameter("texture.weight", weight, "in [0, 1]"));
                }
                if !(finite_pos(sigma) && sigma <= 100.0) {
                    return Err(FlowError::parameter("texture.sigma", sigma, "in (0, 100]"));
                }
            }
        }
        Ok(())
    }
}

impl FlowParams {
    /// These parameters with one field replaced, by name and textual value, for
    /// command-line sweeps (`frf flow-bench --set lambda=5`). Values: numbers; `gray`
    /// or `color`; `bilinear` or `bicubic`; `none`, `rof:WEIGHT:ITERATIONS` or
    /// `gaussian:WEIGHT:SIGMA` for `texture`; `quadratic`, `lorentzian:SIGMA` or
    /// `charbonnier:EPSILON:EXPONENT` for the penalties. The result is validated.
    pub fn with_setting(mut self, key: &str, value: &str) -> Result<Self> {
        let bad = |expected: &'static str| FlowError::InvalidParameter {
            name: "setting",
            value: format!("{key}={value}"),
            expected,
        };
        let num = |v: &str| v.trim().parse::<f32>().map_err(|_| bad("a number"));
        let int = |v: &str| v.trim().parse::<usize>().map_err(|_| bad("a whole number"));
        let parts: Vec<&str> = value.split(':').collect();
        let penalty = |parts: &[&str]| -> Result<Penalty> {
            match parts {
                ["quadratic"] => Ok(Penalty::Quadratic),
                ["lorentzian", s] => Ok(Penalty::Lorentzian { sigma: num(s)? }),
                ["charbonnier", e, a] => Ok(Penalty::Charbonnier {
                    epsilon: num(e)?,
                    exponent: num(a)?,
                }),
                _ => Err(bad(
                    "quadratic, lorentzian:SIGMA or charbonnier:EPSILON:EXPONENT",
                )),
            }
        };
        match key {
            "pyramid_ratio" => self.pyramid_ratio = num(value)?,
            "min_level_px" => self.min_level_px = int(value)?,
            "max_displacement_px" => self.max_displacement_px = num(value)?,
            "finest_level" => self.finest_level = int(value)?,
            "warps" => self.warps = int(value)?,
            "irls_iterations" => self.irls_iterations = int(value)?,
            "sor_iterations" => self.sor_iterations = int(value)?,
            "sor_omega" => self.sor_omega = num(value)?,
            "lambda" => self.lambda = num(value)?,
            "lambda_quadratic" => self.lambda_quadratic = num(value)?,
            "gnc_stages" => self.gnc_stages = int(value)?,
            "gnc_levels" => self.gnc_levels = int(value)?,
            "quadratic_to_finest" => {
                self.quadratic_to_finest = value.parse().map_err(|_| bad("true or false"))?
            }
            "median_radius" => self.median_radius = int(value)?,
            "weighted_median_radius" => self.weighted_median_radius = int(value)?,
            "gradient_weight" => self.gradient_weight = num(value)?,
            "data_penalty" => self.data_penalty = penalty(&parts)?,
            "smoothness_penalty" => self.smoothness_penalty = penalty(&parts)?,
            "color" => {
                self.color = match value {
                    "gray" => ColorMode::Gray,
                    "color" => ColorMode::Color,
                    _ => return Err(bad("gray or color")),
                }
            }
            "interpolation" => {
                self.interpolation = match value {
                    "bilinear" => Interpolation::Bilinear,
                    "bicubic" => Interpolation::Bicubic,
                    _ => return Err(bad("bilinear or bicubic")),
                }
            }
            "texture" => {
                self.texture = match parts.as_slice() {
                    ["none"] => TextureFilter::None,
                    ["rof", w, n] => TextureFilter::Rof {
                        weight: num(w)?,
                        iterations: int(n)?,
                    },
                    ["gaussian", w, s] => TextureFilter::Gaussian {
                        weight: num(w)?,
                        sigma: num(s)?,
                    },
                    _ => return Err(bad("none, rof:WEIGHT:ITERATIONS or gaussian:WEIGHT:SIGMA")),
                }
            }
            _ => return Err(bad("a field of FlowParams")),
        }
        self.validate()?;
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::Preset;

    #[test]
    fn settings_parse_and_absurd_values_are_refused() {
        let p = FlowParams::preset(Preset::Balanced);
        let q = p
            .with_setting("lambda", "5")
            .and_then(|q| q.with_setting("texture", "rof:0.9:50"))
            .and_then(|q| q.with_setting("data_penalty", "lorentzian:2"))
            .unwrap();
        assert_eq!(q.lambda, 5.0);
        assert_eq!(
            q.texture,
            TextureFilter::Rof {
                weight: 0.9,
                iterations: 50
            }
        );
        assert_eq!(q.data_penalty, Penalty::Lorentzian { sigma: 2.0 });
        for (k, v) in [
            ("lambda", "-1"),
            ("lambda", "nan"),
            ("pyramid_ratio", "1.5"),
            ("warps", "0"),
            ("sor_omega", "2.5"),
            ("median_radius", "1000"),
            ("max_displacement_px", "inf"),
            ("texture", "rof:2:10"),
            ("data_penalty", "charbonnier:0:0.5"),
            ("no_such_field", "1"),
            ("warps", "many"),
        ] {
            assert!(
                matches!(
                    p.with_setting(k, v),
                    Err(FlowError::InvalidParameter { .. })
                ),
                "{k}={v} accepted"
            );
        }
    }
}
