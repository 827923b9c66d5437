//! The runs a report is made of: this binary's own verbs, each run's command, output and
//! wall time kept under `runs/` so that an interrupted report resumes where it stopped.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::error::{EvalError, Result};

/// Lines of a failed run's standard error kept in its error.
const STDERR_TAIL_LINES: usize = 40;

/// Runs of this binary, each kept under `runs/` with its wall time.
pub struct Runner {
    /// The `frf` binary.
    pub exe: PathBuf,
    /// Where each run's record and output are kept.
    pub runs: PathBuf,
    /// Counts the runs.
    pub bar: indicatif::ProgressBar,
    /// Wall seconds of every run, whether made now or kept from an earlier invocation.
    pub measured: std::cell::Cell<f64>,
}

/// A finished run as kept under `runs/ID.run.json`.
#[derive(Serialize, Deserialize)]
struct RunRecord {
    /// The command, as `frf ARGS`.
    command: String,
    /// Its wall seconds.
    seconds: f64,
    /// What it printed on stdout.
    stdout: String,
}

/// What a run printed and how long it took.
pub struct Ran {
    /// What it printed on stdout.
    pub stdout: String,
    /// The command, as `frf ARGS`.
    pub command: String,
}

impl Runner {
    /// Runs `frf args` unless `runs/ID.run.json` holds a finished run of the same arguments
    /// (and `outputs` exist).
    pub fn run(&self, id: &str, args: &[String], outputs: &[&Path]) -> Result<Ran> {
        let record = self.runs.join(format!("{id}.run.json"));
        let command = format!("frf {}", args.join(" "));
        self.bar
            .set_message(format!("frf {}", args[..2.min(args.len())].join(" ")));
        if let Ok(text) = std::fs::read_to_string(&record)
            && let Ok(kept) = serde_json::from_str::<RunRecord>(&text)
            && kept.command == command
            && outputs.iter().all(|p| p.exists())
        {
            self.bar.inc(1);
            self.measured.set(self.measured.get() + kept.seconds);
            return Ok(Ran {
                stdout: kept.stdout,
                command,
            });
        }
        let start = Instant::now();
        let mut child = Command::new(&self.exe);
        child.args(args);
        // The adapter named on this command line renders the runs too.
        if let Some(name) = frf_render::gpu::adapter::preferred() {
            child.env(frf_render::gpu::adapter::ADAPTER_ENV, name);
        }
        let exe = &self.exe;
        let out = child
            .output()
            .map_err(|e| frf_core::CoreError::io(exe, e))?;
        let seconds = start.elapsed().as_secs_f64();
        if !out.status.success() {
            let stderr = String::from_utf8_lossy(&out.stderr);
            let lines: Vec<&str> = stderr.trim_end().lines().collect();
            return Err(EvalError::RunFailed {
                command,
                status: out.status.code(),
                stderr_tail: lines[lines.len().saturating_sub(STDERR_TAIL_LINES)..].join("\n"),
            });
        }
        let stdout = String::from_utf8(out.stdout)
            .map_err(|e| EvalError::run(&command, format!("printed other than UTF-8: {e}")))?;
        let kept = RunRecord {
            command: command.clone(),
            seconds,
            stdout: stdout.clone(),
        };
        frf_core::atomic::write_bytes_atomic(
            &record,
            serde_json::to_string_pretty(&kept)
                .map_err(|e| EvalError::Misuse(format!("a run's record as JSON: {e}")))?
                .as_bytes(),
        )?;
        self.bar.inc(1);
        self.measured.set(self.measured.get() + seconds);
        Ok(Ran { stdout, command })
    }
}
