//! The web player's walker among a three.js scene's objects, in Chromium: drawn with its
//! hull's depth, a box in front of it keeps every one of its pixels (the negative
//! control, the walker laid over the scene without depth, draws over the box), and a box
//! behind it is hidden where the walker is opaque.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::Path;
use std::process::Command;

use frf_core::camera::Camera;
use frf_core::io::linear_to_srgb;
use glam::Vec3;

use crate::common::stderr;
use crate::player::{exported, player};

const EYE: [f32; 3] = [0.3, 1.2, 4.2];
const LOOK_AT: [f32; 3] = [0.0, 0.9, 0.0];
const FOV_DEG: f32 = 30.0;
const SIZE: (u32, u32) = (128, 180);
/// A red box between the camera and the walker's hips, and a green one behind it:
/// centre, size, linear colour.
const FRONT: [f32; 9] = [0.15, 0.9, 1.2, 0.3, 0.3, 0.1, 0.8, 0.1, 0.1];
const BEHIND: [f32; 9] = [-0.3, 1.0, -0.8, 0.8, 1.4, 0.1, 0.1, 0.5, 0.1];

fn csv(v: &[f32]) -> String {
    v.iter().map(f32::to_string).collect::<Vec<_>>().join(",")
}

/// The player's frame of pose 0 among `boxes` (none: the walker alone), with or without
/// its depth.
fn shot(glb: &Path, sh: &Path, boxes: &[[f32; 9]], depth: bool, out: &Path) -> image::RgbaImage {
    let mut c = Command::new("node");
    c.arg(player().join("screenshot.mjs"))
        .arg("--glb")
        .arg(glb)
        .args(["--pose", "0", "--fov", &FOV_DEG.to_string()])
        .arg(format!("--camera={}", csv(&EYE)))
        .arg(format!("--look-at={}", csv(&LOOK_AT)))
        .args(["--size", &format!("{}x{}", SIZE.0, SIZE.1), "--sh"])
        .arg(sh)
        .arg("--out")
        .arg(out);
    for b in boxes {
        c.args(["--box", &csv(b)]);
    }
    if !depth {
        c.arg("--no-depth");
    }
    let o = c.output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    image::open(out).unwrap().to_rgba8()
}

/// The pixels inside the projection of a box's face toward the camera, `margin` pixels
/// in from its edges (out, negative).
fn face_pixels(b: &[f32; 9], margin: f32) -> Vec<(u32, u32)> {
    let camera = Camera::look_at(
        Vec3::from(EYE),
        Vec3::from(LOOK_AT),
        Vec3::Y,
        FOV_DEG.to_radians(),
        SIZE.0,
        SIZE.1,
    )
    .unwrap();
    let z = b[2] + b[5] / 2.0;
    let corner = |sx: f32, sy: f32| {
        camera
            .project(Vec3::new(b[0] + sx * b[3] / 2.0, b[1] + sy * b[4] / 2.0, z))
            .unwrap()
    };
    let (lo, hi) = (corner(-1.0, -1.0), corner(1.0, 1.0));
    let (x0, x1) = (
        lo.x.min(hi.x).ceil() + margin,
        lo.x.max(hi.x).floor() - margin,
    );
    let (y0, y1) = (
        lo.y.min(hi.y).ceil() + margin,
        lo.y.max(hi.y).floor() - margin,
    );
    let mut out = Vec::new();
    for y in y0 as u32..=y1 as u32 {
        for x in x0 as u32..=x1 as u32 {
            out.push((x, y));
        }
    }
    out
}

