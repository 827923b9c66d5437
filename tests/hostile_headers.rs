//! Allocation limits against hostile headers, one case per decoder: a header that claims
//! an enormous image, map, plane set, hull or index (with none of the data behind it) is
//! refused with a message saying so, and the decoder reserves almost nothing on the way.
//! A counting allocator measures the peak memory each refusal took.

#![allow(clippy::unwrap_used)]
// tests: a failed unwrap is a failed test
// A global allocator is an unsafe trait; this one only counts and forwards to `System`.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, counting live bytes and their peak.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let now = LIVE.fetch_add(layout.size(), Ordering::SeqCst) + layout.size();
        PEAK.fetch_max(now, Ordering::SeqCst);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::SeqCst);
        // SAFETY: `ptr` came from `System.alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// One measurement at a time (the test harness runs tests on several threads).
static SERIAL: Mutex<()> = Mutex::new(());

/// Runs `decode`, which must fail with a message holding every one of `words`, and
/// returns the most memory it held at once beyond what was live before, in bytes.
fn refused_peak<T>(words: &[&str], decode: impl FnOnce() -> Result<T, String>) -> usize {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let before = LIVE.load(Ordering::SeqCst);
    PEAK.store(before, Ordering::SeqCst);
    let outcome = decode();
    let peak = PEAK.load(Ordering::SeqCst) - before;
    let e = outcome.err().expect("the hostile input was accepted");
    assert!(words.iter().all(|w| e.contains(w)), "{e}");
    peak
}

/// Far below what any of these headers claims (gigabytes), above a decoder's own state.
const SMALL: usize = 8 << 20;

fn bad(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/bad")
        .join(name)
}

fn le(v: u32) -> [u8; 4] {
    v.to_le_bytes()
}

#[test]
fn image_headers_claiming_1e9_pixels_are_refused_before_allocating() {
    for name in ["huge.png", "huge.hdr"] {
        let peak = refused_peak(&[name, "limit"], || {
            frf_core::io::read_rgb(&bad(name)).map_err(|e| e.to_string())
        });
        assert!(peak < SMALL, "{name}: {peak} bytes");
    }
    // An EXR whose data window claims 10^9 x 10^9 pixels: a valid 8x4 file, patched.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.exr");
    let mut bytes = std::fs::read(bad("nan.exr")).unwrap();
    let window = b"dataWindow\0box2i\0";
    let at = bytes
        .windows(window.len())
        .position(|w| w == window)
        .unwrap()
        + window.len()
        + 4;
    bytes[at + 8..at + 12].copy_from_slice(&le(999_999_999));
    bytes[at + 12..at + 16].copy_from_slice(&le(999_999_999));
    std::fs::write(&path, &bytes).unwrap();
    let peak = refused_peak(&["huge.exr"], || {
        frf_core::io::read_rgb(&path).map_err(|e| e.to_string())
    });
    assert!(peak < SMALL, "huge.exr: {peak} bytes");
}

#[test]
fn a_flo_header_claiming_1e9_vectors_is_refused_before_allocating() {
    let path = bad("bad_size.flo");
    let bytes = std::fs::read(&path).unwrap();
    let peak = refused_peak(&["bad_size.flo", "1000000000x1000000000"], || {
        frf_core::flo::decode_flo(&path, &bytes).map_err(|e| e.to_string())
    });
    assert!(peak < SMALL, "{peak} bytes");
}

#[test]
fn field_chunk_headers_claiming_huge_payloads_are_refused_before_allocating() {
    use frf_reflectance::flowcodec::{self, quant::LogQuantizer};
    use frf_reflectance::imagecodec::{decode_basis, decode_planes};
    // A flow map of the largest accepted side whose mask is a few bytes.
    let small_zstd = zstd::bulk::compress(&[1u8; 16], 3).unwrap();
    let mut map = vec![0u8];
    map.extend(le(16384));
    map.extend(le(16384));
    map.extend(le(small_zstd.len() as u32));
    map.extend(&small_zstd);
    map.extend([0u8; 128]);
    let q = LogQuantizer::new(0.3, 20.0).unwrap();
    let peak = refused_peak(&["flow mask", "expected 268435456"], || {
        flowcodec::decode(&map, &q).map_err(|e| e.to_string())
    });
    assert!(peak < SMALL, "flow map: {peak} bytes");
    // 1024 planes of 16384 x 16384 (512 GiB) over a 20-byte payload.
    let mut planes = [le(1024), le(16384), le(16384)].concat();
    planes.extend(&small_zstd);
    let peak = refused_peak(&["plane data", "exceed"], || {
        decode_planes(&planes).map_err(|e| e.to_string())
    });
    assert!(peak < SMALL, "planes: {peak} bytes");
    // A basis mosaic of 26 tiles of 16384 x 16384 whose JPEG is a few bytes.
    let mut basis = [le(26), le(16384), le(16384)].concat();
    basis.extend((0..26).flat_map(|_| 1f32.to_le_bytes()));
    basis.extend([0xFF, 0xD8, 0xFF, 0xD9]);
    let peak = refused_peak(&["basis"], || {
        decode_basis(&basis).map_err(|e| e.to_string())
    });
    assert!(peak < SMALL, "basis: {peak} bytes");
    // A visual hull whose grid claims 4096^3 voxels.
    let mut grid = Vec::new();
    for v in [0f32, 0.0, 0.0, 0.01] {
        grid.extend(v.to_le_bytes());
    }
    grid.extend([le(4096), le(4096), le(4096)].concat());
    let hull = zstd::bulk::compress(&grid, 3).unwrap();
    let peak = refused_peak(&["visual hull"], || {
        frf_reflectance::hull::VoxelHull::decode(&hull).map_err(|e| e.to_string())
    });
    assert!(peak < SMALL, "hull: {peak} bytes");
}

#[test]
fn a_field_index_declaring_gigabytes_is_refused_before_allocating() {
    // Preamble, an index whose zstd frame declares 2 GiB (a frame header only), footer.
    let mut frame = vec![0x28, 0xB5, 0x2F, 0xFD, 0x84, 0x00]; // magic; 8-byte size, no window
    frame.extend((2u64 << 30).to_le_bytes());
    frame.extend([1, 0, 0]); // last raw block of 0 bytes
    let mut file = b"FRFFIELD".to_vec();
    file.extend([le(1), le(0)].concat());
    let at = file.len() as u64;
    file.extend(&frame);
    file.extend(at.to_le_bytes());
    file.extend((frame.len() as u64).to_le_bytes());
    file.extend(le(crc32fast::hash(&frame)));
    file.extend(le(1));
    file.extend(b"FRFEND\0\0");
    let peak = refused_peak(&["hostile.frf", "index", "2147483648"], || {
        frf_reflectance::FieldFile::from_source(Path::new("hostile.frf"), file)
            .map(|_| ())
            .map_err(|e| e.to_string())
    });
    assert!(peak < SMALL, "index: {peak} bytes");
}
