//! `frf flow` (optical flow between two images) and `frf flow-bench` (error and time of
//! the estimator on every Middlebury or Sintel pair of a directory).

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use frf_core::io::read_rgb;
use frf_flow::bench::{find_pairs, run_pair, threads};
use frf_flow::viz::write_flow_png;
use frf_flow::{FlowParams, Preset, estimate_flow_from, read_flo, write_flo};

use crate::CliResult;
use crate::cmd::args::FlowPresetArg;

/// Options shared by both commands: which parameters to use.
#[derive(Args)]
pub struct ParamArgs {
    /// Preset of the estimator.
    #[arg(long, value_enum, default_value = "balanced")]
    preset: FlowPresetArg,
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
    // Sizes checked here, where the files' names are known.
    let size = |w: usize, h: usize| format!("{w}x{h}");
    let a_size = size(a.width(), a.height());
    if (b.width(), b.height()) != (a.width(), a.height()) {
        return Err(format!(
            "{} is {} pixels but {} is {a_size}: the two images must be the same size",
            args.b.display(),
            size(b.width(), b.height()),
            args.a.display()
        )
        .into());
    }
    if let (Some(f), Some(path)) = (&init, &args.init)
        && (f.width(), f.height()) != (a.width(), a.height())
    {
        return Err(format!(
            "{} is a {} flow but {} is {a_size}: the initial flow must be the first image's size",
            path.display(),
            size(f.width(), f.height()),
            args.a.display()
        )
        .into());
    }
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
    let report = bench(&args)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report.json())?);
    } else {
        print!("{}", report.table());
    }
    Ok(())
}

/// What `frf flow-bench` measured.
struct BenchReport {
    label: String,
    repeat: usize,
    results: Vec<frf_flow::bench::PairResult>,
}

/// Runs the estimator on every pair under `args.dir`, showing progress on stderr.
fn bench(args: &FlowBenchArgs) -> CliResult<BenchReport> {
    let params = args.params.params()?;
    let pairs = find_pairs(&args.dir)?;
    let mut results = Vec::with_capacity(pairs.len());
    for (i, pair) in pairs.iter().enumerate() {
        eprint!("[{}/{}] {} ... ", i + 1, pairs.len(), pair.name);
        let r = run_pair(pair, &params, args.repeat)?;
        eprintln!("EPE {:.3} px, {:.3} s", r.errors.epe, r.seconds);
        results.push(r);
    }
    Ok(BenchReport {
        label: args.params.label(),
        repeat: args.repeat.max(1),
        results,
    })
}

impl BenchReport {
    fn mean(&self, f: impl Fn(&frf_flow::bench::PairResult) -> f64) -> f64 {
        self.results.iter().map(f).sum::<f64>() / self.results.len().max(1) as f64
    }

    fn total_seconds(&self) -> f64 {
        self.results.iter().map(|r| r.seconds).sum()
    }

    fn json(&self) -> serde_json::Value {
        let sequences: Vec<serde_json::Value> = self
            .results
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
        serde_json::json!({
            "preset": self.label,
            "threads": threads(),
            "repeat": self.repeat,
            "sequences": sequences,
            "mean_epe": self.mean(|r| r.errors.epe),
            "mean_aae": self.mean(|r| r.errors.aae_deg),
            "total_seconds": self.total_seconds(),
        })
    }

