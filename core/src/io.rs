//! Image files: linear 16-bit PNG and EXR in, linear 16-bit PNG, EXR and 8-bit sRGB
//! previews out. Reading enforces [`limits`] before decoding, so a hostile header cannot
//! make the program allocate gigabytes; writing is atomic (see [`crate::atomic`]).
//!
//! Values are returned as stored, scaled to `[0, 1]` for integer formats
//! (`value / 65535` for 16-bit, `value / 255` for 8-bit): no transfer function is undone,
//! because captured frames are linear by convention ([`crate::conventions`]).

use std::path::Path;

use image::codecs::openexr::OpenExrEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{DynamicImage, ImageBuffer, ImageReader};

use crate::atomic::write_atomic;
use crate::error::{CoreError, Result};
use crate::image::{GrayImage, Image, Rgb, RgbImage, Rgba};

/// Limits on what an image file may make the program allocate.
pub mod limits {
    /// Largest width or height accepted (the largest 2D texture of the GPUs we target).
    pub const MAX_DIMENSION: u32 = 16384;
    /// Largest decoded size in bytes (what the decoder itself may reserve).
    pub const MAX_ALLOC_BYTES: u64 = 1 << 30;
    /// Largest image in pixels: 2^26, e.g. 8192 x 8192 or 16384 x 4096. Decoding holds the
    /// decoder's buffer and then linear `f32` RGB (12 bytes a pixel, 768 MiB at this
    /// size) at once; without this bound a 157-byte GIF claiming 8513 x 11308 pixels
    /// (found by fuzzing) made the loader hold more than 2 GiB.
    pub const MAX_PIXELS: u64 = 1 << 26;
}

/// `reader` with the [`limits`] applied.
fn limited<R: std::io::BufRead + std::io::Seek>(mut reader: ImageReader<R>) -> ImageReader<R> {
    let mut lim = image::Limits::default();
    lim.max_image_width = Some(limits::MAX_DIMENSION);
    lim.max_image_height = Some(limits::MAX_DIMENSION);
    lim.max_alloc = Some(limits::MAX_ALLOC_BYTES);
    reader.limits(lim);
    reader
}

fn reader(path: &Path) -> Result<ImageReader<std::io::BufReader<std::fs::File>>> {
    let reader = ImageReader::open(path)
        .map_err(|e| CoreError::io(path, e))?
        .with_guessed_format()
        .map_err(|e| CoreError::io(path, e))?;
    Ok(limited(reader))
}

/// Decodes what `reader` reads, errors naming `path`.
fn decode_with<R: std::io::BufRead + std::io::Seek>(
    path: &Path,
    reader: ImageReader<R>,
) -> Result<DynamicImage> {
    use image::ImageDecoder;
    let failed = |e: image::ImageError| match e {
        image::ImageError::Limits(l) => CoreError::LimitExceeded {
            what: path.display().to_string(),
            problem: l.to_string(),
        },
        image::ImageError::Unsupported(u) => match u.kind() {
            image::error::UnsupportedErrorKind::Format(
                image::error::ImageFormatHint::PathExtension(ext),
            ) => CoreError::bad_file(
                path,
                format!(
                    "not an image: files named .{} are not an image format this reads (an \
                     environment is a .hdr or .exr file)",
                    ext.to_string_lossy()
                ),
            ),
            _ => CoreError::bad_file(path, format!("cannot decode image: {u}")),
        },
        other => CoreError::bad_file(path, format!("cannot decode image: {other}")),
    };
    let decoder = reader.into_decoder().map_err(failed)?;
    let (w, h) = decoder.dimensions();
    if u64::from(w) * u64::from(h) > limits::MAX_PIXELS {
        return Err(CoreError::LimitExceeded {
            what: path.display().to_string(),
            problem: format!(
                "{w}x{h} pixels exceed the limit of {} pixels (resample the image)",
                limits::MAX_PIXELS
            ),
        });
    }
    DynamicImage::from_decoder(decoder).map_err(failed)
}

/// A missing file: the operating system's fault class, as opening it would say.
fn not_found(path: &Path) -> CoreError {
    CoreError::io(
        path,
        std::io::Error::new(std::io::ErrorKind::NotFound, "file not found"),
    )
}

