//! What the command-line tests share: running the `frf` binary of this build.

#![allow(dead_code)] // each test file uses what it needs

use std::process::{Command, Output};

/// Runs `frf` with `args` (a private runtime directory for the GPU's loader).
pub fn frf(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_frf"))
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("the frf binary runs")
}

/// What a run printed on stderr.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}
