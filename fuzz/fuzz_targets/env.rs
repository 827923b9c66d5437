//! An environment file of arbitrary bytes (Radiance `.hdr`, OpenEXR, PNG: whatever the
//! header says): decoding it within the image limits and making an environment of it
//! must return one or an error, never panic or allocate without bound.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(image) = frf_core::io::read_rgb_bytes(std::path::Path::new("fuzz.hdr"), data) else {
        return;
    };
    let _ = frf_core::env::EnvMap::from_image(image);
});
