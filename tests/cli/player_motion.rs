//! The web player's walk in time, in Chromium against `frf render`: a field of two poses
//! three apart (the tiny preset's 0 and 3, with their true pose-to-pose flows) exported
//! with each view's motion toward the other pose; half-way between them the player
//! morphs the two poses by their motion as frf does, and a player drawing the nearest
//! pose instead (the negative control) misses by far. An export of one of the poses
//! draws the nearest between them and says so; damaged motion is refused by name.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

use crate::common::{frf, stderr};
use crate::player::{Shot, grid_camera_of, list, player, staged_field, subject_psnr};

/// The instant half-way between poses 0 and 3 of a 30-pose, one-second cycle.
pub(crate) const HALF_WAY_S: f64 = 0.05;

/// `node player/screenshot.mjs` of `shot` at instant `time` (seconds), with `extra` flags.
pub(crate) fn screenshot_at(
    glb: &Path,
    sh: &Path,
    shot: &Shot,
    time: f64,
    out: &Path,
    extra: &[&str],
) -> Output {
    Command::new("node")
        .arg(player().join("screenshot.mjs"))
        .arg("--glb")
        .arg(glb)
        .args(["--time", &time.to_string(), "--size", "64x90", "--json"])
        .arg(format!("--camera={}", list(shot.eye)))
        .arg(format!("--look-at={}", list(shot.look_at)))
        .args(["--fov", &shot.fov_deg.to_string()])
        .arg("--sh")
        .arg(sh)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("node runs (scripts/setup.sh installs it)")
}

/// `frf render` of `field` (a walker on the spot) from `shot` at instant `time`, morphed
/// in time (the scene's default where the field holds pose flows): its PNG's path.
fn frf_at(field: &Path, sh: &Path, shot: &Shot, time: f64, dir: &Path) -> PathBuf {
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        format!(
            "field = {field:?}\n[time]\nstart = {time}\nend = {time}\nfps = 30\n\
             [output]\nsize = [64, 90]\n[lighting]\nenv = {sh:?}\n\
             [camera]\n[[camera.key]]\ntime = {time}\nposition = [{}]\nlook_at = [{}]\n\
             fov_deg = {}\n[composite]\nbackdrop = \"none\"\nshadow = \"none\"\n",
            list(shot.eye),
            list(shot.look_at),
            shot.fov_deg
        ),
    )
    .unwrap();
    let out = dir.join("frf");
    let mut args = vec![
        "render".to_string(),
        scene.display().to_string(),
        "--frames".into(),
        "1".into(),
        "--detail".into(),
        "0".into(),
        "--out".into(),
        out.display().to_string(),
    ];
    args.extend(frf_testkit::cpu_flag().map(String::from));
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = frf(&refs);
    assert!(o.status.success(), "{}", stderr(&o));
    out.join("frame_0000.png")
}

/// The two-pose walker, made once for the module's tests: a directory holding the field,
/// its export and the sky's light.
pub(crate) struct TwoPoses {
    pub(crate) dir: tempfile::TempDir,
    pub(crate) field: PathBuf,
    pub(crate) glb: PathBuf,
    pub(crate) sh: PathBuf,
}

pub(crate) fn two_poses() -> &'static TwoPoses {
    static FIXTURE: std::sync::OnceLock<TwoPoses> = std::sync::OnceLock::new();
    FIXTURE.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let (field, glb, sh) = make_two_poses(dir.path());
        TwoPoses {
            dir,
            field,
            glb,
            sh,
        }
    })
}

