//! `frf report --capture CAPTURE --out DIR [--quick]`: every stage's quality knobs swept
//! on a stage capture, each setting's error against the truth beside its run time
//! ([`frf_eval::sweep`] runs them; [`frf_eval::report`] holds the rows, fronts, plots and
//! page).
//!
//! Each measurement is a run of this binary's own verbs (`ingest`, `stage field`,
//! `stage codec-curve`, `eval`), so every row names the command that reproduces it. A
//! run's output is kept under `DIR/runs/`: an interrupted report resumes where it
//! stopped, and a finished one is re-plotted without measuring again.

use std::path::PathBuf;

use clap::Args;
use frf_eval::sweep::{ReportOptions, run_report};

use crate::CliResult;
use frf_core::bars::bar;

/// Arguments of `frf report`.
#[derive(Args)]
pub struct ReportArgs {
    /// A capture written by `frf stage` (its truth scores every setting).
    #[arg(long)]
    capture: PathBuf,
    /// Output directory: `report.json`, one plot per stage (SVG and PNG), `index.html`,
    /// and each measurement's own output under `runs/`.
    #[arg(long)]
    out: PathBuf,
    /// The reduced sweep: a few settings per knob, few cameras (minutes on the tiny preset).
    #[arg(long)]
    quick: bool,
    /// Environment the renders are relit by (lat-long `.hdr`/`.exr`, `sky`, `uniform`).
    #[arg(long, default_value = "sky")]
    env: String,
    /// JSON of `benches/flow_peers/run_peers.py`: its Middlebury means join the report as
    /// the optical-flow plot, OpenCV's methods as peers.
    #[arg(long)]
    peers: Option<PathBuf>,
    /// Render with the CPU reference only (no GPU adapter needed).
    #[arg(long)]
    cpu: bool,
}

/// Runs `frf report`.
pub fn run(args: ReportArgs) -> CliResult {
    let options = ReportOptions {
        exe: std::env::current_exe()?,
        capture: args.capture,
        out: args.out,
        quick: args.quick,
        env: args.env,
        peers: args.peers,
        cpu: args.cpu,
    };
    Ok(run_report(&options, bar("report"))?)
}
