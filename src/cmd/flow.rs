//! `frf flow` (optical flow between two images) and `frf flow-bench` (error and time of
//! the estimator on every Middlebury or Sintel pair of a directory).

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use frf_core::io::read_rgb;
use frf_flow::bench::{find_pairs, run_pair, threads};
use frf_flow::viz::write_flow_png;
use frf_flow::{FlowParams, Preset, estimate_flow_from, read_flo, write_flo};

use crate::CliResult;

/// A preset of the estimator, as the command line names it.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum PresetArg {
    /// Fastest: luminance, solved up to half resolution.
    Fast,
    /// Colour, full resolution, median filtering.
    Balanced,
    /// Classic+NL-style: texture decomposition, GNC, weighted median.
    Accurate,
}

impl From<PresetArg> for Preset {
    fn from(p: PresetArg) -> Self {
        match p {
            PresetArg::Fast => Preset::Fast,
            PresetArg::Balanced => Preset::Balanced,
            PresetArg::Accurate => Preset::Accurate,
        }
    }
}

/// Options shared by both commands: which parameters to use.
#[derive(Args)]
pub struct ParamArgs {
    /// Preset of the estimator.
    #[arg(long, value_enum, default_value = "balanced")]
    preset: PresetArg,
    /// Reach larger displacements (horizontal view pairs: up to ~20 px at 320x448).
    #[arg(long)]
    wide_search: bool,
    /// Override one parameter, e.g. `--set lambda=5` (repeatable; names as in FlowParams).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    settings: Vec<String>,
}

impl ParamArgs {
    fn params(&self) -> CliResult<FlowParams> {
        let mut params = FlowParams::preset(self.preset.into());
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
        let mut label = Preset::from(self.preset).name().to_string();
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
    let a = read_rgb(&args.a)?;
    let b = read_rgb(&args.b)?;
    let init = args.init.as_deref().map(read_flo).transpose()?;
    eprintln!(
        "flow {}x{} ({}), {} threads ...",
        a.width(),
        a.height(),
        args.params.label(),
        threads()
    );
    let start = Instant::now();
    let flow = estimate_flow_from(&a, &b, init.as_ref(), &params)?;
    let seconds = start.elapsed().as_secs_f64();
    write_flo(&args.out, &flow)?;
    let max = flow
        .pixels()
        .iter()
        .map(|f| (f[0] * f[0] + f[1] * f[1]).sqrt())
        .fold(0.0f32, f32::max);
    println!("seconds (wall, estimation of one pair): {seconds:.3}");
    println!("largest displacement (px): {max:.2}");
    println!("flow written to {}", args.out.display());
    if let Some(viz) = &args.viz {
        write_flow_png(viz, &flow, None)?;
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

/// Runs `frf flow-bench`.
pub fn run_bench(args: FlowBenchArgs) -> CliResult {
    let params = args.params.params()?;
    let pairs = find_pairs(&args.dir)?;
    let label = args.params.label();
    let mut results = Vec::with_capacity(pairs.len());
    for (i, pair) in pairs.iter().enumerate() {
        eprint!("[{}/{}] {} ... ", i + 1, pairs.len(), pair.name);
        let r = run_pair(pair, &params, args.repeat)?;
        eprintln!("EPE {:.3} px, {:.3} s", r.errors.epe, r.seconds);
        results.push(r);
    }
    let n = results.len() as f64;
    let mean_epe = results.iter().map(|r| r.errors.epe).sum::<f64>() / n;
    let mean_aae = results.iter().map(|r| r.errors.aae_deg).sum::<f64>() / n;
    let total_seconds: f64 = results.iter().map(|r| r.seconds).sum();
    if args.json {
        let sequences: Vec<serde_json::Value> = results
            .iter()
            .map(|r| {
                serde_json::json!({
                    "name": r.name,
                    "epe": r.errors.epe,
                    "aae": r.errors.aae_deg,
                    "fraction_above_1px": r.errors.fraction_above_1px,
                    "seconds": r.seconds,
                })
            })
            .collect();
        let out = serde_json::json!({
            "preset": label,
            "threads": threads(),
            "sequences": sequences,
            "mean_epe": mean_epe,
            "mean_aae": mean_aae,
            "total_seconds": total_seconds,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "preset: {label}; {} threads; seconds = wall time of the estimation of one pair (median of {})",
        threads(),
        args.repeat.max(1)
    );
    println!(
        "{:<24} {:>9} {:>10} {:>11} {:>9}",
        "sequence", "EPE (px)", "AAE (deg)", "> 1 px (%)", "seconds"
    );
    for r in &results {
        println!(
            "{:<24} {:>9.3} {:>10.3} {:>11.2} {:>9.3}",
            r.name,
            r.errors.epe,
            r.errors.aae_deg,
            100.0 * r.errors.fraction_above_1px,
            r.seconds
        );
    }
    println!(
        "{:<24} {:>9.3} {:>10.3} {:>11} {:>9.3}",
        "mean",
        mean_epe,
        mean_aae,
        "",
        total_seconds / n
    );
    println!("total seconds (wall, all pairs): {total_seconds:.3}");
    Ok(())
}
