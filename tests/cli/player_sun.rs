//! A sun in the web player as frf relights it, in Chromium against `frf render`: the tiny
//! oracle field exported with its basis images (`frf export --basis`), lit by the built-in
//! sky's L2 light and frf's default sun (E = 10) from the front, behind and the side; the
//! player carries the sun by the nearest conditions' images with frf's trust, and the
//! same field exported without them (the sun by albedo and normal, the negative control)
//! misses; the sky's own sun found in its map, and two suns at once. Damaged basis images
//! and a light file's bad sun are refused by name.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::common::{frf, stderr};
use crate::player::{frf_frame, grid_camera, screenshot, subject_psnr};

/// The tiny oracle field's pose 0 exported (`extra` export flags) to `name` in `dir`.
fn export(dir: &Path, name: &str, extra: &[&str]) -> PathBuf {
    let f = frf_testkit::tiny_field();
    let glb = dir.join(name);
    let mut args = vec!["export", f.field.to_str().unwrap(), "--poses", "0"];
    args.extend(extra);
    args.extend(["--out", glb.to_str().unwrap()]);
    let o = frf(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    glb
}

#[test]
fn the_player_relights_a_sun_by_the_basis_as_frf_does() {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    let (basis, plain) = (
        export(dir.path(), "basis.glb", &["--basis"]),
        export(dir.path(), "plain.glb", &[]),
    );
    let sh = dir.path().join("sky.json");
    let o = frf(&["env-sh", "sky", "--out", sh.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let document = frf_export::read::Export::open(&basis).unwrap().document;
    // (u, v, the sun's azimuth and elevation): captured views and quad centres, the sun
    // from the front, behind and the side of the walker (it faces +x: azimuth 90).
    let cases = [
        (3.0, 1.0, "60,40"),
        (20.0, 0.0, "240,40"),
        (11.5, 1.5, "150,30"),
        (3.5, 0.5, "240,40"),
    ];
    let mut control = Vec::new();
    for (k, (u, v, sun)) in cases.into_iter().enumerate() {
        let shot = grid_camera(&document, u, v);
        let case = dir.path().join(format!("{k}"));
        std::fs::create_dir_all(&case).unwrap();
        let reference = frf_frame(&f.field, &sh, &shot, "64x90", Some(sun), &case);
        let mut psnr = [0.0; 2];
        for (i, glb) in [&basis, &plain].into_iter().enumerate() {
            let out = case.join(format!("player-{i}.png"));
            let o = screenshot(glb, &sh, &shot, "64x90", Some(sun), &out);
            assert!(o.status.success(), "{}", stderr(&o));
            psnr[i] = subject_psnr(&reference, &out);
        }
        eprintln!(
            "({u}, {v}), sun {sun}: by the basis {:.2} dB, by albedo and normal {:.2} dB",
            psnr[0], psnr[1]
        );
        assert!(psnr[0] >= 30.0, "({u}, {v}), sun {sun}: {:.2} dB", psnr[0]);
        control.push(psnr[1]);
    }
    // The control: albedo and normal alone miss the target somewhere.
    let worst = control.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(worst < 30.0, "albedo and normal alone: {control:?}");
    // The sky's own sun, found in its map (`frf env-sh --suns`): the light file carries
    // it beside the L2 of the rest; frf paints it back and finds it again.
    let found = dir.path().join("sky-suns.json");
    let o = frf(&["env-sh", "sky", "--suns", "--out", found.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Two suns at once, from either side (a light file's suns, as `frf env-sh --suns`
    // writes them): both relit sharply, their trusts weighted by their luminance.
    let mut light: Value = serde_json::from_slice(&std::fs::read(&sh).unwrap()).unwrap();
    light["suns"] = serde_json::json!([
        {"direction": [0.66, 0.64, 0.38], "diameter_deg": 0.53, "illuminance": [6.0, 6.0, 6.0]},
        {"direction": [-0.75, 0.5, -0.43], "diameter_deg": 0.53, "illuminance": [4.0, 3.5, 3.0]}
    ]);
    let two = dir.path().join("two-suns.json");
    std::fs::write(&two, light.to_string()).unwrap();
    for (u, v, light) in [(3.0, 1.0, &found), (20.0, 0.0, &found), (11.5, 1.5, &two)] {
        let shot = grid_camera(&document, u, v);
        let case = dir.path().join(format!("found-{u}-{v}"));
        std::fs::create_dir_all(&case).unwrap();
        let reference = frf_frame(&f.field, light, &shot, "64x90", None, &case);
        let out = case.join("player.png");
        let o = screenshot(&basis, light, &shot, "64x90", None, &out);
        assert!(o.status.success(), "{}", stderr(&o));
        let psnr = subject_psnr(&reference, &out);
        eprintln!("({u}, {v}), the suns of {light:?}: {psnr:.2} dB");
        assert!(psnr >= 30.0, "({u}, {v}), {light:?}: {psnr:.2} dB");
    }
}

/// A change to an export's JSON.
type Edit = Box<dyn Fn(&mut Value)>;

#[test]
fn damaged_basis_images_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let glb = export(dir.path(), "walker.glb", &["--basis", "--views", "3,1;4,1"]);
    let sh = dir.path().join("sky.json");
    let o = frf(&["env-sh", "sky", "--out", sh.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&glb).unwrap();
    let document = frf_export::read::Export::open(&glb).unwrap().document;
    let shot = grid_camera(&document, 3.0, 1.0);
    let edits: [(&str, Edit, &str); 3] = [
        (
            "scales",
            Box::new(|d| {
                let ext = &mut d["extensions"]["FRF_flowed_reflectance_field"];
                ext["poses"][0]["views"][1]["basis"]["scale"]
                    .as_array_mut()
                    .unwrap()
                    .pop();
            }),
            "view 4,1: its basis holds no three atlases",
        ),
        (
            "conditions",
            Box::new(|d| {
                let ext = &mut d["extensions"]["FRF_flowed_reflectance_field"];
                let c = ext["basis"]["conditions"][0].clone();
                let all = ext["basis"]["conditions"].as_array_mut().unwrap();
                all.extend(std::iter::repeat_n(c, 40));
            }),
            "conditions, this player takes 2 to 32",
        ),
        (
            "atlas",
            // A view's basis atlas swapped for its alpha: the wrong size.
            Box::new(|d| {
                let ext = &mut d["extensions"]["FRF_flowed_reflectance_field"];
                let alpha = ext["poses"][0]["views"][0]["alpha"].clone();
                ext["poses"][0]["views"][0]["basis"]["images"][0] = alpha;
            }),
            "pose 0 view 3,1 basis",
        ),
    ];
    for (name, edit, want) in edits {
        let damaged = dir.path().join(format!("{name}.glb"));
        std::fs::write(&damaged, crate::player::with_json(&bytes, |d| edit(d))).unwrap();
        let out = dir.path().join(format!("{name}.png"));
        let o = screenshot(&damaged, &sh, &shot, "64x90", Some("60,40"), &out);
        let err = stderr(&o);
        assert!(!o.status.success(), "{name}: drawn");
        assert!(
            err.contains(&format!("{name}.glb")) && err.contains(want),
            "{name}: {err}"
        );
        assert!(!out.exists(), "{name}: {out:?} written");
    }
    // A light file's sun the player cannot take, refused by name as frf refuses it.
    let mut light: Value = serde_json::from_slice(&std::fs::read(&sh).unwrap()).unwrap();
    light["suns"] =
        serde_json::json!([{"direction": [0, 1, 0], "diameter_deg": 30, "illuminance": [1, 1, 1]}]);
    let bad = dir.path().join("bad-sun.json");
    std::fs::write(&bad, light.to_string()).unwrap();
    let out = dir.path().join("bad-sun.png");
    let o = screenshot(&glb, &bad, &shot, "64x90", None, &out);
    let err = stderr(&o);
    assert!(!o.status.success() && !out.exists(), "{err}");
    assert!(
        err.contains("bad-sun.json") && err.contains("sun 0's diameter 30°"),
        "{err}"
    );
}
