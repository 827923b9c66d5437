//! A scene file of arbitrary text: parsing and validating it (and, when it parses,
//! listing its frame times) must return a scene or an error naming the line, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(scene) = frf_scene::Scene::parse(std::path::Path::new("fuzz.toml"), text) {
        let _ = scene.frame_times();
    }
});
