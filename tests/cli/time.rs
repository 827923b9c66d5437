//! The walk between captured poses, through the binary: `frf ingest --pose-flow` stores
//! each view's flow to the next and the previous captured pose, reports its error against
//! the stage's truth, and its per-pose parts still merge into the single ingest.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use crate::common::{frf, stderr};

#[test]
fn pose_flows_are_stored_judged_and_merge_like_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cap = d.join("cap");
    let o = frf(&[
        "stage",
        "--preset",
        "tiny",
        "--poses",
        "0,1,2",
        "--size",
        "32x45",
        "--perturbation",
        "0",
        "--lights-per-axis",
        "1",
        "--out",
        cap.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let ingest = |out: &std::path::Path, extra: &[&str]| {
        let mut args = vec![
            "ingest",
            cap.to_str().unwrap(),
            "--flow-preset",
            "fast",
            "--pose-flow",
            "--no-shadows",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = frf(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let whole = d.join("whole.frf");
    let said = ingest(&whole, &[]);
    // Judged against the truth: at 32x45 the walker moves a third of a pixel between
    // poses (measured: error 0.35 px against 0.30 px of true motion); a flow paired with
    // the wrong pose or column would be off by pixels.
    let line = said.lines().find(|l| l.contains("pose to pose")).unwrap();
    let numbers: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|s| s.parse().ok())
        .collect();
    let (epe, motion) = (numbers[0], numbers[1]);
    assert!(motion > 0.1 && epe < motion + 0.25, "{line}");
    // Two steps per view of every pose: 3 poses x 108 views x 2.
    let o = frf(&["info", whole.to_str().unwrap(), "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(info["pose_flow_maps"], 3 * 108 * 2, "{info}");
    // They read back at the field's size, finite where known, with motion near the body.
    let field = frf_reflectance::FieldFile::open(&whole).unwrap();
    for step in frf_core::grid::PoseStep::ALL {
        let f = field.pose_flow(1, 4, 1, step).unwrap().unwrap();
        assert_eq!(f.size(), (32, 45));
        let known: Vec<_> = f
            .pixels()
            .iter()
            .filter(|p| frf_core::flo::is_known(**p))
            .collect();
        assert!(known.len() > 50 && known.iter().all(|p| p[0].is_finite() && p[1].is_finite()));
        assert!(known.iter().any(|p| p[0].hypot(p[1]) > 0.1));
    }
    // Each pose on its own (a farm's task reads its neighbours' frames from the capture),
    // then merged: the same bytes as one ingest.
    let parts: Vec<_> = (0..3).map(|p| d.join(format!("p{p}.frf"))).collect();
    for (p, part) in parts.iter().enumerate() {
        ingest(part, &["--poses", &p.to_string()]);
    }
    let merged = d.join("merged.frf");
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(|p| p.to_str().unwrap()));
    args.extend([
        "--expect",
        cap.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    let o = frf(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(&whole).unwrap() == std::fs::read(&merged).unwrap());
}
