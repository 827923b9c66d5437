//! `frf flow` (optical flow between two images) and `frf flow-bench` (error and time of
//! the estimator on every Middlebury or Sintel pair of a directory).

use std::path::PathBuf;

use clap::Args;
use frf_flow::FlowParams;
use frf_flow::bench::threads;
use frf_flow::files::{FlowFiles, bench_dir, flow_files};

use crate::CliResult;

/// Options shared by both commands: which parameters to use.
#[derive(Args)]
pub struct ParamArgs {
    /// Preset of the estimator.
    #[arg(long, value_enum, default_value = "balanced")]
    preset: frf_flow::Preset,
    /// Reach larger displacements (horizontal view pairs: up to ~20 px at 320x448).
    #[arg(long)]
    wide_search: bool,
    /// Override one parameter, e.g. `--set lambda=5` (repeatable; names as in FlowParams).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    settings: Vec<String>,
}

impl ParamArgs {
    fn params(&self) -> CliResult<FlowParams> {
        let mut params = FlowParams::preset(self.preset);
        if self.wide_search {
            params = params.wide_search();
        }
        for s in &self.settings {
            let (k, v) = s
                .split_once('=')
                .ok_or_else(|| format!("--set {s:?}: expected KEY=VALUE"))?;
            params = params.with_setting(k.trim(), v.trim())?;
        }
        Ok(params)
    }

    fn label(&self) -> String {
        let mut label = self.preset.name().to_string();
        if self.wide_search {
            label.push_str("+wide");
        }
        for s in &self.settings {
            label.push_str(&format!(" {s}"));
        }
        label
    }
}

/// Arguments of `frf flow`.
#[derive(Args)]
pub struct FlowArgs {
    /// First image (PNG, EXR, HDR); the flow is stored on its grid.
    a: PathBuf,
    /// Second image, same size.
    b: PathBuf,
    /// Output flow, Middlebury `.flo`.
    #[arg(long)]
    out: PathBuf,
    /// Also write a colour-wheel visualization (PNG).
    #[arg(long)]
    viz: Option<PathBuf>,
    /// Start from this flow (`.flo`, same size) instead of zero.
    #[arg(long)]
    init: Option<PathBuf>,
    #[command(flatten)]
    params: ParamArgs,
}

/// Runs `frf flow`.
pub fn run(args: FlowArgs) -> CliResult {
    let params = args.params.params()?;
    let files = FlowFiles {
        a: &args.a,
        b: &args.b,
        init: args.init.as_deref(),
        out: &args.out,
        viz: args.viz.as_deref(),
    };
    let label = args.params.label();
    let s = flow_files(&files, &params, |(w, h)| {
        eprintln!("flow {w}x{h} ({label}), {} threads ...", threads());
    })?;
    println!("seconds (wall, estimation of one pair): {:.3}", s.seconds);
    println!("largest displacement (px): {:.2}", s.largest_px);
    println!("flow written to {}", args.out.display());
    if let Some(viz) = &args.viz {
        println!(
            "visualization (colour wheel, normalised by the largest displacement) written to {}",
            viz.display()
        );
    }
    Ok(())
}

/// Arguments of `frf flow-bench`.
#[derive(Args)]
pub struct FlowBenchArgs {
    /// Directory of Middlebury (`<Seq>/frame10.png, frame11.png, flow10.flo`) or Sintel
    /// (`<scene>/clean/frame_NNNN.png`, `<scene>/flow/frame_NNNN.flo`) sequences.
    dir: PathBuf,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Time each pair this many times and report the median.
    #[arg(long, default_value_t = 1)]
    repeat: usize,
    #[command(flatten)]
    params: ParamArgs,
}

/// Runs `frf flow-bench`, showing progress on stderr.
pub fn run_bench(args: FlowBenchArgs) -> CliResult {
    let params = args.params.params()?;
    let report = bench_dir(
        &args.dir,
        &params,
        args.params.label(),
        args.repeat,
        &mut |i, n, name, result| match result {
            None => eprint!("[{}/{n}] {name} ... ", i + 1),
            Some(r) => eprintln!("EPE {:.3} px, {:.3} s", r.errors.epe, r.seconds),
        },
    )?;
    if args.json {
        println!("{}", report.json());
    } else {
        print!("{}", report.table());
    }
    Ok(())
}
