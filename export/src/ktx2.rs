//! An atlas as a GPU-compressed KTX2 image (`frf export --textures ktx2`, docs/export.md):
//! UASTC 4x4 blocks (Basis Universal's transcodable format: 16 bytes a 4 x 4 block of
//! texels, 8 bits a texel, which a player transcodes straight to its GPU's own block
//! format, ASTC, BC7 or ETC2, without decoding texels) under zstd, the codes linear, the
//! atlas' channels in R, G and B (a grey atlas in R, copied to G and B).
//!
//! The blocks come from the basisu encoder ([`basis_universal`]); it writes them in its
//! own `.basis` container, from which [`slice_blocks`] takes them, and this module writes
//! the KTX2 container (KTX 2.0 specification: the header, the level index, a data format
//! descriptor of the UASTC colour model, the writer's name, the level) and reads it back
//! ([`read`]). What a reader decodes is decoded here too, by basisu's transcoder, so the
//! export states the error its codes carry ([`Encoded::decoded`]).

use basis_universal::{BasisTextureFormat, ColorSpace, Compressor, CompressorParams, DecodeFlags};

use crate::error::{ExportError, Result};

/// A block's side in texels: KTX2 images of UASTC are a whole number of blocks a side.
pub const BLOCK: usize = 4;
/// Bytes of a UASTC block.
const BLOCK_BYTES: usize = 16;
/// The zstd level of the level's bytes (KTX2's supercompression scheme 2).
const ZSTD_LEVEL: i32 = 19;
/// The file identifier of KTX 2.0.
const IDENTIFIER: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];
/// KTX2's supercompression scheme of zstd.
const SUPERCOMPRESSION_ZSTD: u32 = 2;
/// The Khronos data format's colour model of UASTC.
const COLOR_MODEL_UASTC: u8 = 166;
/// UASTC's channel types: RGB, and one channel read in R, G and B.
const CHANNEL_RGB: u8 = 0;
const CHANNEL_RRR: u8 = 4;

/// An atlas encoded.
#[derive(Debug, Clone)]
pub struct Encoded {
    /// The KTX2 file.
    pub ktx2: Vec<u8>,
    /// Its texels as a reader decodes them, RGBA, row-major, of the padded size.
    pub decoded: Vec<u8>,
}

/// `n` rounded up to whole blocks.
pub fn padded(n: usize) -> usize {
    n.div_ceil(BLOCK) * BLOCK
}

/// Encodes an RGBA image of `w x h` texels (whole blocks, [`padded`]) whose channels are
/// codes (linear); `grey` when only its R channel carries them (G and B copies).
pub fn encode(rgba: &[u8], w: usize, h: usize, grey: bool) -> Result<Encoded> {
    if w == 0
        || h == 0
        || !w.is_multiple_of(BLOCK)
        || !h.is_multiple_of(BLOCK)
        || rgba.len() != 4 * w * h
    {
        return Err(ExportError::Field(format!(
            "a KTX2 atlas of {w}x{h} texels from {} bytes: expected whole 4x4 blocks, 4 bytes a texel",
            rgba.len()
        )));
    }
    let blocks = slice_blocks(&basis_file(rgba, w, h)?, w, h)?;
    let decoded = decode_blocks(&blocks, w, h).map_err(ExportError::Field)?;
    let level = zstd::bulk::compress(&blocks, ZSTD_LEVEL)
        .map_err(|e| ExportError::Field(format!("compressing a KTX2 level: {e}")))?;
    let channel = if grey { CHANNEL_RRR } else { CHANNEL_RGB };
    Ok(Encoded {
        ktx2: container(w, h, channel, &level, blocks.len()),
        decoded,
    })
}

