//! Image-based relighting on the CPU (Debevec et al., SIGGRAPH 2000): the image under a
//! new lighting is the sum of the basis images weighted by the environment's
//! coefficients ([`crate::project`]), in linear light and f32. The GPU twin in `render/`
//! is tested against this one.

use frf_core::image::{Image, Rgb, RgbImage};
use rayon::prelude::*;

use crate::error::{ReflectanceError, Result};

/// `Σ_k coefficients[k] ⊙ basis[k]`; conditions whose coefficient is zero are skipped.
/// Non-finite coefficients, and products or sums that overflow `f32`, are refused.
pub fn relight(basis: &[RgbImage], coefficients: &[Rgb]) -> Result<RgbImage> {
    if basis.len() != coefficients.len() {
        return Err(ReflectanceError::Mismatch {
            what: "relighting coefficients".into(),
            expected: basis.len().to_string(),
            got: coefficients.len().to_string(),
        });
    }
    let Some(first) = basis.first() else {
        return Err(ReflectanceError::Misuse(
            "no basis images to relight".into(),
        ));
    };
    let (w, h) = first.size();
    if let Some(bad) = basis.iter().find(|b| b.size() != (w, h)) {
        return Err(ReflectanceError::Mismatch {
            what: "basis image size".into(),
            expected: format!("{w}x{h}"),
            got: format!("{}x{}", bad.width(), bad.height()),
        });
    }
    if let Some(c) = coefficients
        .iter()
        .find(|c| c.iter().any(|v| !v.is_finite()))
    {
        return Err(ReflectanceError::NonFinite {
            what: format!("coefficient {c:?}"),
        });
    }
    let active: Vec<(&RgbImage, Rgb)> = basis
        .iter()
        .zip(coefficients)
        .filter(|(_, c)| c.iter().any(|&v| v != 0.0))
        .map(|(b, &c)| (b, c))
        .collect();
    let pixels: Vec<Rgb> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let mut out = [0.0f32; 3];
            for (b, c) in &active {
                let p = b.pixels()[i];
                for k in 0..3 {
                    out[k] += c[k] * p[k];
                }
            }
            out
        })
        .collect();
    // Finite inputs can still overflow f32 (huge coefficients on bright texels): refuse
    // rather than return infinities.
    if let Some(i) = pixels.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
        return Err(ReflectanceError::NonFinite {
            what: format!(
                "relit pixel ({}, {}) (it overflows f32: coefficients too large for the basis)",
                i % w,
                i / w
            ),
        });
    }
    Ok(Image::from_vec(w, h, pixels)?)
}
