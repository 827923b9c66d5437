//! Backward warping: `I'(s) = I(s + F(s))`, bilinear, which brings the second image of
//! a flow onto the grid of the first (see [`frf_core::conventions`]). Pixels whose
//! flow is unknown (a component beyond [`frf_core::flo::UNKNOWN_THRESHOLD`] or not
//! finite) become zero and are flagged invalid; samples that fall outside the image
//! follow the chosen [`Border`] and are flagged invalid too.

use frf_core::flo::is_known;
use frf_core::image::{Border, FlowImage, GrayImage, Image, Pixel};
use rayon::prelude::*;

use crate::error::{FlowError, Result};

/// `I'(s) = I(s + F(s))`, bilinear, with `border` outside the image; unknown flow gives
/// zero. `img` and `flow` must have the same size.
pub fn backward_warp<P: Pixel>(
    img: &Image<P>,
    flow: &FlowImage,
    border: Border,
) -> Result<Image<P>> {
    backward_warp_masked(img, flow, border).map(|(warped, _)| warped)
}

/// [`backward_warp`] and a validity mask: 1 where the flow is known and `s + F(s)`
/// lies inside the image's area `[−½, w − ½] × [−½, h − ½]`, else 0.
pub fn backward_warp_masked<P: Pixel>(
    img: &Image<P>,
    flow: &FlowImage,
    border: Border,
) -> Result<(Image<P>, GrayImage)> {
    if !img.same_size(flow) {
        return Err(FlowError::SizeMismatch {
            what: "flow for backward warp",
            expected: img.size(),
            got: flow.size(),
        });
    }
    let (w, h) = img.size();
    let mut out = vec![P::zero(); w * h];
    let mut valid = vec![0.0f32; w * h];
    let (xmax, ymax) = (w as f32 - 0.5, h as f32 - 0.5);
    out.par_chunks_mut(w.max(1))
        .zip(valid.par_chunks_mut(w.max(1)))
        .enumerate()
        .for_each(|(y, (row, vrow))| {
            for x in 0..w {
                let f = flow.get(x, y);
                if !is_known(f) {
                    continue;
                }
                let (sx, sy) = (x as f32 + f[0], y as f32 + f[1]);
                row[x] = img.sample_bilinear(sx, sy, border);
                let inside = (-0.5..=xmax).contains(&sx) && (-0.5..=ymax).contains(&sy);
                vrow[x] = if inside { 1.0 } else { 0.0 };
            }
        });
    let warped = Image::from_vec(w, h, out)?;
    let mask = Image::from_vec(w, h, valid)?;
    Ok((warped, mask))
}

#[cfg(test)]
mod tests {
    use super::*;
    use frf_core::flo::UNKNOWN;

    #[test]
    fn zero_flow_is_identity_and_integer_shift_is_exact() {
        let img = Image::from_fn(6, 4, |x, y| [x as f32, y as f32, 1.0]);
        let same = backward_warp(&img, &Image::new(6, 4, [0.0, 0.0]), Border::Zero).unwrap();
        assert_eq!(same, img);
        let shifted = backward_warp(&img, &Image::new(6, 4, [2.0, 1.0]), Border::Clamp).unwrap();
        assert_eq!(shifted.get(1, 1), [3.0, 2.0, 1.0]);
        let half = backward_warp(&img, &Image::new(6, 4, [0.5, 0.0]), Border::Clamp).unwrap();
        assert!((half.get(2, 0)[0] - 2.5).abs() < 1e-6);
    }

    #[test]
    fn borders_unknown_flow_and_sizes_behave_as_documented() {
        let img = Image::new(3, 3, 2.0f32);
        let mut flow = Image::new(3, 3, [-5.0f32, 0.0]);
        flow.set(1, 1, [UNKNOWN, 0.0]);
        flow.set(2, 2, [0.0, f32::NAN]);
        let (clamped, mask) = backward_warp_masked(&img, &flow, Border::Clamp).unwrap();
        assert_eq!(clamped.get(0, 0), 2.0);
        assert_eq!(mask.get(0, 0), 0.0, "outside is flagged");
        assert_eq!(
            (clamped.get(1, 1), mask.get(1, 1)),
            (0.0, 0.0),
            "unknown flow"
        );
        assert_eq!((clamped.get(2, 2), mask.get(2, 2)), (0.0, 0.0), "NaN flow");
        let zero = backward_warp(&img, &flow, Border::Zero).unwrap();
        assert_eq!(zero.get(0, 0), 0.0);
        let inside = backward_warp_masked(&img, &Image::new(3, 3, [0.4, -0.4]), Border::Zero)
            .unwrap()
            .1;
        assert!(inside.pixels().iter().all(|&v| v == 1.0));
        let err = backward_warp(&img, &Image::new(2, 3, [0.0, 0.0]), Border::Zero).unwrap_err();
        assert!(matches!(
            err,
            FlowError::SizeMismatch {
                expected: (3, 3),
                got: (2, 3),
                ..
            }
        ));
    }
}
