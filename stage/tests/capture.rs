//! A written stage capture: deterministic for a seed on any number of threads, its matte
//! frames separate subject from background, its basis frames are linear in their
//! lights, it resumes after an interruption, and broken manifests and frame files are
//! refused with a message naming what is wrong.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::Path;

use frf_core::capture::Capture;
use frf_core::image::luminance;
use frf_core::manifest::Manifest;
use frf_stage::render::{Scene, render};
use frf_stage::rig::{REFERENCE_SLOT, StageSlot, slot_time_offset_s};
use frf_stage::studio::Illumination;
use frf_stage::{Gait, Preset, SetFlowTruth, Stage, StageConfig, write_capture};

/// A small capture: tiny images, 3 cycles, one pose.
fn small_config() -> StageConfig {
    let mut c = StageConfig::preset(Preset::Tiny);
    c.cycles = 3;
    c.poses = vec![2];
    c.set_flow_truth = SetFlowTruth::None;
    c
}

fn write(config: StageConfig, dir: &Path) -> frf_stage::WriteReport {
    write_capture(&Stage::new(config).unwrap(), dir, &|_, _| {}).unwrap()
}

fn tree_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_string_lossy().into_owned();
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn capture_is_deterministic_for_a_seed_on_any_number_of_threads() {
    let (a, b, c) = (
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
    );
    write(small_config(), a.path());
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| write(small_config(), b.path()));
    let files_a = tree_bytes(a.path());
    assert!(files_a.len() > 300, "{} files", files_a.len());
    assert!(
        files_a == tree_bytes(b.path()),
        "same seed, different bytes"
    );
    let mut other = small_config();
    other.seed = 2;
    write(other, c.path());
    let differing = files_a
        .iter()
        .zip(tree_bytes(c.path()))
        .filter(|(x, y)| x.1 != y.1)
        .count();
    // Another seed changes the noise of every frame and the perturbation of every cycle.
    assert!(
        differing > files_a.len() / 2,
        "only {differing} files differ"
    );
}

#[test]
fn matte_frames_separate_subject_and_background() {
    let stage = Stage::new(small_config()).unwrap();
    let (pose, track, matte) = (2, REFERENCE_SLOT, REFERENCE_SLOT + 1);
    assert_eq!(stage.schedule()[matte], StageSlot::Matte(1));
    for cycle in 0..3 {
        for camera in 0..3 {
            let t = stage.capture_frame(pose, cycle, camera, track).unwrap();
            let m = stage.capture_frame(pose, cycle, camera, matte).unwrap();
            let (_, alpha) = stage.reference_surface(pose, cycle, camera).unwrap();
            let (mut right, mut total) = (0, 0);
            for i in 0..alpha.pixels().len() {
                let a = alpha.pixels()[i];
                // Only pixels that are clearly subject or clearly background.
                if a > 0.02 && a < 0.98 {
                    continue;
                }
                let subject = luminance(t.pixels()[i]) > luminance(m.pixels()[i]);
                right += (subject == (a >= 0.98)) as usize;
                total += 1;
            }
            let accuracy = right as f64 / total as f64;
            eprintln!("view ({cycle}, {camera}): matte separation {accuracy:.5}");
            // Measured: at least 99.98 % on every view of this capture (one pixel).
            assert!(accuracy > 0.999, "view ({cycle}, {camera}): {accuracy}");
        }
    }
}

