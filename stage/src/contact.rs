//! Contact sheets of a capture, for people: the 33 frames of one lighting set, and the
//! reference frame of every view of one pose (the 36x3 grid, lowest camera at the
//! bottom), as 8-bit sRGB PNGs under `preview/`.

use std::path::Path;

use frf_core::capture::Capture;
use frf_core::image::{Image, Rgb, RgbImage};
use frf_core::io::write_png8_srgb;

use crate::error::Result;

/// Widest contact sheet, pixels: tiles are shrunk by an integer factor to fit.
const MAX_SHEET_WIDTH: usize = 2400;

/// Box-downsamples by an integer factor.
fn shrink(img: &RgbImage, factor: usize) -> RgbImage {
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

/// Writes `preview/set.png` and `preview/views.png` for the first pose.
pub fn write_previews(capture: &Capture, dir: &Path) -> Result<()> {
    let pose = capture.poses()[0];
    let camera = capture.cameras().len() / 2;
    let set = (0..capture.slots().len())
        .map(|slot| capture.load_frame(pose, 0, camera, slot))
        .collect::<frf_core::Result<Vec<_>>>()?;
    write_png8_srgb(&dir.join("preview/set.png"), &sheet(&set, 11), 1.0)?;

    let width = capture.cameras()[0].width as usize;
    let factor = (capture.cycles() * width).div_ceil(MAX_SHEET_WIDTH);
    let reference = capture.reference_track().track_slot;
    let mut views = Vec::new();
    for camera in (0..capture.cameras().len()).rev() {
        for cycle in 0..capture.cycles() {
            views.push(shrink(
                &capture.load_frame(pose, cycle, camera, reference)?,
                factor,
            ));
        }
    }
    write_png8_srgb(
        &dir.join("preview/views.png"),
        &sheet(&views, capture.cycles()),
        1.0,
    )?;
    Ok(())
}