/// The basisu encoder's `.basis` file of an RGBA image (whole blocks) as UASTC.
#[allow(unsafe_code)]
fn basis_file(rgba: &[u8], w: usize, h: usize) -> Result<Vec<u8>> {
    let mut params = CompressorParams::new();
    params.set_basis_format(BasisTextureFormat::UASTC4x4);
    params.set_color_space(ColorSpace::Linear);
    params.set_generate_mipmaps(false);
    // basisu's default UASTC level: its slower levels (and favouring BC7's error) moved the
    // player's frame against frf by under 0.4 dB on the tiny field, for twice the time.
    params.source_image_mut(0).init(rgba, w as u32, h as u32, 4);
    // One thread: the export encodes its views on rayon's threads already.
    let mut compressor = Compressor::new(1);
    // SAFETY: the parameters are the library's own (CompressorParams::new) with one
    // source image of w x h RGBA texels whose bytes it copied (checked by `encode`), no
    // mipmaps, and the UASTC format: the valid configuration the crate documents.
    let ready = unsafe { compressor.init(&params) };
    if !ready {
        return Err(ExportError::Field(
            "the UASTC encoder refused its parameters".into(),
        ));
    }
    // SAFETY: as above, the compressor initialised with valid parameters.
    unsafe { compressor.process() }
        .map_err(|e| ExportError::Field(format!("UASTC encoding failed: {e:?}")))?;
    Ok(compressor.basis_file().to_vec())
}

/// The raw blocks of the one slice of a `.basis` file of a `w x h` UASTC image.
fn slice_blocks(basis: &[u8], w: usize, h: usize) -> Result<Vec<u8>> {
    let bad = |what: &str| ExportError::Field(format!("the UASTC encoder's output: {what}"));
    let u16_at = |o: usize| {
        basis
            .get(o..o + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
    };
    let u24_at = |o: usize| {
        basis
            .get(o..o + 3)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], 0]))
    };
    let u32_at =
        |o: usize| (basis.get(o..o + 4)).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    // The header: "sB", its size, the slice count, the slice descriptions' offset.
    if basis.get(0..2) != Some(b"sB".as_slice()) {
        return Err(bad("no .basis signature"));
    }
    if u24_at(14) != Some(1) {
        return Err(bad("not one slice"));
    }
    let desc = u32_at(65).ok_or_else(|| bad("a truncated header"))? as usize;
    // The slice: its size in blocks at 9 and 11, its data's offset and size at 13 and 17.
    let (bx, by) = (u16_at(desc + 9), u16_at(desc + 11));
    let (offset, size) = (u32_at(desc + 13), u32_at(desc + 17));
    let (Some(bx), Some(by), Some(offset), Some(size)) = (bx, by, offset, size) else {
        return Err(bad("a truncated slice description"));
    };
    if (usize::from(bx), usize::from(by)) != (w / BLOCK, h / BLOCK) {
        return Err(bad(&format!("{bx}x{by} blocks for a {w}x{h} image")));
    }
    let (offset, size) = (offset as usize, size as usize);
    if size != w / BLOCK * (h / BLOCK) * BLOCK_BYTES {
        return Err(bad(&format!("{size} bytes of blocks for a {w}x{h} image")));
    }
    basis
        .get(offset..offset + size)
        .map(<[u8]>::to_vec)
        .ok_or_else(|| bad("a truncated slice"))
}

