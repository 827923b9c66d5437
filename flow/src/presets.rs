//! Measured presets of [`FlowParams`], from `Fast` to `Accurate`, and the wide-search
//! variant for the larger displacements between horizontal view pairs. The figures
//! each preset reaches, and the peers they were measured against, are in
//! `docs/results/flow.md`.

use crate::params::{ColorMode, FlowParams, Interpolation, TextureFilter};
use crate::penalty::Penalty;

/// A named trade-off between error and run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Preset {
    /// Tens of milliseconds for 640x480: one luminance plane solved up to half resolution.
    Fast,
    /// Colour, full resolution, median filtering, no GNC.
    Balanced,
    /// Classic+NL-style: structure–texture input, GNC, median and weighted median.
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
    /// The parameters of `preset`.
    pub fn preset(preset: Preset) -> Self {
        let base = FlowParams {
            pyramid_ratio: 0.5,
            min_level_px: 16,
            max_displacement_px: 32.0,
            finest_level: 0,
            warps: 3,
            irls_iterations: 2,
            sor_iterations: 10,
            sor_omega: 1.9,
            data_penalty: Penalty::SUN_CHARBONNIER,
            smoothness_penalty: Penalty::SUN_CHARBONNIER,
            lambda: 3.0,
            lambda_quadratic: 300.0,
            gnc_stages: 1,
            gnc_levels: 2,
            median_radius: 2,
            weighted_median_radius: 0,
            color: ColorMode::Color,
            texture: TextureFilter::None,
            gradient_weight: 0.0,
            interpolation: Interpolation::Bicubic,
        };
        match preset {
            Preset::Fast => FlowParams {
                finest_level: 1,
                warps: 2,
                irls_iterations: 2,
                sor_iterations: 8,
                median_radius: 0,
                color: ColorMode::Gray,
                interpolation: Interpolation::Bilinear,
                ..base
            },
            Preset::Balanced => base,
            Preset::Accurate => FlowParams {
                warps: 3,
                irls_iterations: 3,
                gnc_stages: 3,
                texture: TextureFilter::Rof {
                    weight: 0.95,
                    iterations: 100,
                },
                ..base
            },
        }
    }

    /// The same parameters, set up for displacements up to about 20 px at 320x448 (the
    /// horizontal view pairs of the capture): twice the displacement reach and coarser
    /// levels allowed.
    pub fn wide_search(self) -> Self {
        FlowParams {
            max_displacement_px: self.max_displacement_px.max(64.0),
            min_level_px: self.min_level_px.min(8),
            ..self
        }
    }
}
