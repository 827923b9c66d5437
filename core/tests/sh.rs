//! L2 lights (`frf_core::sh`) and their maps (`frf_core::env`): the basis is orthonormal,
//! a projection recovers a band-limited light, irradiance is the cosine integral and
//! three.js's published constants, the conventions round trip, a light in an engine's
//! frame is the same light, and files round trip or are refused by name.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::f32::consts::PI;

use frf_core::env::EnvMap;
use frf_core::sh::{ENGINE_FRAMES, SH_COUNT, SH_ORDER, ShLight, sh_basis, weighted};
use glam::{Mat3, Vec3};

/// Unit directions spread over the sphere.
fn directions(n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let phi = i as f32 * 2.399_963;
            let r = (1.0 - y * y).sqrt();
            Vec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

fn light() -> ShLight {
    let mut c = [[0.0f32; 3]; SH_COUNT];
    for (i, ci) in c.iter_mut().enumerate() {
        let i = i as f32;
        *ci = [0.3 / (1.0 + i), 0.1 - 0.03 * i, 0.3 * (i * 0.7).sin()];
    }
    // Band 0 above the others' largest sum: positive everywhere.
    c[0] = [6.0, 5.5, 5.0];
    ShLight::from_coefficients(c)
}

#[test]
fn the_basis_is_orthonormal_and_a_projection_recovers_a_band_limited_light() {
    let probe = EnvMap::uniform([0.0; 3], 256);
    let mut gram = [[0.0f64; SH_COUNT]; SH_COUNT];
    for y in 0..256 {
        let omega = probe.texel_solid_angle(y) as f64;
        for x in 0..512 {
            let b = sh_basis(probe.direction_of(x as f32, y as f32));
            for i in 0..SH_COUNT {
                for j in 0..SH_COUNT {
                    gram[i][j] += b[i] as f64 * b[j] as f64 * omega;
                }
            }
        }
    }
    for (i, row) in gram.iter().enumerate() {
        for (j, g) in row.iter().enumerate() {
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((g - want).abs() < 2e-3, "<Y{i}, Y{j}> = {g}");
        }
    }
    let l = light();
    let back = EnvMap::from_sh(&l, 256).unwrap().to_sh();
    for (a, b) in l.coefficients.iter().zip(back.coefficients) {
        for c in 0..3 {
            assert!(
                (a[c] - b[c]).abs() < 2e-3 * (1.0 + a[c].abs()),
                "{a:?} {b:?}"
            );
        }
    }
}

#[test]
fn irradiance_is_the_cosine_integral_and_matches_three_js_constants() {
    let l = light();
    let env = EnvMap::from_sh_clamped(&l, 256).unwrap();
    assert_eq!(env.clamped_texels(), 0, "the test light is positive");
    for n in directions(12) {
        // The cosine integral of the map itself.
        let mut e = [0.0f64; 3];
        for y in 0..256 {
            let omega = env.texel_solid_angle(y) as f64;
            for x in 0..512 {
                let d = env.direction_of(x as f32, y as f32);
                let cos = n.dot(d).max(0.0) as f64;
                let r = env.image().get(x, y);
                for c in 0..3 {
                    e[c] += r[c] as f64 * cos * omega;
                }
            }
        }
        // Three.js's getIrradianceAt, its published constants.
        let (x, y, z) = (n.x, n.y, n.z);
        let k = [
            0.886_227,
            2.0 * 0.511_664 * y,
            2.0 * 0.511_664 * z,
            2.0 * 0.511_664 * x,
            2.0 * 0.429_043 * x * y,
            2.0 * 0.429_043 * y * z,
            0.743_125 * z * z - 0.247_708,
            2.0 * 0.429_043 * x * z,
            0.429_043 * (x * x - y * y),
        ];
        let three = weighted(&l.coefficients, k);
        let ours = l.irradiance(n);
        for c in 0..3 {
            assert!(
                (ours[c] - three[c]).abs() < 1e-4 * (1.0 + three[c].abs()),
                "{ours:?} {three:?}"
            );
            // Exact for a band-limited light (the lobe's higher bands meet none of
            // it): quadrature error only.
            assert!(
                (ours[c] as f64 - e[c]).abs() < 1e-3 * e[c].abs(),
                "{ours:?} {e:?}"
            );
        }
    }
}

#[test]
fn conventions_round_trip() {
    let l = light();
    // Condon–Shortley: odd m negated, and back.
    let cs = l.condon_shortley();
    assert_eq!(cs[1], l.coefficients[1].map(|v| -v));
    assert_eq!(cs[2], l.coefficients[2]);
    assert_eq!(cs[7], l.coefficients[7].map(|v| -v));
    assert_eq!(ShLight::from_condon_shortley(cs), l);
    // With the phase in the basis too, the light is the same.
    for d in directions(20) {
        let mut b = sh_basis(d);
        for (i, (_, m)) in SH_ORDER.iter().enumerate() {
            if m % 2 != 0 {
                b[i] = -b[i];
            }
        }
        let (a, r) = (weighted(&cs, b), l.radiance(d));
        assert!((0..3).all(|c| (a[c] - r[c]).abs() < 1e-5), "{a:?} {r:?}");
    }
    // Unity's seven vectors give the irradiance over π.
    let v = l.unity_shader_vectors();
    for n in directions(20) {
        let (x, y, z) = (n.x, n.y, n.z);
        let e = l.irradiance(n);
        for c in 0..3 {
            let (a, b) = (v[c], v[3 + c]);
            let shade = a[0] * x
                + a[1] * y
                + a[2] * z
                + a[3]
                + b[0] * x * y
                + b[1] * y * z
                + b[2] * z * z
                + b[3] * z * x
                + v[6][c] * (x * x - y * y);
            assert!((shade - e[c] / PI).abs() < 1e-5, "{shade} {}", e[c] / PI);
        }
    }
}

#[test]
fn files_round_trip_and_bad_ones_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("light.json");
    let l = light();
    l.save(&path, "test").unwrap();
    assert_eq!(ShLight::load(&path).unwrap(), l);
    let text = std::fs::read_to_string(&path).unwrap();
    let cases = [
        (
            text.replace("\"version\": 1", "\"version\": 2"),
            "version 2",
        ),
        (
            text.replace(
                "\"condon_shortley_phase\": false",
                "\"condon_shortley_phase\": true",
            ),
            "its convention is not frf's: condon_shortley_phase true, frf's false",
        ),
        // Band 0 below zero: a light that takes light away (it rendered at -16 dB).
        (
            text.replacen("5.5,", "-5.5,", 1),
            "band 0 (its total light) is negative in channel 1",
        ),
        (text.replace("frf-sh-l2", "other"), "format"),
        (text[..text.len() / 2].to_string(), "not an SH light"),
    ];
    for (bad, want) in cases {
        std::fs::write(&path, bad).unwrap();
        let e = ShLight::load(&path).unwrap_err().to_string();
        assert!(e.contains(want) && e.contains("light.json"), "{e}");
        // The difference named, not two structs printed.
        assert!(!e.contains("Convention {"), "{e}");
    }
    // A byte-order mark before the JSON is read past.
    let mut with_bom = b"\xEF\xBB\xBF".to_vec();
    with_bom.extend_from_slice(text.as_bytes());
    std::fs::write(&path, with_bom).unwrap();
    assert_eq!(ShLight::load(&path).unwrap(), l);
    let mut f: serde_json::Value = serde_json::from_str(&text).unwrap();
    f["coefficients"].as_array_mut().unwrap().pop();
    std::fs::write(&path, f.to_string()).unwrap();
    let e = ShLight::load(&path).unwrap_err().to_string();
    assert!(e.contains("8 coefficients"), "{e}");
    f["coefficients"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!([1e39, 0, 0]));
    std::fs::write(&path, f.to_string()).unwrap();
    let e = ShLight::load(&path).unwrap_err().to_string();
    // Beyond f32 is refused as JSON out of f32's range.
    assert!(e.contains("number out of range"), "{e}");
    // Beyond the stated 1e30 of total light, and not only at f32's end.
    f["coefficients"].as_array_mut().unwrap().pop();
    f["coefficients"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!([0, 0, 0]));
    f["coefficients"][0] = serde_json::json!([1e30, 1.0, 1.0]);
    std::fs::write(&path, f.to_string()).unwrap();
    let e = ShLight::load(&path).unwrap_err().to_string();
    assert!(e.contains("beyond what relighting can sum"), "{e}");
}

