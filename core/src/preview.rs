//! Animated previews of rendered sequences, for people: an animated PNG (full colour,
//! 8-bit sRGB with alpha, loops) or a GIF (256 colours, loops), written atomically, with
//! frames shrunk by an integer factor to fit a width.

use std::path::Path;

use crate::atomic::write_atomic;
use crate::contact::shrink;
use crate::error::{CoreError, Result};
use crate::image::{Image, Rgba};
use crate::io::srgba8_straight;

/// Shrinks premultiplied RGBA frames by the smallest integer factor that makes them at
/// most `max_width` wide.
pub fn fit_width(frames: &[Image<Rgba>], max_width: usize) -> Vec<Image<Rgba>> {
    frames
        .iter()
        .map(|f| {
            let factor = f.width().div_ceil(max_width.max(1)).max(1);
            let rgb = shrink(&f.map(|p| [p[0], p[1], p[2]]), factor);
            let a = shrink(&f.map(|p| [p[3], 0.0, 0.0]), factor);
            Image::from_fn(rgb.width(), rgb.height(), |x, y| {
                let c = rgb.get(x, y);
                [c[0], c[1], c[2], a.get(x, y)[0]]
            })
        })
        .collect()
}

fn check(frames: &[Image<Rgba>], path: &Path) -> Result<(u32, u32)> {
    let Some(first) = frames.first() else {
        return Err(CoreError::invalid(
            format!("animated preview {}", path.display()),
            "no frame to write",
        ));
    };
    if frames.iter().any(|f| f.size() != first.size()) {
        return Err(CoreError::bad_file(path, "preview frames differ in size"));
    }
    Ok((first.width() as u32, first.height() as u32))
}

/// Writes an animated PNG of `frames` (premultiplied linear RGBA) at `fps`, looping.
pub fn write_apng(path: &Path, frames: &[Image<Rgba>], fps: f32, exposure: f32) -> Result<()> {
    let (w, h) = check(frames, path)?;
    let delay = |fps: f32| -> (u16, u16) {
        // The delay as a fraction of a second: 1000 / (fps x 1000), clamped to u16.
        let den = 1000u16;
        let num = (1000.0 / fps.max(0.01)).round().clamp(1.0, u16::MAX as f32) as u16;
        (num, den)
    };
    write_atomic(path, |out| {
        let err = |e: png::EncodingError| CoreError::bad_file(path, format!("APNG: {e}"));
        let mut encoder = png::Encoder::new(out, w, h);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_animated(frames.len() as u32, 0).map_err(err)?;
        let (num, den) = delay(fps);
        encoder.set_frame_delay(num, den).map_err(err)?;
        let mut writer = encoder.write_header().map_err(err)?;
        for f in frames {
            writer
                .write_image_data(&srgba8_straight(f, exposure))
                .map_err(err)?;
        }
        writer.finish().map_err(err)?;
        Ok(())
    })
}

/// Writes a GIF of `frames` (premultiplied linear RGBA) at `fps`, looping; transparent
/// pixels (alpha below one half) are transparent.
pub fn write_gif(path: &Path, frames: &[Image<Rgba>], fps: f32, exposure: f32) -> Result<()> {
    let (w, h) = check(frames, path)?;
    write_atomic(path, |out| {
        let err = |e: image::ImageError| CoreError::bad_file(path, format!("GIF: {e}"));
        let mut encoder = image::codecs::gif::GifEncoder::new_with_speed(out, 10);
        encoder
            .set_repeat(image::codecs::gif::Repeat::Infinite)
            .map_err(err)?;
        let delay = image::Delay::from_numer_denom_ms(1000, fps.max(0.01).round().max(1.0) as u32);
        for f in frames {
            let buffer = image::RgbaImage::from_raw(w, h, srgba8_straight(f, exposure))
                .ok_or_else(|| CoreError::bad_file(path, "frame size"))?;
            encoder
                .encode_frame(image::Frame::from_parts(buffer, 0, 0, delay))
                .map_err(err)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames() -> Vec<Image<Rgba>> {
        (0..3)
            .map(|k| {
                Image::from_fn(20, 10, |x, _| {
                    [0.1 * k as f32, 0.2, 0.3, if x > 4 { 1.0 } else { 0.0 }]
                })
            })
            .collect()
    }

    #[test]
    fn an_animated_png_holds_every_frame_and_loops() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.png");
        write_apng(&path, &frames(), 12.0, 1.0).unwrap();
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let reader = decoder.read_info().unwrap();
        let actl = reader.info().animation_control().unwrap();
        assert_eq!((actl.num_frames, actl.num_plays), (3, 0));
        assert_eq!((reader.info().width, reader.info().height), (20, 10));
        let e = write_apng(&path, &[], 12.0, 1.0).unwrap_err().to_string();
        assert!(
            e.contains(&path.display().to_string()) && e.contains("no frame"),
            "{e}"
        );
    }

    #[test]
    fn a_gif_is_written_and_frames_fit_a_width() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.gif");
        write_gif(&path, &frames(), 10.0, 1.0).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.starts_with(b"GIF89a"));
        let small = fit_width(&frames(), 10);
        assert_eq!(small[0].size(), (10, 5));
        assert!((small[0].get(4, 0)[3] - 1.0).abs() < 1e-6 && small[0].get(0, 0)[3] == 0.0);
    }
}
