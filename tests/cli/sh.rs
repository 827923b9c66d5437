//! `frf env-sh` and SH lights as `--env`: the file holds the map's projection; a light
//! that is L2 already (a uniform furnace) renders the same through its SH file as
//! itself; a damaged SH file is refused by name and nothing is written.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use crate::common::{frf, stderr};

/// Renders one frame of the tiny oracle field under `env` into `out`; its PNG's pixels.
fn one_frame(env: &str, out: &std::path::Path) -> Result<image::RgbaImage, String> {
    let f = frf_testkit::tiny_field();
    let mut args = vec![
        "render",
        f.field.to_str().unwrap(),
        "--env",
        env,
        "--orbit",
        "3.2,1.3",
        "--frames",
        "1",
        "--size",
        "48x64",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(frf_testkit::cpu_flag());
    let o = frf(&args);
    if !o.status.success() {
        return Err(stderr(&o));
    }
    Ok(image::open(out.join("frame_0000.png")).unwrap().to_rgba8())
}

#[test]
fn env_sh_writes_the_projection_and_renders_an_l2_light_as_itself() {
    let dir = tempfile::tempdir().unwrap();
    let sky = dir.path().join("sky.json");
    let o = frf(&["env-sh", "sky", "--out", sky.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("energy kept by L2"), "{text}");
    let written = frf_core::sh::ShLight::load(&sky).unwrap();
    let map = frf_core::env::EnvMap::sky();
    assert_eq!(written, map.to_sh());
    // Checked apart from the projection's code too (it was checked against the same
    // `to_sh` call): band 0 is the total light over 2 sqrt(pi), and band 1's y term
    // (three.js's second, sqrt(3 / 4 pi) y) its light weighted by height, each summed
    // here texel by texel.
    let img = map.image();
    let (mut total, mut up) = ([0.0f64; 3], [0.0f64; 3]);
    for y in 0..img.height() {
        let omega = f64::from(map.texel_solid_angle(y));
        for x in 0..img.width() {
            let d = map.direction_of(x as f32, y as f32);
            let l = img.get(x, y);
            for c in 0..3 {
                total[c] += f64::from(l[c]) * omega;
                up[c] += f64::from(l[c]) * f64::from(d.y) * omega;
            }
        }
    }
    let pi = std::f64::consts::PI;
    for c in 0..3 {
        let band_0 = total[c] / (2.0 * pi.sqrt());
        let y_term = (3.0 / (4.0 * pi)).sqrt() * up[c];
        let (got_0, got_y) = (
            f64::from(written.coefficients[0][c]),
            f64::from(written.coefficients[1][c]),
        );
        assert!(
            (got_0 - band_0).abs() < 1e-4 * band_0,
            "band 0: {got_0} vs {band_0}"
        );
        assert!(
            (got_y - y_term).abs() < 1e-3 * band_0,
            "band 1 y: {got_y} vs {y_term}"
        );
    }

    // A furnace is band 0 alone: through its file it lights as itself.
    let uniform = dir.path().join("uniform.json");
    let o = frf(&["env-sh", "uniform", "--out", uniform.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let direct = one_frame("uniform", &dir.path().join("direct")).unwrap();
    let by_sh = one_frame(uniform.to_str().unwrap(), &dir.path().join("sh")).unwrap();
    let lit = direct.pixels().filter(|p| p[3] > 128 && p[0] > 10).count();
    assert!(lit > 200, "{lit} lit pixels");
    // The subject (the ground's shadow is cast by lights sampled from the map, whose
    // samples move with its resolution).
    let worst = direct
        .pixels()
        .zip(by_sh.pixels())
        .filter(|(a, _)| a[3] > 200)
        .map(|(a, b)| (0..4).map(|c| a[c].abs_diff(b[c])).max().unwrap())
        .max()
        .unwrap();
    assert!(worst <= 1, "the SH furnace differs by {worst} codes");

    // A damaged file: refused, naming it; no frame written.
    let bad = dir.path().join("bad.json");
    let cut = std::fs::read_to_string(&uniform).unwrap();
    std::fs::write(&bad, &cut[..cut.len() / 3]).unwrap();
    let out = dir.path().join("bad_out");
    let e = one_frame(bad.to_str().unwrap(), &out).unwrap_err();
    assert!(
        e.contains("bad.json") && e.contains("not an SH light"),
        "{e}"
    );
    assert!(!out.join("frame_0000.png").exists());
}

/// A 1x1 uniform map is the uniform light it stands for (issue 59): `env-sh` keeps 100 %
/// of its energy in band 0 (it reported 900 %) and a frame under it is the frame under the
/// built-in uniform light of the same radiance (its subject was 12 times darker). A map
/// with a negative texel is read with a warning naming the file and the value (it was
/// clamped silently).
#[test]
fn a_one_texel_map_lights_as_the_uniform_light_and_a_negative_texel_is_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one.exr");
    frf_core::io::write_exr_rgb(&one, &frf_core::image::Image::new(1, 1, [1.0f32; 3])).unwrap();
    let sh = dir.path().join("one.json");
    let o = frf(&[
        "env-sh",
        one.to_str().unwrap(),
        "--out",
        sh.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("energy kept by L2 (sum of squared coefficients / integral of squared radiance, luminance): 100.0 %"), "{text}");
    let direct = one_frame("uniform", &dir.path().join("direct")).unwrap();
    let by_map = one_frame(one.to_str().unwrap(), &dir.path().join("map")).unwrap();
    let subject = |img: &image::RgbaImage| {
        let lit: Vec<f64> = (img.pixels())
            .filter(|p| p[3] > 200)
            .map(|p| f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2]))
            .collect();
        lit.iter().sum::<f64>() / lit.len().max(1) as f64
    };
    let (a, b) = (subject(&direct), subject(&by_map));
    assert!(
        a > 30.0 && (a - b).abs() < 0.03 * a,
        "uniform {a:.1}, 1x1 map {b:.1}"
    );
    // A texel of -1e6 among positive ones.
    let mut img = frf_core::image::Image::new(8, 4, [1.0f32; 3]);
    img.set(3, 2, [-1e6, 1.0, 1.0]);
    let negative = dir.path().join("negative.exr");
    frf_core::io::write_exr_rgb(&negative, &img).unwrap();
    let o = frf(&[
        "env-sh",
        negative.to_str().unwrap(),
        "--out",
        dir.path().join("negative.json").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("negative.exr") && err.contains("-1.000e6") && err.contains("clamped"),
        "{err}"
    );
}

/// `env-sh --yaw` of any size turns the map by the turn it names mod 360 (1e9° is -80°;
/// its f32 radians gave coefficients off by up to 0.85), and beyond the stated range it is
/// refused by name (issue 59).
#[test]
fn a_yaw_of_any_size_is_the_turn_it_names() {
    let dir = tempfile::tempdir().unwrap();
    let project = |yaw: &str| {
        let out = dir.path().join(format!("sky_{yaw}.json"));
        let o = frf(&[
            "env-sh",
            "sky",
            "--yaw",
            yaw,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        frf_core::sh::ShLight::load(&out).unwrap()
    };
    assert_eq!(project("1e9"), project("-80"));
    assert_ne!(project("1e9"), project("0"));
    let o = frf(&["env-sh", "sky", "--yaw", "2e15", "--out", "x.json"]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("--yaw") && e.contains("beyond"), "{e}");
}

/// `frf env-sh --suns`: the built-in sky's sun is found where the sky puts it (azimuth
/// 60°, elevation 40°) and written beside the L2 light of the sky less it, whose total
/// light is the sky's less the sun's; a map with no sun writes none and says so.
#[test]
fn env_sh_suns_takes_the_maps_suns_out_and_writes_them_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sky.json");
    let o = frf(&["env-sh", "sky", "--suns", "--out", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("sun 0: azimuth 60.0°, elevation 40."),
        "{text}"
    );
    let (rest, suns) = frf_core::sh::ShLight::load_with_suns(&path).unwrap();
    assert_eq!(suns.len(), 1, "{suns:?}");
    let whole = frf_core::env::EnvMap::sky().to_sh();
    let band0 = (4.0 * std::f32::consts::PI).sqrt();
    for c in 0..3 {
        let taken = (whole.coefficients[0][c] - rest.coefficients[0][c]) * band0;
        let e = suns[0].illuminance[c];
        assert!(
            (taken - e).abs() < 0.02 * e,
            "channel {c}: {taken} taken, sun {e}"
        );
    }
    let uniform = dir.path().join("uniform.json");
    let o = frf(&[
        "env-sh",
        "uniform",
        "--suns",
        "--out",
        uniform.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("no sun found"));
    assert!(
        frf_core::sh::ShLight::load_with_suns(&uniform)
            .unwrap()
            .1
            .is_empty()
    );
}
