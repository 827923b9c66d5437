//! Middlebury `.flo` optical-flow files (Baker et al., IJCV 2011): little-endian float32
//! magic `202021.25`, int32 width, int32 height, then `width * height` interleaved
//! float32 `(u, v)` pairs, row-major from the top-left. A component whose magnitude
//! exceeds [`UNKNOWN_THRESHOLD`] marks unknown flow; the project writes [`UNKNOWN`].

use std::path::Path;

use crate::atomic::write_bytes_atomic;
use crate::error::{CoreError, Result};
use crate::image::{Flow, FlowImage, Image};
use crate::io::limits::MAX_DIMENSION;

/// The magic number that opens every `.flo` file ("PIEH" read as a float).
pub const MAGIC: f32 = 202_021.25;
/// The value the project writes for unknown flow.
pub const UNKNOWN: f32 = 1e10;
/// Components beyond this magnitude mean "unknown" (Middlebury convention).
pub const UNKNOWN_THRESHOLD: f32 = 1e9;

/// Whether a flow vector is known (finite and within the unknown threshold).
#[inline]
pub fn is_known(f: Flow) -> bool {
    f[0].is_finite()
        && f[1].is_finite()
        && f[0].abs() <= UNKNOWN_THRESHOLD
        && f[1].abs() <= UNKNOWN_THRESHOLD
}

/// Parses `.flo` bytes; `path` is only used in error messages.
pub fn decode_flo(path: &Path, bytes: &[u8]) -> Result<FlowImage> {
    if bytes.len() < 12 {
        return Err(CoreError::bad_file(
            path,
            format!("truncated .flo header: {} bytes, needs 12", bytes.len()),
        ));
    }
    let word = |i: usize| [bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]];
    let magic = f32::from_le_bytes(word(0));
    if magic != MAGIC {
        return Err(CoreError::bad_file(
            path,
            format!("not a .flo file: magic {magic} instead of {MAGIC}"),
        ));
    }
    let width = i32::from_le_bytes(word(4));
    let height = i32::from_le_bytes(word(8));
    let max = MAX_DIMENSION as i32;
    if width <= 0 || height <= 0 || width > max || height > max {
        return Err(CoreError::LimitExceeded {
            what: path.display().to_string(),
            problem: format!("flow size {width}x{height} outside 1..={max} per side"),
        });
    }
    let (w, h) = (width as usize, height as usize);
    let expected = 12 + w * h * 8;
    if bytes.len() != expected {
        return Err(CoreError::bad_file(
            path,
            format!(
                "{}x{} flow needs {expected} bytes, file has {} ({})",
                w,
                h,
                bytes.len(),
                if bytes.len() < expected {
                    "truncated"
                } else {
                    "trailing data"
                }
            ),
        ));
    }
    let pixels = bytes[12..]
        .chunks_exact(8)
        .map(|c| {
            [
                f32::from_le_bytes([c[0], c[1], c[2], c[3]]),
                f32::from_le_bytes([c[4], c[5], c[6], c[7]]),
            ]
        })
        .collect();
    Image::from_vec(w, h, pixels)
}

/// Reads a `.flo` file.
pub fn read_flo(path: &Path) -> Result<FlowImage> {
    let bytes = std::fs::read(path).map_err(|e| CoreError::io(path, e))?;
    decode_flo(path, &bytes)
}

/// Serializes a flow field in `.flo` layout.
pub fn encode_flo(flow: &FlowImage) -> Vec<u8> {
    let mut out = Vec::with_capacity(12 + flow.pixels().len() * 8);
    out.extend_from_slice(&MAGIC.to_le_bytes());
    out.extend_from_slice(&(flow.width() as i32).to_le_bytes());
    out.extend_from_slice(&(flow.height() as i32).to_le_bytes());
    for p in flow.pixels() {
        out.extend_from_slice(&p[0].to_le_bytes());
        out.extend_from_slice(&p[1].to_le_bytes());
    }
    out
}

/// Writes a `.flo` file atomically.
pub fn write_flo(path: &Path, flow: &FlowImage) -> Result<()> {
    if flow.width() == 0 || flow.height() == 0 {
        return Err(CoreError::invalid(
            "flow",
            "cannot write an empty flow field",
        ));
    }
    write_bytes_atomic(path, &encode_flo(flow))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_every_bit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.flo");
        let flow = Image::from_fn(5, 3, |x, y| {
            [x as f32 * 0.25 - 1.0, UNKNOWN * (y == 2) as i32 as f32]
        });
        write_flo(&path, &flow).unwrap();
        let back = read_flo(&path).unwrap();
        assert_eq!(back, flow);
        assert!(!is_known(back.get(0, 2)));
        assert!(is_known(back.get(0, 1)));
    }

    #[test]
    fn truncated_and_hostile_files_are_refused() {
        let p = Path::new("bad.flo");
        let flow = Image::new(4, 4, [1.0f32, 2.0]);
        let bytes = encode_flo(&flow);
        let err = decode_flo(p, &bytes[..bytes.len() - 3])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("bad.flo") && err.contains("truncated"),
            "{err}"
        );
        let mut hostile = bytes.clone();
        hostile[4..8].copy_from_slice(&i32::MAX.to_le_bytes());
        let e = decode_flo(p, &hostile).unwrap_err().to_string();
        assert!(e.contains("bad.flo") && e.contains("2147483647x4"), "{e}");
        let mut wrong_magic = bytes;
        wrong_magic[0] ^= 1;
        assert!(
            decode_flo(p, &wrong_magic)
                .unwrap_err()
                .to_string()
                .contains("magic")
        );
        let e = decode_flo(p, &[0u8; 5]).unwrap_err().to_string();
        assert!(
            e.contains("bad.flo") && e.contains("truncated") && e.contains("5 bytes"),
            "{e}"
        );
    }
}
