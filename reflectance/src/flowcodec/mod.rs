//! The flow codec: each displacement component quantized to 8 bits on a signed
//! logarithmic scale ([`quant`]), optionally predicted from its left neighbour, then
//! entropy coded with a canonical Huffman code ([`huffman`]) built for the map.
//!
//! A coded map is `[flags u8][width u32][height u32][Huffman table, 128 bytes][bits]`,
//! little-endian. The codes are laid out as two planes (all `u`, then all `v`), row-major.
//! With prediction (flag bit 0) each code is replaced by its difference from the code to
//! its left (the one above for the first column), modulo 256: flow is smooth inside the
//! subject and constant (unknown) outside, so the differences cluster at zero and the
//! Huffman code gets short. The original reached 34 % of the 8-bit size without
//! prediction (BRIEF section 4).

pub mod huffman;
pub mod quant;

use frf_core::image::{FlowImage, Image};

use crate::error::{ReflectanceError, Result};
use huffman::{HuffmanTable, TABLE_BYTES};
use quant::LogQuantizer;

/// Flag: codes are left-predicted.
const FLAG_PREDICT: u8 = 1;
const HEADER_BYTES: usize = 9;
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

/// Replaces codes by their difference from the left (or, in the first column, upper)
/// neighbour in the same plane, modulo 256; the inverse of [`unpredict`].
fn predict(codes: &[i8], width: usize) -> Vec<u8> {
    let plane = codes.len() / 2;
    let mut out = Vec::with_capacity(codes.len());
    for (i, &c) in codes.iter().enumerate() {
        out.push((c as u8).wrapping_sub(neighbour(codes, i, width, plane) as u8));
    }
    out
}

/// The predicting neighbour of code `i` in planes of `plane` codes (0 for the first of
/// each plane); only codes before `i` are read.
#[inline]
fn neighbour(codes: &[i8], i: usize, width: usize, plane: usize) -> i8 {
    let j = i % plane.max(1);
    if !j.is_multiple_of(width) {
        codes[i - 1]
    } else if j >= width {
        codes[i - width]
    } else {
        0
    }
}

fn unpredict(residuals: &[u8], width: usize) -> Vec<i8> {
    let plane = residuals.len() / 2;
    let mut codes: Vec<i8> = Vec::with_capacity(residuals.len());
    for (i, &r) in residuals.iter().enumerate() {
        let pred = neighbour(&codes, i, width, plane);
        codes.push(r.wrapping_add(pred as u8) as i8);
    }
    codes
}

/// Encodes a flow map.
pub fn encode(flow: &FlowImage, q: &LogQuantizer, predicted: bool) -> Result<Vec<u8>> {
    let codes = quantize(flow, q);
    let symbols: Vec<u8> = if predicted {
        predict(&codes, flow.width())
    } else {
        codes.iter().map(|&c| c as u8).collect()
    };
    let mut counts = [0u64; 256];
    for &s in &symbols {
        counts[s as usize] += 1;
    }
    let table = HuffmanTable::from_counts(&counts);
    let bits = table.encode(&symbols)?;
    let mut out = Vec::with_capacity(HEADER_BYTES + TABLE_BYTES + bits.len());
    out.push(if predicted { FLAG_PREDICT } else { 0 });
    out.extend_from_slice(&(flow.width() as u32).to_le_bytes());
    out.extend_from_slice(&(flow.height() as u32).to_le_bytes());
    out.extend_from_slice(&table.to_bytes());
    out.extend_from_slice(&bits);
    Ok(out)
}

/// Decodes a flow map into its 8-bit codes (two planes), with its size.
pub fn decode_codes(bytes: &[u8]) -> Result<(usize, usize, Vec<i8>)> {
    if bytes.len() < HEADER_BYTES + TABLE_BYTES {
        return Err(ReflectanceError::Corrupt(format!(
            "flow map truncated: {} bytes, the header alone needs {}",
            bytes.len(),
            HEADER_BYTES + TABLE_BYTES
        )));
    }
    let flags = bytes[0];
    if flags & !FLAG_PREDICT != 0 {
        return Err(ReflectanceError::Corrupt(format!(
            "unknown flow-map flags {flags:#x}"
        )));
    }
    let word = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    let (w, h) = (word(1), word(5));
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(ReflectanceError::Corrupt(format!(
            "flow map size {w}x{h} outside 1..={MAX_SIDE} per side"
        )));
    }
    let (w, h) = (w as usize, h as usize);
    let table = HuffmanTable::from_bytes(&bytes[HEADER_BYTES..])?;
    let symbols = table.decode(&bytes[HEADER_BYTES + TABLE_BYTES..], 2 * w * h)?;
    let codes = if flags & FLAG_PREDICT != 0 {
        unpredict(&symbols, w)
    } else {
        symbols.iter().map(|&s| s as i8).collect()
    };
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

        #[test]
        fn corrupted_maps_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let q = LogQuantizer::new(0.3, 30.0).unwrap();
            let _ = decode(&bytes, &q);
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
        assert!(decode(&bytes[..bytes.len() - 2], &q).is_err());
        let mut flagged = bytes.clone();
        flagged[0] = 0x80;
        assert!(decode(&flagged, &q).is_err());
    }
}
