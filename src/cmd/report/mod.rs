//! `frf report --capture CAPTURE --out DIR [--quick]`: every stage's quality knobs swept
//! on a stage capture, each setting's error against the truth beside its run time
//! ([`frf_eval::report`] holds the rows, fronts, plots and page).
//!
//! Each measurement is a run of this binary's own verbs (`ingest`, `stage field`,
//! `stage codec-curve`, `eval`), so every row names the command that reproduces it. A
//! run's output is kept under `DIR/runs/`: an interrupted report resumes where it
//! stopped, and a finished one is re-plotted without measuring again.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use frf_core::capture::Capture;
use frf_eval::report::{Machine, Report, STAGES};

use super::progress::bar;
use crate::CliResult;
use runner::Runner;
use sweep::Sweep;
use write::{commit, peer_rows, write_report};

mod capture_size;
mod runner;
mod sweep;
mod time;
mod write;

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
    let start = Instant::now();
    let capture = Capture::open(&args.capture)?;
    let pose = *capture
        .poses()
        .first()
        .ok_or_else(|| format!("{}: the capture has no poses", args.capture.display()))?;
    // Peers are read first: a bad file is refused before minutes of measuring.
    let (mut peer_flow_rows, mut peers) = (Vec::new(), Vec::new());
    if let Some(p) = &args.peers {
        peer_rows(p, &mut peer_flow_rows, &mut peers)?;
    }
    let runs = args.out.join("runs");
    std::fs::create_dir_all(&runs).map_err(|e| frf_core::CoreError::io(&runs, e))?;
    let (w, h) = (capture.cameras()[0].width, capture.cameras()[0].height);
    // The capture filmed again at smaller sizes, when it films every view.
    let stage_config = frf_stage::writer::read_stage_config(&args.capture)?;
    let runner = Runner {
        exe: std::env::current_exe()?,
        runs: runs.clone(),
        bar: bar("report"),
        measured: std::cell::Cell::new(0.0),
    };
    let mut sweep = Sweep {
        runner: &runner,
        cap: args.capture.display().to_string(),
        pose,
        env: args.env.clone(),
        cpu: args.cpu.then(|| "--cpu".to_string()).into_iter().collect(),
        quick: args.quick,
        rows: Vec::new(),
        adapter: String::from("none (CPU reference)"),
    };
    // Runs: ingests (presets and λs), codec curve, views and suite, renderers, a field
    // and an eval per shadow setting, an eval per frame size, and filming, ingest and
    // eval per capture size; filming, ingest and two evals per set of poses kept.
    let (ingests, sizes) = if args.quick { (2, 2) } else { (5, 4) };
    let total = ingests
        + 1
        + 2
        + if args.cpu { 1 } else { 2 }
        + 2 * sweep.shadow_settings().len()
        + sizes
        + 3 * sweep.smaller(&stage_config, w, h).len()
        + 2 * 4;
    runner.bar.set_length(total as u64);

    let (field, ingest_seconds, ingest_command) = sweep.ingest(&runs)?;
    sweep.flow_storage(&capture, &args.capture)?;
    sweep.basis_compression()?;
    sweep.novel_views(&field)?;
    sweep.camera_paths(&field)?;
    sweep.sizes(
        &field,
        &runs,
        &stage_config,
        (w, h),
        (ingest_seconds, &ingest_command),
    )?;
    sweep.renderers(&field, args.cpu)?;
    sweep.shadows(&runs)?;
    sweep.time_between_poses(&runs, &stage_config, (w, h))?;
    runner.bar.finish_and_clear();

    let mut rows = sweep.rows;
    rows.extend(peer_flow_rows);
    let report = Report {
        capture: args.capture.display().to_string(),
        commit: commit(),
        machine: Machine {
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            adapter: sweep.adapter,
            os: format!("{} {}", std::env::consts::OS, std::env::consts::ARCH),
        },
        quick: args.quick,
        // The runs' own times (kept ones included) and this invocation's other work.
        seconds_total: runner.measured.get().max(start.elapsed().as_secs_f64()),
        rows,
        peers,
    };
    let problems = report.problems(STAGES);
    write_report(&report, &args.out)?;
    if !problems.is_empty() {
        return Err(format!("the report is incomplete:\n{}", problems.join("\n")).into());
    }
    Ok(())
}