/// A map of fewer than `MIN_MAP_ROWS` rows read from a file is integrated as its texels'
/// regions: the L2 light of a uniform 1x1, 2x1 and 4x2 map is band 0 alone (bands 1-8
/// within 1e-3 of it; 8e-4 measured, the row centres' error at 32 rows), `L * 2 sqrt(pi)`;
/// a 2x1 map of two halves projects as the same halves on a 256x128 grid (within 1e-3 of its band 0), and a loaded map keeps its total
/// light. Control: the same images wrapped as they are (`EnvMap::from_image`, texel
/// centres alone) give bands 1-8 as bright as band 0.
#[test]
fn a_tiny_map_integrates_its_texels_regions() {
    use frf_core::image::Image;
    let dir = tempfile::tempdir().unwrap();
    let read = |name: &str, img: &frf_core::image::RgbImage| {
        let path = dir.path().join(name);
        frf_core::io::write_exr_rgb(&path, img).unwrap();
        EnvMap::load(&path).unwrap()
    };
    let largest_past_band_0 = |sh: &ShLight| {
        sh.coefficients[1..]
            .iter()
            .flatten()
            .fold(0.0f32, |m, &c| m.max(c.abs()))
    };
    let band_0 = 2.0 * PI.sqrt();
    for (w, h) in [(1, 1), (2, 1), (4, 2)] {
        let img = Image::new(w, h, [1.0f32, 2.0, 3.0]);
        let sh = read(&format!("u{w}x{h}.exr"), &img).to_sh();
        for c in 0..3 {
            let want = (c + 1) as f32 * band_0;
            let got = sh.coefficients[0][c];
            assert!((got - want).abs() < 1e-4 * want, "{w}x{h}: {got} vs {want}");
        }
        // Against the brightest channel's band 0.
        let past = largest_past_band_0(&sh);
        assert!(
            past < 1e-3 * 3.0 * band_0,
            "{w}x{h}: bands 1-8 up to {past}"
        );
        // Control: the centres alone.
        let centres = EnvMap::from_image(img).unwrap().to_sh();
        assert!(
            largest_past_band_0(&centres) > 0.5 * band_0,
            "{w}x{h}: the centres alone ring less than expected"
        );
    }
    // Two halves: west 1, east 4.
    let halves = Image::from_vec(2, 1, vec![[1.0f32; 3], [4.0; 3]]).unwrap();
    let loaded = read("halves.exr", &halves);
    let fine = Image::from_fn(
        256,
        128,
        |x, _| if x < 128 { [1.0f32; 3] } else { [4.0; 3] },
    );
    let want = EnvMap::from_image(fine).unwrap().to_sh();
    let got = loaded.to_sh();
    for (a, b) in got.coefficients.iter().zip(&want.coefficients) {
        let scale = want.coefficients[0][0];
        assert!((a[0] - b[0]).abs() < 1e-3 * scale, "{a:?} vs {b:?}");
    }
    let total = loaded.total_light()[0];
    assert!((total - 10.0 * PI).abs() < 1e-4 * total, "total {total}");
}

