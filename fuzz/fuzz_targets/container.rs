//! A field file of arbitrary bytes: opening it, reading and decoding every chunk it
//! indexes (basis, alpha, flows, pose-to-pose flows, shadow maps, hulls: what `frf info
//! --check` does), checking its pose flows' records and its statistics must return
//! errors, never panic or allocate without bound.
#![no_main]

use frf_reflectance::FieldFile;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(field) = FieldFile::from_source(std::path::Path::new("fuzz.frf"), data.to_vec()) else {
        return;
    };
    let _ = field.stats();
    let _ = field.header().check_pose_flows();
    if field.chunks().count() <= 256 {
        let _ = field.verify(&|| {});
    }
});
