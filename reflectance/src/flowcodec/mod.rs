//! The flow codec: each displacement component quantized to 8 bits on a signed
//! logarithmic scale ([`quant`]), optionally predicted from its neighbours, then entropy
//! coded with a canonical Huffman code ([`huffman`]) built for the map.
//!
//! A coded map is, little-endian:
//! `[flags u8][width u32][height u32][mask length u32][mask][Huffman table, 128 B][bits]`.
//! The mask says which pixels have known flow (one byte per pixel, 0 or 1, zstd-coded:
//! the unknown background is a few long runs, which cost next to nothing there, while
//! Huffman coding cannot spend less than one bit per symbol on them). Only the known
//! pixels' codes are Huffman-coded, as two planes (all `u`, then all `v`), row-major.
//! With prediction (flag bit 0) each code is replaced by its difference, modulo 256, from
//! the code of its left neighbour if that is known, else of the one above, else 0: flow is
//! smooth inside the subject, so the differences cluster at zero. The original reached
//! 34 % of the 8-bit size with Huffman coding alone (docs/design.md section 3.6).

pub mod huffman;
pub mod quant;

use frf_core::image::{FlowImage, Image};

use crate::error::{ReflectanceError, Result};
use huffman::{HuffmanTable, TABLE_BYTES};
use quant::LogQuantizer;

/// Flag: codes are left-predicted.
const FLAG_PREDICT: u8 = 1;
const HEADER_BYTES: usize = 13;
/// Largest flow map accepted from a file, pixels per side.
const MAX_SIDE: u32 = frf_core::io::limits::MAX_DIMENSION;

/// The 8-bit codes of a flow map, two planes (`u` then `v`), row-major.
pub fn quantize(flow: &FlowImage, q: &LogQuantizer) -> Vec<i8> {
    let mut codes = Vec::with_capacity(flow.pixels().len() * 2);
    for c in 0..2 {
        codes.extend(flow.pixels().iter().map(|f| {
            if frf_core::flo::is_known(*f) {
                q.encode(f[c])
            } else {
                quant::UNKNOWN_CODE
            }
        }));
    }
    codes
}

/// The flow map of `codes` (as from [`quantize`]).
pub fn dequantize(
    width: usize,
    height: usize,
    codes: &[i8],
    q: &LogQuantizer,
) -> Result<FlowImage> {
    let n = width * height;
    if codes.len() != 2 * n {
        return Err(ReflectanceError::Corrupt(format!(
            "{} flow codes for a {width}x{height} map",
            codes.len()
        )));
    }
    let pixels = (0..n)
        .map(|i| {
            let (a, b) = (codes[i], codes[n + i]);
            if a == quant::UNKNOWN_CODE || b == quant::UNKNOWN_CODE {
                [frf_core::flo::UNKNOWN; 2]
            } else {
                [q.decode(a), q.decode(b)]
            }
        })
        .collect();
    Ok(Image::from_vec(width, height, pixels)?)
}

/// The predicting code for pixel `i` of a `width`-wide plane (`plane` = the plane's
/// codes, only those before `i` are read): the left neighbour if known, else the one
/// above if known, else 0.
#[inline]
fn prediction(plane: &[i8], i: usize, width: usize) -> i8 {
    let left = (!i.is_multiple_of(width)).then(|| plane[i - 1]);
    let up = (i >= width).then(|| plane[i - width]);
    [left, up]
        .into_iter()
        .flatten()
        .find(|&c| c != quant::UNKNOWN_CODE)
        .unwrap_or(0)
}

fn corrupt(what: impl Into<String>) -> ReflectanceError {
    ReflectanceError::Corrupt(what.into())
}