/// The RGBA texels of a `w x h` image's UASTC blocks (whole blocks, row by row), as a
/// transcoder decodes them.
#[allow(unsafe_code)]
pub fn decode_blocks(blocks: &[u8], w: usize, h: usize) -> std::result::Result<Vec<u8>, String> {
    if w == 0 || h == 0 || blocks.len() != w.div_ceil(BLOCK) * h.div_ceil(BLOCK) * BLOCK_BYTES {
        return Err(format!(
            "{} bytes of UASTC blocks for a {w}x{h} image",
            blocks.len()
        ));
    }
    basis_universal::transcoder_init();
    let mut out = vec![0u8; 4 * w * h];
    // SAFETY: the transcoder is made, used once and deleted here. The call reads
    // `blocks.len()` bytes, which hold every block of the w x h image (checked above), and
    // writes `w` RGBA32 pixels a row (4 bytes each) for `h` rows: `out`'s 4 w h bytes.
    let ok = unsafe {
        let t = basis_universal::sys::low_level_uastc_transcoder_new();
        let ok = basis_universal::sys::low_level_uastc_transcoder_transcode_slice(
            t,
            out.as_mut_ptr().cast(),
            w.div_ceil(BLOCK) as u32,
            h.div_ceil(BLOCK) as u32,
            blocks.as_ptr(),
            blocks.len() as u32,
            basis_universal::sys::basist_block_format_cRGBA32,
            4,
            false,
            false,
            w as u32,
            h as u32,
            w as u32,
            std::ptr::null_mut(),
            h as u32,
            -1,
            -1,
            DecodeFlags::HIGH_QUALITY.bits(),
        );
        basis_universal::sys::low_level_uastc_transcoder_delete(t);
        ok
    };
    match ok {
        true => Ok(out),
        false => Err("the UASTC blocks do not decode".into()),
    }
}

/// Reads a KTX2 file of one 2D level of UASTC blocks (zstd or not), as the export writes
/// them: its width, height and RGBA texels as a transcoder decodes them.
pub fn read(bytes: &[u8]) -> std::result::Result<(usize, usize, Vec<u8>), String> {
    if bytes.get(..12) != Some(IDENTIFIER.as_slice()) {
        return Err("not a KTX2 file (no KTX 2.0 identifier)".into());
    }
    let u32_at = |o: usize| {
        (bytes.get(o..o + 4))
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
            .ok_or_else(|| format!("a KTX2 file cut short at byte {o}"))
    };
    let u64_at = |o: usize| Ok::<_, String>(u32_at(o)? | (u32_at(o + 4)? << 32));
    let (w, h) = (u32_at(20)?, u32_at(24)?);
    let (depth, layers, faces, levels) = (u32_at(28)?, u32_at(32)?, u32_at(36)?, u32_at(40)?);
    let scheme = u32_at(44)? as u32;
    if (depth, layers, faces, levels) != (0, 0, 1, 1) {
        return Err(format!(
            "a KTX2 image of depth {depth}, {layers} layers, {faces} faces and {levels} levels: expected one 2D level"
        ));
    }
    let dfd = u32_at(48)?;
    let model = bytes.get(dfd + 12).copied();
    if model != Some(COLOR_MODEL_UASTC) {
        return Err(format!(
            "a KTX2 image of colour model {model:?}: expected UASTC ({COLOR_MODEL_UASTC})"
        ));
    }
    let (at, len, raw) = (u64_at(80)?, u64_at(88)?, u64_at(96)?);
    let level = (at.checked_add(len))
        .and_then(|end| bytes.get(at..end))
        .ok_or_else(|| format!("a KTX2 level of {len} bytes at {at} beyond the file's end"))?;
    let expected = w.div_ceil(BLOCK) * h.div_ceil(BLOCK) * BLOCK_BYTES;
    if raw != expected {
        return Err(format!(
            "a KTX2 level of {raw} bytes for a {w}x{h} image of UASTC blocks ({expected})"
        ));
    }
    let blocks = match scheme {
        0 => level.to_vec(),
        SUPERCOMPRESSION_ZSTD => zstd::bulk::decompress(level, raw)
            .map_err(|e| format!("the KTX2 level does not decompress: {e}"))?,
        other => {
            return Err(format!(
                "KTX2 supercompression {other}: expected none or zstd"
            ));
        }
    };
    if blocks.len() != raw {
        return Err(format!(
            "the KTX2 level decompresses to {} bytes, not {raw}",
            blocks.len()
        ));
    }
    Ok((w, h, decode_blocks(&blocks, w, h)?))
}

