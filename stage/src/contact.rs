//! Contact sheets of a capture, for people: the 33 frames of one lighting set, and the
//! reference frame of every view of one pose (the 36x3 grid, lowest camera at the
//! bottom), as 8-bit sRGB PNGs under `preview/`.

use std::path::Path;

use frf_core::capture::Capture;
use frf_core::contact::{sheet, shrink};
use frf_core::io::write_png8_srgb;

use crate::error::Result;

/// Widest contact sheet, pixels: tiles are shrunk by an integer factor to fit.
const MAX_SHEET_WIDTH: usize = 2400;

/// Writes `preview/set.png` (the first filmed view's set) and `preview/views.png` for the
/// first pose (views not filmed are black).
pub fn write_previews(capture: &Capture, dir: &Path) -> Result<()> {
    let pose = capture.poses()[0];
    let (w, h) = (
        capture.cameras()[0].width as usize,
        capture.cameras()[0].height as usize,
    );
    let middle = capture.cameras().len() / 2;
    let first = (0..capture.cycles())
        .flat_map(|u| (0..capture.cameras().len()).map(move |v| (u, v)))
        .min_by_key(|&(u, v)| (!capture.is_filmed(pose, u, v), v != middle, u));
    let Some((u0, v0)) = first.filter(|&(u, v)| capture.is_filmed(pose, u, v)) else {
        return Ok(());
    };
    let set = (0..capture.slots().len())
        .map(|slot| capture.load_frame(pose, u0, v0, slot))
        .collect::<frf_core::Result<Vec<_>>>()?;
    write_png8_srgb(&dir.join("preview/set.png"), &sheet(&set, 11), 1.0)?;

    let width = capture.cameras()[0].width as usize;
    let factor = (capture.cycles() * width).div_ceil(MAX_SHEET_WIDTH);
    let reference = capture.reference_track().track_slot;
    let mut views = Vec::new();
    for camera in (0..capture.cameras().len()).rev() {
        for cycle in 0..capture.cycles() {
            let frame = if capture.is_filmed(pose, cycle, camera) {
                capture.load_frame(pose, cycle, camera, reference)?
            } else {
                frf_core::image::Image::new(w, h, [0.0; 3])
            };
            views.push(shrink(&frame, factor));
        }
    }
    write_png8_srgb(
        &dir.join("preview/views.png"),
        &sheet(&views, capture.cycles()),
        1.0,
    )?;
    Ok(())
}
