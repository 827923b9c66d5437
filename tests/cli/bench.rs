//! `frf bench interp` at small sizes on whatever adapter the machine has (lavapipe in
//! CI): the JSON report holds every variant in both stages with times, the floor pass,
//! the CPU reference and the pose's resident bytes; the GPU's frames agree with the CPU
//! reference; absurd sizes and missing fields are refused with messages that name them.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use crate::common::{frf, stderr};

#[test]
fn the_bench_reports_every_variant_stage_and_the_floor_as_json() {
    let o = frf(&[
        "bench",
        "interp",
        "--size",
        "64x48",
        "--size",
        "96x64",
        "--formats",
        "default",
        "--warmup",
        "1",
        "--repeats",
        "2",
        "--cpu-repeats",
        "1",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for key in ["adapter", "backend", "clock"] {
        assert!(report[key].as_str().is_some_and(|s| !s.is_empty()), "{key}");
    }
    assert!(report["bytes_per_pose"].as_u64().unwrap() > 10_000_000);
    let rows = report["rows"].as_array().unwrap();
    for size in [(64, 48), (96, 64)] {
        for stage in ["fragment", "compute"] {
            for variant in [
                "floor",
                "nearest",
                "linear",
                "twoway",
                "fourway-e06",
                "fourway",
            ] {
                let row = rows
                    .iter()
                    .find(|r| {
                        r["variant"] == variant
                            && r["stage"] == stage
                            && r["width"] == size.0
                            && r["height"] == size.1
                    })
                    .unwrap_or_else(|| panic!("no {variant} {stage} row at {size:?}"));
                let (median, min) = (
                    row["ms_median"].as_f64().unwrap(),
                    row["ms_min"].as_f64().unwrap(),
                );
                assert!(
                    min > 0.0 && min <= median,
                    "{variant} {stage}: {min} {median}"
                );
                assert!(row["flow_format"].is_string() && row["image_format"].is_string());
                // Morphs at the first size are checked against the CPU reference.
                if variant != "floor" && size == (64, 48) {
                    let err = row["max_abs_vs_cpu"].as_f64().unwrap();
                    assert!(err < 2e-2, "{variant} {stage}: max |GPU - CPU| {err}");
                }
            }
        }
    }
    let cpu = report["cpu_rows"].as_array().unwrap();
    assert_eq!(cpu.len(), 2 * 5, "the CPU reference's rows");
    assert!(report["fastest_correct_fourway"].is_string());
}

#[test]
fn absurd_sizes_and_missing_fields_are_refused() {
    let o = frf(&["bench", "interp", "--size", "0x48"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("0x48"), "{}", stderr(&o));
    // A CPU reference bound that is no number of megapixels (it skipped the reference
    // without a word).
    for bad in ["NaN", "-1", "inf"] {
        let o = frf(&["bench", "interp", "--cpu-max-mp", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("--cpu-max-mp") && stderr(&o).contains("0 or more"),
            "{}",
            stderr(&o)
        );
    }
    // A size given twice (it was timed twice).
    let o = frf(&["bench", "interp", "--size", "64x48", "--size", "64x48"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("given again at place 2"),
        "{}",
        stderr(&o)
    );
    // A pose the field lacks, said once (it read "pose 7: pose 7 is not in the field").
    let f = frf_testkit::tiny_field();
    let o = frf(&[
        "bench",
        "interp",
        "--field",
        f.field.to_str().unwrap(),
        "--pose",
        "7",
    ]);
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("pose 7 is not in the field"),
        "{e}"
    );
    assert_eq!(e.matches("pose 7").count(), 1, "{e}");
    let o = frf(&["bench", "interp", "--field", "/nonexistent/field.frf"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("/nonexistent/field.frf"),
        "{}",
        stderr(&o)
    );
}
