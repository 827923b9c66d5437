//! The command-line verbs that had no end-to-end test, through the binary, each checked
//! against a value known independently of the code under test: `info` (its byte
//! accounting against the file's size), `flow` and `flow-bench` (a synthetic pair with a
//! known translation), `stage projection-error` and `stage codec-curve` (bounds from
//! their measured values with headroom, and the ordering JPEG quality must give),
//! `hull` (a mesh where the walker stands), and `render --camera --floor ground --pose`; and
//! `info` into a closed pipe, which ends quietly.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use crate::common::frf;

use std::path::Path;
use std::process::Output;

fn ok_json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!("{e}: {}", String::from_utf8_lossy(&o.stdout));
    })
}

/// A smooth textured grey image, and the same translated by `(dx, dy)` whole pixels
/// (`B(x, y) = A(x − dx, y − dy)`, so the flow from A to B is `(dx, dy)` everywhere;
/// the texture is analytic, so nothing enters from outside the frame).
fn shifted_pair(dir: &Path, (dx, dy): (i32, i32)) -> (std::path::PathBuf, std::path::PathBuf) {
    let texture = |x: i32, y: i32| {
        let (x, y) = (x as f32, y as f32);
        (127.0 + 60.0 * (x * 0.5).sin() + 50.0 * (y * 0.45 + x * 0.1).cos()) as u8
    };
    let (w, h) = (48u32, 40u32);
    let a = image::GrayImage::from_fn(w, h, |x, y| image::Luma([texture(x as i32, y as i32)]));
    let b = image::GrayImage::from_fn(w, h, |x, y| {
        image::Luma([texture(x as i32 - dx, y as i32 - dy)])
    });
    let (pa, pb) = (dir.join("frame10.png"), dir.join("frame11.png"));
    a.save(&pa).unwrap();
    b.save(&pb).unwrap();
    (pa, pb)
}

#[test]
fn info_accounts_for_the_bytes_of_the_field_file() {
    let field = &frf_testkit::tiny_field().field;
    let report = ok_json(&frf(&["info", field.to_str().unwrap(), "--json"]));
    assert_eq!(report["views"], 108);
    assert_eq!(report["poses"], 1);
    // 36 x 3 views: 216 horizontal and 144 vertical neighbour flows.
    assert_eq!(report["flow_maps"], 360);
    let parts: u64 = report["bytes"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    let size = std::fs::metadata(field).unwrap().len();
    // The chunks account for the file, less its header and index (under 1 %).
    assert!(
        parts <= size && parts as f64 > 0.99 * size as f64,
        "{parts} of {size}"
    );
}

/// `frf info FIELD | head`: when the reader of its output is gone, `frf` ends as a Unix
/// tool does, by SIGPIPE, quietly, and does not panic in `println!`.
#[test]
fn a_closed_pipe_ends_the_program_quietly() {
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    let field = &frf_testkit::tiny_field().field;
    // The reader is closed before `frf` starts, so no process can hold it open (with a
    // reader the child would inherit, another test's process started meanwhile could).
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let o = crate::common::frf_command(&["info", field.to_str().unwrap()])
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.signal(), Some(13), "{:?}: {stderr}", o.status);
    assert!(stderr.is_empty(), "{stderr}");
}

#[test]
fn flow_recovers_a_known_translation() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = shifted_pair(dir.path(), (2, 1));
    let out = dir.path().join("f.flo");
    let o = frf(&[
        "flow",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let flow = frf_flow::read_flo(&out).unwrap();
    let (mut sum, mut n) = ([0.0f64; 2], 0usize);
    // The interior, away from the border the estimator extrapolates over.
    for y in 4..flow.height() - 4 {
        for x in 4..flow.width() - 4 {
            let f = flow.get(x, y);
            sum[0] += f[0] as f64;
            sum[1] += f[1] as f64;
            n += 1;
        }
    }
    let mean = [sum[0] / n as f64, sum[1] / n as f64];
    // Measured mean error 0.02 px (flow-bench below); 0.1 px leaves headroom.
    assert!(
        (mean[0] - 2.0).abs() < 0.1 && (mean[1] - 1.0).abs() < 0.1,
        "{mean:?}"
    );
}

#[test]
fn flow_bench_scores_a_sequence_against_its_true_flow() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("Shift");
    std::fs::create_dir_all(&seq).unwrap();
    shifted_pair(&seq, (2, 1));
    let truth = frf_core::image::Image::from_fn(48, 40, |_, _| [2.0f32, 1.0]);
    frf_flow::write_flo(&seq.join("flow10.flo"), &truth).unwrap();
    let report = ok_json(&frf(&[
        "flow-bench",
        dir.path().to_str().unwrap(),
        "--json",
    ]));
    let s = &report["sequences"][0];
    assert_eq!(s["name"], "Shift");
    // Measured 0.016 px; a translation this smooth is the estimator's easy case.
    let epe = s["epe"].as_f64().unwrap();
    assert!(epe < 0.1, "EPE {epe}");
    assert!(s["seconds"].as_f64().unwrap() > 0.0);
}