/// Encodes a flow map.
pub fn encode(flow: &FlowImage, q: &LogQuantizer, predicted: bool) -> Result<Vec<u8>> {
    let (w, n) = (flow.width(), flow.pixels().len());
    let codes = quantize(flow, q);
    let known: Vec<u8> = codes[..n]
        .iter()
        .map(|&c| (c != quant::UNKNOWN_CODE) as u8)
        .collect();
    let mut symbols = Vec::with_capacity(2 * n);
    for plane in codes.chunks_exact(n.max(1)) {
        for (i, &c) in plane.iter().enumerate() {
            if known[i] == 1 {
                let pred = if predicted {
                    prediction(plane, i, w)
                } else {
                    0
                };
                symbols.push((c as u8).wrapping_sub(pred as u8));
            }
        }
    }
    let mask = zstd::bulk::compress(&known, crate::imagecodec::ZSTD_LEVEL).map_err(|e| {
        ReflectanceError::Codec {
            what: "zstd",
            problem: e.to_string(),
        }
    })?;
    let mut counts = [0u64; 256];
    for &s in &symbols {
        counts[s as usize] += 1;
    }
    let table = HuffmanTable::from_counts(&counts);
    let bits = table.encode(&symbols)?;
    let mut out = Vec::with_capacity(HEADER_BYTES + mask.len() + TABLE_BYTES + bits.len());
    out.push(if predicted { FLAG_PREDICT } else { 0 });
    for v in [flow.width() as u32, flow.height() as u32, mask.len() as u32] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&mask);
    out.extend_from_slice(&table.to_bytes());
    out.extend_from_slice(&bits);
    Ok(out)
}

/// Decodes a flow map into its 8-bit codes (two planes), with its size.
pub fn decode_codes(bytes: &[u8]) -> Result<(usize, usize, Vec<i8>)> {
    if bytes.len() < HEADER_BYTES {
        return Err(corrupt(format!(
            "flow map truncated: {} bytes, the header needs {HEADER_BYTES}",
            bytes.len()
        )));
    }
    let flags = bytes[0];
    if flags & !FLAG_PREDICT != 0 {
        return Err(corrupt(format!("unknown flow-map flags {flags:#x}")));
    }
    let word = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    let (w, h, mask_len) = (word(1), word(5), word(9) as usize);
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(corrupt(format!(
            "flow map size {w}x{h} outside 1..={MAX_SIDE} per side"
        )));
    }
    let (w, h) = (w as usize, h as usize);
    let n = w * h;
    let table_at = HEADER_BYTES
        .checked_add(mask_len)
        .filter(|&t| t + TABLE_BYTES <= bytes.len())
        .ok_or_else(|| corrupt("flow map truncated in its mask or table"))?;
    let known = crate::unzstd::decompress_exact(&bytes[HEADER_BYTES..table_at], n, "flow mask")?;
    if known.iter().any(|&k| k > 1) {
        return Err(corrupt(format!(
            "flow mask holds {} entries, expected {n} of 0 or 1",
            known.len()
        )));
    }
    let count = known.iter().filter(|&&k| k == 1).count();
    let table = HuffmanTable::from_bytes(&bytes[table_at..])?;
    let symbols = table.decode(&bytes[table_at + TABLE_BYTES..], 2 * count)?;
    let mut codes = vec![quant::UNKNOWN_CODE; 2 * n];
    let mut next = symbols.iter();
    for plane in codes.chunks_exact_mut(n) {
        for i in 0..n {
            if known[i] == 1 {
                let pred = if flags & FLAG_PREDICT != 0 {
                    prediction(plane, i, w)
                } else {
                    0
                };
                let s = next.next().copied().unwrap_or(0);
                plane[i] = s.wrapping_add(pred as u8) as i8;
            }
        }
    }
    Ok((w, h, codes))
}

