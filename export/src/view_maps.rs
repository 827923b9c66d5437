//! A view's maps as web images (docs/export.md): the SH transfer as three grey JPEG
//! atlases (red, green, blue; a colour JPEG's chroma subsampling would mix the
//! channels, which are not a colour) or one GPU-compressed KTX2 atlas of the three
//! ([`crate::ktx2`]), each of 3 x 3 tiles with a scale and offset per
//! tile and channel (`value = offset + scale · code`, codes 0–255 linear), alpha as an 8-bit grey PNG, normals (subject frame) as an
//! RGBA PNG (`n = 2 · rgb / 255 − 1`, alpha 0 where none was fitted), albedo as an RGB PNG
//! with a scale per channel, and flows and the subject's motion toward the next and previous
//! pose as 16-bit grey-alpha PNGs ([`crate::format`]).

use std::io::Cursor;

use frf_core::image::{FlowImage, GrayImage, Rgb};
use frf_core::sh::SH_COUNT;
use glam::{Vec2, Vec3};
use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};

use crate::error::{ExportError, Result};
use crate::format::{ATLAS_COLUMNS, FLOW_OFFSET_PX, FLOW_SCALE, MOTION_ZERO};

/// How a view's atlases are stored (`frf export --textures`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AtlasFormat {
    /// One grey JPEG a channel, of this quality (1 to 100).
    Jpeg(u8),
    /// One KTX2 image of UASTC blocks, the channels in R, G and B ([`crate::ktx2`]).
    Ktx2,
}

impl AtlasFormat {
    /// The media type of its images.
    pub fn mime(self) -> &'static str {
        match self {
            AtlasFormat::Jpeg(_) => "image/jpeg",
            AtlasFormat::Ktx2 => "image/ktx2",
        }
    }
}

/// A view's tiles (the SH transfer's nine coefficients, or the basis' images) as atlases
/// and how to read their codes back.
#[derive(Debug, Clone)]
pub struct Atlas {
    /// The images: one grey JPEG per channel encoded, or one KTX2 image of them all.
    pub images: Vec<Vec<u8>>,
    /// Their media type.
    pub mime: &'static str,
    /// Per tile and channel: value per code.
    pub scale: Vec<Rgb>,
    /// Per tile and channel: value of code 0.
    pub offset: Vec<Rgb>,
    /// The codes' error as a reader decodes them, over the texels the view sees.
    pub error: CodeError,
}

/// The error of an atlas' codes as a reader decodes them against the codes encoded,
/// over the texels its view sees (alpha above 0), every tile and channel: a code is a
/// 255th of its tile's range.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct CodeError {
    /// The squared errors' sum, codes².
    pub squared: f64,
    /// Codes compared.
    pub count: u64,
    /// The largest error, codes.
    pub largest: u8,
}

impl CodeError {
    /// Root mean square error, codes.
    pub fn rms(&self) -> f64 {
        (self.squared / self.count.max(1) as f64).sqrt()
    }

    /// Peak signal to noise ratio over the 255 codes, dB (infinite when exact).
    pub fn psnr_db(&self) -> f64 {
        20.0 * (255.0 / self.rms()).log10()
    }

    /// Both errors pooled.
    pub fn add(&mut self, other: &CodeError) {
        self.squared += other.squared;
        self.count += other.count;
        self.largest = self.largest.max(other.largest);
    }
}

fn encoding_error(what: &str, e: image::ImageError) -> ExportError {
    ExportError::Field(format!("encoding {what}: {e}"))
}

/// The atlases of a view's transfer (`w x h` texels, row-major) for its first
/// `channels` channels (3; 1 for the compact tier's grey transfer), [`ATLAS_COLUMNS`]
/// tiles a row ([`tile_atlas`]).
pub fn transfer_atlas(
    transfer: &[[Rgb; SH_COUNT]],
    alpha: &GrayImage,
    format: AtlasFormat,
    channels: usize,
) -> Result<Atlas> {
    let tiles = (SH_COUNT, ATLAS_COLUMNS);
    tile_atlas(|p, i| transfer[p][i], tiles, alpha, format, channels)
}

