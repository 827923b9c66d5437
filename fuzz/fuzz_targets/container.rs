//! A field file of arbitrary bytes: opening it, reading every chunk it indexes and its
//! statistics must return errors, never panic or allocate without bound.
#![no_main]

use frf_reflectance::FieldFile;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(field) = FieldFile::from_source(std::path::Path::new("fuzz.frf"), data.to_vec()) else {
        return;
    };
    let _ = field.stats();
    let keys: Vec<_> = field.chunks().map(|c| c.key).collect();
    for key in keys.iter().take(64) {
        let _ = field.view(key.pose, key.u as usize, key.v as usize);
        let _ = field.shadows(key.pose);
    }
});
