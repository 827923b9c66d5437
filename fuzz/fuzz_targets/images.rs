//! Basis mosaics and 16-bit planes of arbitrary bytes: errors, never panics.
#![no_main]

use frf_reflectance::imagecodec::{decode_basis, decode_planes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = decode_basis(data);
    let _ = decode_planes(data);
});
