//! A capture manifest (`capture.toml`) of arbitrary text: parsing and validating it must
//! return a capture or an error naming the field, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = frf_core::capture::Capture::parse_manifest(std::path::Path::new("fuzz"), text);
});
