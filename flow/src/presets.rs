//! Measured presets of [`FlowParams`], from `Fast` to `Accurate`, and the wide-search
//! variant for the larger displacements between horizontal view pairs. The figures
//! each preset reaches, and the peers they were measured against, are in
//! `docs/results/flow.md`.

use crate::params::{ColorMode, FlowParams, Interpolation, TextureFilter};
use crate::penalty::Penalty;

/// A named trade-off between error and run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Preset {
    /// About 3x OpenCV's DIS (medium) in time and more accurate: one luminance plane,
    /// solved up to half resolution.
    Fast,
    /// Luminance at full resolution, one warp per level, weighted median.
    Balanced,
    /// Classic+NL-style: colour, three warps per level, structure–texture input, GNC,
    /// median and weighted median.
    Accurate,
}

impl Preset {
    /// Every preset, fastest first.
    pub const ALL: [Preset; 3] = [Preset::Fast, Preset::Balanced, Preset::Accurate];

    /// The preset's lower-case name, as the CLI spells it.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Fast => "fast",
            Preset::Balanced => "balanced",
            Preset::Accurate => "accurate",
        }
    }

    /// The preset called `name` (case-insensitive), if any.
    pub fn from_name(name: &str) -> Option<Preset> {
        Preset::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name))
    }
}

impl FlowParams {
    /// The parameters of `preset`. Every value below was chosen by measuring mean EPE
    /// and instruction counts on the five Middlebury training pairs of
    /// `../shared/data/middlebury_flow` (see `docs/results/flow.md` for the sweeps and
    /// the final figures); the shared starting point is Sun et al.'s Classic+NL:
    /// generalized Charbonnier (a = 0.45, ε = 0.001), pyramid ratio ½, bicubic warping,
    /// 5x5 median, structure–texture input, GNC from a quadratic start.
    pub fn preset(preset: Preset) -> Self {
        let accurate = FlowParams {
            pyramid_ratio: 0.5,
            min_level_px: 16,
            // Middlebury's largest motion is 22 px (Urban2); 32 leaves headroom.
            max_displacement_px: 32.0,
            finest_level: 0,
            // Sun et al. use 3 warps per level; 4 measured 0.003 px better for 30% more time.
            warps: 3,
            irls_iterations: 2,
            // 6 sweeps: +0.003 px; 15: −0.001 px for 10% more time (measured).
            sor_iterations: 10,
            // Measured (balanced): ω = 1.5, 1.7, 1.9, 1.95 give 0.223, 0.216, 0.212, 0.215 px.
            sor_omega: 1.9,
            data_penalty: Penalty::SUN_CHARBONNIER,
            smoothness_penalty: Penalty::SUN_CHARBONNIER,
            // On texture planes normalised to DATA_SCALE: swept 2–36, best at 24.
            lambda: 24.0,
            // Swept 10–1000 for the quadratic stage, best at 30.
            lambda_quadratic: 30.0,
            // Quadratic then robust. Sun et al.'s three stages (with α = ½) measured
            // 0.003 px better for 40% more time.
            gnc_stages: 2,
            // The robust stage re-runs the finest two levels (one: +0.05 px).
            gnc_levels: 2,
            quadratic_to_finest: true,
            // Sun et al.'s 5x5.
            median_radius: 2,
            // Sampled every second pixel: 49 votes (see `weighted_median.rs`).
            weighted_median_radius: 6,
            // Colour: 0.02 px better than luminance here.
            color: ColorMode::Color,
            // θ = 1/8, 0.95 of the structure removed (Wedel et al.; Sun et al.).
            // Measured (balanced): 10, 25, 50, 100 iterations give 0.234, 0.212, 0.211,
            // 0.209 px; no texture filter 0.271, a Gaussian high-pass 0.260.
            texture: TextureFilter::Rof {
                weight: 0.95,
                iterations: 25,
            },
            gradient_weight: 0.0,
            // Bilinear: +0.009 px (measured).
            interpolation: Interpolation::Bicubic,
        };
        match preset {
            Preset::Accurate => accurate,
            // One luminance plane, one warp per level: 0.04 px worse than accurate at
            // about a third of its time.
            Preset::Balanced => FlowParams {
                warps: 1,
                color: ColorMode::Gray,
                ..accurate
            },
            // Solved up to half resolution (a quarter of the pixels) and upsampled; no
            // weighted median. λ and the sweeps re-tuned for the half-resolution planes
            // (λ swept 12–36, λ_q 30–60, sweeps 6–10; Urban2 is the sensitive pair).
            Preset::Fast => FlowParams {
                finest_level: 1,
                warps: 1,
                sor_iterations: 8,
                color: ColorMode::Gray,
                weighted_median_radius: 0,
                lambda: 12.0,
                lambda_quadratic: 60.0,
                ..accurate
            },
        }
    }

    /// The same parameters, set up for displacements up to about 20 px at 320x448 (the
    /// horizontal view pairs of the capture): twice the displacement reach and coarser
    /// levels allowed (8 px on the shorter side instead of 16).
    pub fn wide_search(self) -> Self {
        FlowParams {
            max_displacement_px: self.max_displacement_px.max(64.0),
            min_level_px: self.min_level_px.min(8),
            ..self
        }
    }
}