    fn table(&self) -> String {
        let mut out = format!(
            "preset: {}; {} threads; seconds = wall time of the estimation of one pair (median of {})\n",
            self.label,
            threads(),
            self.repeat
        );
        out += &format!(
            "{:<24} {:>9} {:>10} {:>11} {:>9}\n",
            "sequence", "EPE (px)", "AAE (deg)", "> 1 px (%)", "seconds"
        );
        for r in &self.results {
            out += &format!(
                "{:<24} {:>9.3} {:>10.3} {:>11.2} {:>9.3}\n",
                r.name,
                r.errors.epe,
                r.errors.aae_deg,
                100.0 * r.errors.fraction_above_1px,
                r.seconds
            );
        }
        out += &format!(
            "{:<24} {:>9.3} {:>10.3} {:>11.2} {:>9.3}\n",
            "mean",
            self.mean(|r| r.errors.epe),
            self.mean(|r| r.errors.aae_deg),
            100.0 * self.mean(|r| r.errors.fraction_above_1px),
            self.mean(|r| r.seconds)
        );
        out += &format!(
            "total seconds (wall, all pairs): {:.3}\n",
            self.total_seconds()
        );
        out
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use clap::Parser;
    use frf_core::image::{Image, RgbImage};

    use super::*;

    #[derive(Parser)]
    struct FlowCli {
        #[command(flatten)]
        args: FlowArgs,
    }

    #[derive(Parser)]
    struct BenchCli {
        #[command(flatten)]
        args: FlowBenchArgs,
    }

    /// A smooth texture displaced by `-d`: `I(s) = T(s − d)`, so the flow is `d`.
    fn texture(w: usize, h: usize, d: [f32; 2]) -> RgbImage {
        let waves = [
            (0.31f32, 0.12f32, 0.4f32),
            (-0.17, 0.29, 1.3),
            (0.08, -0.41, 2.1),
            (0.45, 0.2, 0.7),
        ];
        Image::from_fn(w, h, |x, y| {
            let (x, y) = (x as f32 - d[0], y as f32 - d[1]);
            let v: f32 = waves
                .iter()
                .map(|(kx, ky, p)| (kx * x + ky * y + p).sin())
                .sum();
            let c = 0.5 + 0.1 * v;
            [c, 0.9 * c, 1.0 - c]
        })
    }

    fn write_pair(dir: &Path, d: [f32; 2]) {
        std::fs::create_dir_all(dir).unwrap();
        frf_core::io::write_png16_rgb(&dir.join("frame10.png"), &texture(64, 48, [0.0, 0.0]))
            .unwrap();
        frf_core::io::write_png16_rgb(&dir.join("frame11.png"), &texture(64, 48, d)).unwrap();
        write_flo(&dir.join("flow10.flo"), &Image::new(64, 48, d)).unwrap();
    }

    #[test]
    fn flow_writes_the_flow_and_its_visualization() {
        let dir = tempfile::tempdir().unwrap();
        let d = [1.5f32, -0.5];
        write_pair(dir.path(), d);
        let p = |f: &str| dir.path().join(f).display().to_string();
        let cli = FlowCli::try_parse_from([
            "flow",
            &p("frame10.png"),
            &p("frame11.png"),
            "--out",
            &p("f.flo"),
            "--viz",
            &p("f.png"),
            "--preset",
            "fast",
        ])
        .unwrap();
        run(cli.args).unwrap();
        let flow = read_flo(&dir.path().join("f.flo")).unwrap();
        assert_eq!(flow.size(), (64, 48));
        let centre = flow.get(32, 24);
        assert!(
            (centre[0] - d[0]).abs() < 0.2 && (centre[1] - d[1]).abs() < 0.2,
            "{centre:?}"
        );
        assert_eq!(
            frf_core::io::image_dimensions(&dir.path().join("f.png")).unwrap(),
            (64, 48)
        );
    }

    #[test]
    fn flow_refuses_images_of_different_sizes_and_bad_settings() {
        let dir = tempfile::tempdir().unwrap();
        let p = |f: &str| dir.path().join(f).display().to_string();
        frf_core::io::write_png16_rgb(Path::new(&p("a.png")), &texture(32, 32, [0.0, 0.0]))
            .unwrap();
        frf_core::io::write_png16_rgb(Path::new(&p("b.png")), &texture(32, 31, [0.0, 0.0]))
            .unwrap();
        let cli = FlowCli::try_parse_from(["flow", &p("a.png"), &p("b.png"), "--out", &p("f.flo")])
            .unwrap();
        let err = run(cli.args).unwrap_err().to_string();
        assert!(
            err.contains("b.png is 32x31") && err.contains("a.png is 32x32"),
            "{err}"
        );
        assert!(!dir.path().join("f.flo").exists());
        let cli = FlowCli::try_parse_from([
            "flow",
            &p("a.png"),
            &p("a.png"),
            "--out",
            &p("f.flo"),
            "--set",
            "lambda=-3",
        ])
        .unwrap();
        assert!(run(cli.args).unwrap_err().to_string().contains("lambda"));
    }

    #[test]
    fn flow_bench_reports_every_sequence() {
        let dir = tempfile::tempdir().unwrap();
        write_pair(&dir.path().join("SeqA"), [0.5, 0.25]);
        write_pair(&dir.path().join("SeqB"), [-1.0, 0.75]);
        let root = dir.path().display().to_string();
        let cli = BenchCli::try_parse_from(["flow-bench", &root, "--json", "--preset", "balanced"])
            .unwrap();
        let json = bench(&cli.args).unwrap().json();
        assert_eq!(json["preset"], "balanced");
        let seqs = json["sequences"].as_array().unwrap();
        let names: Vec<&str> = seqs.iter().map(|s| s["name"].as_str().unwrap()).collect();
        assert_eq!(names, ["SeqA", "SeqB"]);
        for s in seqs {
            // Whole-image EPE, including the borders where content enters the frame.
            assert!(s["epe"].as_f64().unwrap() < 0.3, "{s}");
            assert!(s["aae"].as_f64().unwrap() >= 0.0 && s["seconds"].as_f64().unwrap() > 0.0);
        }
        assert!(json["mean_epe"].as_f64().unwrap() < 0.3);
        assert!(json["total_seconds"].as_f64().unwrap() > 0.0);
        let table = bench(&cli.args).unwrap().table();
        assert!(
            table.contains("EPE (px)") && table.contains("mean"),
            "{table}"
        );

        let empty = tempfile::tempdir().unwrap();
        let cli =
            BenchCli::try_parse_from(["flow-bench", &empty.path().display().to_string()]).unwrap();
        assert!(
            bench(&cli.args)
                .err()
                .unwrap()
                .to_string()
                .contains("no sequence found")
        );
    }
}