#[test]
fn a_basis_frame_is_the_sum_of_its_lights_rendered_alone() {
    let stage = Stage::new(small_config()).unwrap();
    let (pose, cycle, camera) = (2, 1, 1);
    let slot = 12;
    let StageSlot::Basis(condition) = stage.schedule()[slot] else {
        panic!("slot {slot} is not a basis slot");
    };
    let whole = stage.render_frame(pose, cycle, camera, slot).unwrap().color;
    let setup = stage
        .view_setup(pose, cycle, camera, slot_time_offset_s(slot))
        .unwrap();
    let lights = stage.condition_lights(condition).unwrap();
    assert!(lights.len() >= 4);
    let mut sum = vec![[0.0f32; 3]; whole.pixels().len()];
    for light in lights {
        let illumination = Illumination::Lights(vec![light]);
        let scene = Scene {
            actor: Some(&setup.actor),
            studio: true,
            illumination: &illumination,
        };
        let part = render(&setup.camera, &scene, stage.config().samples_per_axis).color;
        for (s, p) in sum.iter_mut().zip(part.pixels()) {
            for c in 0..3 {
                s[c] += p[c];
            }
        }
    }
    let peak = whole.pixels().iter().map(|p| p[1]).fold(0.0, f32::max);
    let max_diff = whole
        .pixels()
        .iter()
        .zip(&sum)
        .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max))
        .fold(0.0, f32::max);
    assert!(peak > 0.05);
    // Float summation order only.
    assert!(max_diff < 1e-5 * peak.max(1.0), "max difference {max_diff}");
}

/// A basis frame checked against a computation of its own: where a pixel sees the gray
/// backdrop (18 % Lambertian paper, facing +z, behind the subject; every sub-sample's ray
/// meets it, found here by intersecting the plane), its radiance is `ρ/π Σ E_l max(0,
/// l_z)` over the condition's lights, less only what the actor's shadows take.
#[test]
fn a_basis_frame_shows_the_backdrop_at_its_lambertian_radiance() {
    let stage = Stage::new(small_config()).unwrap();
    let (pose, cycle, camera) = (2, 1, 1);
    let lambertian = |condition: usize| -> [f32; 3] {
        let lights = stage.condition_lights(condition).unwrap();
        std::array::from_fn(|c| {
            lights
                .iter()
                .map(|l| 0.18 / std::f32::consts::PI * l.irradiance[c] * l.direction.z.max(0.0))
                .sum()
        })
    };
    // The basis slot whose condition lights the backdrop most.
    let (slot, expected) = (0..stage.schedule().len())
        .filter_map(|slot| match stage.schedule()[slot] {
            StageSlot::Basis(c) => Some((slot, lambertian(c))),
            _ => None,
        })
        .max_by(|a, b| a.1[1].total_cmp(&b.1[1]))
        .unwrap();
    assert!(
        expected[1] > 1e-3,
        "no condition lights the backdrop: {expected:?}"
    );
    let frame = stage.render_frame(pose, cycle, camera, slot).unwrap();
    let cam = stage
        .view_setup(pose, cycle, camera, slot_time_offset_s(slot))
        .unwrap()
        .camera;
    let on_backdrop = |x: f32, y: f32| {
        let d = cam.ray_direction(glam::Vec2::new(x, y));
        let t = (-frf_stage::studio::BACKDROP_DISTANCE_M - cam.centre().z) / d.z;
        let p = cam.centre() + d * t;
        d.z < 0.0 && t > 0.0 && p.x.abs() < 2.4 && (0.05..3.9).contains(&p.y)
    };
    let (mut seen, mut exact) = (0, 0);
    for (i, (c, a)) in frame
        .color
        .pixels()
        .iter()
        .zip(frame.alpha.pixels())
        .enumerate()
    {
        let (x, y) = (
            (i % frame.color.width()) as f32,
            (i / frame.color.width()) as f32,
        );
        let corners = [
            (-0.5, -0.5),
            (0.5, -0.5),
            (-0.5, 0.5),
            (0.5, 0.5),
            (0.0, 0.0),
        ];
        if *a > 0.0 || !corners.iter().all(|(dx, dy)| on_backdrop(x + dx, y + dy)) {
            continue;
        }
        seen += 1;
        for ch in 0..3 {
            assert!(
                c[ch] <= expected[ch] * (1.0 + 1e-4),
                "pixel ({x}, {y}): {c:?} above {expected:?}"
            );
        }
        exact += (0..3).all(|ch| (c[ch] - expected[ch]).abs() <= 1e-4 * expected[ch]) as usize;
    }
    // The backdrop fills the view behind the subject; the actor's shadows fall on a part
    // (measured: 65 % of the pixels exact, the condition chosen lighting from the front).
    assert!(seen > 100, "{seen} backdrop pixels");
    assert!(
        exact * 10 >= seen * 6,
        "{exact} of {seen} backdrop pixels at the Lambertian value"
    );
}