/// The atlases of `count` tiles of a view (`tile(texel, i)`: tile `i`'s value at texel
/// `texel` of the `w x h` view, row-major), `columns` tiles a row, tile `i` at column
/// `i % columns`, row `i / columns`, for the first `channels` channels; each tile's range
/// taken inside `alpha`, texels outside taking the code of zero. A KTX2 atlas is padded
/// to whole blocks at its right and bottom (code 0).
pub fn tile_atlas(
    tile: impl Fn(usize, usize) -> Rgb,
    (count, columns): (usize, usize),
    alpha: &GrayImage,
    format: AtlasFormat,
    channels: usize,
) -> Result<Atlas> {
    let (w, h) = alpha.size();
    let mut lo = vec![[f32::INFINITY; 3]; count];
    let mut hi = vec![[f32::NEG_INFINITY; 3]; count];
    for (p, &a) in alpha.pixels().iter().enumerate() {
        if a > 0.0 {
            for i in 0..count {
                let t = tile(p, i);
                for c in 0..3 {
                    lo[i][c] = lo[i][c].min(t[c]);
                    hi[i][c] = hi[i][c].max(t[c]);
                }
            }
        }
    }
    let mut scale = vec![[0.0f32; 3]; count];
    let mut offset = vec![[0.0f32; 3]; count];
    for i in 0..count {
        for c in 0..3 {
            if lo[i][c] > hi[i][c] {
                (lo[i][c], hi[i][c]) = (0.0, 0.0);
            }
            offset[i][c] = lo[i][c];
            scale[i][c] = ((hi[i][c] - lo[i][c]) / 255.0).max(f32::MIN_POSITIVE);
        }
    }
    let rows = count.div_ceil(columns);
    let (aw, ah) = (w * columns, h * rows);
    // Each channel's codes, and where the view sees (the texels the error is taken on).
    let channels = channels.clamp(1, 3);
    let mut codes = vec![vec![0u8; aw * ah]; channels];
    let mut seen = vec![false; aw * ah];
    for i in 0..count {
        let (tx, ty) = ((i % columns) * w, (i / columns) * h);
        for y in 0..h {
            for x in 0..w {
                let (p, q) = (y * w + x, (ty + y) * aw + tx + x);
                let t = tile(p, i);
                for (c, out) in codes.iter_mut().enumerate() {
                    let code = (t[c] - offset[i][c]) / scale[i][c];
                    out[q] = code.round().clamp(0.0, 255.0) as u8;
                }
                seen[q] = alpha.pixels()[p] > 0.0;
            }
        }
    }
    let (images, error) = encode_codes(&codes, &seen, (aw, ah), format)?;
    Ok(Atlas {
        images,
        mime: format.mime(),
        scale,
        offset,
        error,
    })
}