fn decode(path: &Path) -> Result<DynamicImage> {
    if !path.exists() {
        return Err(not_found(path));
    }
    decode_with(path, reader(path)?)
}

/// [`read_rgb`] of the bytes of a file named `name` (the same formats, limits and checks;
/// for decoders fed from memory, such as the fuzz targets).
pub fn read_rgb_bytes(name: &Path, bytes: &[u8]) -> Result<RgbImage> {
    let reader = ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| CoreError::io(name, e))?;
    rgb_checked(name, decode_with(name, limited(reader))?)
}

/// Checks that `path` is a regular file (a directory, a FIFO or a device is refused by
/// name: reading a FIFO would wait for a writer, a device might never end) and returns
/// its size in bytes.
pub fn regular_file(path: &Path) -> Result<u64> {
    let meta = std::fs::metadata(path).map_err(|e| CoreError::io(path, e))?;
    if !meta.is_file() {
        let kind = if meta.is_dir() {
            "a directory"
        } else {
            "not a regular file (a FIFO, a socket or a device)"
        };
        return Err(CoreError::bad_file(path, format!("{kind}: give a file")));
    }
    Ok(meta.len())
}

/// What identifies the content of the regular file at `path`: its size in bytes and the
/// CRC-32 of its bytes (read in blocks: any size).
pub fn content_identity(path: &Path) -> Result<(u64, u32)> {
    use std::io::Read;
    let size = regular_file(path)?;
    let mut file = std::fs::File::open(path).map_err(|e| CoreError::io(path, e))?;
    let mut hasher = crc32fast::Hasher::new();
    let mut block = vec![0u8; 1 << 20];
    loop {
        match file.read(&mut block) {
            Ok(0) => break,
            Ok(n) => hasher.update(&block[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(CoreError::io(path, e)),
        }
    }
    Ok((size, hasher.finalize()))
}

/// Reads the text file at `path`, refusing what is not a regular file
/// ([`regular_file`]) and a file larger than `limit` bytes (a hand-written file is
/// small; a larger one is something else).
pub fn read_text(path: &Path, limit: u64) -> Result<String> {
    let size = regular_file(path)?;
    if size > limit {
        return Err(CoreError::bad_file(
            path,
            format!("{size} bytes, more than the {limit} a file of this kind may have"),
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| CoreError::io(path, e))?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..at].iter().filter(|&&b| b == b'\n').count();
        CoreError::bad_file(
            path,
            format!("line {line} is not UTF-8 text (byte {at} of the file)"),
        )
    })
}

/// Width and height of an image file, read from its header only.
pub fn image_dimensions(path: &Path) -> Result<(usize, usize)> {
    if !path.exists() {
        return Err(not_found(path));
    }
    let (w, h) = reader(path)?
        .into_dimensions()
        .map_err(|e| CoreError::bad_file(path, format!("cannot read image header: {e}")))?;
    Ok((w as usize, h as usize))
}

fn check_finite<P: crate::image::Pixel>(path: &Path, img: &Image<P>) -> Result<()> {
    if let Some(i) = img
        .pixels()
        .iter()
        .position(|p| p.channels().iter().any(|c| !c.is_finite()))
    {
        let (x, y) = (i % img.width(), i / img.width());
        return Err(CoreError::bad_file(
            path,
            format!("pixel ({x}, {y}) is not finite (NaN or infinity)"),
        ));
    }
    Ok(())
}

/// Reads an RGB image (PNG 8/16-bit gray, RGB or RGBA; EXR; Radiance HDR). Alpha is dropped.
/// Non-finite values are refused.
pub fn read_rgb(path: &Path) -> Result<RgbImage> {
    rgb_checked(path, decode(path)?)
}

/// Reads a high-dynamic-range image (Radiance `.hdr`, float or half EXR, 16-bit PNG) as
/// linear RGB; an 8-bit image is refused naming `path`: it is display-encoded and clipped
/// (the sun at 1.0), not radiance.
pub fn read_hdr_rgb(path: &Path) -> Result<RgbImage> {
    let img = decode(path)?;
    use image::ColorType as C;
    if matches!(img.color(), C::L8 | C::La8 | C::Rgb8 | C::Rgba8) {
        return Err(CoreError::bad_file(
            path,
            "an 8-bit image is not a high-dynamic-range environment (display-encoded, \
             clipped at 1): give a .hdr or .exr",
        ));
    }
    rgb_checked(path, img)
}

/// A decoded image as linear RGB, alpha dropped, non-finite values refused naming `path`.
fn rgb_checked(path: &Path, img: DynamicImage) -> Result<RgbImage> {
    let img = img.into_rgb32f();
    let (w, h) = (img.width() as usize, img.height() as usize);
    let pixels = img
        .into_raw()
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let img = Image::from_vec(w, h, pixels)?;
    check_finite(path, &img)?;
    Ok(img)
}

/// Reads a photograph as linear RGB: 8-bit images (PNG, JPEG) are sRGB-encoded and are
/// decoded; 16-bit PNG, EXR and HDR already hold linear values (as everywhere in the
/// project). Non-finite values are refused.
pub fn read_photo(path: &Path) -> Result<RgbImage> {
    let img = decode(path)?;
    let srgb = matches!(
        img.color(),
        image::ColorType::L8
            | image::ColorType::La8
            | image::ColorType::Rgb8
            | image::ColorType::Rgba8
    );
    let (w, h) = (img.width() as usize, img.height() as usize);
    let pixels = img
        .into_rgb32f()
        .into_raw()
        .chunks_exact(3)
        .map(|c| {
            let p = [c[0], c[1], c[2]];
            if srgb { p.map(srgb_to_linear) } else { p }
        })
        .collect();
    let img = Image::from_vec(w, h, pixels)?;
    check_finite(path, &img)?;
    Ok(img)
}

/// Reads an RGBA image (missing alpha reads as 1). Non-finite values are refused.
pub fn read_rgba(path: &Path) -> Result<Image<Rgba>> {
    let img = decode(path)?.into_rgba32f();
    let (w, h) = (img.width() as usize, img.height() as usize);
    let pixels = img
        .into_raw()
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect();
    let img = Image::from_vec(w, h, pixels)?;
    check_finite(path, &img)?;
    Ok(img)
}

/// Reads a one-channel image; colour images are reduced to their Rec. 709 luminance.
pub fn read_gray(path: &Path) -> Result<GrayImage> {
    let rgb = read_rgb(path)?;
    Ok(rgb.map(crate::image::luminance))
}

/// Reads an image and checks that it is `width x height`.
pub fn read_rgb_sized(path: &Path, width: usize, height: usize) -> Result<RgbImage> {
    read_rgb_sized_bits(path, width, height).map(|(img, _)| img)
}

/// [`read_rgb_sized`], with the file's bits per channel (8, 16 or 32), from one decode.
pub fn read_rgb_sized_bits(path: &Path, width: usize, height: usize) -> Result<(RgbImage, u16)> {
    let decoded = decode(path)?;
    let color = decoded.color();
    let bits = color.bits_per_pixel() / u16::from(color.channel_count());
    let img = rgb_checked(path, decoded)?;
    if img.size() != (width, height) {
        return Err(CoreError::SizeMismatch {
            path: path.to_path_buf(),
            expected_width: width,
            expected_height: height,
            got_width: img.width(),
            got_height: img.height(),
        });
    }
    Ok((img, bits))
}

fn to_u16(v: f32) -> u16 {
    (v.clamp(0.0, 1.0) * 65535.0).round() as u16
}

fn to_u8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The sRGB transfer function, encoded to linear (IEC 61966-2-1), as a GPU's `*-srgb`
/// formats apply it.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB transfer function, linear to encoded (IEC 61966-2-1), clamped to [0, 1].
#[inline]
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

fn write_dynamic(path: &Path, image: DynamicImage) -> Result<()> {
    let is_exr = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    write_atomic(path, |w| {
        let result = if is_exr {
            image.write_with_encoder(OpenExrEncoder::new(&mut *w))
        } else {
            image.write_with_encoder(PngEncoder::new_with_quality(
                &mut *w,
                CompressionType::Fast,
                FilterType::Adaptive,
            ))
        };
        result.map_err(|e| CoreError::bad_file(path, format!("cannot encode image: {e}")))
    })
}

/// Wraps raw samples as an `image` buffer of `img`'s size.
fn buffer<Q: image::Pixel, P: Copy>(
    img: &Image<P>,
    raw: Vec<Q::Subpixel>,
) -> Result<ImageBuffer<Q, Vec<Q::Subpixel>>> {
    ImageBuffer::from_raw(img.width() as u32, img.height() as u32, raw)
        .ok_or_else(|| CoreError::invalid("image", "buffer size mismatch"))
}

/// Writes linear RGB as a 16-bit PNG (`value = round(clamp(v) * 65535)`).
pub fn write_png16_rgb(path: &Path, img: &RgbImage) -> Result<()> {
    let raw: Vec<u16> = img.pixels().iter().flatten().map(|&v| to_u16(v)).collect();
    let buf = buffer::<image::Rgb<u16>, _>(img, raw)?;
    write_dynamic(path, DynamicImage::ImageRgb16(buf))
}

/// Writes a one-channel image as a 16-bit gray PNG.
pub fn write_png16_gray(path: &Path, img: &GrayImage) -> Result<()> {
    let raw: Vec<u16> = img.pixels().iter().map(|&v| to_u16(v)).collect();
    let buf = buffer::<image::Luma<u16>, _>(img, raw)?;
    write_dynamic(path, DynamicImage::ImageLuma16(buf))
}

/// Writes a one-channel image as an 8-bit gray PNG (masks, no transfer function).
pub fn write_png8_gray(path: &Path, img: &GrayImage) -> Result<()> {
    let raw: Vec<u8> = img.pixels().iter().map(|&v| to_u8(v)).collect();
    let buf = buffer::<image::Luma<u8>, _>(img, raw)?;
    write_dynamic(path, DynamicImage::ImageLuma8(buf))
}

/// Writes linear RGB as an 8-bit sRGB PNG preview, after multiplying by `exposure`.
pub fn write_png8_srgb(path: &Path, img: &RgbImage, exposure: f32) -> Result<()> {
    let raw: Vec<u8> = img
        .pixels()
        .iter()
        .flatten()
        .map(|&v| to_u8(linear_to_srgb(v * exposure)))
        .collect();
    let buf = buffer::<image::Rgb<u8>, _>(img, raw)?;
    write_dynamic(path, DynamicImage::ImageRgb8(buf))
}

/// 8-bit sRGB with straight alpha (the PNG convention) of premultiplied linear RGBA
/// multiplied by `exposure`: colour is divided by alpha before encoding.
pub fn srgba8_straight(img: &Image<Rgba>, exposure: f32) -> Vec<u8> {
    let mut raw = Vec::with_capacity(img.pixels().len() * 4);
    for p in img.pixels() {
        let a = p[3].clamp(0.0, 1.0);
        let inv = if a > 0.0 { exposure / a } else { 0.0 };
        for c in &p[..3] {
            raw.push(to_u8(linear_to_srgb(c * inv)));
        }
        raw.push(to_u8(a));
    }
    raw
}

/// Writes premultiplied linear RGBA as an 8-bit sRGB PNG with straight alpha
/// ([`srgba8_straight`]).
pub fn write_png8_srgba(path: &Path, img: &Image<Rgba>, exposure: f32) -> Result<()> {
    let raw = srgba8_straight(img, exposure);
    let buf = buffer::<image::Rgba<u8>, _>(img, raw)?;
    write_dynamic(path, DynamicImage::ImageRgba8(buf))
}

/// Writes premultiplied linear RGBA as a float EXR.
pub fn write_exr_rgba(path: &Path, img: &Image<Rgba>) -> Result<()> {
    let raw: Vec<f32> = img.pixels().iter().flatten().copied().collect();
    let buf = buffer::<image::Rgba<f32>, _>(img, raw)?;
    write_dynamic(path, DynamicImage::ImageRgba32F(buf))
}

/// Writes linear RGB as a float EXR.
pub fn write_exr_rgb(path: &Path, img: &RgbImage) -> Result<()> {
    let raw: Vec<f32> = img.pixels().iter().flatten().copied().collect();
    let buf = buffer::<image::Rgb<f32>, _>(img, raw)?;
    write_dynamic(path, DynamicImage::ImageRgb32F(buf))
}

/// Combines colour and alpha into premultiplied RGBA (colour is already premultiplied).
pub fn rgba_from(rgb: &RgbImage, alpha: &GrayImage) -> Result<Image<Rgba>> {
    if !rgb.same_size(alpha) {
        return Err(CoreError::invalid("alpha", "colour and alpha sizes differ"));
    }
    let pixels = rgb
        .pixels()
        .iter()
        .zip(alpha.pixels())
        .map(|(c, &a): (&Rgb, &f32)| [c[0], c[1], c[2], a])
        .collect();
    Image::from_vec(rgb.width(), rgb.height(), pixels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_read_from_bytes_match_the_file_and_keep_the_limits() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let img = Image::from_fn(6, 4, |x, y| [x as f32 / 6.0, y as f32 / 4.0, 0.5]);
        write_png16_rgb(&path, &img).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let from_bytes = read_rgb_bytes(&path, &bytes).unwrap();
        assert_eq!(from_bytes.pixels(), read_rgb(&path).unwrap().pixels());
        // A Radiance header claiming 10^9 x 10^9 pixels is refused by the limits, named.
        let huge = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1000000000 +X 1000000000\n";
        let e = read_rgb_bytes(Path::new("huge.hdr"), huge)
            .unwrap_err()
            .to_string();
        assert!(e.contains("huge.hdr"), "{e}");
        // Half a file is an error naming it, not a panic.
        let e = read_rgb_bytes(&path, &bytes[..bytes.len() / 2]).unwrap_err();
        assert!(e.to_string().contains("a.png"), "{e}");
    }

    /// A file whose name is no image format's (a field given as a map) is named with its
    /// extension in words (it read "The file extension `.\"frf\"` was not recognized").
    #[test]
    fn a_file_of_no_image_format_is_named_plainly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("walk.frf");
        std::fs::write(&path, b"FRF1 not an image").unwrap();
        let e = read_hdr_rgb(&path).unwrap_err().to_string();
        assert!(
            e.contains("walk.frf") && e.contains("files named .frf are not an image format"),
            "{e}"
        );
        assert!(!e.contains('"') && !e.contains('`'), "{e}");
    }

    #[test]
    fn png16_round_trip_is_exact_to_16_bits() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let img = Image::from_fn(7, 5, |x, y| [x as f32 / 7.0, y as f32 / 5.0, 0.25]);
        write_png16_rgb(&path, &img).unwrap();
        let back = read_rgb_sized(&path, 7, 5).unwrap();
        for (a, b) in img.pixels().iter().zip(back.pixels()) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= 0.5 / 65535.0 + 1e-7);
            }
        }
        assert_eq!(image_dimensions(&path).unwrap(), (7, 5));
    }

    #[test]
    fn exr_round_trip_keeps_hdr_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        let img = Image::from_fn(3, 2, |x, y| [x as f32 * 100.0, y as f32, 0.5, 0.75]);
        write_exr_rgba(&path, &img).unwrap();
        let back = read_rgba(&path).unwrap();
        assert_eq!(back.pixels(), img.pixels());
    }

    #[test]
    fn wrong_size_missing_and_garbage_files_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        write_png16_gray(&path, &Image::new(4, 4, 0.5)).unwrap();
        let err = read_rgb_sized(&path, 5, 4).unwrap_err().to_string();
        assert!(
            err.contains("a.png") && err.contains("expected 5x4"),
            "{err}"
        );
        let missing = dir.path().join("missing.png");
        assert!(
            read_rgb(&missing)
                .unwrap_err()
                .to_string()
                .contains("missing.png")
        );
        let garbage = dir.path().join("garbage.png");
        std::fs::write(&garbage, b"\x89PNG\r\n\x1a\nnot really").unwrap();
        assert!(
            read_rgb(&garbage)
                .unwrap_err()
                .to_string()
                .contains("garbage.png")
        );
    }
}