#[test]
fn an_interrupted_capture_resumes_and_a_different_one_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let first = write(small_config(), dir.path());
    assert_eq!(first.units_skipped, 0);
    // Simulate an interruption inside one view: its marker and one frame are missing.
    let capture = Capture::open(dir.path()).unwrap();
    let frame = capture.frame_path(2, 1, 0, 5);
    let before = std::fs::read(&frame).unwrap();
    std::fs::remove_file(&frame).unwrap();
    std::fs::remove_file(dir.path().join(".progress/p02_v0_u01")).unwrap();
    let e = Capture::open(dir.path()).unwrap_err().to_string();
    assert!(
        e.contains(&frame.display().to_string()) && e.contains("not found"),
        "{e}"
    );
    let second = write(small_config(), dir.path());
    assert_eq!(
        (second.units_rendered, second.units_skipped),
        (1, first.units_rendered - 1)
    );
    assert_eq!(std::fs::read(&frame).unwrap(), before);
    Capture::open(dir.path()).unwrap();
    // Another seed into the same directory is refused, naming the field.
    let mut other = small_config();
    other.seed = 5;
    let err = write_capture(&Stage::new(other).unwrap(), dir.path(), &|_, _| {})
        .unwrap_err()
        .to_string();
    assert!(err.contains("seed"), "{err}");
}

/// Writes a manifest as text, the way a person would edit one.
fn save(dir: &Path, manifest: &Manifest) {
    let text = toml::to_string(manifest).unwrap();
    std::fs::write(dir.join("capture.toml"), text).unwrap();
}

