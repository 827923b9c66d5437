//! Reading an export back (what a player does, in Rust: the reference for loaders and
//! the tests' round trip): the GLB's chunks checked, the extension's version checked and
//! its object parsed into the types the writer wrote it from ([`crate::model`]), a view's
//! transfer decoded and relit by an L2 light.

use std::path::{Path, PathBuf};

use frf_core::image::{Image, Rgb, RgbImage};
use frf_core::sh::{SH_COUNT, ShLight};
use serde_json::Value;

use crate::error::{ExportError, Result};
use crate::format::{ATLAS_COLUMNS, EXTENSION, VERSION};
use crate::model::{Extension, ViewRecord};

/// An export, read.
#[derive(Debug)]
pub struct Export {
    path: PathBuf,
    /// The glTF document.
    pub document: Value,
    extension: Extension,
    bin: Vec<u8>,
}

impl Export {
    /// Reads and checks `path`: a GLB 2.0 of a JSON and a binary chunk, whole, holding the
    /// extension at a version this reader knows.
    pub fn open(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| frf_core::CoreError::io(path, e))?;
        Self::from_bytes(path, &bytes)
    }

    /// [`Export::open`] of bytes read already.
    pub fn from_bytes(path: &Path, bytes: &[u8]) -> Result<Self> {
        let bad = |problem: String| ExportError::BadFile {
            file: path.to_path_buf(),
            problem,
        };
        let (document, bin) = crate::glb::unpack(bytes).map_err(bad)?;
        let bin = bin.to_vec();
        let ext = &document["extensions"][EXTENSION];
        if ext.is_null() {
            return Err(bad(format!(
                "it holds no {EXTENSION}: a glTF file, but not a walker exported by frf"
            )));
        }
        if ext["version"].as_u64() != Some(VERSION as u64) {
            return Err(bad(format!(
                "{EXTENSION} version {}; this reader knows version {VERSION}",
                ext["version"]
            )));
        }
        let extension: Extension = serde_json::from_value(ext.clone())
            .map_err(|e| bad(format!("its {EXTENSION} does not hold what it must: {e}")))?;
        Ok(Self {
            path: path.to_path_buf(),
            document,
            extension,
            bin,
        })
    }

    /// The extension's object.
    pub fn field(&self) -> &Extension {
        &self.extension
    }

    fn bad(&self, problem: String) -> ExportError {
        ExportError::BadFile {
            file: self.path.clone(),
            problem,
        }
    }

    /// The bytes of image `index`.
    pub fn image_bytes(&self, index: usize) -> Result<&[u8]> {
        let image = &self.document["images"][index];
        let view = &self.document["bufferViews"]
            [image["bufferView"].as_u64().unwrap_or(u64::MAX) as usize];
        let (start, len) = (
            view["byteOffset"].as_u64().unwrap_or(0) as usize,
            view["byteLength"].as_u64().unwrap_or(0) as usize,
        );
        self.bin
            .get(start..start + len)
            .ok_or_else(|| self.bad(format!("image {index} lies outside the binary chunk")))
    }

    /// The view `(u, v)` of `pose`'s record.
    pub fn view(&self, pose: u32, u: usize, v: usize) -> Result<&ViewRecord> {
        let p = (self.extension.poses.iter())
            .find(|p| p.pose == pose)
            .ok_or_else(|| self.bad(format!("pose {pose} is not in the export")))?;
        (p.views.iter())
            .find(|x| x.u == u && x.v == v)
            .ok_or_else(|| self.bad(format!("view {u},{v} of pose {pose} is not in the export")))
    }

    /// A view's transfer, decoded: per texel, nine RGB coefficients.
    pub fn transfer(&self, pose: u32, u: usize, v: usize) -> Result<Image<[Rgb; SH_COUNT]>> {
        let view = self.view(pose, u, v)?;
        let t = &view.transfer;
        let images = t.images.len();
        if images != 3 && images != 1 {
            return Err(self.bad(format!(
                "view {u},{v} has {images} transfer atlases, expected 3 or 1"
            )));
        }
        // Three grey atlases, one KTX2 of the three, or one of either (the compact tier).
        let channels = match t.colour {
            Some(_) => 1,
            None => 3,
        };
        let rows = SH_COUNT.div_ceil(ATLAS_COLUMNS) as u32;
        let grid = self.extension.grid;
        let tiles = (ATLAS_COLUMNS as u32 * grid.width, rows * grid.height);
        let atlas = self.grey_atlases(
            &t.images,
            (channels, tiles),
            &format!("transfer atlas of view {u},{v}"),
        )?;
        // The compact tier: one grey atlas and a colour per texel.
        let colour = match (&t.colour, atlas.len()) {
            (Some(c), 1) => {
                let png = image::load_from_memory(self.image_bytes(c.image)?)
                    .map_err(|e| self.bad(format!("the transfer colour of view {u},{v}: {e}")))?
                    .to_rgb8();
                Some((png, c.scale))
            }
            (None, 1) => {
                return Err(self.bad(format!("view {u},{v} has one transfer atlas and no colour")));
            }
            _ => None,
        };
        let (scale, offset) = (t.scale, t.offset);
        let (w, h) = (
            atlas[0].width() / ATLAS_COLUMNS as u32,
            atlas[0].height() / rows,
        );
        Ok(Image::from_fn(w as usize, h as usize, |x, y| {
            std::array::from_fn(|i| {
                let (ax, ay) = (
                    (i % ATLAS_COLUMNS) as u32 * w + x as u32,
                    (i / ATLAS_COLUMNS) as u32 * h + y as u32,
                );
                let code = |c: usize| atlas[c.min(atlas.len() - 1)].get_pixel(ax, ay)[0] as f32;
                match &colour {
                    None => std::array::from_fn(|c| offset[i][c] + scale[i][c] * code(c)),
                    Some((png, s)) => {
                        let grey = offset[i][0] + scale[i][0] * code(0);
                        let p = png.get_pixel(x as u32, y as u32);
                        std::array::from_fn(|c| grey * s[c] * p[c] as f32)
                    }
                }
            })
        }))
    }

    /// Whether image `index` is a KTX2 image (its channels in R, G and B).
    fn is_ktx2(&self, index: usize) -> bool {
        self.document["images"][index]["mimeType"] == "image/ktx2"
    }

    /// Grey atlases `images` decoded, checked to be of one size (`what` names them): grey
    /// JPEGs, or one KTX2 image's R, G and B (its first `channels`; cropped to
    /// `tiles_size`, the atlas before its padding to whole blocks).
    fn grey_atlases(
        &self,
        images: &[usize],
        (channels, tiles_size): (usize, (u32, u32)),
        what: &str,
    ) -> Result<Vec<image::GrayImage>> {
        if let [index] = images
            && self.is_ktx2(*index)
        {
            let (w, h, rgba) = crate::ktx2::read(self.image_bytes(*index)?)
                .map_err(|e| self.bad(format!("the {what}: {e}")))?;
            let (tw, th) = tiles_size;
            if (w as u32) < tw || (h as u32) < th {
                return Err(self.bad(format!(
                    "the {what} is {w}x{h}, smaller than its tiles' {tw}x{th}"
                )));
            }
            return Ok((0..channels)
                .map(|c| {
                    image::GrayImage::from_fn(tw, th, |x, y| {
                        image::Luma([rgba[4 * (y as usize * w + x as usize) + c]])
                    })
                })
                .collect());
        }
        let atlas = (images.iter().enumerate())
            .map(|(c, &index)| {
                image::load_from_memory(self.image_bytes(index)?)
                    .map(|i| i.to_luma8())
                    .map_err(|e| self.bad(format!("the {what} {c}: {e}")))
            })
            .collect::<Result<Vec<_>>>()?;
        if atlas
            .iter()
            .any(|a| a.dimensions() != atlas[0].dimensions())
        {
            return Err(self.bad(format!("the {what}es differ in size")));
        }
        Ok(atlas)
    }

    /// A view's basis images (`frf export --basis`), decoded: one RGB image per condition.
    pub fn basis(&self, pose: u32, u: usize, v: usize) -> Result<Vec<RgbImage>> {
        let view = self.view(pose, u, v)?;
        let (Some(basis), Some(b)) = (&self.extension.basis, &view.basis) else {
            return Err(self.bad(format!(
                "view {u},{v} of pose {pose} holds no basis images (export with --basis)"
            )));
        };
        let count = basis.conditions.len();
        let atlases = match b.images.as_slice() {
            [one] if self.is_ktx2(*one) => 1,
            _ => 3,
        };
        if b.images.len() != atlases || b.scale.len() != count || b.offset.len() != count {
            return Err(self.bad(format!(
                "view {u},{v}'s basis: {} atlases and {} scales for {count} conditions, expected 3 (or one KTX2) and {count}",
                b.images.len(),
                b.scale.len()
            )));
        }
        let columns = basis.columns.max(1);
        let rows = count.div_ceil(columns) as u32;
        let grid = self.extension.grid;
        let tiles = (columns as u32 * grid.width, rows * grid.height);
        let what = format!("basis atlas of view {u},{v}");
        let atlas = self.grey_atlases(&b.images, (3, tiles), &what)?;
        let (w, h) = (atlas[0].width() / columns as u32, atlas[0].height() / rows);
        Ok((0..count)
            .map(|k| {
                let (tx, ty) = ((k % columns) as u32 * w, (k / columns) as u32 * h);
                Image::from_fn(w as usize, h as usize, |x, y| {
                    std::array::from_fn(|c| {
                        let code = atlas[c].get_pixel(tx + x as u32, ty + y as u32)[0] as f32;
                        b.offset[k][c] + b.scale[k][c] * code
                    })
                })
            })
            .collect())
    }

    /// A view's alpha.
    pub fn alpha(&self, pose: u32, u: usize, v: usize) -> Result<frf_core::image::GrayImage> {
        let view = self.view(pose, u, v)?;
        let png = image::load_from_memory(self.image_bytes(view.alpha)?)
            .map_err(|e| self.bad(format!("the alpha of view {u},{v}: {e}")))?
            .to_luma8();
        Ok(Image::from_fn(
            png.width() as usize,
            png.height() as usize,
            |x, y| png.get_pixel(x as u32, y as u32)[0] as f32 / 255.0,
        ))
    }

    /// A view relit by `light`: `Σ_i c_i T_i` per texel.
    pub fn relight(&self, pose: u32, u: usize, v: usize, light: &ShLight) -> Result<RgbImage> {
        let t = self.transfer(pose, u, v)?;
        Ok(t.map(|t| {
            let mut out = [0.0f32; 3];
            for (ti, ci) in t.iter().zip(&light.coefficients) {
                for c in 0..3 {
                    out[c] += ti[c] * ci[c];
                }
            }
            out
        }))
    }
}