/// A KTX2 file of one zstd-compressed level of UASTC blocks (`blocks_bytes` before
/// compression) of a `w x h` image, of channel type `channel`.
fn container(w: usize, h: usize, channel: u8, level: &[u8], blocks_bytes: usize) -> Vec<u8> {
    let dfd = descriptor(channel);
    let kvd = key_value("KTXwriter", concat!("frf ", env!("CARGO_PKG_VERSION")));
    // The header (48 bytes after the identifier's 12), the index (32), one level's (24).
    let dfd_at = 12 + 68 + 24;
    let kvd_at = dfd_at + dfd.len();
    let level_at = kvd_at + kvd.len();
    let mut out = Vec::with_capacity(level_at + level.len());
    out.extend_from_slice(&IDENTIFIER);
    let u32s = [
        0, // vkFormat: undefined (a transcodable format)
        1, // typeSize
        w as u32,
        h as u32,
        0, // pixelDepth: a 2D image
        0, // layerCount: not an array
        1, // faceCount
        1, // levelCount
        SUPERCOMPRESSION_ZSTD,
        dfd_at as u32,
        dfd.len() as u32,
        kvd_at as u32,
        kvd.len() as u32,
    ];
    u32s.iter()
        .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    // No supercompression global data (zstd has none).
    out.extend_from_slice(&0u64.to_le_bytes());
    out.extend_from_slice(&0u64.to_le_bytes());
    for v in [level_at, level.len(), blocks_bytes] {
        out.extend_from_slice(&(v as u64).to_le_bytes());
    }
    out.extend_from_slice(&dfd);
    out.extend_from_slice(&kvd);
    out.extend_from_slice(level);
    out
}

/// The data format descriptor: its total size, then one basic block of one sample.
fn descriptor(channel: u8) -> Vec<u8> {
    let mut d = Vec::with_capacity(44);
    d.extend_from_slice(&44u32.to_le_bytes());
    d.extend_from_slice(&0u32.to_le_bytes()); // vendor Khronos, basic descriptor type
    d.extend_from_slice(&2u16.to_le_bytes()); // version 1.3
    d.extend_from_slice(&40u16.to_le_bytes()); // the block's bytes
    // UASTC, BT.709 primaries, a linear transfer, straight alpha.
    d.extend_from_slice(&[COLOR_MODEL_UASTC, 1, 1, 0]);
    d.extend_from_slice(&[3, 3, 0, 0]); // 4 x 4 x 1 texels a block (each less one)
    d.extend_from_slice(&[0; 8]); // bytes a plane: 0, the level supercompressed
    // The sample: the block's 128 bits, of the channel type, the full range.
    d.extend_from_slice(&0u16.to_le_bytes());
    d.extend_from_slice(&[127, channel]);
    d.extend_from_slice(&[0; 4]);
    d.extend_from_slice(&0u32.to_le_bytes());
    d.extend_from_slice(&u32::MAX.to_le_bytes());
    d
}

