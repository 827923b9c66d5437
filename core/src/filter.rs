//! Image filters shared by the pipeline: separable Gaussian blur, and filling unknown
//! values from the nearest known one.

use std::collections::VecDeque;

use crate::image::{Image, Pixel};

/// Separable Gaussian blur with standard deviation `sigma` pixels, truncated at 3σ,
/// borders clamped. `sigma <= 0` returns a copy.
pub fn gaussian_blur<P: Pixel>(img: &Image<P>, sigma: f32) -> Image<P> {
    if sigma <= 0.0 || img.pixels().is_empty() {
        return img.clone();
    }
    let radius = (3.0 * sigma).ceil() as i64;
    let weights: Vec<f32> = (-radius..=radius)
        .map(|i| (-(i * i) as f32 / (2.0 * sigma * sigma)).exp())
        .collect();
    let norm: f32 = weights.iter().sum();
    let (w, h) = (img.width() as i64, img.height() as i64);
    let pass = |src: &Image<P>, dx: i64, dy: i64| {
        Image::from_fn(w as usize, h as usize, |x, y| {
            let mut acc = P::zero();
            for (k, wt) in weights.iter().enumerate() {
                let o = k as i64 - radius;
                let xs = (x as i64 + o * dx).clamp(0, w - 1) as usize;
                let ys = (y as i64 + o * dy).clamp(0, h - 1) as usize;
                acc = acc.add_scaled(src.get(xs, ys), wt / norm);
            }
            acc
        })
    };
    pass(&pass(img, 1, 0), 0, 1)
}

/// Gives every value of a `width x height` image for which `known` fails the value of
/// the nearest one for which it holds (breadth first from every known value, 4-connected;
/// ties to the first reached in row order). An image with nothing known is unchanged.
pub fn extend_nearest<T: Copy>(
    values: &mut [T],
    width: usize,
    height: usize,
    known: impl Fn(&T) -> bool,
) {
    debug_assert_eq!(values.len(), width * height);
    let mut done: Vec<bool> = values.iter().map(&known).collect();
    let mut queue: VecDeque<usize> = (0..values.len()).filter(|&i| done[i]).collect();
    while let Some(i) = queue.pop_front() {
        let (x, y) = (i % width, i / width);
        let value = values[i];
        let mut visit = |j: usize| {
            if !done[j] {
                done[j] = true;
                values[j] = value;
                queue.push_back(j);
            }
        };
        if x > 0 {
            visit(i - 1);
        }
        if x + 1 < width {
            visit(i + 1);
        }
        if y > 0 {
            visit(i - width);
        }
        if y + 1 < height {
            visit(i + width);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_keeps_the_mean_and_spreads_a_point() {
        let mut img = Image::new(21, 21, 0.0f32);
        img.set(10, 10, 1.0);
        let b = gaussian_blur(&img, 1.0);
        let sum: f32 = b.pixels().iter().sum();
        assert!((sum - 1.0).abs() < 1e-5);
        // Centre of a unit-σ 2D Gaussian sampled on the grid: about 1 / (2π) = 0.159.
        assert!((b.get(10, 10) - 0.159).abs() < 0.01, "{}", b.get(10, 10));
        assert!((b.get(11, 10) / b.get(10, 10) - (-0.5f32).exp()).abs() < 1e-3);
        assert_eq!(gaussian_blur(&img, 0.0), img);
    }
}
