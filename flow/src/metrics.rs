//! Flow error metrics against ground truth, as the Middlebury benchmark defines them
//! (Baker et al., IJCV 2011): average end-point error (EPE, pixels), average angular
//! error (AAE, degrees, the angle between `(u, v, 1)` and `(u_gt, v_gt, 1)`; Barron et
//! al. 1994) and the fraction of pixels whose end-point error exceeds 1 px. Pixels of
//! unknown ground truth (a component beyond 1e9) are skipped, and so are pixels outside
//! an optional mask.

use frf_core::flo::is_known;
use frf_core::image::{FlowImage, GrayImage};

use crate::error::{FlowError, Result};

/// Errors of an estimated flow field against ground truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowErrors {
    /// Average end-point error, pixels.
    pub epe: f64,
    /// Average angular error, degrees.
    pub aae_deg: f64,
    /// Fraction (0..1) of evaluated pixels with end-point error above 1 px.
    pub fraction_above_1px: f64,
    /// Number of pixels evaluated.
    pub pixels: usize,
}

/// Errors of `estimate` against `truth`, over the pixels whose truth is known and
/// whose `mask` value (if any) is above ½.
pub fn flow_errors(
    estimate: &FlowImage,
    truth: &FlowImage,
    mask: Option<&GrayImage>,
) -> Result<FlowErrors> {
    if !estimate.same_size(truth) {
        return Err(FlowError::SizeMismatch {
            what: "estimated flow",
            expected: truth.size(),
            got: estimate.size(),
        });
    }
    if let Some(m) = mask
        && !m.same_size(truth)
    {
        return Err(FlowError::SizeMismatch {
            what: "mask",
            expected: truth.size(),
            got: m.size(),
        });
    }
    let w = truth.width();
    let (mut epe, mut aae, mut above, mut n) = (0.0f64, 0.0f64, 0usize, 0usize);
    for (i, (e, t)) in estimate.pixels().iter().zip(truth.pixels()).enumerate() {
        if !is_known(*t) || mask.is_some_and(|m| m.pixels()[i] <= 0.5) {
            continue;
        }
        if !(e[0].is_finite() && e[1].is_finite()) {
            return Err(FlowError::NonFinite {
                what: "estimated flow",
                x: i % w,
                y: i / w,
            });
        }
        let (u, v) = (e[0] as f64, e[1] as f64);
        let (ut, vt) = (t[0] as f64, t[1] as f64);
        let d = ((u - ut).powi(2) + (v - vt).powi(2)).sqrt();
        epe += d;
        above += usize::from(d > 1.0);
        let cos =
            (u * ut + v * vt + 1.0) / ((u * u + v * v + 1.0) * (ut * ut + vt * vt + 1.0)).sqrt();
        aae += cos.clamp(-1.0, 1.0).acos().to_degrees();
        n += 1;
    }
    if n == 0 {
        return Err(FlowError::NoValidPixels);
    }
    Ok(FlowErrors {
        epe: epe / n as f64,
        aae_deg: aae / n as f64,
        fraction_above_1px: above as f64 / n as f64,
        pixels: n,
    })
}

/// Average end-point error, pixels (see [`flow_errors`]).
pub fn epe(estimate: &FlowImage, truth: &FlowImage, mask: Option<&GrayImage>) -> Result<f64> {
    flow_errors(estimate, truth, mask).map(|e| e.epe)
}

/// Average angular error, degrees (see [`flow_errors`]).
pub fn aae(estimate: &FlowImage, truth: &FlowImage, mask: Option<&GrayImage>) -> Result<f64> {
    flow_errors(estimate, truth, mask).map(|e| e.aae_deg)
}

/// Fraction of pixels with end-point error above 1 px (see [`flow_errors`]).
pub fn fraction_above_1px(
    estimate: &FlowImage,
    truth: &FlowImage,
    mask: Option<&GrayImage>,
) -> Result<f64> {
    flow_errors(estimate, truth, mask).map(|e| e.fraction_above_1px)
}

#[cfg(test)]
mod tests {
    use super::*;
    use frf_core::flo::UNKNOWN;
    use frf_core::image::Image;

    #[test]
    fn known_values() {
        let truth = Image::new(4, 1, [0.0f32, 0.0]);
        let est = Image::from_vec(
            4,
            1,
            vec![[3.0f32, 4.0], [0.0, 0.0], [0.0, 0.5], [1.0, 0.0]],
        )
        .unwrap();
        let e = flow_errors(&est, &truth, None).unwrap();
        assert!((e.epe - (5.0 + 0.0 + 0.5 + 1.0) / 4.0).abs() < 1e-9);
        assert!(
            (e.fraction_above_1px - 0.25).abs() < 1e-12,
            "exactly 1 px is not above 1 px"
        );
        // Angle between (1, 0, 1) and (0, 0, 1) is 45 degrees.
        let one = Image::new(1, 1, [1.0f32, 0.0]);
        let zero = Image::new(1, 1, [0.0f32, 0.0]);
        assert!((aae(&one, &zero, None).unwrap() - 45.0).abs() < 1e-9);
        assert_eq!(aae(&zero, &zero, None).unwrap(), 0.0);
    }

    #[test]
    fn unknown_truth_and_mask_are_skipped() {
        let truth = Image::from_vec(3, 1, vec![[0.0f32, 0.0], [UNKNOWN, 0.0], [0.0, 0.0]]).unwrap();
        let est = Image::from_vec(3, 1, vec![[1.0f32, 0.0], [100.0, 0.0], [7.0, 0.0]]).unwrap();
        assert_eq!(epe(&est, &truth, None).unwrap(), 4.0);
        let mask = Image::from_vec(3, 1, vec![1.0f32, 1.0, 0.0]).unwrap();
        let e = flow_errors(&est, &truth, Some(&mask)).unwrap();
        assert_eq!((e.epe, e.pixels), (1.0, 1));
        assert!(matches!(
            flow_errors(&est, &truth, Some(&Image::new(3, 1, 0.0))),
            Err(FlowError::NoValidPixels)
        ));
    }

    #[test]
    fn bad_input_is_refused() {
        let truth = Image::new(2, 2, [0.0f32, 0.0]);
        assert!(matches!(
            epe(&Image::new(3, 2, [0.0f32, 0.0]), &truth, None),
            Err(FlowError::SizeMismatch { .. })
        ));
        assert!(matches!(
            epe(&truth, &truth, Some(&Image::new(1, 1, 1.0))),
            Err(FlowError::SizeMismatch { .. })
        ));
        let mut nan = truth.clone();
        nan.set(1, 1, [f32::NAN, 0.0]);
        assert!(matches!(
            epe(&nan, &truth, None),
            Err(FlowError::NonFinite { x: 1, y: 1, .. })
        ));
    }
}