/// Decodes a flow map.
pub fn decode(bytes: &[u8], q: &LogQuantizer) -> Result<FlowImage> {
    let (w, h, codes) = decode_codes(bytes)?;
    dequantize(w, h, &codes, q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn smooth_flow(w: usize, h: usize) -> FlowImage {
        Image::from_fn(w, h, |x, y| {
            let inside = (x as f32 - w as f32 / 2.0).powi(2) + (y as f32 - h as f32 / 2.0).powi(2)
                < (w.min(h) as f32 / 3.0).powi(2);
            if inside {
                [3.0 + 0.05 * x as f32, -1.0 + 0.02 * y as f32]
            } else {
                [frf_core::flo::UNKNOWN; 2]
            }
        })
    }

    #[test]
    fn decode_gives_exactly_the_dequantized_values() {
        let flow = smooth_flow(37, 23);
        let q = LogQuantizer::fit(flow.pixels().iter().flatten().copied());
        let expected = dequantize(37, 23, &quantize(&flow, &q), &q).unwrap();
        for predicted in [false, true] {
            let bytes = encode(&flow, &q, predicted).unwrap();
            assert_eq!(decode(&bytes, &q).unwrap(), expected);
        }
    }

    #[test]
    fn prediction_and_huffman_compress_smooth_flow() {
        let flow = smooth_flow(160, 224);
        let q = LogQuantizer::fit(flow.pixels().iter().flatten().copied());
        let eight_bit = 2 * 160 * 224;
        let plain = encode(&flow, &q, false).unwrap().len();
        let predicted = encode(&flow, &q, true).unwrap().len();
        assert!(plain < eight_bit / 2, "plain {plain} of {eight_bit}");
        assert!(
            predicted < plain / 2,
            "predicted {predicted} vs plain {plain}"
        );
    }

    proptest! {
        #[test]
        fn arbitrary_maps_round_trip(w in 1usize..20, h in 1usize..20,
                                     values in proptest::collection::vec(-40.0f32..40.0, 800),
                                     predicted in any::<bool>()) {
            let flow = Image::from_fn(w, h, |x, y| {
                let i = 2 * (y * w + x);
                if values[i] > 35.0 { [frf_core::flo::UNKNOWN; 2] } else { [values[i], values[i + 1]] }
            });
            let q = LogQuantizer::new(0.3, 30.0).unwrap();
            let expected = dequantize(w, h, &quantize(&flow, &q), &q).unwrap();
            let bytes = encode(&flow, &q, predicted).unwrap();
            prop_assert_eq!(decode(&bytes, &q).unwrap(), expected);
        }

        /// A valid map, then damaged (flipped bits anywhere, header included, and a cut
        /// tail): it decodes to a map of the size its header declares, or is refused with
        /// an error saying what is wrong. Random bytes would stop at the size check.
        #[test]
        fn damaged_maps_decode_or_are_refused(
            w in 1usize..24, h in 1usize..24, predicted in any::<bool>(),
            flips in proptest::collection::vec((any::<prop::sample::Index>(), 0u8..8), 1..4),
            cut in 0usize..4,
        ) {
            let q = LogQuantizer::new(0.3, 30.0).unwrap();
            let flow = smooth_flow(w, h);
            let mut bytes = encode(&flow, &q, predicted).unwrap();
            for (at, bit) in &flips {
                let i = at.index(bytes.len());
                bytes[i] ^= 1 << bit;
            }
            bytes.truncate(bytes.len() - cut.min(bytes.len()));
            match decode(&bytes, &q) {
                Ok(map) => {
                    let (dw, dh) = (
                        u32::from_le_bytes(bytes[1..5].try_into().unwrap()) as usize,
                        u32::from_le_bytes(bytes[5..9].try_into().unwrap()) as usize,
                    );
                    prop_assert_eq!((map.width(), map.height()), (dw, dh));
                    prop_assert!(map.pixels().iter().flatten().all(|c| c.is_finite() || *c == frf_core::flo::UNKNOWN));
                }
                Err(e) => prop_assert!(matches!(e, ReflectanceError::Corrupt(_)), "{}", e),
            }
        }
    }

    #[test]
    fn hostile_headers_are_refused() {
        let q = LogQuantizer::new(0.3, 30.0).unwrap();
        let flow = smooth_flow(8, 8);
        let mut bytes = encode(&flow, &q, true).unwrap();
        bytes[1..5].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode(&bytes, &q).unwrap_err().to_string().contains("size"));
        let bytes = encode(&flow, &q, true).unwrap();
        let e = decode(&bytes[..bytes.len() - 2], &q)
            .unwrap_err()
            .to_string();
        assert!(e.contains("42 symbols cannot fit in 5 bytes"), "{e}");
        let mut flagged = bytes.clone();
        flagged[0] = 0x80;
        let e = decode(&flagged, &q).unwrap_err().to_string();
        assert!(e.contains("flags 0x80"), "{e}");
    }
}