/// One key/value entry (its length, the key and value each ending in NUL), padded to 4.
fn key_value(key: &str, value: &str) -> Vec<u8> {
    let mut entry = Vec::new();
    entry.extend_from_slice(key.as_bytes());
    entry.push(0);
    entry.extend_from_slice(value.as_bytes());
    entry.push(0);
    let mut out = (entry.len() as u32).to_le_bytes().to_vec();
    out.extend_from_slice(&entry);
    out.resize(out.len().div_ceil(4) * 4, 0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth RGB image of three unlike channels (as a transfer atlas' three are).
    fn image(w: usize, h: usize) -> Vec<u8> {
        (0..w * h)
            .flat_map(|i| {
                let (x, y) = ((i % w) as f32, (i / w) as f32);
                [
                    (127.5 + 120.0 * (x / 7.0).sin()) as u8,
                    (y / h as f32 * 255.0) as u8,
                    (127.5 + 100.0 * ((x + y) / 11.0).cos()) as u8,
                    255,
                ]
            })
            .collect()
    }

    /// The file an independent reader (the `ktx2` crate) opens: its size, one level of
    /// the UASTC model, zstd; the level decompresses to the encoder's blocks (it is
    /// deterministic), and what a reader decodes is within 4 codes RMS of the source.
    #[test]
    fn a_reader_opens_what_it_writes() {
        let (w, h) = (24, 16);
        let src = image(w, h);
        let e = encode(&src, w, h, false).unwrap();
        let r = ktx2::Reader::new(e.ktx2.as_slice()).unwrap();
        let hd = r.header();
        assert_eq!((hd.pixel_width, hd.pixel_height), (w as u32, h as u32));
        assert_eq!((hd.level_count, hd.face_count, hd.layer_count), (1, 1, 0));
        assert_eq!(
            hd.supercompression_scheme,
            Some(ktx2::SupercompressionScheme::Zstandard)
        );
        assert_eq!(r.color_model(), Some(ktx2::ColorModel::UASTC));
        assert_eq!(r.transfer_function(), Some(ktx2::TransferFunction::Linear));
        assert!(r.writer().unwrap().starts_with("frf "));
        let level = r.levels().next().unwrap();
        let blocks = zstd::bulk::decompress(level.data, 1 << 20).unwrap();
        assert_eq!(blocks.len() as u64, level.uncompressed_byte_length);
        let basis = basis_file(&src, w, h).unwrap();
        assert_eq!(blocks, slice_blocks(&basis, w, h).unwrap());
        assert_eq!(e.decoded.len(), src.len());
        // Its own reader decodes what the encoder's transcoder did.
        assert_eq!(read(&e.ktx2).unwrap(), (w, h, e.decoded.clone()));
        let se: f64 = (src.iter().zip(&e.decoded))
            .map(|(&a, &b)| (f64::from(a) - f64::from(b)).powi(2))
            .sum();
        let rms = (se / src.len() as f64).sqrt();
        assert!(rms < 4.0, "RMS {rms} codes");
    }

    /// A damaged file is refused, never read past its end: its identifier, a cut, a level
    /// beyond the end, another colour model.
    #[test]
    fn the_reader_refuses_damaged_files() {
        let (w, h) = (8, 8);
        let good = encode(&image(w, h), w, h, false).unwrap().ktx2;
        let mut bad = good.clone();
        bad[0] = 0;
        assert!(read(&bad).unwrap_err().contains("identifier"));
        for cut in [12, 40, 90, 150, good.len() - 1] {
            assert!(read(&good[..cut]).is_err(), "cut at {cut}");
        }
        let mut far = good.clone();
        far[80..88].copy_from_slice(&(1u64 << 40).to_le_bytes());
        assert!(read(&far).unwrap_err().contains("beyond the file's end"));
        let mut model = good.clone();
        model[104 + 12] = 160;
        assert!(read(&model).unwrap_err().contains("colour model"));
        assert!(decode_blocks(&[0; 10], w, h).is_err());
    }

    /// An image not of whole blocks, or of the wrong byte count, is refused by name.
    #[test]
    fn refuses_partial_blocks() {
        for (w, h, len) in [(6, 8, 6 * 8 * 4), (8, 8, 10), (0, 8, 0)] {
            let e = encode(&vec![0; len], w, h, false).unwrap_err().to_string();
            assert!(e.contains("whole 4x4 blocks"), "{e}");
        }
    }

    /// A `.basis` file cut short, of another image's size or not one at all is refused,
    /// never read past its end.
    #[test]
    fn refuses_a_bad_basis_file() {
        let (w, h) = (8, 8);
        let file = basis_file(&image(w, h), w, h).unwrap();
        assert_eq!(slice_blocks(&file, w, h).unwrap().len(), w * h);
        for cut in [0, 2, 20, 70, file.len() / 2, file.len() - 1] {
            assert!(slice_blocks(&file[..cut], w, h).is_err(), "cut at {cut}");
        }
        let e = slice_blocks(&file, 8, 12).unwrap_err().to_string();
        assert!(e.contains("2x2 blocks for a 8x12 image"), "{e}");
        let mut other = file.clone();
        other[0] = b'x';
        assert!(slice_blocks(&other, w, h).is_err());
    }
}
