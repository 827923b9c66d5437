//! The capture the reflectance tests build fields on: the manifest of the virtual stage's
//! tiny preset (`data/tiny_capture.toml`, as `frf stage --preset tiny` writes it), read
//! without the stage, optionally with fewer columns and smaller images.

#![allow(dead_code)] // each test file uses part of it
#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::capture::Capture;
use frf_core::manifest::Manifest;

/// The tiny preset's capture with `cycles` columns spread evenly over a turn (a ring, as
/// the stage makes it) and images of `width x height` (intrinsics scaled to match).
pub fn tiny_capture(cycles: usize, width: u32, height: u32) -> Capture {
    let mut m: Manifest = toml::from_str(include_str!("../data/tiny_capture.toml")).unwrap();
    let step = 360.0 / cycles as f64;
    m.turntable.azimuth_deg = (0..cycles).map(|i| i as f64 * step).collect();
    m.turntable.degrees_per_cycle = step;
    for c in &mut m.cameras {
        let (sx, sy) = (
            width as f64 / c.width as f64,
            height as f64 / c.height as f64,
        );
        c.fx *= sx;
        c.fy *= sy;
        c.cx = (c.cx + 0.5) * sx - 0.5;
        c.cy = (c.cy + 0.5) * sy - 0.5;
        c.width = width;
        c.height = height;
    }
    Capture::from_manifest(std::path::Path::new("."), m).unwrap()
}
