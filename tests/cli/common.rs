//! What the command-line tests share: running the `frf` binary of this build.

#![allow(dead_code)] // each test file uses what it needs

use std::ffi::OsStr;
use std::process::{Command, Output};

/// The `frf` binary of this build with `args`, not started (a private runtime directory
/// for the GPU's loader).
pub fn frf_command<S: AsRef<OsStr>>(args: &[S]) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_frf"));
    cmd.args(args).env("XDG_RUNTIME_DIR", std::env::temp_dir());
    cmd
}

/// Runs `frf` with `args`.
pub fn frf(args: &[&str]) -> Output {
    frf_command(args).output().expect("the frf binary runs")
}

/// What a run printed on stderr.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A small capture made through the binary in `dir/cap`: the tiny preset's rig at 32x45
/// pixels, one pose, one light per basis condition, the default true set flows (seconds).
pub fn staged_capture(dir: &std::path::Path) -> std::path::PathBuf {
    let cap = dir.join("cap");
    let o = frf(&[
        "stage",
        "--preset",
        "tiny",
        "--poses",
        "0",
        "--size",
        "32x45",
        "--lights-per-axis",
        "1",
        "--out",
        cap.to_str().expect("a UTF-8 path"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(said.contains("36 cycles x 3 cameras, 1 poses"), "{said}");
    cap
}