#[test]
fn broken_captures_are_refused_naming_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    write(small_config(), dir.path());
    let good = Capture::open(dir.path()).unwrap().manifest().clone();

    // A missing frame file.
    let capture = Capture::open(dir.path()).unwrap();
    let frame = capture.frame_path(2, 2, 1, 30);
    let saved = std::fs::read(&frame).unwrap();
    std::fs::remove_file(&frame).unwrap();
    let err = Capture::open(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("s30.png") && err.contains("not found"),
        "{err}"
    );
    std::fs::write(&frame, &saved).unwrap();

    // A frame of the wrong size.
    frf_core::io::write_png16_rgb(&frame, &frf_core::image::Image::new(10, 12, [0.5; 3])).unwrap();
    let err = Capture::open(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("s30.png") && err.contains("expected 64x90") && err.contains("10x12"),
        "{err}"
    );
    std::fs::write(&frame, &saved).unwrap();

    // A truncated frame file.
    std::fs::write(&frame, &saved[..saved.len() / 2]).unwrap();
    let err = capture.load_frame(2, 2, 1, 30).unwrap_err().to_string();
    assert!(err.contains("s30.png"), "{err}");
    std::fs::write(&frame, &saved).unwrap();

    // An unknown slot kind.
    let mut m = good.clone();
    m.schedule[4].kind = "flash".into();
    save(dir.path(), &m);
    let err = Capture::open(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("capture.toml") && err.contains("schedule[4].kind") && err.contains("flash"),
        "{err}"
    );

    // The belt's speed: the stage writes it; a manifest without it reads (older and real
    // captures); a negative or NaN one is refused naming the field.
    assert_eq!(good.timing.gait_speed_mps, Some(Gait::Walk.speed_mps()));
    let mut m = good.clone();
    m.timing.gait_speed_mps = None;
    save(dir.path(), &m);
    let text = std::fs::read_to_string(dir.path().join("capture.toml")).unwrap();
    assert!(!text.contains("gait_speed_mps"), "{text}");
    let read = Capture::open(dir.path()).unwrap();
    assert_eq!(read.manifest().timing.gait_speed_mps, None);
    for bad in [-1.0, f64::NAN] {
        m.timing.gait_speed_mps = Some(bad);
        save(dir.path(), &m);
        let err = Capture::open(dir.path()).unwrap_err().to_string();
        assert!(err.contains("timing.gait_speed_mps"), "{err}");
    }

    // NaN in a camera matrix.
    let mut m = good.clone();
    m.cameras[1].world_from_camera[2][1] = f64::NAN;
    save(dir.path(), &m);
    let err = Capture::open(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("cameras[1].world_from_camera[2][1]") && err.contains("NaN"),
        "{err}"
    );

    // A rotation that is not a rotation.
    let mut m = good.clone();
    m.cameras[0].world_from_camera[0][0] = 2.0;
    save(dir.path(), &m);
    let err = Capture::open(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("cameras[0].world_from_camera") && err.contains("orthonormal"),
        "{err}"
    );

    // A basis slot pointing at a missing condition, and a track frame without a matte.
    let mut m = good.clone();
    m.schedule[0].condition = Some(99);
    save(dir.path(), &m);
    let err = Capture::open(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("schedule[0].condition") && err.contains("99"),
        "{err}"
    );
    let mut m = good.clone();
    m.schedule[REFERENCE_SLOT + 1].kind = "unused".into();
    save(dir.path(), &m);
    let err = Capture::open(dir.path()).unwrap_err().to_string();
    assert!(err.contains("T1") && err.contains("M1"), "{err}");

    // A pattern with an unknown placeholder, and a syntax error.
    let mut m = good.clone();
    m.files.frame = "frames/{pose}/{cam}/{cycle}/{slot}.png".into();
    save(dir.path(), &m);
    let err = Capture::open(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("files.frame") && err.contains("{cam}"),
        "{err}"
    );
    std::fs::write(
        dir.path().join("capture.toml"),
        "format = \"frf-capture\"\nversion = [",
    )
    .unwrap();
    let err = Capture::open(dir.path()).unwrap_err().to_string();
    assert!(err.contains("capture.toml"), "{err}");

    // And the untouched manifest still opens.
    save(dir.path(), &good);
    Capture::open(dir.path()).unwrap();
}

#[test]
fn frames_read_back_as_the_stage_rendered_them() {
    let dir = tempfile::tempdir().unwrap();
    write(small_config(), dir.path());
    let capture = Capture::open(dir.path()).unwrap();
    let stage = Stage::new(small_config()).unwrap();
    let (pose, cycle, camera, slot) = (2, 2, 2, 9);
    let read = capture.load_frame(pose, cycle, camera, slot).unwrap();
    let rendered = stage.capture_frame(pose, cycle, camera, slot).unwrap();
    // 12-bit codes survive the 16-bit PNG round trip exactly (up to f32 rounding).
    for (a, b) in read.pixels().iter().zip(rendered.pixels()) {
        for c in 0..3 {
            assert!((a[c] - b[c]).abs() < 1e-6, "{a:?} vs {b:?}");
        }
    }
    // The manifest's geometry matches the stage's.
    assert_eq!(capture.cameras().len(), 3);
    let angle = capture.view_angle(2, pose);
    assert!((angle - stage.turntable_angle(2, stage.pose_time_s(pose))).abs() < 1e-6);
    assert_eq!(capture.reference_track().track_slot, REFERENCE_SLOT);
    assert_eq!(capture.conditions().len(), 26);
    assert_eq!(capture.conditions().iter().filter(|c| c.floor).count(), 3);
}