/// Unity's `ShadeSH9` of its seven shader vectors `v` at normal `n`, channel `c`.
fn shade_sh9(v: &[[f32; 4]; 7], n: Vec3, c: usize) -> f32 {
    let (a, b) = (v[c], v[3 + c]);
    a[0] * n.x
        + a[1] * n.y
        + a[2] * n.z
        + a[3]
        + b[0] * n.x * n.y
        + b[1] * n.y * n.z
        + b[2] * n.z * n.z
        + b[3] * n.z * n.x
        + v[6][c] * (n.x * n.x - n.y * n.y)
}

/// Issue 60: a light taken into an engine's frame is the same light: its radiance at the
/// engine's direction of `d` is frf's at `d`, for each engine's frame, a turn and a z-up
/// left-handed frame; Unity's shader vectors of the light in Unity's frame shade Unity's
/// normal as frf's irradiance shades frf's (the worked example of docs/export.md), where
/// the light left in frf's frame does not (the control: the mirror matters).
#[test]
fn a_light_in_an_engines_frame_is_the_same_light() {
    let l = light();
    let mut frames: Vec<(&str, Mat3)> = ENGINE_FRAMES.to_vec();
    frames.push((
        "a turn",
        Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(-0.4),
    ));
    // z up, left-handed: (x, y, z) -> (z, -x, y).
    frames.push((
        "z up",
        Mat3::from_cols(Vec3::new(0.0, -1.0, 0.0), Vec3::Z, Vec3::X),
    ));
    for (name, to) in frames {
        let moved = l.in_frame(to);
        for d in directions(40) {
            let (a, b) = (moved.radiance(to * d), l.radiance(d));
            assert!(
                (0..3).all(|c| (a[c] - b[c]).abs() < 1e-4),
                "{name}: {a:?} against {b:?} at {d}"
            );
        }
    }
    // The worked example: a light brighter toward +x, radiance 0.282095 + 0.5 * 0.488603
    // x; in Unity's frame its x coefficient changes sign, and toward Unity's -x (frf's
    // +x) it is as bright.
    let mut c = [[0.0f32; 3]; SH_COUNT];
    (c[0], c[3]) = ([1.0; 3], [0.5; 3]);
    let example = ShLight::from_coefficients(c);
    let unity = ENGINE_FRAMES[3].1;
    let in_unity = example.in_frame(unity);
    assert!((in_unity.coefficients[3][0] + 0.5).abs() < 1e-6);
    let want = 0.282_095 + 0.5 * 0.488_603;
    assert!((example.radiance(Vec3::X)[0] - want).abs() < 1e-6);
    assert!((in_unity.radiance(Vec3::NEG_X)[0] - want).abs() < 1e-6);
    // Unity's ShadeSH9 of the light in Unity's frame, at Unity's normal.
    let v = l.in_frame(unity).unity_shader_vectors();
    let unmoved = l.unity_shader_vectors();
    let mut control = 0.0f32;
    for n in directions(20) {
        for (c, e) in l.irradiance(n).into_iter().enumerate() {
            let shade = shade_sh9(&v, unity * n, c);
            assert!((shade - e / PI).abs() < 1e-4, "{shade} {}", e / PI);
            control = control.max((shade_sh9(&unmoved, unity * n, c) - e / PI).abs());
        }
    }
    assert!(
        control > 1e-2,
        "the light left unmirrored shades Unity's normals alike"
    );
}

