//! zstd decompression of untrusted data without unbounded allocation. A zstd frame
//! declares its decompressed size in its header; a hostile header (or a field header
//! claiming huge planes) must not make the decoder reserve gigabytes before the data is
//! even looked at. So the declared size is read first, checked against what the caller
//! expects and against [`MAX_DECODED_BYTES`], and only then is memory reserved.

use crate::error::{ReflectanceError, Result};

/// Largest decompressed size accepted from a file: 1 GiB, above any real chunk (the
/// largest, a 4096x4096 view's alpha plane, is 32 MiB).
pub const MAX_DECODED_BYTES: usize = 1 << 30;

fn declared(src: &[u8], what: &str) -> Result<usize> {
    match zstd::zstd_safe::get_frame_content_size(src) {
        Ok(Some(n)) => usize::try_from(n)
            .map_err(|_| ReflectanceError::Corrupt(format!("{what}: declared size {n} is absurd"))),
        Ok(None) => Err(ReflectanceError::Corrupt(format!(
            "{what}: zstd frame without a declared size"
        ))),
        Err(_) => Err(ReflectanceError::Corrupt(format!(
            "{what}: not a zstd frame"
        ))),
    }
}

/// Decompresses `src`, which must declare exactly `expected` bytes.
pub fn decompress_exact(src: &[u8], expected: usize, what: &str) -> Result<Vec<u8>> {
    if expected > MAX_DECODED_BYTES {
        return Err(ReflectanceError::Corrupt(format!(
            "{what}: {expected} bytes exceed the {MAX_DECODED_BYTES}-byte limit"
        )));
    }
    let n = declared(src, what)?;
    if n != expected {
        return Err(ReflectanceError::Corrupt(format!(
            "{what}: holds {n} bytes, expected {expected}"
        )));
    }
    let out = zstd::bulk::decompress(src, expected).map_err(|e| {
        ReflectanceError::Corrupt(format!("{what}: damaged or truncated zstd data ({e})"))
    })?;
    if out.len() != expected {
        return Err(ReflectanceError::Corrupt(format!(
            "{what}: holds {} bytes, expected {expected}",
            out.len()
        )));
    }
    Ok(out)
}

/// Decompresses `src`, which must declare at most `limit` bytes.
pub fn decompress_at_most(src: &[u8], limit: usize, what: &str) -> Result<Vec<u8>> {
    let n = declared(src, what)?;
    if n > limit.min(MAX_DECODED_BYTES) {
        return Err(ReflectanceError::Corrupt(format!(
            "{what}: declares {n} bytes, more than the {limit} allowed"
        )));
    }
    decompress_exact(src, n, what)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_checked_before_allocating() {
        let data = vec![7u8; 1000];
        let packed = zstd::bulk::compress(&data, 3).unwrap();
        assert_eq!(decompress_exact(&packed, 1000, "x").unwrap(), data);
        let e = decompress_exact(&packed, 999, "x").unwrap_err().to_string();
        assert!(e.contains("x: holds 1000 bytes, expected 999"), "{e}");
        let e = decompress_exact(&packed, usize::MAX / 2, "x")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("x: ") && e.contains("exceed the 1073741824-byte limit"),
            "{e}"
        );
        assert_eq!(decompress_at_most(&packed, 1000, "x").unwrap(), data);
        let e = decompress_at_most(&packed, 999, "x")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("x: declares 1000 bytes, more than the 999 allowed"),
            "{e}"
        );
        let e = decompress_exact(&[0x0a], 10, "x").unwrap_err().to_string();
        assert!(e.contains("x: not a zstd frame"), "{e}");
        let e = decompress_at_most(&packed[..packed.len() - 2], 5000, "x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("x: damaged or truncated"), "{e}");
    }
}
