//! File outputs claimed before the work, through the binary: a second writer of the same
//! field is refused by name while the first goes on, and a run removes the temporary file
//! an interrupted run of the same output left (it used to stay forever).

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::Path;
use std::process::Stdio;
use std::time::Duration;

use crate::common::{frf, frf_command, stderr};

/// The arguments of `frf stage field` of the tiny stage into `out`.
fn oracle_field_args(out: &Path) -> Vec<String> {
    [
        "stage",
        "field",
        "--capture",
        frf_testkit::tiny_field().capture().to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--shadow-texels",
        "16",
    ]
    .map(String::from)
    .to_vec()
}

#[test]
fn a_second_writer_of_a_field_is_refused_while_the_first_finishes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.frf");
    let lock = dir.path().join(".f.frf.lock");
    let mut first = frf_command(&oracle_field_args(&out))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The lock file appears before it is locked; its holder writes its process id into it
    // once the lock is held. Waiting for the file alone let the second writer take the lock
    // first in that gap (a CI run saw it), so wait for the first writer's id.
    let held = first.id().to_string();
    while std::fs::read_to_string(&lock).map_or(true, |s| s.trim() != held) {
        assert!(
            first.try_wait().unwrap().is_none(),
            "the first writer ended before it was seen writing"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    let second = frf_command(&oracle_field_args(&out)).output().unwrap();
    let first = first.wait_with_output().unwrap();
    assert!(first.status.success(), "{}", stderr(&first));
    // Busy, not damaged (it was 3): the same command succeeds once the first ends.
    assert_eq!(second.status.code(), Some(75), "{}", stderr(&second));
    let said = stderr(&second);
    assert!(said.contains("f.frf"), "{said}");
    assert!(said.contains("another process is writing it"), "{said}");
    // The first field is whole, and nothing but it is left.
    frf_reflectance::FieldFile::open(&out).unwrap();
    let left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, ["f.frf"]);
}

#[test]
fn a_temporary_file_an_interrupted_run_left_is_removed_by_the_next() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.frf");
    // What a `stage field` killed before its rename leaves: `.NAME.PID.tmp`.
    let stale = dir.path().join(".f.frf.999999.tmp");
    std::fs::write(&stale, vec![0u8; 4096]).unwrap();
    let o = frf(&oracle_field_args(&out)
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stale.exists());
    assert!(
        stderr(&o).contains("removed 1 temporary file"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains(".f.frf.999999.tmp"), "{}", stderr(&o));
}