/// An atlas' channels (`codes`, each `aw x ah`) encoded as `format`, and the error of what
/// a reader decodes over the texels `seen`.
fn encode_codes(
    codes: &[Vec<u8>],
    seen: &[bool],
    (aw, ah): (usize, usize),
    format: AtlasFormat,
) -> Result<(Vec<Vec<u8>>, CodeError)> {
    let mut error = CodeError::default();
    let mut compare = |codes: &[u8], decoded: &mut dyn Iterator<Item = u8>| {
        for ((&a, b), &s) in codes.iter().zip(decoded).zip(seen) {
            if s {
                let d = a.abs_diff(b);
                error.squared += f64::from(d).powi(2);
                error.count += 1;
                error.largest = error.largest.max(d);
            }
        }
    };
    let images = match format {
        AtlasFormat::Jpeg(quality) => {
            let mut images = Vec::with_capacity(codes.len());
            for channel in codes {
                let mut jpeg = Vec::new();
                JpegEncoder::new_with_quality(&mut jpeg, quality)
                    .write_image(channel, aw as u32, ah as u32, ExtendedColorType::L8)
                    .map_err(|e| encoding_error("an atlas", e))?;
                let decoded = image::load_from_memory(&jpeg)
                    .map_err(|e| encoding_error("an atlas (decoding it back)", e))?
                    .into_luma8();
                compare(channel, &mut decoded.into_raw().into_iter());
                images.push(jpeg);
            }
            images
        }
        AtlasFormat::Ktx2 => {
            // The atlas padded to whole blocks (code 0, as the texels the view does not
            // see: their nearest seen texel's codes instead left the error unchanged, 40.4
            // dB on the tiny field's views, and the file 1 % larger).
            let (pw, ph) = (crate::ktx2::padded(aw), crate::ktx2::padded(ah));
            let mut rgba = vec![0u8; 4 * pw * ph];
            for y in 0..ah {
                for x in 0..aw {
                    let o = 4 * (y * pw + x);
                    for c in 0..3 {
                        rgba[o + c] = codes[c.min(codes.len() - 1)][y * aw + x];
                    }
                    rgba[o + 3] = 255;
                }
            }
            let e = crate::ktx2::encode(&rgba, pw, ph, codes.len() == 1)?;
            for (c, channel) in codes.iter().enumerate() {
                let mut decoded = (0..aw * ah).map(|t| e.decoded[4 * ((t / aw) * pw + t % aw) + c]);
                compare(channel, &mut decoded);
            }
            vec![e.ktx2]
        }
    };
    Ok((images, error))
}

fn png(bytes: &[u8], w: usize, h: usize, kind: ExtendedColorType) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    PngEncoder::new(Cursor::new(&mut out))
        .write_image(bytes, w as u32, h as u32, kind)
        .map_err(|e| encoding_error("a PNG", e))?;
    Ok(out)
}