/// The tiny preset's poses 0 and 3 staged, their oracle field with its true pose flows,
/// exported, and the built-in sky's L2 light.
fn make_two_poses(dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let field = staged_field(dir, "0,3", &["--pose-flow"]);
    let glb = dir.join("two.glb");
    let o = frf(&[
        "export",
        field.to_str().unwrap(),
        "--out",
        glb.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sh = dir.join("sky.json");
    let o = frf(&["env-sh", "sky", "--out", sh.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    (field, glb, sh)
}

#[test]
fn half_way_between_poses_the_player_moves_as_frf_does() {
    let TwoPoses {
        dir,
        field,
        glb,
        sh,
    } = two_poses();
    let d = &dir.path().join("half-way");
    std::fs::create_dir_all(d).unwrap();
    let document = frf_export::read::Export::open(glb).unwrap().document;
    let ext = &document["extensions"]["FRF_flowed_reflectance_field"];
    assert_eq!(
        ext["poses"][0]["motion_to"]["next"], 3,
        "{}",
        ext["poses"][0]["motion_to"]
    );
    assert_eq!(ext["poses"][1]["motion_to"]["prev"], 0);
    // The motion images keep the file valid: the Khronos validator, uncapped.
    let v = Command::new("node")
        .arg(player().join("validate.mjs"))
        .arg(glb)
        .output()
        .unwrap();
    let line = String::from_utf8_lossy(&v.stdout);
    let r: Value = serde_json::from_str(line.trim()).unwrap();
    assert_eq!(
        (r["errors"].as_u64(), r["warnings"].as_u64()),
        (Some(0), Some(0)),
        "{line}"
    );
    assert_eq!(r["truncated"], false, "{line}");
    // Quad centres and a captured view, in three rows of cameras round the walker.
    for (k, (u, v)) in [(3.5, 0.5), (20.0, 0.0), (11.5, 1.5)]
        .into_iter()
        .enumerate()
    {
        let shot = grid_camera_of(&document, 0, u, v);
        let case = d.join(format!("case{k}"));
        std::fs::create_dir_all(&case).unwrap();
        let reference = frf_at(field, sh, &shot, HALF_WAY_S, &case);
        let score = |name: &str, extra: &[&str]| {
            let out = case.join(format!("{name}.png"));
            let o = screenshot_at(glb, sh, &shot, HALF_WAY_S, &out, extra);
            assert!(
                o.status.success(),
                "{}{}",
                String::from_utf8_lossy(&o.stdout),
                stderr(&o)
            );
            let report: Value = serde_json::from_slice(&o.stdout).unwrap();
            (subject_psnr(&reference, &out), report)
        };
        let (morphed, report) = score("flow", &[]);
        assert_eq!(report["pose"], 0, "{report}");
        assert_eq!(report["between"]["after"], 3, "{report}");
        assert!(
            (report["between"]["s"].as_f64().unwrap() - 0.5).abs() < 1e-6,
            "{report}"
        );
        // The negative control: the nearest pose, as frf's `interpolate = "nearest"`.
        let (nearest, report) = score("nearest", &["--interpolate", "nearest"]);
        assert!(report["between"].is_null(), "{report}");
        eprintln!("({u}, {v}) half-way: morphed {morphed:.2} dB, nearest pose {nearest:.2} dB");
        assert!(morphed >= 33.0, "({u}, {v}): {morphed:.2} dB");
        assert!(
            nearest < 33.0,
            "({u}, {v}): the nearest pose {nearest:.2} dB"
        );
    }
}

#[test]
fn the_player_without_a_poses_motion_draws_the_nearest_and_refuses_damaged_motion() {
    let TwoPoses {
        dir,
        field,
        glb,
        sh,
    } = two_poses();
    let d = &dir.path().join("damaged");
    std::fs::create_dir_all(d).unwrap();
    let shot = Shot {
        eye: [0.0, 1.2, 4.5],
        look_at: [0.0, 0.9, 0.0],
        fov_deg: 30.0,
    };
    // One pose exported: its motion leads to a pose the export lacks.
    let one = d.join("one.glb");
    let o = frf(&[
        "export",
        field.to_str().unwrap(),
        "--poses",
        "0",
        "--out",
        one.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = d.join("one.png");
    let o = screenshot_at(&one, sh, &shot, HALF_WAY_S, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["pose"], 0, "{report}");
    assert!(report["between"].is_null(), "{report}");
    // Damaged: a motion image that is not 16-bit, and motion_to naming a pose whose
    // views hold none.
    let bytes = std::fs::read(glb).unwrap();
    let damaged = |name: &str, edit: &dyn Fn(&mut Value)| {
        let (mut doc, bin) = frf_export::glb::unpack(&bytes).unwrap();
        edit(&mut doc["extensions"]["FRF_flowed_reflectance_field"]);
        let path = d.join(name);
        std::fs::write(&path, frf_export::glb::pack(&doc, bin)).unwrap();
        let out = d.join(format!("{name}.png"));
        let o = screenshot_at(&path, sh, &shot, HALF_WAY_S, &out, &[]);
        assert!(!o.status.success(), "{name} was drawn");
        assert!(!out.exists(), "{name}: an output was written");
        stderr(&o)
    };
    let said = damaged("alpha-as-motion.glb", &|e| {
        let alpha = e["poses"][0]["views"][0]["alpha"].clone();
        e["poses"][0]["views"][0]["motion"]["next"]["image"] = alpha;
    });
    assert!(
        said.contains("alpha-as-motion.glb") && said.contains("pose 0 view 0,0 motion next"),
        "{said}"
    );
    let said = damaged("no-motion.glb", &|e| {
        for v in e["poses"][1]["views"].as_array_mut().unwrap() {
            v["motion"] = serde_json::json!({});
        }
    });
    assert!(
        said.contains("no-motion.glb") && said.contains("pose 3 holds no view's motion prev"),
        "{said}"
    );
    let said = damaged("bad-step.glb", &|e| {
        e["poses"][0]["views"][0]["motion"]["next"]["step_m"] = serde_json::json!(-1.0);
    });
    assert!(said.contains("step_m -1"), "{said}");
    // --pose and --time together are refused.
    let o = Command::new("node")
        .arg(player().join("screenshot.mjs"))
        .arg("--glb")
        .arg(glb)
        .args([
            "--pose",
            "0",
            "--time",
            "0.05",
            "--camera=0,1,4",
            "--size",
            "8x8",
            "--sh",
        ])
        .arg(sh)
        .args(["--out", d.join("x.png").to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        !o.status.success() && stderr(&o).contains("--pose and --time"),
        "{}",
        stderr(&o)
    );
}
