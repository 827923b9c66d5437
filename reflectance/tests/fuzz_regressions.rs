//! Inputs that fuzzing (`fuzz/`) once found to crash or to allocate without bound, kept
//! and replayed: each must now be refused with an error.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::Path;

use frf_reflectance::FieldFile;
use frf_reflectance::flowcodec::{self, quant::LogQuantizer};
use frf_reflectance::imagecodec::{decode_basis, decode_planes};

fn inputs(target: &str) -> Vec<(String, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_regressions")
        .join(target);
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            (p.display().to_string(), std::fs::read(&p).unwrap())
        })
        .collect();
    out.sort();
    out
}

#[test]
fn image_decoder_regressions_are_refused() {
    let cases = inputs("images");
    assert!(!cases.is_empty(), "the regression inputs are missing");
    for (name, bytes) in cases {
        for e in [decode_planes(&bytes).err(), decode_basis(&bytes).err()] {
            let e = e.unwrap_or_else(|| panic!("{name} decodes")).to_string();
            assert!(e.starts_with("corrupt data:"), "{name}: {e}");
        }
        // Run through every decoder: none may panic on it.
        let _ = flowcodec::decode(&bytes, &LogQuantizer::new(0.3, 20.0).unwrap());
        let _ = FieldFile::from_source(Path::new(&name), bytes);
    }
}

#[test]
fn environment_regressions_are_refused_within_the_image_limits() {
    let cases = inputs("env");
    assert!(!cases.is_empty(), "the regression inputs are missing");
    for (name, bytes) in cases {
        let e = frf_core::io::read_rgb_bytes(Path::new(&name), &bytes)
            .err()
            .unwrap_or_else(|| panic!("{name} decodes"))
            .to_string();
        assert!(e.contains(&name) && e.contains("limit"), "{e}");
    }
}