/// Alpha as an 8-bit grey PNG.
pub fn alpha_png(alpha: &GrayImage) -> Result<Vec<u8>> {
    let (w, h) = alpha.size();
    let codes: Vec<u8> = alpha
        .pixels()
        .iter()
        .map(|a| (a.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    png(&codes, w, h, ExtendedColorType::L8)
}

/// Normals (already in the subject frame) as an RGBA PNG.
pub fn normals_png(normals: &[Option<Vec3>], w: usize, h: usize) -> Result<Vec<u8>> {
    let bytes: Vec<u8> = normals
        .iter()
        .flat_map(|n| match n {
            Some(n) => {
                let c = |v: f32| ((v.clamp(-1.0, 1.0) * 0.5 + 0.5) * 255.0).round() as u8;
                [c(n.x), c(n.y), c(n.z), 255]
            }
            None => [128, 128, 128, 0],
        })
        .collect();
    png(&bytes, w, h, ExtendedColorType::Rgba8)
}

/// Non-negative RGB values (albedo, the compact tier's colour) as an RGB PNG and its
/// scale per channel (`value = scale · code`).
pub fn scaled_rgb_png(albedo: &[Rgb], w: usize, h: usize) -> Result<(Vec<u8>, Rgb)> {
    let mut top = [0.0f32; 3];
    for a in albedo {
        for c in 0..3 {
            top[c] = top[c].max(a[c]);
        }
    }
    let scale = top.map(|t| (t / 255.0).max(f32::MIN_POSITIVE));
    let bytes: Vec<u8> = albedo
        .iter()
        .flat_map(|a| [0, 1, 2].map(|c| (a[c] / scale[c]).round().clamp(0.0, 255.0) as u8))
        .collect();
    Ok((png(&bytes, w, h, ExtendedColorType::Rgb8)?, scale))
}

/// A flow as a 16-bit grey-alpha PNG (`u` in grey, `v` in alpha), and its largest
/// component as a reader decodes it, pixels.
pub fn flow_png(flow: &FlowImage) -> Result<(Vec<u8>, f32)> {
    let (w, h) = flow.size();
    let q = |f: f32| {
        ((f + FLOW_OFFSET_PX) * FLOW_SCALE)
            .round()
            .clamp(0.0, 65535.0) as u16
    };
    let codes: Vec<u16> = flow
        .pixels()
        .iter()
        .flat_map(|f| [q(f[0]), q(f[1])])
        .collect();
    // The largest component a reader decodes (`q / FLOW_SCALE − FLOW_OFFSET_PX`).
    let largest = (codes.iter())
        .map(|&c| (f32::from(c) / FLOW_SCALE - FLOW_OFFSET_PX).abs())
        .fold(0.0f32, f32::max);
    let bytes: Vec<u8> = codes.iter().flat_map(|v| v.to_ne_bytes()).collect();
    Ok((png(&bytes, w, h, ExtendedColorType::La16)?, largest))
}

/// A pose's ground-shadow maps (values 0 to 1, all of one size) as one 8-bit grey PNG,
/// map `m` at rows `m · height` on.
pub fn stacked_maps_png(maps: &[GrayImage]) -> Result<Vec<u8>> {
    let (w, h) = maps.first().map_or((1, 1), |m| m.size());
    let bytes: Vec<u8> = maps
        .iter()
        .flat_map(|m| m.pixels().iter())
        .map(|&a| (a.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    png(&bytes, w, h * maps.len().max(1), ExtendedColorType::L8)
}

/// A view's motion (metres across the axis and up it) as a 16-bit grey-alpha PNG and its
/// metres a code ([`MOTION_ZERO`] is none).
pub fn motion_png(metres: &[Vec2], w: usize, h: usize) -> Result<(Vec<u8>, f32)> {
    let reach = metres
        .iter()
        .map(|m| m.abs().max_element())
        .fold(0.0f32, f32::max);
    let step = (reach / f32::from(MOTION_ZERO - 1)).max(f32::MIN_POSITIVE);
    let zero = f32::from(MOTION_ZERO);
    let q = |m: f32| (m / step + zero).round().clamp(0.0, 65535.0) as u16;
    let bytes: Vec<u8> = metres
        .iter()
        .flat_map(|m| [q(m.x), q(m.y)])
        .flat_map(|v| v.to_ne_bytes())
        .collect();
    Ok((png(&bytes, w, h, ExtendedColorType::La16)?, step))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Motion comes back from its PNG within half a code, signs and all, and a view that
    /// does not move stores its zero exactly.
    #[test]
    fn motion_survives_its_png() {
        let (w, h) = (7, 5);
        let metres: Vec<Vec2> = (0..w * h)
            .map(|i| Vec2::new(0.2 * (i as f32 / 34.0 - 0.5), -0.03 + 0.002 * i as f32))
            .collect();
        let (bytes, step) = motion_png(&metres, w, h).unwrap();
        let img = image::load_from_memory(&bytes).unwrap().into_luma_alpha16();
        assert_eq!(img.dimensions(), (w as u32, h as u32));
        for (m, p) in metres.iter().zip(img.pixels()) {
            let got = Vec2::new(
                (f32::from(p[0]) - f32::from(MOTION_ZERO)) * step,
                (f32::from(p[1]) - f32::from(MOTION_ZERO)) * step,
            );
            assert!(
                (got - *m).abs().max_element() <= 0.5 * step + 1e-9,
                "{m} -> {got}"
            );
        }
        let (bytes, _) = motion_png(&[Vec2::ZERO; 4], 2, 2).unwrap();
        let img = image::load_from_memory(&bytes).unwrap().into_luma_alpha16();
        assert!(
            img.pixels()
                .all(|p| p[0] == MOTION_ZERO && p[1] == MOTION_ZERO)
        );
    }
}