#[test]
fn projection_error_and_codec_curve_report_bounded_errors() {
    let capture = frf_testkit::tiny_field().capture();
    let cap = capture.to_str().unwrap();
    let rows = ok_json(&frf(&[
        "stage",
        "projection-error",
        "--capture",
        cap,
        "--env",
        "sky",
        "--json",
    ]));
    let sky = &rows[0];
    let mean = sky["mean_psnr_subject_db"].as_f64().unwrap();
    let min = sky["min_psnr_subject_db"].as_f64().unwrap();
    // Measured on the tiny preset under the sky: 29.4 dB mean, 26.4 dB worst view.
    assert!(mean > 26.0 && min > 23.0 && min <= mean, "{sky}");

    let rows = ok_json(&frf(&[
        "stage",
        "codec-curve",
        "--capture",
        cap,
        "--qualities",
        "50,95",
        "--json",
    ]));
    let (low, high) = (&rows[0], &rows[1]);
    let ratio = |r: &serde_json::Value| r["ratio_vs_16bit"].as_f64().unwrap();
    let psnr = |r: &serde_json::Value| r["mean_relit_psnr_db"].as_f64().unwrap();
    // Lower quality compresses more and relights worse; measured 66:1 / 30.2 dB at 50,
    // 26:1 / 42.1 dB at 95.
    assert!(ratio(low) > ratio(high) && ratio(high) > 10.0, "{rows}");
    assert!(psnr(high) > psnr(low) + 5.0 && psnr(high) > 38.0, "{rows}");
}

#[test]
fn hull_exports_a_mesh_where_the_walker_stands() {
    let field = &frf_testkit::tiny_field().field;
    let dir = tempfile::tempdir().unwrap();
    let ply = dir.path().join("hull.ply");
    let o = frf(&[
        "hull",
        field.to_str().unwrap(),
        "--out",
        ply.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read(&ply).unwrap();
    let header_end = text.windows(10).position(|w| w == b"end_header").unwrap();
    let header = String::from_utf8_lossy(&text[..header_end]);
    let count = |what: &str| -> usize {
        header
            .lines()
            .find_map(|l| l.strip_prefix(&format!("element {what} ")))
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    assert!(count("vertex") > 50 && count("face") > 50, "{header}");
}

#[test]
fn render_follows_a_camera_path_with_a_grey_ground_and_a_chosen_pose() {
    let field = &frf_testkit::tiny_field().field;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("path.toml");
    std::fs::write(
        &path,
        "[[key]]\ntime = 0.0\nposition = [0.0, 1.2, 3.0]\nlook_at = [0.0, 0.9, 0.0]\nfov_deg = 40.0\n\
         [[key]]\ntime = 1.0\nposition = [3.0, 1.2, 0.0]\nlook_at = [0.0, 0.9, 0.0]\nfov_deg = 40.0\n",
    )
    .unwrap();
    let out = dir.path().join("shot");
    let mut args = vec![
        "render",
        field.to_str().unwrap(),
        "--env",
        "sky",
        "--floor",
        "ground",
        "--pose",
        "0",
        "--camera",
        path.to_str().unwrap(),
        "--frames",
        "2",
        "--size",
        "48x64",
        "--out",
        out.to_str().unwrap(),
    ];
    if let Some(flag) = frf_testkit::cpu_flag() {
        args.push(flag);
    }
    let o = frf(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for i in 0..2 {
        let img = image::open(out.join(format!("frame_{i:04}.png")))
            .unwrap()
            .to_rgba8();
        assert_eq!(img.dimensions(), (48, 64));
        let covered = img.pixels().filter(|p| p[3] > 128).count();
        assert!(
            covered > 100,
            "frame {i}: the walker covers {covered} pixels"
        );
    }
}
