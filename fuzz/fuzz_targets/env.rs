//! An environment file of arbitrary bytes (Radiance `.hdr`, OpenEXR, PNG: whatever the
//! header says): decoding it within the image limits and making an environment of it
//! must return one or an error, never panic or allocate without bound. An accepted map's
//! suns are then taken out of it as the yaw table does (each found in what the last
//! left, at most `MAX_SUNS`): every sun found must have a finite unit direction and a
//! finite, non-negative illuminance.
#![no_main]

use frf_core::env::EnvMap;
use frf_core::sun::Sun;
use frf_reflectance::sun_light::MAX_SUNS;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(image) = frf_core::io::read_rgb_bytes(std::path::Path::new("fuzz.hdr"), data) else {
        return;
    };
    let Ok(env) = EnvMap::from_image(image) else {
        return;
    };
    let mut rest: Option<EnvMap> = None;
    for _ in 0..MAX_SUNS {
        let Ok(Some((sun, less))) = Sun::extract(rest.as_ref().unwrap_or(&env)) else {
            break;
        };
        let d = sun.direction();
        assert!(
            d.is_finite() && (d.length() - 1.0).abs() <= 1e-4,
            "sun direction {d} is not a finite unit vector"
        );
        let e = sun.illuminance();
        assert!(
            e.iter().all(|c| c.is_finite() && *c >= 0.0),
            "sun illuminance {e:?} is not finite and non-negative"
        );
        rest = Some(less);
    }
});
