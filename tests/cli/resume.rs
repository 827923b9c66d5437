//! Resuming a render into a directory that holds frames, through the binary: a rerun keeps
//! only frames made from the same things (the field's content, not only its path), reads
//! the same directory and files however their paths are spelled, refuses other settings
//! whichever frames are there, renders a frame cut short again, and reports the kept
//! frames' statistics and timings from their records.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::Path;
use std::process::Output;

use crate::common::{frf, stderr};

/// A 4-frame CPU orbit of the field at `field` into `out`.
fn render(field: &Path, out: &Path) -> Output {
    frf(&[
        "render",
        field.to_str().unwrap(),
        "--env",
        "sky",
        "--orbit",
        "3.2,1.3",
        "--size",
        "48x36",
        "--frames",
        "4",
        "--cpu",
        "--out",
        out.to_str().unwrap(),
    ])
}

fn report(out: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(out.join("render.json")).unwrap()).unwrap()
}

#[test]
fn a_rerun_resumes_only_frames_made_from_the_same_field_and_keeps_their_statistics() {
    let dir = tempfile::tempdir().unwrap();
    let field = dir.path().join("walker.frf");
    std::fs::copy(&frf_testkit::tiny_field().field, &field).unwrap();
    let out = dir.path().join("shot");
    let o = render(&field, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    let first = report(&out);
    assert_eq!(first["frames_rendered"], 4);
    let inside = first["pixels_inside"].as_u64().unwrap();
    assert!(inside > 0);

    // The same field and directory spelled otherwise (absolute, trailing slash, `./`):
    // everything resumes, and the report keeps the statistics and the timings the frames'
    // records hold (it used to write zero statistics and -0.0 s).
    let spelled = format!("{}/./", out.display());
    let o = render(
        &dir.path().join(".").join("walker.frf"),
        Path::new(&spelled),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let again = report(&out);
    assert_eq!(again["frames_resumed"], 4, "{again}");
    assert_eq!(again["frames_rendered"], 0);
    assert_eq!(again["pixels_inside"], first["pixels_inside"]);
    assert_eq!(
        again["seconds_per_frame_median"],
        first["seconds_per_frame_median"]
    );
    assert!(again["timings_of"].as_str().unwrap().contains("resumed"));

    // A frame cut short is rendered again, and said; the others stay.
    let exr = out.join("frame_0002.exr");
    let bytes = std::fs::metadata(&exr).unwrap().len();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&exr)
        .unwrap()
        .set_len(bytes / 2)
        .unwrap();
    let o = render(&field, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("frame 2:"), "{}", stderr(&o));
    assert!(stderr(&o).contains("rendering it again"), "{}", stderr(&o));
    let repaired = report(&out);
    assert_eq!(repaired["frames_rendered"], 1);
    assert_eq!(repaired["frames_resumed"], 3);
    // Statistics of the whole shot, not of the one frame rendered again.
    assert_eq!(repaired["pixels_inside"], first["pixels_inside"]);
    assert_eq!(std::fs::metadata(&exr).unwrap().len(), bytes);

    // A frame overwritten in place, same size, four bytes changed (issue 35: resume
    // compared sizes only and kept it).
    let png = out.join("frame_0001.png");
    let mut b = std::fs::read(&png).unwrap();
    let middle = b.len() / 2;
    for x in &mut b[middle..middle + 4] {
        *x ^= 0xff;
    }
    std::fs::write(&png, &b).unwrap();
    let o = render(&field, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("frame 1:"), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("differ from those its record lists"),
        "{}",
        stderr(&o)
    );
    assert_eq!(report(&out)["frames_rendered"], 1);
    assert_ne!(std::fs::read(&png).unwrap(), b);

    // Another field under the same path (one without shadow maps): not a resume (it used
    // to keep the old frames, as only the arguments were compared).
    let other = frf(&[
        "stage",
        "field",
        "--capture",
        frf_testkit::tiny_field().capture().to_str().unwrap(),
        "--out",
        field.to_str().unwrap(),
        "--no-shadows",
    ]);
    assert!(other.status.success(), "{}", stderr(&other));
    // With frame 0 gone the guard still sees the others (it looked at frame 0 alone).
    std::fs::remove_file(out.join("frame_0000.png")).unwrap();
    std::fs::remove_file(out.join("frame_0000.exr")).unwrap();
    std::fs::remove_file(out.join("frame_0000.json")).unwrap();
    let o = render(&field, &out);
    assert!(!o.status.success());
    let said = stderr(&o);
    assert!(said.contains("other settings"), "{said}");
    assert!(said.contains("files.field"), "{said}");
    assert!(said.contains("--overwrite"), "{said}");
}
