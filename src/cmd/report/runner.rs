//! The runs a report is made of: this binary's own verbs, each run's command, output and
//! wall time kept under `runs/` so that an interrupted report resumes where it stopped.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::CliResult;

/// Runs of this binary, each kept under `runs/` with its wall time.
pub struct Runner {
    pub exe: PathBuf,
    pub runs: PathBuf,
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
    pub stdout: String,
    pub command: String,
}

impl Runner {
    /// Runs `frf args` unless `runs/ID.run.json` holds a finished run of the same arguments
    /// (and `outputs` exist).
    pub fn run(&self, id: &str, args: &[String], outputs: &[&Path]) -> CliResult<Ran> {
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
        let out = child.output()?;
        let seconds = start.elapsed().as_secs_f64();
        if !out.status.success() {
            return Err(format!(
                "{command} failed:\n{}",
                String::from_utf8_lossy(&out.stderr).trim_end()
            )
            .into());
        }
        let stdout = String::from_utf8(out.stdout)?;
        let kept = RunRecord {
            command: command.clone(),
            seconds,
            stdout: stdout.clone(),
        };
        frf_core::atomic::write_bytes_atomic(
            &record,
            serde_json::to_string_pretty(&kept)?.as_bytes(),
        )?;
        self.bar.inc(1);
        self.measured.set(self.measured.get() + seconds);
        Ok(Ran { stdout, command })
    }
}
