//! `frf report --quick` end to end on a small stage capture: every stage present with a
//! default setting, every error and time finite, a plot per stage and the page; the
//! peers' JSON joins as the optical-flow plot; a rerun keeps every run; bad peers are
//! refused naming the file.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use crate::common::{frf_command, staged_capture, stderr};
use frf_eval::report::STAGES;

#[test]
fn a_quick_report_measures_every_stage_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let cap = staged_capture(dir.path());
    // The peer script's output shape (benches/flow_peers/run_peers.py), two of ours and
    // two of OpenCV's methods.
    let peers = dir.path().join("peers.json");
    std::fs::write(
        &peers,
        r#"{"meta": {"command": "run_peers.py"}, "summary": {
            "frf_fast": {"epe": 0.4, "aae": 5.0, "seconds": 0.2},
            "frf_balanced": {"epe": 0.25, "aae": 3.0, "seconds": 1.5},
            "farneback": {"epe": 0.9, "aae": 9.0, "seconds": 0.05},
            "dis_medium": {"epe": 0.6, "aae": 7.0, "seconds": 0.02}}}"#,
    )
    .unwrap();
    let out = dir.path().join("report");
    // `--out` relative to the working directory, as a person types it: the shots' scene
    // files named their field relative to it, and a scene reads paths relative to itself
    // (the field was looked for at report/runs/report/runs/...).
    let mut args = vec![
        "report",
        "--capture",
        cap.to_str().unwrap(),
        "--out",
        "report",
        "--quick",
        "--peers",
        peers.to_str().unwrap(),
    ];
    args.extend(frf_testkit::cpu_flag());
    let o = frf_command(&args).current_dir(dir.path()).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    let rows = report["rows"].as_array().unwrap();
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    let mut stages = STAGES.to_vec();
    stages.push("optical flow (Middlebury)");
    for stage in &stages {
        let of: Vec<_> = rows.iter().filter(|r| r["stage"] == *stage).collect();
        assert!(!of.is_empty(), "no rows for {stage}");
        assert!(
            of.iter().any(|r| r["default"] == true),
            "{stage}: no default setting"
        );
        for r in &of {
            let (e, s) = (r["error"].as_f64(), r["seconds"].as_f64());
            assert!(
                e.is_some_and(f64::is_finite) && s.is_some_and(|s| s.is_finite() && s >= 0.0),
                "{stage}: {r}"
            );
            assert!(!r["command"].as_str().unwrap().is_empty(), "{r}");
        }
        let name = frf_eval::report::html::plot_name(stage);
        let svg = std::fs::read_to_string(out.join(format!("{name}.svg"))).unwrap();
        assert!(svg.contains("Pareto front"), "{name}.svg");
        assert!(page.contains(&format!("{name}.")), "the page lacks {name}");
    }
    assert_eq!(
        report["peers"].as_array().unwrap().len(),
        2,
        "{}",
        report["peers"]
    );
    assert!(report["machine"]["cores"].as_u64().unwrap() >= 1);
    // Scores a reader relies on: the four-way morph beats nearest-view at quad centres;
    // JPEG 95 relights better than 50.
    let row = |stage: &str, value: &str, metric: &str| {
        rows.iter()
            .find(|r| {
                r["stage"] == stage
                    && r["metric"] == metric
                    && r["value"].as_str().unwrap().starts_with(value)
            })
            .unwrap_or_else(|| panic!("no {stage} / {value} / {metric}"))["error"]
            .as_f64()
            .unwrap()
    };
    assert!(
        row("novel views", "fourway", "subject PSNR dB")
            > row("novel views", "nearest", "subject PSNR dB")
    );
    assert!(
        row("basis compression", "95", "relit PSNR dB")
            > row("basis compression", "50", "relit PSNR dB")
    );

    // A rerun keeps every run: the same rows, measured before.
    let o = frf_command(&args).current_dir(dir.path()).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let again: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    let strip = |v: &serde_json::Value| {
        v["rows"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r["stage"] != "flow storage") // timed in process, each time anew
            .cloned()
            .collect::<Vec<_>>()
    };
    assert_eq!(strip(&again), strip(&report));

    // Peers that are not the peer script's output are refused naming the file.
    std::fs::write(&peers, "{\"results\": {}}").unwrap();
    let o = frf_command(&args).current_dir(dir.path()).output().unwrap();
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("peers.json") && e.contains("summary"),
        "{e}"
    );
}
