//! Contact sheets, for people: tiles laid out in rows over a dark border, and integer
//! box shrinking to fit them. Used for a capture's previews and a render's frames.

use crate::image::{Image, Rgb, RgbImage};

/// Box-downsamples by an integer factor.
pub fn shrink(img: &RgbImage, factor: usize) -> RgbImage {
    if factor <= 1 {
        return img.clone();
    }
    let (w, h) = (img.width() / factor, img.height() / factor);
    Image::from_fn(w, h, |x, y| {
        let mut acc = [0.0; 3];
        for dy in 0..factor {
            for dx in 0..factor {
                let p = img.get(x * factor + dx, y * factor + dy);
                for c in 0..3 {
                    acc[c] += p[c];
                }
            }
        }
        acc.map(|v| v / (factor * factor) as f32)
    })
}

/// Lays tiles out in rows of `columns`, separated by a 2-pixel gray border.
pub fn sheet(tiles: &[RgbImage], columns: usize) -> RgbImage {
    let border = 2;
    let (tw, th) = tiles.first().map(|t| t.size()).unwrap_or((1, 1));
    let rows = tiles.len().div_ceil(columns.max(1));
    let gray: Rgb = [0.05; 3];
    let mut out = Image::new(
        columns * (tw + border) + border,
        rows * (th + border) + border,
        gray,
    );
    for (i, tile) in tiles.iter().enumerate() {
        let (x0, y0) = (
            border + (i % columns) * (tw + border),
            border + (i / columns) * (th + border),
        );
        for y in 0..th.min(tile.height()) {
            for x in 0..tw.min(tile.width()) {
                out.set(x0 + x, y0 + y, tile.get(x, y));
            }
        }
    }
    out
}
