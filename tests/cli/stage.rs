//! The `frf stage` command line: truth renders from a capture directory, and refusal of
//! bad arguments with messages that name them (never a panic).

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use crate::common::{frf, staged_capture, stderr};

use std::path::Path;

use frf_stage::{Preset, SetFlowTruth, Stage, StageConfig, write_capture};

fn small_capture(dir: &Path) {
    let mut c = StageConfig::preset(Preset::Tiny);
    c.cycles = 2;
    c.poses = vec![0];
    c.set_flow_truth = SetFlowTruth::None;
    write_capture(&Stage::new(c).unwrap(), dir, &|_, _| {}).unwrap();
}

#[test]
fn truth_renders_a_novel_camera_under_the_built_in_sky_and_a_basis_mix() {
    let dir = tempfile::tempdir().unwrap();
    small_capture(dir.path());
    let cap = dir.path().to_str().unwrap();
    let png = dir.path().join("novel.png");
    let o = frf(&[
        "stage",
        "truth",
        "--capture",
        cap,
        "--eye",
        "-2,1.5,-3",
        "--look-at",
        "0,0.9,0",
        "--size",
        "48x64",
        "--env",
        "sky",
        "--lights",
        "64",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&png).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (48, 64));
    let covered = img.pixels().filter(|p| p[3] > 0).count();
    assert!(
        covered > 100,
        "the walker should be in view: {covered} pixels"
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("subject coverage") && stdout.contains("render time"),
        "{stdout}"
    );

    let exr = dir.path().join("view.exr");
    let o = frf(&[
        "stage",
        "truth",
        "--capture",
        cap,
        "--view",
        "1,2",
        "--basis",
        "0=1,24=0.5",
        "--out",
        exr.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let back = frf_core::io::read_rgba(&exr).unwrap();
    assert_eq!(back.size(), (64, 90));
    assert!(back.pixels().iter().any(|p| p[3] > 0.99 && p[1] > 0.0));
}

#[test]
fn bad_arguments_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    small_capture(dir.path());
    let cap = dir.path().to_str().unwrap();
    let out = dir.path().join("x.png");
    let out = out.to_str().unwrap();
    for (args, expected) in [
        (vec!["stage", "--preset", "huge", "--out", out], "huge"),
        (
            vec!["stage", "--preset", "tiny", "--poses", "4..2", "--out", out],
            "--poses",
        ),
        (
            vec!["stage", "--preset", "tiny", "--poses", "99", "--out", out],
            "pose 99",
        ),
        (
            vec![
                "stage",
                "truth",
                "--capture",
                cap,
                "--eye",
                "nan,1,1",
                "--basis",
                "0=1",
                "--out",
                out,
            ],
            "--eye",
        ),
        (
            vec![
                "stage",
                "truth",
                "--capture",
                cap,
                "--view",
                "0,1",
                "--size",
                "0x5",
                "--basis",
                "0=1",
                "--out",
                out,
            ],
            "--size",
        ),
        (
            vec![
                "stage",
                "truth",
                "--capture",
                cap,
                "--view",
                "0,1",
                "--basis",
                "99=1",
                "--out",
                out,
            ],
            "--basis",
        ),
        (
            vec![
                "stage",
                "truth",
                "--capture",
                cap,
                "--view",
                "7,1",
                "--basis",
                "0=1",
                "--out",
                out,
            ],
            "cycle",
        ),
        (
            vec![
                "stage",
                "truth",
                "--capture",
                cap,
                "--view",
                "0,1",
                "--env",
                "/no/such.hdr",
                "--out",
                out,
            ],
            "such.hdr",
        ),
        (
            vec![
                "stage",
                "truth",
                "--capture",
                "/no/such/dir",
                "--view",
                "0,1",
                "--basis",
                "0=1",
                "--out",
                out,
            ],
            "stage.toml",
        ),
    ] {
        let o = frf(&args);
        let err = stderr(&o);
        assert!(!o.status.success(), "{args:?} should fail");
        assert!(err.contains(expected), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    }
    assert!(!Path::new(out).exists(), "a failed command left an output");
}

/// A capture made through the binary with the default settings carries the true set
/// flows (track slots), and `stage field` turns it into a complete oracle field whose
/// flows are the truth's within the quantizer's bound.
#[test]
fn a_capture_through_the_binary_carries_its_truth_and_becomes_an_oracle_field() {
    let dir = tempfile::tempdir().unwrap();
    let cap = staged_capture(dir.path());
    let capture = frf_core::capture::Capture::open(&cap).unwrap();
    capture.check_files().unwrap();

    // Default set-flow truth: from the reference track slot to each other track slot.
    let reference = capture.reference_track().track_slot;
    let others: Vec<usize> = capture
        .tracks()
        .iter()
        .map(|t| t.track_slot)
        .filter(|&s| s != reference)
        .collect();
    assert_eq!(others.len(), 2, "tracks {:?}", capture.tracks());
    let (mut known, mut largest) = (0usize, 0.0f32);
    for camera in 0..3 {
        for cycle in 0..36 {
            for &slot in &others {
                let path = frf_stage::writer::truth_set_flow_path(&cap, 0, cycle, camera, slot);
                let flow = frf_core::flo::read_flo(&path).unwrap();
                assert_eq!(flow.size(), (32, 45), "{}", path.display());
                for f in flow
                    .pixels()
                    .iter()
                    .filter(|f| frf_core::flo::is_known(**f))
                {
                    assert!(f.iter().all(|c| c.is_finite()), "{}", path.display());
                    largest = largest.max(f[0].hypot(f[1]));
                    known += 1;
                }
            }
        }
    }
    // The subject covers part of each view; it moves between track slots 16 ms apart by
    // at most a few pixels at this size.
    assert!(known > 36 * 3 * 2 * 50, "{known} known set-flow vectors");
    assert!(
        largest > 0.0 && largest < 8.0,
        "largest set flow {largest} px"
    );

    let field = dir.path().join("oracle.frf");
    let o = frf(&[
        "stage",
        "field",
        "--capture",
        cap.to_str().unwrap(),
        "--out",
        field.to_str().unwrap(),
        "--shadow-texels",
        "32",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = frf(&["info", field.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // A 36 x 3 grid: 108 views of 26 basis images; right and left flows in every row,
    // up and down flows between the rows; one hull for the pose.
    assert_eq!(info["views"], 108, "{info}");
    assert_eq!(info["basis_images"], 108 * 26, "{info}");
    assert_eq!(info["flow_maps"], 2 * 36 * 3 + 2 * 36 * 2, "{info}");
    assert_eq!(info["hulls"], 1, "{info}");
    let file = frf_reflectance::FieldFile::open(&field).unwrap();
    let q = file.header().pose(0).unwrap().flow_quantizer;
    for (cycle, camera) in [(0, 0), (17, 1), (35, 2)] {
        for n in frf_core::grid::Neighbour::ALL {
            let Some(stored) = file.flow(0, cycle, camera, n).unwrap() else {
                continue;
            };
            let truth = frf_stage::writer::truth_flow_path(&cap, 0, cycle, camera, n);
            let truth = frf_core::flo::read_flo(&truth).unwrap();
            for (s, t) in stored.pixels().iter().zip(truth.pixels()) {
                if frf_core::flo::is_known(*t) && t[0].hypot(t[1]) < q.range {
                    for c in 0..2 {
                        assert!(
                            (s[c] - t[c]).abs() <= q.error_bound(t[c]) + 1e-4,
                            "view ({cycle}, {camera}) {n:?}: {s:?} vs truth {t:?}"
                        );
                    }
                }
            }
        }
    }
}

/// A capture too small for any pixel to lie wholly inside the subject (8x12) ingests, and
/// its report says the flow errors were not measured instead of a perfect 0 px.
#[test]
fn an_ingest_too_small_to_measure_says_so_instead_of_a_perfect_score() {
    let dir = tempfile::tempdir().unwrap();
    let cap = dir.path().join("cap");
    let field = dir.path().join("f.frf");
    let o = frf(&[
        "stage",
        "--poses",
        "0",
        "--size",
        "8x12",
        "--lights-per-axis",
        "1",
        "--out",
        cap.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = frf(&[
        "ingest",
        cap.to_str().unwrap(),
        "--out",
        field.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let said = String::from_utf8_lossy(&o.stdout);
    for line in [
        "flow EPE inside matte, horizontal",
        "flow EPE inside matte, vertical",
    ] {
        let line = said.lines().find(|l| l.contains(line)).unwrap();
        assert!(line.contains("not measured"), "{line}");
    }
}
