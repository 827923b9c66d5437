//! The `frf stage` command line: truth renders from a capture directory, and refusal of
//! bad arguments with messages that name them (never a panic).

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

mod common;

use common::{frf, stderr};

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