/// A light file's suns (`frf env-sh --suns`) come back as written, a bad one is refused
/// by name, and frf paints them into the light's map: its `∫ L dω` grows by their
/// illuminance, and [`frf_core::sun::Sun::extract`] finds the brightest where it was put.
#[test]
fn a_light_files_suns_round_trip_and_are_painted_into_its_map() {
    use frf_core::sh::ShSun;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("light.json");
    let l = light();
    let suns = [
        ShSun {
            direction: [0.5, 0.6, 0.2],
            diameter_deg: 0.53,
            illuminance: [9.0, 8.0, 7.0],
        },
        ShSun {
            direction: [-0.3, 0.2, -0.9],
            diameter_deg: 3.0,
            illuminance: [1.0, 1.0, 1.0],
        },
    ];
    l.save_with_suns(&path, "test", &suns).unwrap();
    let (back, back_suns) = ShLight::load_with_suns(&path).unwrap();
    assert_eq!((back, back_suns.as_slice()), (l.clone(), &suns[..]));
    let with = frf_core::env::EnvMap::load(&path).unwrap().total_light();
    l.save(&path, "test").unwrap();
    let without = frf_core::env::EnvMap::load(&path).unwrap().total_light();
    for c in 0..3 {
        let added = with[c] - without[c];
        let want = suns[0].illuminance[c] + suns[1].illuminance[c];
        assert!((added - want).abs() < 1e-3 * want, "{added} vs {want}");
    }
    l.save_with_suns(&path, "test", &suns).unwrap();
    let map = frf_core::env::EnvMap::load(&path).unwrap();
    let (found, _) = frf_core::sun::Sun::extract(&map).unwrap().unwrap();
    let want = glam::Vec3::from(suns[0].direction).normalize();
    assert!(found.direction().angle_between(want) < 1.5f32.to_radians());
    // Bad suns, refused by name.
    let text = std::fs::read_to_string(&path).unwrap();
    let mut f: serde_json::Value = serde_json::from_str(&text).unwrap();
    for (edit, want) in [
        (
            serde_json::json!({"direction": [0, 0, 0], "diameter_deg": 1, "illuminance": [1, 1, 1]}),
            "sun 1's direction",
        ),
        (
            serde_json::json!({"direction": [0, 1, 0], "diameter_deg": 30, "illuminance": [1, 1, 1]}),
            "sun 1's diameter 30°",
        ),
        (
            serde_json::json!({"direction": [0, 1, 0], "diameter_deg": 1, "illuminance": [1, -1, 1]}),
            "sun 1's illuminance",
        ),
    ] {
        f["suns"][1] = edit;
        std::fs::write(&path, f.to_string()).unwrap();
        let e = ShLight::load(&path).unwrap_err().to_string();
        assert!(e.contains(want) && e.contains("light.json"), "{e}");
    }
}

/// A sun painted into a signed map (an L2 light's, its negative lobes kept) and taken out
/// again leaves its other texels as they were, negative ones too: frf relights the light a
/// player relights, not that light clamped (clamped, a light file's sun rendered 15 dB
/// from the player's frame).
#[test]
fn a_sun_painted_into_a_signed_map_and_taken_out_keeps_its_negative_texels() {
    use frf_core::env::EnvMap;
    use frf_core::image::Image;
    let (w, h) = (64, 32);
    let radiance = Image::from_fn(w, h, |x, _| if x < 8 { [-0.2; 3] } else { [0.5; 3] });
    let map = EnvMap::signed(radiance).unwrap();
    let lit = map
        .with_disc(glam::Vec3::new(0.3, 0.8, 0.2).normalize(), 0.005, [20.0; 3])
        .unwrap();
    let (sun, rest) = frf_core::sun::Sun::extract(&lit).unwrap().unwrap();
    assert!(
        (sun.illuminance()[0] - 20.0).abs() < 0.5,
        "{:?}",
        sun.illuminance()
    );
    for (name, m) in [("lit", &lit), ("rest", &rest)] {
        let negative = m.image().pixels().iter().filter(|p| p[0] < 0.0).count();
        assert_eq!(negative, 8 * h, "{name}: {negative} negative texels");
    }
}
