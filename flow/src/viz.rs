//! Flow visualization with the colour wheel of the Middlebury benchmark (Baker et al.,
//! IJCV 2011): hue gives the direction, saturation the magnitude relative to the
//! largest known flow of the field (or a fixed maximum), white is no motion and unknown
//! flow is black. The wheel runs red → yellow → green → cyan → blue → magenta in 15, 6,
//! 4, 11, 13 and 6 steps (55 colours), the spacing Baker et al. chose to make the hues
//! perceptually even; flow pointing right (+x) is red-magenta, down (+y) is yellow-green
//! ... as in their `flowToColor`.

use std::path::Path;

use frf_core::CoreError;
use frf_core::atomic::write_atomic;
use frf_core::flo::is_known;
use frf_core::image::FlowImage;
use image::ImageEncoder;
use image::codecs::png::PngEncoder;

use crate::error::Result;

/// Steps between the wheel's primaries: RY, YG, GC, CB, BM, MR (Baker et al.).
const SEGMENTS: [usize; 6] = [15, 6, 4, 11, 13, 6];

/// The 55 colours of the wheel, channels in [0, 1].
fn wheel() -> Vec<[f32; 3]> {
    // Each segment ramps one channel up or down between two primaries.
    let primaries: [[f32; 3]; 6] = [
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 1.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
    ];
    let mut colours = Vec::with_capacity(SEGMENTS.iter().sum());
    for (k, &n) in SEGMENTS.iter().enumerate() {
        let (from, to) = (primaries[k], primaries[(k + 1) % 6]);
        for i in 0..n {
            // Baker et al. quantise the ramp to 8 bits: floor(255 i / n) / 255.
            let t = (255 * i / n) as f32 / 255.0;
            colours.push(std::array::from_fn(|c| from[c] + (to[c] - from[c]) * t));
        }
    }
    colours
}

/// The wheel colour (channels in [0, 1]) of a flow vector already divided by the
/// normalising maximum: inside the unit disc saturation grows with the radius, outside
/// it the colour is darkened to 75%.
pub fn wheel_colour(u: f32, v: f32, colours: &[[f32; 3]]) -> [f32; 3] {
    let n = colours.len();
    let radius = (u * u + v * v).sqrt();
    let angle = (-v).atan2(-u) / std::f32::consts::PI;
    let fk = (angle + 1.0) / 2.0 * (n - 1) as f32;
    let k0 = (fk.floor() as usize).min(n - 1);
    let k1 = (k0 + 1) % n;
    let f = fk - k0 as f32;
    std::array::from_fn(|c| {
        let col = (1.0 - f) * colours[k0][c] + f * colours[k1][c];
        if radius <= 1.0 {
            1.0 - radius * (1.0 - col)
        } else {
            col * 0.75
        }
    })
}

/// 8-bit RGB pixels of the visualization, row-major; `max_flow` normalises the
/// magnitude (default: the largest known magnitude of the field, or 1 if it is zero).
pub fn flow_to_rgb8(flow: &FlowImage, max_flow: Option<f32>) -> Vec<[u8; 3]> {
    let max = max_flow
        .filter(|m| m.is_finite() && *m > 0.0)
        .unwrap_or_else(|| {
            let m = flow
                .pixels()
                .iter()
                .filter(|f| is_known(**f))
                .map(|f| (f[0] * f[0] + f[1] * f[1]).sqrt())
                .fold(0.0f32, f32::max);
            if m > 0.0 { m } else { 1.0 }
        });
    let colours = wheel();
    flow.pixels()
        .iter()
        .map(|&f| {
            if !is_known(f) {
                return [0, 0, 0];
            }
            let c = wheel_colour(f[0] / max, f[1] / max, &colours);
            c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
        })
        .collect()
}

/// Writes the visualization of `flow` as an 8-bit RGB PNG, atomically.
pub fn write_flow_png(path: &Path, flow: &FlowImage, max_flow: Option<f32>) -> Result<()> {
    if flow.width() == 0 || flow.height() == 0 {
        return Err(crate::FlowError::EmptyImage {
            what: "flow to visualize",
            width: flow.width(),
            height: flow.height(),
        });
    }
    let bytes: Vec<u8> = flow_to_rgb8(flow, max_flow).into_iter().flatten().collect();
    write_atomic(path, |w| {
        PngEncoder::new(&mut *w)
            .write_image(
                &bytes,
                flow.width() as u32,
                flow.height() as u32,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| CoreError::bad_file(path, format!("cannot encode PNG: {e}")))
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use frf_core::flo::UNKNOWN;
    use frf_core::image::Image;

    #[test]
    fn wheel_has_baker_et_al_colours() {
        let colours = wheel();
        assert_eq!(colours.len(), 55);
        let flow = Image::from_vec(
            6,
            1,
            vec![
                [0.0f32, 0.0],
                [UNKNOWN, 0.0],
                [1.0, 0.0],
                [-1.0, 0.0],
                [0.0, 1.0],
                [0.0, 2.0],
            ],
        )
        .unwrap();
        let px = flow_to_rgb8(&flow, Some(1.0));
        assert_eq!(px[0], [255, 255, 255], "no motion is white");
        assert_eq!(px[1], [0, 0, 0], "unknown is black");
        // Right sits where the wheel closes: the last entry (magenta→red step 5 of 6,
        // blue = 255 − ⌊255·5/6⌋ = 43) or the first (pure red), by the sign of zero.
        assert!(
            px[2] == [255, 0, 43] || px[2] == [255, 0, 0],
            "right is red: {:?}",
            px[2]
        );
        // Left: entry 27, cyan→blue step 2 of 11: green = 255 − ⌊255·2/11⌋ = 209.
        assert_eq!(px[3], [0, 209, 255], "left is cyan");
        // Down: half-way between entries 13 and 14 of red→yellow: green ≈ (221 + 238)/2.
        assert!(
            px[4][0] == 255 && (229..=230).contains(&px[4][1]) && px[4][2] == 0,
            "{:?}",
            px[4]
        );
        let beyond = px[5];
        assert!(
            beyond[0] == 191 && (171..=173).contains(&beyond[1]) && beyond[2] == 0,
            "beyond the maximum: darkened to 75%: {beyond:?}"
        );
        // Normalised by the field's own maximum when none is given.
        let auto = flow_to_rgb8(&flow, None);
        assert_eq!(auto[5], flow_to_rgb8(&flow, Some(2.0))[5]);
    }

    #[test]
    fn png_is_written_and_readable() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("viz.png");
        let flow = Image::from_fn(8, 5, |x, y| [x as f32 - 4.0, y as f32 - 2.0]);
        write_flow_png(&path, &flow, None).unwrap();
        let back = frf_core::io::read_rgb(&path).unwrap();
        assert_eq!(back.size(), (8, 5));
        let empty = Image::<[f32; 2]>::new(0, 0, [0.0, 0.0]);
        let e = write_flow_png(&path, &empty, None).unwrap_err().to_string();
        assert!(e.contains("flow to visualize") && e.contains("0x0"), "{e}");
    }
}
