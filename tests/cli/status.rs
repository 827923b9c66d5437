//! The exit status tells who is at fault (README, "Exit status"): 2 a bad argument or
//! input, 3 a damaged file, 4 the GPU (tests/cli/adapter.rs), 5 the operating system.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use crate::common::{frf, stderr};

#[test]
fn the_exit_status_says_who_is_at_fault() {
    let field = &frf_testkit::tiny_field().field;
    let dir = tempfile::tempdir().unwrap();
    // A damaged file: the field cut short.
    let bytes = std::fs::read(field).unwrap();
    let cut = dir.path().join("cut.frf");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let missing = dir.path().join("missing.frf");
    let out = dir.path().join("frames");
    let cases: [(Vec<&str>, i32); 4] = [
        (vec!["info", cut.to_str().unwrap()], 3),
        (vec!["info", missing.to_str().unwrap()], 5),
        (
            vec![
                "render",
                field.to_str().unwrap(),
                "--env",
                "sky",
                "--orbit",
                "3,1.2",
                "--frames",
                "0",
                "--out",
                out.to_str().unwrap(),
            ],
            2,
        ),
        (vec!["no-such-verb"], 2),
    ];
    for (args, status) in cases {
        let o = frf(&args);
        assert_eq!(o.status.code(), Some(status), "{args:?}: {}", stderr(&o));
    }
}
