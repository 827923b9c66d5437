//! `frf report`'s sweeps: every stage's quality knobs swept on a stage capture, each
//! setting's error against the truth beside its run time ([`crate::report`] holds the
//! rows, fronts, plots and page).
//!
//! Each measurement is a run of the `frf` binary's own verbs (`ingest`, `stage field`,
//! `stage codec-curve`, `eval`; [`runner`]), so every row names the command that
//! reproduces it. A run's output is kept under `OUT/runs/`: an interrupted report resumes
//! where it stopped, and a finished one is re-plotted without measuring again.
//! [`stages`] sweeps each stage, [`time`] the time between poses, [`capture_size`] the
//! capture filmed again smaller; [`write`] writes the report and reads peers' results.

pub mod capture_size;
pub mod runner;
pub mod stages;
pub mod time;
pub mod write;

use std::path::PathBuf;
use std::time::Instant;

use frf_core::capture::Capture;

use crate::error::{EvalError, Result};
use crate::report::{Machine, Report, STAGES};
use runner::Runner;
use stages::Sweep;
use write::{commit, peer_rows, write_report};

/// What a report sweeps and where it writes.
pub struct ReportOptions {
    /// The `frf` binary whose verbs make the runs.
    pub exe: PathBuf,
    /// A capture written by `frf stage` (its truth scores every setting).
    pub capture: PathBuf,
    /// Output directory: `report.json`, plots, `index.html`, `runs/`.
    pub out: PathBuf,
    /// The reduced sweep.
    pub quick: bool,
    /// The environment renders are relit by.
    pub env: String,
    /// Peers' results (`benches/flow_peers/run_peers.py`'s JSON).
    pub peers: Option<PathBuf>,
    /// The CPU reference only.
    pub cpu: bool,
}

/// Sweeps every stage on `options.capture` and writes the report into `options.out`,
/// counting runs on `bar`; an error listing what is missing when the report is
/// incomplete.
pub fn run_report(options: &ReportOptions, bar: indicatif::ProgressBar) -> Result<()> {
    let start = Instant::now();
    let capture = Capture::open(&options.capture)?;
    let pose =
        *capture
            .poses()
            .first()
            .ok_or_else(|| frf_reflectance::ReflectanceError::Missing {
                file: options.capture.clone(),
                what: "the capture has no poses".into(),
            })?;
    // Peers are read first: a bad file is refused before minutes of measuring.
    let (mut peer_flow_rows, mut peers) = (Vec::new(), Vec::new());
    if let Some(p) = &options.peers {
        peer_rows(p, &mut peer_flow_rows, &mut peers)?;
    }
    let runs = options.out.join("runs");
    std::fs::create_dir_all(&runs).map_err(|e| frf_core::CoreError::io(&runs, e))?;
    let (w, h) = (capture.cameras()[0].width, capture.cameras()[0].height);
    // The capture filmed again at smaller sizes, when it films every view.
    let stage_config = frf_stage::writer::read_stage_config(&options.capture)?;
    let runner = Runner {
        exe: options.exe.clone(),
        runs: runs.clone(),
        bar,
        measured: std::cell::Cell::new(0.0),
    };
    let mut sweep = Sweep {
        runner: &runner,
        cap: options.capture.display().to_string(),
        pose,
        env: options.env.clone(),
        cpu: options
            .cpu
            .then(|| "--cpu".to_string())
            .into_iter()
            .collect(),
        quick: options.quick,
        rows: Vec::new(),
        adapter: String::from("none (CPU reference)"),
    };
    // Runs: ingests (presets and λs), codec curve, views and suite, renderers, a field
    // and an eval per shadow setting, an eval per frame size, and filming, ingest and
    // eval per capture size; filming, ingest and two evals per set of poses kept.
    let (ingests, sizes) = if options.quick { (2, 2) } else { (5, 4) };
    let total = ingests
        + 1
        + 2
        + if options.cpu { 1 } else { 2 }
        + 2 * sweep.shadow_settings().len()
        + sizes
        + 3 * sweep.smaller(&stage_config, w, h).len()
        + 2 * 4;
    runner.bar.set_length(total as u64);

    let (field, ingest_seconds, ingest_command) = sweep.ingest(&runs)?;
    sweep.flow_storage(&capture, &options.capture)?;
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
    sweep.renderers(&field, options.cpu)?;
    sweep.shadows(&runs)?;
    sweep.time_between_poses(&runs, &stage_config, (w, h))?;
    runner.bar.finish_and_clear();

    let mut rows = sweep.rows;
    rows.extend(peer_flow_rows);
    let report = Report {
        capture: options.capture.display().to_string(),
        commit: commit(),
        machine: Machine {
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            adapter: sweep.adapter,
            os: format!("{} {}", std::env::consts::OS, std::env::consts::ARCH),
        },
        quick: options.quick,
        // The runs' own times (kept ones included) and this invocation's other work.
        seconds_total: runner.measured.get().max(start.elapsed().as_secs_f64()),
        rows,
        peers,
    };
    let problems = report.problems(STAGES);
    write_report(&report, &options.out)?;
    if !problems.is_empty() {
        return Err(EvalError::Incomplete(problems));
    }
    Ok(())
}
