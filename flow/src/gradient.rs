//! Spatial image derivatives for the linearised data term: the 5-tap central
//! difference `[−1, 8, 0, −8, 1] / 12` (exact for polynomials up to degree 4), the
//! derivative filter of Sun et al.'s Classic methods, with edges clamped.

use frf_core::image::{GrayImage, Image};
use rayon::prelude::*;

/// Taps of `∂/∂x` at offsets −2..=2 (`f'(0) ≈ Σ k_i f(i)`).
const TAPS: [f32; 5] = [1.0 / 12.0, -8.0 / 12.0, 0.0, 8.0 / 12.0, -1.0 / 12.0];

/// `(∂I/∂x, ∂I/∂y)` of a plane.
pub(crate) fn derivatives(img: &GrayImage) -> (GrayImage, GrayImage) {
    let (w, h) = img.size();
    let src = img.pixels();
    let mut dx = vec![0.0f32; w * h];
    let mut dy = vec![0.0f32; w * h];
    dx.par_chunks_mut(w.max(1))
        .zip(dy.par_chunks_mut(w.max(1)))
        .enumerate()
        .for_each(|(y, (rx, ry))| {
            let rows: [&[f32]; 5] = std::array::from_fn(|i| {
                let yi = (y as isize + i as isize - 2).clamp(0, h as isize - 1) as usize;
                &src[yi * w..(yi + 1) * w]
            });
            for x in 0..w {
                let mut gx = 0.0;
                for (i, &k) in TAPS.iter().enumerate() {
                    let xi = (x as isize + i as isize - 2).clamp(0, w as isize - 1) as usize;
                    gx += k * rows[2][xi];
                }
                rx[x] = gx;
                ry[x] = TAPS.iter().zip(rows).map(|(&k, r)| k * r[x]).sum();
            }
        });
    let make = |v| Image::from_vec(w, h, v).unwrap_or_else(|_| Image::new(w, h, 0.0));
    (make(dx), make(dy))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivative_of_a_cubic_is_exact_inside() {
        let f = |x: f32, y: f32| 0.01 * x * x * x - 0.2 * x * y + 0.5 * y * y;
        let img = Image::from_fn(12, 10, |x, y| f(x as f32, y as f32));
        let (dx, dy) = derivatives(&img);
        for y in 2..8 {
            for x in 2..10 {
                let (xf, yf) = (x as f32, y as f32);
                assert!((dx.get(x, y) - (0.03 * xf * xf - 0.2 * yf)).abs() < 1e-3);
                assert!((dy.get(x, y) - (-0.2 * xf + yf)).abs() < 1e-3);
            }
        }
        let (dx, dy) = derivatives(&Image::new(1, 1, 3.0));
        assert_eq!((dx.get(0, 0), dy.get(0, 0)), (0.0, 0.0));
    }
}
