//! `frf render SCENE.toml` end to end on the tiny stage's oracle field: the planner
//! leaves things out and the frames do not change for it, a camera on one side reads
//! only that side, a shot splits into frame ranges that resume, two walkers agree
//! between the GPU and the CPU reference, a distant crowd drawn at reduced detail matches
//! full detail; and upstream, `frf stage --for` and
//! `frf ingest --for` film and ingest only what a scene needs, and per-pose parts merge
//! into the same bytes as one ingest.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use crate::common::{frf, stderr};

use std::path::{Path, PathBuf};
use std::process::Output;

fn ok(args: &[&str]) -> Output {
    let o = frf(args);
    assert!(
        o.status.success(),
        "frf {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn gpu_flag() -> Option<&'static str> {
    frf_testkit::cpu_flag()
}

fn field() -> &'static PathBuf {
    &frf_testkit::tiny_field().field
}

/// A scene of `walkers` walkers on the tiny field, `frames` frames at 64x48, a camera
/// moving from `from` to `to` (x, y, z) looking at the first walker, over the built-in
/// sky's backdrop with the shadow from the maps; written into `dir`.
fn write_scene(dir: &Path, name: &str, walkers: &str, from: &str, to: &str) -> PathBuf {
    let text = format!(
        r#"field = "{field}"

[time]
start = 0.0
end = 0.4
fps = 10.0

[output]
size = [64, 48]

[lighting]
env = "sky"

[camera]
[[camera.key]]
time = 0.0
position = {from}
look_at = [0.0, 0.9, 0.0]
fov_deg = 45.0

[[camera.key]]
time = 0.4
position = {to}
look_at = [0.0, 0.9, 0.0]
fov_deg = 45.0

[composite]
backdrop = "env"
shadow = "maps"
{walkers}
"#,
        field = field().display()
    );
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn plan_json(scene: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["render", scene.to_str().unwrap(), "--plan", "--json"];
    args.extend(extra);
    serde_json::from_slice(&ok(&args).stdout).unwrap()
}

fn read_exr(path: &Path) -> Vec<f32> {
    image::open(path)
        .unwrap()
        .to_rgba32f()
        .into_raw()
        .into_iter()
        .collect()
}

#[test]
fn the_planner_leaves_work_out_and_the_frames_do_not_change() {
    let dir = tempfile::tempdir().unwrap();
    let walkers = "[[instance]]\n[[instance]]\nposition = [0.9, 0.0, -0.6]\nheading_deg = 60.0\ntime_offset = 0.4\n";
    let scene = write_scene(
        dir.path(),
        "two.toml",
        walkers,
        "[1.2, 1.3, 3.0]",
        "[-0.8, 1.4, 3.1]",
    );
    let plan = plan_json(&scene, &[]);
    for key in [
        "poses_used",
        "poses_total",
        "views_used",
        "views_total",
        "flows_used",
        "flows_total",
        "conditions_used",
        "conditions_total",
        "bytes_read",
        "bytes_total",
    ] {
        assert!(plan[key].is_u64(), "--plan --json lacks {key}: {plan}");
    }
    let n = |k: &str| plan[k].as_u64().unwrap();
    assert!(n("views_used") < n("views_total"), "{plan}");
    assert!(n("flows_used") < n("flows_total"), "{plan}");
    assert!(n("bytes_read") < n("bytes_total"), "{plan}");
    // Per walker: what its own rays reach, within what the shot reads (each walker is
    // made resident with its own views only; the frames below must not change for it).
    let walkers = plan["walker_counts"].as_array().unwrap();
    assert_eq!(walkers.len(), 2, "{plan}");
    for w in walkers {
        let views = w["views"].as_u64().unwrap();
        assert!(views > 0 && views <= n("views_used"), "{plan}");
    }

    let mut frames = Vec::new();
    // At full detail (the level of detail has its own test below).
    let planned = ["--detail", "0"];
    for (out, flags) in [("planned", &planned[..]), ("unplanned", &["--no-plan"][..])] {
        let out = dir.path().join(out);
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(flags);
        args.extend(gpu_flag());
        ok(&args);
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("render.json")).unwrap()).unwrap();
        // Every frame says which poses it drew.
        assert_eq!(report["frames"].as_array().unwrap().len(), 4);
        assert_eq!(report["frames"][0]["poses"].as_array().unwrap().len(), 2);
        frames.push(
            (0..4)
                .map(|i| read_exr(&out.join(format!("frame_{i:04}.exr"))))
                .collect::<Vec<_>>(),
        );
    }
    assert_eq!(
        frames[0], frames[1],
        "the planned frames differ from the unplanned ones"
    );
}