#[test]
fn a_box_in_front_of_the_walker_hides_it_and_one_behind_is_hidden() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (glb, sh) = exported(d);
    let alone = shot(&glb, &sh, &[], true, &d.join("alone.png"));
    let with = shot(&glb, &sh, &[FRONT, BEHIND], true, &d.join("depth.png"));
    let over = shot(&glb, &sh, &[FRONT, BEHIND], false, &d.join("over.png"));
    let code = |v: f32| (linear_to_srgb(v) * 255.0).round() as i32;
    // In front: the walker covers part of the box's face, and every pixel of the face is
    // the box's, the same everywhere (unlit) and its colour's code within a rounding.
    let front = face_pixels(&FRONT, 1.0);
    let near_front = face_pixels(&FRONT, -3.0);
    let covered = front
        .iter()
        .filter(|&&(x, y)| alone.get_pixel(x, y)[3] > 128)
        .count();
    assert!(
        covered > 100,
        "the walker covers {covered} of the box's {} pixels",
        front.len()
    );
    let first = *with.get_pixel(front[0].0, front[0].1);
    for &(x, y) in &front {
        assert_eq!(*with.get_pixel(x, y), first, "({x}, {y})");
    }
    assert_eq!(first[3], 255);
    for c in 0..3 {
        assert!(
            (i32::from(first[c]) - code(FRONT[6 + c])).abs() <= 1,
            "{first:?}"
        );
    }
    // The control: laid over the scene without depth, the walker draws over the box.
    let drawn_over = front
        .iter()
        .filter(|&&(x, y)| *over.get_pixel(x, y) != first)
        .count();
    assert!(
        drawn_over > covered / 2,
        "{drawn_over} of {covered} covered pixels changed"
    );
    // Behind (away from the box in front): where the walker is opaque it is drawn as
    // alone; elsewhere the box shows.
    let behind = face_pixels(&BEHIND, 1.0);
    let (mut hidden, mut shown) = (0, 0);
    for &(x, y) in behind.iter().filter(|p| !near_front.contains(p)) {
        let (a, w) = (alone.get_pixel(x, y), with.get_pixel(x, y));
        if a[3] == 255 {
            hidden += 1;
            for c in 0..3 {
                assert!(
                    (i32::from(a[c]) - i32::from(w[c])).abs() <= 1,
                    "({x}, {y}): {a:?} {w:?}"
                );
            }
        } else if a[3] == 0 {
            // (The walker's faintest fringe, under half a code of alpha, may tint the box
            // by a code or two.)
            shown += 1;
            for c in 0..3 {
                assert!(
                    (i32::from(w[c]) - code(BEHIND[6 + c])).abs() <= 2,
                    "({x}, {y}): {w:?}"
                );
            }
        }
    }
    assert!(
        hidden > 100 && shown > 100,
        "{hidden} hidden, {shown} shown"
    );
}

