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