#[test]
fn a_camera_on_one_side_reads_only_that_side() {
    let dir = tempfile::tempdir().unwrap();
    let one_side = write_scene(
        dir.path(),
        "side.toml",
        "",
        "[0.4, 1.3, 3.0]",
        "[-0.4, 1.3, 3.0]",
    );
    let plan = plan_json(&one_side, &[]);
    let n = |k: &str| plan[k].as_u64().unwrap();
    // The camera sees the subject from the front only: well under half the grid.
    assert!(2 * n("views_used") < n("views_total"), "{plan}");
    assert!(plan["shadow_maps_read"].as_bool().unwrap(), "{plan}");
    // Each pose's subject is bounded round its hull: tighter than a walking person's
    // design bounds (1.2 m round the axis), and holding the whole body.
    let bounds = plan["bounds"].as_array().unwrap();
    assert_eq!(bounds.len(), plan["poses"].as_array().unwrap().len());
    for b in bounds {
        let radius = b["radius"].as_f64().unwrap();
        let (lo, hi) = (
            b["heights"][0].as_f64().unwrap(),
            b["heights"][1].as_f64().unwrap(),
        );
        assert!(radius > 0.3 && radius < 1.0, "{b}");
        assert!(lo < 0.0 && hi > 1.7 && hi < 2.3, "{b}");
    }

    // Without a shadow the maps are not read.
    let text = std::fs::read_to_string(&one_side)
        .unwrap()
        .replace("shadow = \"maps\"", "shadow = \"none\"");
    let no_shadow = dir.path().join("no_shadow.toml");
    std::fs::write(&no_shadow, text).unwrap();
    let plan2 = plan_json(&no_shadow, &[]);
    assert!(!plan2["shadow_maps_read"].as_bool().unwrap());
    assert!(plan2["bytes_read"].as_u64().unwrap() < n("bytes_read"));
}

#[test]
fn a_walker_turning_on_its_path_reads_the_views_of_every_heading_it_passes() {
    let dir = tempfile::tempdir().unwrap();
    let camera = "[0.0, 1.3, 3.0]";
    let standing = |heading: f32| format!("[[instance]]\nheading_deg = {heading}\n");
    let turning = "[[instance]]\n\
                   [[instance.key]]\ntime = 0.0\nposition = [0.0, 0.0, 0.0]\nheading_deg = 0.0\n\
                   [[instance.key]]\ntime = 0.4\nposition = [0.4, 0.0, 0.0]\nheading_deg = 90.0\n";
    let plans: Vec<serde_json::Value> = [standing(0.0), standing(90.0), turning.to_string()]
        .iter()
        .enumerate()
        .map(|(k, w)| {
            plan_json(
                &write_scene(dir.path(), &format!("w{k}.toml"), w, camera, camera),
                &[],
            )
        })
        .collect();
    let n = |p: &serde_json::Value, k: &str| p[k].as_u64().unwrap();
    let (start, end, walking) = (&plans[0], &plans[1], &plans[2]);
    // The two ends see different sides of the walker; walking between them reads both
    // and what lies between, and still not the whole grid.
    for k in ["views_used", "bytes_read"] {
        assert!(n(walking, k) > n(start, k).max(n(end, k)), "{k}: {plans:?}");
    }
    assert!(
        n(walking, "views_used") < n(walking, "views_total"),
        "{walking}"
    );
}

#[test]
fn frame_ranges_split_a_shot_and_a_rerun_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(
        dir.path(),
        "s.toml",
        "",
        "[1.0, 1.3, 3.0]",
        "[-1.0, 1.3, 3.0]",
    );
    let out = dir.path().join("shot");
    let run = |range: &str| {
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--frames",
            range,
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(gpu_flag());
        ok(&args)
    };
    run("0..2");
    assert!(out.join("render_frames_0-2.json").exists());
    assert!(!out.join("contact.png").exists(), "a sheet of half a shot");
    run("2..4");
    // The second job completes the shot: the sheet and the animated preview appear.
    assert!(out.join("contact.png").exists());
    let preview = std::fs::read(out.join("preview.png")).unwrap();
    assert!(
        preview.windows(4).any(|w| w == b"acTL"),
        "preview.png is not animated"
    );
    // A rerun keeps the frames there.
    run("0..2");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("render_frames_0-2.json")).unwrap())
            .unwrap();
    assert_eq!(report["frames_resumed"], 2);
    assert_eq!(report["frames_rendered"], 0);
    // A range outside the shot is refused, naming it.
    let o = frf(&[
        "render",
        scene.to_str().unwrap(),
        "--frames",
        "3..9",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("3..9"));
}