/// The ground shadow the player relights from the exported basis, seen as frf's shadow
/// layer (the ground's relative irradiance under the walker) from a camera above the
/// patch, against `frf render --layers` under the same L2 light; a ground left
/// unshadowed (the control) misses by far.
#[test]
fn the_players_ground_shadow_is_frfs() {
    let f = frf_testkit::tiny_field();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (glb, sh) = exported(d);
    let document = frf_export::read::Export::open(&glb).unwrap().document;
    let extent = document["extensions"]["FRF_flowed_reflectance_field"]["ground_shadow"]["extent_m"]
        .as_f64()
        .unwrap() as f32;
    let (eye, look_at, fov_deg, (w, h)) = ([1.8, 2.2, 2.6], [0.0, 0.3, 0.0], 45.0, (160, 120));
    let out = d.join("player.png");
    let layer = d.join("shadow.png");
    let o = Command::new("node")
        .arg(player().join("screenshot.mjs"))
        .arg("--glb")
        .arg(&glb)
        .args(["--pose", "0", "--fov", &fov_deg.to_string()])
        .arg(format!("--camera={}", csv(&eye)))
        .arg(format!("--look-at={}", csv(&look_at)))
        .args(["--size", &format!("{w}x{h}"), "--sh"])
        .arg(&sh)
        .arg("--out")
        .arg(&out)
        .arg("--shadow-out")
        .arg(&layer)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let camera_toml = d.join("camera.toml");
    std::fs::write(
        &camera_toml,
        format!(
            "[[key]]\ntime = 0.0\nposition = [{}]\nlook_at = [{}]\nfov_deg = {fov_deg}\n",
            csv(&eye),
            csv(&look_at)
        ),
    )
    .unwrap();
    let frf_out = d.join("frf");
    let mut args = vec![
        "render".to_string(),
        f.field.display().to_string(),
        "--env".into(),
        sh.display().to_string(),
        "--camera".into(),
        camera_toml.display().to_string(),
        "--frames".into(),
        "1".into(),
        "--detail".into(),
        "0".into(),
        "--size".into(),
        format!("{w}x{h}"),
        "--layers".into(),
        "--out".into(),
        frf_out.display().to_string(),
    ];
    args.extend(frf_testkit::cpu_flag().map(String::from));
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = crate::common::frf(&refs);
    assert!(o.status.success(), "{}", stderr(&o));
    let reference = frf_core::io::read_hdr_rgb(&frf_out.join("frame_0000_shadow.exr")).unwrap();
    let ours = image::open(&layer).unwrap().into_rgb16();
    assert_eq!(
        (reference.width(), reference.height()),
        (w as usize, h as usize)
    );
    // The pixels whose ray meets the ground on the patch.
    let camera = Camera::look_at(
        Vec3::from(eye),
        Vec3::from(look_at),
        Vec3::Y,
        f32::to_radians(fov_deg),
        w,
        h,
    )
    .unwrap();
    let (mut se, mut se_unshadowed, mut n, mut shaded) = (0.0f64, 0.0f64, 0usize, 0usize);
    for y in 0..h {
        for x in 0..w {
            let dir = camera.ray_direction(glam::Vec2::new(x as f32, y as f32));
            let Some(hit) = frf_render::shadow::ground_hit(camera.centre(), dir) else {
                continue;
            };
            if hit.x.abs() > extent / 2.0 || hit.z.abs() > extent / 2.0 {
                continue;
            }
            let r = reference.get(x as usize, y as usize);
            let p = ours.get_pixel(x, y);
            for c in 0..3 {
                let v = f64::from(p[c]) / 65535.0;
                se += (v - f64::from(r[c])).powi(2);
                se_unshadowed += (1.0 - f64::from(r[c])).powi(2);
            }
            n += 3;
            shaded += usize::from(r[1] < 0.9);
        }
    }
    assert!(n > 3000 && shaded > 100, "{n} samples, {shaded} shaded");
    let psnr = |se: f64| 10.0 * (n as f64 / se).log10();
    let (ours_db, none_db) = (psnr(se), psnr(se_unshadowed));
    eprintln!(
        "ground shadow against frf's over the patch: {ours_db:.2} dB (unshadowed: {none_db:.2} dB)"
    );
    assert!(ours_db >= 30.0, "{ours_db:.2} dB");
    assert!(
        none_db < 30.0,
        "the unshadowed ground scores {none_db:.2} dB: the view shows too little shadow"
    );
}

/// The demo page (player/scene.html): the walker of two poses walks its loop among a
/// ground, a box and a sun, morphed between its poses, without an error.
#[test]
fn the_scene_page_walks_the_walker_round_its_loop() {
    let dir = tempfile::tempdir().unwrap();
    let (glb, sh) = exported(dir.path());
    let o = Command::new("node")
        .arg(player().join("page-check.mjs"))
        .args(["--page", "scene.html", "--frames", "3", "--glb"])
        .arg(&glb)
        .arg("--sh")
        .arg(&sh)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(r["frames"].as_u64().unwrap() >= 3, "{r}");
    assert_eq!(r["error"], "", "{r}");
    assert_eq!(r["logs"], serde_json::json!([]), "{r}");
    assert!(r["status"].as_str().unwrap().contains("pose 0"), "{r}");
    // A control: without a walker the page says so.
    let o = Command::new("node")
        .arg(player().join("page-check.mjs"))
        .args(["--page", "scene.html", "--frames", "1", "--glb"])
        .arg(dir.path().join("missing.glb"))
        .output()
        .unwrap();
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(r["error"].as_str().unwrap().contains("404"), "{r}");
}
