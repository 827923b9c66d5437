//! The web player's mask (`player/src/mask.js`): the frame passes shade only the tiles
//! where a camera sees the pose's hull grown by a margin, not the walker's whole pixel
//! box. The tiles hold every pixel whose ray passes within the margin of a hull (a
//! box's, checked ray by ray; a mask of no margin, the control, misses some), a camera
//! amid the mask asks for the whole box, and in Chromium a masked frame is the frame of
//! the whole box, at a pose and between two, from above the grid and inside it.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::process::Command;

use serde_json::Value;

use crate::common::stderr;
use crate::player::{grid_camera_of, player, subject_psnr};
use crate::player_motion::{screenshot_at, two_poses};

/// Runs `body` (a module script) with `mask.js`, `geometry.js` and `footprint.js`
/// imported as `m`, `g` and `fp`; its printed JSON.
fn with_mask_module(body: &str) -> Value {
    let url = |f: &str| format!("file://{}", player().join("src").join(f).display());
    let script = format!(
        "const m = await import({mask:?});\nconst g = await import({geometry:?});\n\
         const fp = await import({footprint:?});\n{body}",
        mask = url("mask.js"),
        geometry = url("geometry.js"),
        footprint = url("footprint.js"),
    );
    let o = Command::new("node")
        .args(["--input-type=module", "-e", &script])
        .output()
        .expect("node runs (scripts/setup.sh installs it)");
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// A hull of three closed boxes (two legs apart under a torso, 1.6 m tall), and per
/// camera and margin: the pixels whose ray passes within `margin` of the box that no
/// tile holds (none), those the mask of no margin leaves out (the control: some), and
/// how many pixels the tiles hold (in all, fewer than frf's pixel boxes of the grown hull).
#[test]
fn the_masks_tiles_hold_every_pixel_within_its_margin_of_the_hull() {
    let report = with_mask_module(
        r#"
// Two legs apart under a torso: three closed boxes.
const boxes = [[[-0.5, 0, -0.07], [-0.36, 0.9, 0.07]], [[0.36, 0, -0.07], [0.5, 0.9, 0.07]], [[-0.5, 0.9, -0.15], [0.5, 1.6, 0.15]]];
const [lo, hi] = [[-0.5, 0, -0.15], [0.5, 1.6, 0.15]];
const positions = [];
const indices = [];
const quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
for (const [l, h] of boxes) {
  const first = positions.length / 3;
  for (let i = 0; i < 8; i++) positions.push(i & 1 ? h[0] : l[0], i & 2 ? h[1] : l[1], i & 4 ? h[2] : l[2]);
  indices.push(...quads.flatMap(([a, b, c, d]) => [a, b, c, a, c, d].map((k) => first + k)));
}
const boxDistance = (p) => Math.min(...boxes.map(([l, h]) => Math.hypot(...p.map((x, a) => Math.max(l[a] - x, 0, x - h[a])))));
const [W, H] = [320, 240];
const out = [];
for (const [eye, margin] of [[[0.3, 1.2, 3.0], 0.08], [[0.5, 3.0, 1.5], 0.08], [[-0.8, 0.4, -2.6], 0.12]]) {
  const camera = g.lookAt(eye, [0, 0.8, 0], (35 * Math.PI) / 180, W, H);
  const box = { x0: 0, y0: 0, x1: W, y1: H };
  const held = (tiles) => {
    const set = new Set();
    for (let i = 0; i < tiles.centres.length; i += 2) {
      const [cx, cy] = [((tiles.centres[i] + 1) / 2) * W, ((1 - tiles.centres[i + 1]) / 2) * H];
      // A point sprite covers the pixels whose centres (x + 0.5 in the window) it holds.
      const span = (c) => [Math.ceil(c - m.TILE_PX / 2 - 0.5), c + m.TILE_PX / 2 - 0.5];
      const [[x0, x1], [y0, y1]] = [span(cx), span(cy)];
      for (let y = y0; y < y1; y++) for (let x = x0; x < x1; x++) set.add(y * W + x);
    }
    return set;
  };
  const grown = held(m.maskTiles(m.maskVoxels(positions, indices, margin), camera, box));
  const bare = held(m.maskTiles(m.maskVoxels(positions, indices, 0), camera, box));
  let near = 0, missed = 0, missedBare = 0;
  for (let y = 0; y < H; y++) {
    for (let x = 0; x < W; x++) {
      const [r, d, f] = camera.axes;
      const dc = [(x - camera.k.cx) / camera.k.fx, (y - camera.k.cy) / camera.k.fy, 1];
      const dir = g.normalizeOrZero([0, 1, 2].map((a) => r[a] * dc[0] + d[a] * dc[1] + f[a] * dc[2]));
      // The distance to each box along the ray is convex in t: a ternary search per box.
      let best = Infinity;
      for (const [l, h] of boxes) {
        const at = (t) => Math.hypot(...eye.map((e, a) => e + dir[a] * t).map((x, a) => Math.max(l[a] - x, 0, x - h[a])));
        let [t0, t1] = [0, 10];
        for (let k = 0; k < 60; k++) {
          const [a, b] = [t0 + (t1 - t0) / 3, t1 - (t1 - t0) / 3];
          if (at(a) <= at(b)) t1 = b; else t0 = a;
        }
        best = Math.min(best, at((t0 + t1) / 2));
      }
      if (best > margin) continue;
      near++;
      if (!grown.has(y * W + x)) missed++;
      if (!bare.has(y * W + x)) missedBare++;
    }
  }
  // frf's pixel box of the hull grown by the margin: what the passes shaded before.
  const b = fp.pixelBox(fp.subjectBounds(positions, margin), camera);
  const boxed = (b.x1 - b.x0) * (b.y1 - b.y0);
  out.push({ eye, margin, near, missed, missedBare, held: grown.size, boxed });
}
const inside = m.maskTiles(m.maskVoxels(positions, indices, 0.1), g.lookAt([0.1, 1.2, 0.25], [0, 1.2, -1], 1, 16, 16), { x0: 0, y0: 0, x1: 16, y1: 16 });
let refused = '';
try { m.maskVoxels(positions, indices, NaN); } catch (e) { refused = e.message; }
console.log(JSON.stringify({ out, inside, refused, empty: m.maskVoxels([], [], 0.1).centres.length }));
"#,
    );
    let (mut held, mut boxed) = (0, 0);
    for case in report["out"].as_array().unwrap() {
        let n = |k: &str| case[k].as_u64().unwrap();
        eprintln!(
            "camera {}, margin {} m: {} pixels within it, {} held by no tile ({} by the mask of no margin); the tiles hold {}, frf's pixel box of it {}",
            case["eye"],
            case["margin"],
            n("near"),
            n("missed"),
            n("missedBare"),
            n("held"),
            n("boxed")
        );
        assert!(n("near") > 1000, "{case}");
        assert_eq!(n("missed"), 0, "{case}");
        // The control: the mask of the bare hull leaves out pixels within the margin.
        assert!(n("missedBare") > 50, "{case}");
        held += n("held");
        boxed += n("boxed");
    }
    // And the tiles hold fewer pixels than frf's pixel box (on this small frame, a tile a
    // few centimetres across, by a fifth).
    assert!(held * 10 < boxed * 9, "{held} of {boxed}");
    assert!(report["inside"].is_null(), "{}", report["inside"]);
    assert!(
        report["refused"]
            .as_str()
            .unwrap()
            .contains("mask margin NaN m"),
        "{}",
        report["refused"]
    );
    assert_eq!(report["empty"], 0);
}

/// In Chromium, the tiny two-pose walker at pose 0 and half-way to pose 3, at 256x360:
/// its masked frame against the frame of its whole pixel box (`--mask none`), from above
/// the grid and inside it (a captured view: `the_player_decodes_only_the_views_a_camera_reaches`
/// draws it masked, against frf).
#[test]
fn a_masked_frame_is_the_frame_of_the_whole_box() {
    let fixture = two_poses();
    let d = &fixture.dir.path().join("mask");
    std::fs::create_dir_all(d).unwrap();
    let document = frf_export::read::Export::open(&fixture.glb)
        .unwrap()
        .document;
    let mut above = grid_camera_of(&document, 0, 3.0, 1.0);
    above.eye = [above.eye[0] * 0.5, 2.6, above.eye[2] * 0.5];
    above.look_at = [0.0, 0.9, 0.0];
    above.fov_deg = 60.0;
    let mut inside = grid_camera_of(&document, 0, 11.0, 1.0);
    inside.eye = [inside.eye[0] * 0.4, 1.0, inside.eye[2] * 0.4];
    inside.look_at = [0.0, 0.9, 0.0];
    inside.fov_deg = 90.0;
    for (name, shot) in [("above", above), ("inside", inside)] {
        for time in [0.0, crate::player_motion::HALF_WAY_S] {
            let mut frames = Vec::new();
            let mut pixels = Vec::new();
            for mask in ["none", "8"] {
                let out = d.join(format!("{name}-{time}-{mask}.png"));
                let o = screenshot_at(
                    &fixture.glb,
                    &fixture.sh,
                    &shot,
                    time,
                    &out,
                    &["--mask", mask, "--size", "256x360"],
                );
                assert!(o.status.success(), "{}", stderr(&o));
                let report: Value = serde_json::from_slice(&o.stdout).unwrap();
                pixels.push(report["shaded_pixels"].as_u64().unwrap());
                frames.push(out);
            }
            let a = image::open(&frames[0]).unwrap().to_rgba8();
            let b = image::open(&frames[1]).unwrap().to_rgba8();
            let differ = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
            let psnr = subject_psnr(&frames[0], &frames[1]);
            eprintln!(
                "{name}, {time} s: {differ} of {} pixels differ ({psnr:.1} dB); shaded {} of the box's {}",
                a.len() / 4,
                pixels[1],
                pixels[0]
            );
            assert!(
                differ * 1000 <= a.len() / 4,
                "{name} {time}: {differ} differ"
            );
            assert!(psnr >= 50.0, "{name} {time}: {psnr:.1} dB");
            // The mask shades fewer pixels than the box (else the comparison is idle).
            assert!(pixels[1] * 10 < pixels[0] * 9, "{name} {time}: {pixels:?}");
        }
    }
}