#[test]
fn walkers_agree_between_the_gpu_and_the_cpu_reference() {
    if gpu_flag().is_some() {
        eprintln!("FRF_SKIP_GPU=1: no GPU to compare with");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // Two walkers near the camera, and a third far enough away that the planner relights
    // its shadow maps at a coarser level than theirs.
    let walkers = "[[instance]]\nposition = [-0.5, 0.0, 0.0]\n[[instance]]\nposition = [0.6, 0.0, -0.4]\nheading_deg = 90.0\n[[instance]]\nposition = [-1.0, 0.0, -5.0]\nheading_deg = 30.0\n";
    let scene = write_scene(
        dir.path(),
        "three.toml",
        walkers,
        "[0.5, 4.0, 3.2]",
        "[-0.5, 4.0, 3.2]",
    );
    // Seen from above, large enough for the far walker's shadow to cover some hundreds
    // of pixels.
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&scene, text.replace("size = [64, 48]", "size = [192, 144]")).unwrap();
    let plan = plan_json(&scene, &[]);
    let shadow_levels: Vec<u64> = plan["walker_counts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["shadow_levels"][0].as_u64().unwrap())
        .collect();
    assert!(shadow_levels[0] < shadow_levels[2], "{shadow_levels:?}");
    let mut frames = Vec::new();
    for (out, flag) in [("gpu", None), ("cpu", Some("--cpu"))] {
        let out = dir.path().join(out);
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--frames",
            "0..1",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(flag);
        ok(&args);
        frames.push(read_exr(&out.join("frame_0000.exr")));
    }
    let (g, c) = (&frames[0], &frames[1]);
    let diff = g
        .iter()
        .zip(c)
        .map(|(a, b)| (a - b).abs() / b.abs().max(0.05))
        .collect::<Vec<_>>();
    let bad = diff.iter().filter(|&&d| d > 0.02).count();
    // Filtering at texel edges may differ on a few pixels; the frame agrees.
    assert!(
        bad * 200 < diff.len(),
        "{bad} of {} channels differ by more than 2 %",
        diff.len()
    );
}

#[test]
fn stage_and_ingest_for_a_scene_and_merged_parts_are_one_ingest() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Two poses of the walk (0.0 s and 0.1 s: poses 0 and 3), seen from the front.
    let text = std::fs::read_to_string(write_scene(
        d,
        "s.toml",
        "",
        "[0.5, 1.3, 3.0]",
        "[-0.5, 1.3, 3.0]",
    ))
    .unwrap()
    .replace("end = 0.4", "end = 0.2")
    .replace("time = 0.4", "time = 0.2");
    let scene = d.join("front.toml");
    std::fs::write(&scene, text).unwrap();
    let capture = d.join("capture");
    let o = ok(&[
        "stage",
        "--preset",
        "tiny",
        "--for",
        scene.to_str().unwrap(),
        "--out",
        capture.to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(said.contains("2 of 30 poses"), "{said}");
    let manifest = std::fs::read_to_string(capture.join("capture.toml")).unwrap();
    assert!(
        manifest.contains("filmed"),
        "the manifest does not say what was filmed"
    );

    let ingest = |out: &Path, extra: &[&str]| -> String {
        let mut args = vec![
            "ingest",
            capture.to_str().unwrap(),
            "--for",
            scene.to_str().unwrap(),
            "--flow-preset",
            "fast",
            "--no-eval",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        String::from_utf8_lossy(&ok(&args).stdout).into_owned()
    };
    let whole = d.join("whole.frf");
    // The built-in sky's sun, 40° high, casts a person's shadow 2.7 m long: the patch of
    // maps is made large enough for it to end before the maps fade (6.9 m).
    let said = ingest(&whole, &[]);
    assert!(said.contains("shadow maps: a 6.9 m patch"), "{said}");
    let parts = [d.join("p0.frf"), d.join("p3.frf")];
    ingest(&parts[0], &["--poses", "0"]);
    ingest(&parts[1], &["--poses", "3"]);
    let merged = d.join("merged.frf");
    ok(&[
        "merge",
        parts[0].to_str().unwrap(),
        parts[1].to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert!(
        std::fs::read(&whole).unwrap() == std::fs::read(&merged).unwrap(),
        "the merged parts differ from the single ingest"
    );

    // The field renders the scene it was made for; its plan needs nothing it lacks.
    let out = d.join("shot");
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--field",
        whole.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(gpu_flag());
    let o = ok(&args);
    assert!(out.join("frame_0001.png").exists());
    let warning = "warning: the lights that make the shadow are as low as";
    assert!(!stderr(&o).contains(warning), "{}", stderr(&o));
    // The tiny field's 3 m patch cuts that shadow: said, with the extent that holds it.
    let mut args = vec!["render", scene.to_str().unwrap(), "--frames", "1"];
    let cut = d.join("cut");
    args.extend(["--out", cut.to_str().unwrap()]);
    args.extend(gpu_flag());
    let said = stderr(&ok(&args));
    assert!(said.contains(warning), "{said}");
    assert!(said.contains("--shadow-extent 7"), "{said}");

    // A scene seen from behind needs views the field was not made with: its plan names
    // them, and its render is refused before it writes anything (it used to fail after
    // writing its settings).
    let behind = d.join("behind.toml");
    std::fs::write(
        &behind,
        std::fs::read_to_string(&scene)
            .unwrap()
            .replace("[0.5, 1.3, 3.0]", "[0.5, 1.3, -3.0]")
            .replace("[-0.5, 1.3, 3.0]", "[-0.5, 1.3, -3.0]"),
    )
    .unwrap();
    let behind_out = d.join("behind_shot");
    for extra in [&["--plan"][..], &["--out", behind_out.to_str().unwrap()]] {
        let mut args = vec![
            "render",
            behind.to_str().unwrap(),
            "--field",
            whole.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = frf(&args);
        let said = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{said}");
        assert!(said.contains("whole.frf: lacks"), "{said}");
        assert!(said.contains("pose 0 view ("), "{said}");
    }
    assert!(!behind_out.exists(), "a refused render left its directory");

    // A merge says which poses it holds; expecting the capture's, a missing pose is named
    // and nothing is written.
    let o = frf(&[
        "merge",
        parts[0].to_str().unwrap(),
        "--expect",
        capture.to_str().unwrap(),
        "--out",
        d.join("half.frf").to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{said}");
    assert!(said.contains("poses [3] are missing"), "{said}");
    assert!(!d.join("half.frf").exists());
    let o = ok(&[
        "merge",
        parts[0].to_str().unwrap(),
        parts[1].to_str().unwrap(),
        "--expect",
        "0,3",
        "--out",
        d.join("again.frf").to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        said.contains("2 poses [0, 3] (every one of the 2"),
        "{said}"
    );

    // Parts that share a pose are refused, naming it.
    let o = frf(&[
        "merge",
        parts[0].to_str().unwrap(),
        parts[0].to_str().unwrap(),
        "--out",
        d.join("bad.frf").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(!d.join("bad.frf").exists(), "a refused merge left a file");
}

/// `frf eval SCENE` judges each frame against the true walker at the frame's instant: on
/// the tiny field, which holds pose 0 only, a frame 0.1 s or more into the walk draws pose
/// 0 and scores far below the same frame judged at the pose's instant (`--truth-at
/// pose`); at 0 s the two truths are one.
#[test]
fn eval_judges_a_scene_against_the_walker_at_each_frames_instant() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(
        dir.path(),
        "s.toml",
        "",
        "[0.4, 1.3, 3.0]",
        "[-0.4, 1.3, 3.0]",
    );
    let capture = frf_testkit::tiny_field()
        .capture()
        .to_str()
        .unwrap()
        .to_string();
    let eval = |truth_at: &str| -> frf_eval::shot::ShotReport {
        let mut args = vec![
            "eval",
            scene.to_str().unwrap(),
            "--capture",
            &capture,
            "--frames",
            "4",
            "--lights",
            "32",
            "--truth-at",
            truth_at,
            "--json",
        ];
        args.extend(gpu_flag());
        serde_json::from_slice(&ok(&args).stdout).unwrap()
    };
    let (instant, pose) = (eval("instant"), eval("pose"));
    assert_eq!(instant.frames.len(), 4);
    for (a, b) in instant.frames.iter().zip(&pose.frames) {
        assert_eq!(a.pose, 0);
        assert!((a.time_from_pose_s - a.time).abs() < 1e-6, "{a:?}");
        assert!((a.truth_time_s - a.time).abs() < 1e-6, "{a:?}");
        assert_eq!(b.time_from_pose_s, 0.0);
        if a.index == 0 {
            assert!(
                (a.psnr_subject - b.psnr_subject).abs() < 1e-9,
                "{a:?} {b:?}"
            );
        } else {
            // The walker moved for 0.1 s or more; its nearest captured pose did not.
            assert!(a.psnr_subject + 3.0 < b.psnr_subject, "{a:?} {b:?}");
        }
    }
}

/// PSNR (peak 1) of `a` against `b`, RGBA frames of `w x h`, after averaging each over
/// blocks of `k x k` pixels.
fn block_psnr(a: &[f32], b: &[f32], (w, h): (usize, usize), k: usize) -> f64 {
    let (bw, bh) = (w / k, h / k);
    let mut se = 0.0f64;
    for by in 0..bh {
        for bx in 0..bw {
            for c in 0..4 {
                let mut d = 0.0f64;
                for y in by * k..(by + 1) * k {
                    for x in bx * k..(bx + 1) * k {
                        let i = (y * w + x) * 4 + c;
                        d += (a[i] - b[i]) as f64;
                    }
                }
                se += (d / (k * k) as f64).powi(2);
            }
        }
    }
    10.0 * (1.0 / (se / (bw * bh * 4) as f64)).log10()
}

#[test]
fn a_distant_crowd_at_reduced_detail_matches_full_detail() {
    // Four walkers 8-13 m from the camera: the planner draws them at reduced detail
    // (docs/design.md section 6.5); unplanned, every walker is at full detail.
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("crowd.toml");
    std::fs::write(
        &scene,
        format!(
            r#"field = "{field}"
[time]
start = 0.0
end = 0.1
fps = 10.0
interpolate = "nearest"
[output]
size = [160, 96]
[lighting]
env = "sky"
[camera]
[[camera.key]]
time = 0.0
position = [0.0, 2.0, 10.0]
look_at = [0.0, 0.8, 0.0]
fov_deg = 40.0
[composite]
backdrop = "env"
shadow = "maps"
[[instance]]
[[instance]]
position = [1.5, 0.0, -2.0]
heading_deg = 60.0
time_offset = 0.4
[[instance]]
position = [-1.8, 0.0, 1.0]
heading_deg = -120.0
[[instance]]
position = [0.6, 0.0, 3.0]
heading_deg = 200.0
"#,
            field = field().display()
        ),
    )
    .unwrap();
    let plan = plan_json(&scene, &[]);
    let levels: Vec<u64> = plan["walker_counts"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|w| w["levels"].as_array().unwrap().clone())
        .map(|l| l.as_u64().unwrap())
        .collect();
    assert!(levels.iter().all(|&l| (1..=2).contains(&l)), "{levels:?}");

    let mut frames = Vec::new();
    for (out, flag) in [("reduced", None), ("full", Some("--no-plan"))] {
        let out = dir.path().join(out);
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--layers",
        ];
        args.extend(flag);
        args.extend(gpu_flag());
        ok(&args);
        frames.push((
            read_exr(&out.join("frame_0000.exr")),
            read_exr(&out.join("frame_0000_subject.exr")),
        ));
        // render.json says how many views were reduced: none at full detail.
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("render.json")).unwrap()).unwrap();
        let made = report["residency"]["reduced_made"].as_u64().unwrap();
        assert_eq!(made > 0, flag.is_none(), "{made} views reduced");
    }
    let (reduced, full) = (&frames[0], &frames[1]);
    // The walkers cover the same pixels...
    let coverage = |layer: &[f32]| layer.iter().skip(3).step_by(4).sum::<f32>();
    let (a, b) = (coverage(&reduced.1), coverage(&full.1));
    assert!(b > 100.0 && (a - b).abs() < 0.02 * b, "coverage {a} vs {b}");
    // ...and the frames agree to the detail the frame's pixels hold: within 28 dB pixel
    // by pixel (a pixel samples the full views at one point: aliased), 40 dB over 4x4
    // blocks (measured: 30.7 and 45.3 dB).
    let size = (160, 96);
    let pixel = block_psnr(&reduced.0, &full.0, size, 1);
    let blocks = block_psnr(&reduced.0, &full.0, size, 4);
    assert!(
        pixel > 28.0 && blocks > 40.0,
        "{pixel:.1} dB, {blocks:.1} dB over 4x4"
    );
}

/// A light that turns every frame (issue 37): the shot relights its resident poses in
/// place, from the basis codes they keep, and every frame equals the same frame rendered
/// alone, its poses made resident afresh under that light: to 1e-6 where the host works
/// the coefficients out both times (the CPU reference); on the GPU, whose relights in
/// place look them up on the device (design §4.9), to the GPU-vs-CPU tolerance of
/// `tests/gpu_vs_cpu.rs` (2e-3: the lookup's float rounding can move a pre-lit code by
/// one; measured 4e-4).
#[test]
fn a_turning_light_relit_in_place_draws_what_a_fresh_residency_draws() {
    let dir = tempfile::tempdir().unwrap();
    let walkers = "[[instance]]\n[[instance]]\nposition = [0.9, 0.0, -0.6]\nheading_deg = 60.0\n";
    let scene = write_scene(
        dir.path(),
        "turning.toml",
        walkers,
        "[0.0, 1.4, 3.0]",
        "[0.4, 1.4, 3.0]",
    );
    let text = std::fs::read_to_string(&scene).unwrap().replace(
        "[lighting]\nenv = \"sky\"\n",
        "[lighting]\nenv = \"sky\"\n[[lighting.key]]\ntime = 0.0\nyaw_deg = 0.0\n\
         [[lighting.key]]\ntime = 0.4\nyaw_deg = 120.0\n",
    );
    std::fs::write(&scene, text).unwrap();
    let render = |out: &Path, frames: &str| {
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--frames",
            frames,
        ];
        args.extend(gpu_flag());
        ok(&args);
    };
    let whole = dir.path().join("whole");
    render(&whole, "0..3");
    let report = whole.join("render_frames_0-3.json");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(report).unwrap()).unwrap();
    let relights = report["residency"]["relights"].as_u64().unwrap();
    assert!(
        relights >= 4,
        "two walkers relit on frames 1 and 2: {relights}"
    );
    for k in 0..3 {
        let alone = dir.path().join(format!("alone{k}"));
        render(&alone, &format!("{k}..{}", k + 1));
        let name = format!("frame_{k:04}.exr");
        let (a, b) = (read_exr(&whole.join(&name)), read_exr(&alone.join(&name)));
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max);
        let bound = if gpu_flag().is_none() { 2e-3 } else { 1e-6 };
        assert!(
            worst <= bound,
            "frame {k}: relit in place differs by {worst}"
        );
    }
}

/// `frf bench frame` (issue 37): a row per walker count and lighting, the fields its JSON
/// promises, turning rows relighting every walker every frame and constant ones none;
/// per-pass device times and dispatches where the adapter has timestamps (issues 47, 58).
#[test]
fn the_frame_bench_reports_a_row_per_walkers_and_light() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(
        dir.path(),
        "bench.toml",
        "[[instance]]\n",
        "[0.0, 1.4, 3.0]",
        "[0.0, 1.4, 3.0]",
    );
    // `frf bench frame` of the scene with `extra` arguments, its JSON report.
    let bench = |extra: &[&str]| -> serde_json::Value {
        let mut args = vec!["bench", "frame", scene.to_str().unwrap(), "--json"];
        args.extend(extra);
        args.extend(gpu_flag());
        serde_json::from_slice(&ok(&args).stdout).unwrap()
    };
    let report = bench(&["--walkers", "1,3", "--frames", "2"]);
    let rows = report["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4, "{report}");
    for r in rows {
        for key in [
            "walkers",
            "light",
            "host_ms_per_frame",
            "gpu_ms_per_frame",
            "wall_ms_per_frame",
        ] {
            assert!(!r[key].is_null(), "{key} missing: {r}");
        }
        let walkers = r["walkers"].as_f64().unwrap();
        let relit = r["relights_per_frame"].as_f64().unwrap();
        match r["light"].as_str().unwrap() {
            "turning" => assert_eq!(relit, walkers, "{r}"),
            "constant" => assert_eq!(relit, 0.0, "{r}"),
            other => panic!("light {other}"),
        }
        // Host and device time are parts of the frame's: each frame's wait on the device
        // is within its wall time, and so are their medians.
        let ms = |key: &str| r[key].as_f64().unwrap();
        let (host, gpu, wall) = (
            ms("host_ms_per_frame"),
            ms("gpu_ms_per_frame"),
            ms("wall_ms_per_frame"),
        );
        assert!(host > 0.0 && host <= wall, "{r}");
        assert!(gpu >= 0.0 && gpu <= wall, "{r}");
        // Submitting is part of the host's work.
        let submit = ms("submit_ms_per_frame");
        assert!(submit > 0.0 && submit <= host, "{r}");
        // The calling thread's own CPU time (Unix has its clock): each frame's is within its
        // wall time, and so is their median.
        let cpu = ms("host_cpu_ms_per_frame");
        assert!(cpu > 0.0 && cpu <= wall, "{r}");
        // The first frame makes the walkers' poses resident: slower than the frames
        // after it.
        assert!(ms("first_frame_ms") > wall, "{r}");
        // Reading and relighting poses: only under the turning light, within the frame.
        let relighting = ms("residency_ms_per_frame");
        match r["light"].as_str().unwrap() {
            "turning" => assert!(relighting > 0.0 && relighting <= wall, "{r}"),
            _ => assert_eq!(relighting, 0.0, "{r}"),
        }
        let passes = r["passes"].as_array().unwrap();
        let pass = |name: &str| passes.iter().find(|p| p["pass"] == name);
        if report["pass_clock"] == "gpu-timestamps" {
            for name in ["frame", "composite"] {
                let p = pass(name).unwrap_or_else(|| panic!("no {name} pass: {r}"));
                assert!(p["passes"].as_u64().unwrap() >= 1, "{r}");
                assert!(p["ms"].as_f64().unwrap() >= 0.0, "{r}");
            }
            assert_eq!(pass("relight").is_some(), r["light"] == "turning", "{r}");
            assert!(ms("gpu_timestamps_ms_per_frame") > 0.0, "{r}");
            // Dispatches a frame that do not grow with walkers: every walker's light looked
            // up on the device in one, every walker's views relit by one pair (sums,
            // encoding: it was a pair a walker), every shadow in one, the composite one;
            // the frame pass one for the copies of a pose at a level of detail in a page
            // (here every walker draws the one pose, at one or two levels: it was one a
            // walker).
            let dispatches = |name: &str| pass(name).map(|p| p["dispatches"].as_u64().unwrap());
            if r["light"] == "turning" {
                assert_eq!(dispatches("turn light"), Some(1), "{r}");
                assert_eq!(dispatches("relight"), Some(2), "{r}");
            }
            assert_eq!(dispatches("composite"), Some(1), "{r}");
            let frame = dispatches("frame").unwrap();
            assert!((1..=2).contains(&frame), "{r}");
        } else {
            assert!(passes.is_empty(), "{r}");
            assert!(r["gpu_timestamps_ms_per_frame"].is_null(), "{r}");
        }
    }
    if gpu_flag().is_none() {
        // Lavapipe and real GPUs have timestamp queries.
        assert_eq!(report["pass_clock"], "gpu-timestamps", "{report}");
    }
    assert_eq!(report["spacing"], "held", "{report}");
    // Frames spaced as the shot's (10 fps; the tiny field holds one pose, so none streams
    // in here).
    let unread = ok(&[
        "bench",
        "frame",
        scene.to_str().unwrap(),
        "--walkers",
        "1",
        "--light",
        "constant",
        "--frames",
        "3",
        "--spacing",
        "shot",
        "--no-readback",
        "--json",
    ]);
    let shot: serde_json::Value = serde_json::from_slice(&unread.stdout).unwrap();
    assert_eq!(shot["spacing"], "shot", "{shot}");
    // Drawn and waited for, not read back (as a viewer shows a frame); read back by
    // default.
    assert_eq!(
        (report["readback"].clone(), shot["readback"].clone()),
        (true.into(), false.into())
    );
    assert!(
        stderr(&unread).contains("not read back"),
        "{}",
        stderr(&unread)
    );
    assert!(
        shot["rows"][0]["wall_ms_per_frame"].as_f64().unwrap() > 0.0,
        "{shot}"
    );
    let bad = frf(&["bench", "frame", scene.to_str().unwrap(), "--walkers", "0"]);
    assert!(!bad.status.success());
    assert!(stderr(&bad).contains("--walkers 0"), "{}", stderr(&bad));
    // Issue 59: a stray comma was "invalid value ''"; a count given twice was timed twice.
    for (walkers, want) in [("1,", "an empty count"), ("1,2,1", "1 is given twice")] {
        let bad = frf(&[
            "bench",
            "frame",
            scene.to_str().unwrap(),
            "--walkers",
            walkers,
        ]);
        assert!(!bad.status.success(), "--walkers {walkers} accepted");
        assert!(stderr(&bad).contains(want), "{}", stderr(&bad));
    }
    // A light turning 1° a frame, within the shot's light tolerance (2°): a light's turn
    // relative to a walker is held to the tolerance a walker's own turn is, and a walker
    // is lit for the farthest frame ahead whose light holds its own. Lit at frame 0 for
    // frame 2's light, it holds frames 0 to 4 and is relit once in 9 frames, at frame 5
    // (for frame 7's); lit for its own frame, every third frame (2 of 9); relit for any
    // turn, every frame.
    let slow = bench(&[
        "--walkers",
        "1",
        "--light",
        "turning",
        "--turn-deg",
        "1",
        "--frames",
        "9",
    ]);
    assert_eq!(slow["turn_deg_per_frame"], 1.0, "{slow}");
    let relit = slow["rows"][0]["relights_per_frame"].as_f64().unwrap();
    assert!(relit > 0.0 && relit <= 1.0 / 9.0 + 1e-9, "{slow}");
    let bad = frf(&["bench", "frame", scene.to_str().unwrap(), "--turn-deg", "0"]);
    assert!(!bad.status.success());
    assert!(stderr(&bad).contains("--turn-deg 0"), "{}", stderr(&bad));
    if gpu_flag().is_none() {
        // More walkers than the device's array textures hold: refused up front, by name,
        // before any pose is read (it panicked in wgpu, issue 48).
        let many = frf(&[
            "bench",
            "frame",
            scene.to_str().unwrap(),
            "--walkers",
            "5000",
        ]);
        assert!(!many.status.success());
        let text = stderr(&many);
        assert!(
            text.contains("--walkers 5000") && text.contains("at most 682 walkers"),
            "{text}"
        );
        assert!(!text.contains("panicked"), "{text}");
    }
}

/// `--sun` on a scene is added to its lighting, or replaces the scene's own sun, and says
/// which (it was once ignored silently); `--yaw`, which a scene's lighting keys give, is
/// refused.
#[test]
fn a_sun_flag_on_a_scene_is_used_and_said() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(
        dir.path(),
        "one.toml",
        "[[instance]]\n",
        "[1.2, 1.3, 3.0]",
        "[1.2, 1.3, 3.0]",
    );
    // `file`'s first frame (into `out`) with `extra` arguments, and what was said.
    let render_of = |file: &std::path::Path, out: &str, extra: &[&str]| {
        let out = dir.path().join(out);
        let mut args = vec![
            "render",
            file.to_str().unwrap(),
            "--frames",
            "0..1",
            "--cpu",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = ok(&args);
        (read_exr(&out.join("frame_0000.exr")), stderr(&o))
    };
    let render = |out: &str, extra: &[&str]| render_of(&scene, out, extra);
    let (plain, _) = render("plain", &[]);
    let (sunlit, said) = render("sunlit", &["--sun", "22,30,0.53,500"]);
    assert!(
        said.contains("--sun: added to the scene's lighting"),
        "{said}"
    );
    let sum = |v: &[f32]| v.iter().map(|&x| x as f64).sum::<f64>();
    assert!(
        sum(&sunlit) > sum(&plain) * 1.05,
        "{} {}",
        sum(&sunlit),
        sum(&plain)
    );
    let o = frf(&["render", scene.to_str().unwrap(), "--yaw", "30", "--plan"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--yaw"), "{}", stderr(&o));

    // A scene with a sun of its own: the flag's replaces it (the frame is the frame of
    // the scene whose own sun is the flag's), not added to it (this was untested).
    let text = std::fs::read_to_string(&scene).unwrap();
    let with_sun = |az: f32, e: f32| {
        text.replace(
            "env = \"sky\"",
            &format!(
                "env = \"sky\"\n[lighting.sun]\nazimuth_deg = {az}\nelevation_deg = 30.0\n\
                 angular_diameter_deg = 0.53\nilluminance = {e}"
            ),
        )
    };
    let own = dir.path().join("own.toml");
    std::fs::write(&own, with_sun(-120.0, 300.0)).unwrap();
    let same = dir.path().join("same.toml");
    std::fs::write(&same, with_sun(22.0, 500.0)).unwrap();
    let (replaced, said) = render_of(&own, "replaced", &["--sun", "22,30,0.53,500"]);
    assert!(said.contains("--sun: replaces the scene's sun"), "{said}");
    let (reference, _) = render_of(&same, "reference", &[]);
    let (kept, _) = render_of(&own, "kept", &[]);
    let worst = |a: &[f32], b: &[f32]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max)
    };
    assert!(
        worst(&replaced, &reference) < 1e-5,
        "{}",
        worst(&replaced, &reference)
    );
    // Control: the scene's own sun gives another frame.
    assert!(
        worst(&kept, &reference) > 1e-2,
        "{}",
        worst(&kept, &reference)
    );
}

/// Two walkers side by side walking toward the camera under a low sun from their left,
/// on the tiny field: `frf eval` scores each against the stage's truth of both (their
/// placements, instants and light), their feet stay planted on straight paths at the
/// captured speed, the one in the other's shadow scores better with walker-on-walker
/// shadows than without (`--no-walker-shadows`), and `--standing` finds the walking walker
/// as good as the same walker standing. A scene whose path has one key is refused by name,
/// and nothing is written.
#[test]
fn eval_scores_walkers_on_paths_that_shade_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let capture = frf_testkit::tiny_field()
        .capture()
        .to_str()
        .unwrap()
        .to_string();
    let scene = dir.path().join("side.toml");
    std::fs::write(
        &scene,
        format!(
            r#"field = "{field}"
[time]
end = 1.0
fps = 10.0
[output]
size = [96, 72]
[lighting]
env = "uniform"
intensity = 0.35
[lighting.sun]
azimuth_deg = -90.0
elevation_deg = 25.0
illuminance = 12.0
[camera]
[[camera.key]]
time = 0.0
position = [-3.0, 1.6, 4.0]
look_at = [0.3, 0.8, -1.0]
fov_deg = 40.0
[composite]
backdrop = "env"
ground = 0.3
[[instance]]
[[instance.key]]
time = 0.0
position = [-0.55, 0.0, -2.0]
[[instance.key]]
time = 1.0
position = [-0.55, 0.0, -0.95]
[[instance]]
[[instance.key]]
time = 0.0
position = [0.55, 0.0, -2.0]
[[instance.key]]
time = 1.0
position = [0.55, 0.0, -0.95]
"#,
            field = field().display()
        ),
    )
    .unwrap();
    let eval = |extra: &[&str]| -> frf_eval::shot::ShotReport {
        let mut args = vec![
            "eval",
            scene.to_str().unwrap(),
            "--capture",
            &capture,
            "--frames",
            "3",
            "--lights",
            "32",
            "--truth-at",
            "pose",
            "--json",
        ];
        args.extend(extra);
        args.extend(gpu_flag());
        serde_json::from_slice(&ok(&args).stdout).unwrap()
    };
    let with = eval(&[]);
    let without = eval(&["--no-walker-shadows"]);
    assert_eq!(with.frames.len(), 3);
    assert!(with.frames.iter().all(|f| f.walkers.len() == 2));
    // 1.05 m in 1 s along straight lines: the captured speed, feet planted.
    assert!(with.foot_slide_cm < 0.1, "{}", with.foot_slide_cm);
    assert!(with.alpha_iou_mean > 0.7, "{}", with.alpha_iou_mean);
    let shaded = |r: &frf_eval::shot::ShotReport| r.walkers[1].psnr_subject_mean.unwrap();
    eprintln!(
        "walker in the other's shadow: {:.2} dB with walker shadows, {:.2} without",
        shaded(&with),
        shaded(&without)
    );
    assert!(shaded(&with) > shaded(&without) + 1.0);
    // The walker on the left does not change: nothing stands between it and the sun.
    let left = |r: &frf_eval::shot::ShotReport| r.walkers[0].psnr_subject_mean.unwrap();
    assert!((left(&with) - left(&without)).abs() < 0.05);

    // One walker's path, against itself standing: what walking costs.
    let text = std::fs::read_to_string(&scene).unwrap();
    let cut = text
        .find("[[instance]]\n[[instance.key]]\ntime = 0.0\nposition = [0.55")
        .unwrap();
    let one = dir.path().join("one.toml");
    std::fs::write(&one, &text[..cut]).unwrap();
    let mut args = vec![
        "eval",
        one.to_str().unwrap(),
        "--capture",
        &capture,
        "--frames",
        "2",
        "--lights",
        "32",
        "--standing",
        "--json",
    ];
    args.extend(gpu_flag());
    let r: frf_eval::shot::ShotReport = serde_json::from_slice(&ok(&args).stdout).unwrap();
    let standing = r.psnr_subject_standing_mean.unwrap();
    assert!(
        (r.psnr_subject_mean - standing).abs() < 0.5,
        "{} vs {standing}",
        r.psnr_subject_mean
    );

    // A path of one key: refused naming the walker's key, and no frame written.
    let bad = dir.path().join("bad.toml");
    let cut = text
        .find("[[instance.key]]\ntime = 1.0\nposition = [-0.55")
        .unwrap();
    let end = text
        .find("[[instance]]\n[[instance.key]]\ntime = 0.0\nposition = [0.55")
        .unwrap();
    std::fs::write(&bad, format!("{}{}", &text[..cut], &text[end..])).unwrap();
    let out = dir.path().join("bad_out");
    let o = frf(&[
        "render",
        bad.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("instance[0].key[0]") && e.contains("two keys"),
        "{e}"
    );
    assert!(!out.exists(), "a refused scene wrote {}", out.display());
}
