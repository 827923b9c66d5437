//! `frf flow` and `frf flow-bench` as library functions: the flow between two image files
//! written as a `.flo` (and its colour wheel), and the estimator measured over a
//! directory of sequences with ground truth ([`BenchReport`], as JSON or a table).

use std::path::Path;
use std::time::Instant;

use frf_core::io::read_rgb;
use serde::Serialize;

use crate::bench::{PairResult, find_pairs, run_pair, threads};
use crate::error::{FlowError, Result};
use crate::params::FlowParams;
use crate::viz::write_flow_png;
use crate::{estimate_flow_from, read_flo, write_flo};

/// The files of one estimation: the two images, a starting flow, the outputs.
pub struct FlowFiles<'a> {
    /// First image; the flow is stored on its grid.
    pub a: &'a Path,
    /// Second image, the first's size.
    pub b: &'a Path,
    /// A flow to start from (`.flo`, the first image's size).
    pub init: Option<&'a Path>,
    /// The flow written (`.flo`).
    pub out: &'a Path,
    /// Its colour-wheel visualization (PNG).
    pub viz: Option<&'a Path>,
}

/// What one estimation took and found.
#[derive(Debug, Clone, Copy)]
pub struct FlowSummary {
    /// Width and height.
    pub size: (usize, usize),
    /// Wall seconds of the estimation.
    pub seconds: f64,
    /// The largest displacement, pixels.
    pub largest_px: f32,
}

/// Reads the images of `files` (checking their sizes, naming the files), estimates the
/// flow with `params` and writes it (and its visualization); `started` is told the size
/// before the estimation begins.
pub fn flow_files(
    files: &FlowFiles,
    params: &FlowParams,
    started: impl FnOnce((usize, usize)),
) -> Result<FlowSummary> {
    let a = read_rgb(files.a)?;
    let b = read_rgb(files.b)?;
    let init = files.init.map(read_flo).transpose()?;
    // Sizes checked here, where the files' names are known.
    // The second image and the starting flow are of the first image's size.
    let same = |what: &'static str, path: &Path, size: (usize, usize)| -> Result<()> {
        if size == a.size() {
            return Ok(());
        }
        Err(FlowError::NotSameSize {
            what,
            path: path.to_path_buf(),
            size,
            first: files.a.to_path_buf(),
            first_size: a.size(),
        })
    };
    same("the two images must be the same size", files.b, b.size())?;
    if let (Some(f), Some(path)) = (&init, files.init) {
        same(
            "the initial flow must be the first image's size",
            path,
            f.size(),
        )?;
    }
    started(a.size());
    let start = Instant::now();
    let flow = estimate_flow_from(&a, &b, init.as_ref(), params)?;
    let seconds = start.elapsed().as_secs_f64();
    write_flo(files.out, &flow)?;
    let largest_px = flow
        .pixels()
        .iter()
        .map(|f| (f[0] * f[0] + f[1] * f[1]).sqrt())
        .fold(0.0f32, f32::max);
    if let Some(viz) = files.viz {
        write_flow_png(viz, &flow, None)?;
    }
    Ok(FlowSummary {
        size: a.size(),
        seconds,
        largest_px,
    })
}

/// What `frf flow-bench` measured.
pub struct BenchReport {
    /// The parameters, named (`balanced+wide lambda=5`).
    pub label: String,
    /// Times each pair was timed (the median kept).
    pub repeat: usize,
    /// Per sequence.
    pub results: Vec<PairResult>,
}

/// One sequence of the JSON report.
#[derive(Serialize)]
struct SequenceJson<'a> {
    name: &'a str,
    epe: f64,
    aae: f64,
    fraction_above_1px: f64,
    seconds: f64,
}

/// The JSON report.
#[derive(Serialize)]
struct BenchJson<'a> {
    preset: &'a str,
    threads: usize,
    repeat: usize,
    sequences: Vec<SequenceJson<'a>>,
    mean_epe: f64,
    mean_aae: f64,
    total_seconds: f64,
}

/// Told of pair `i` of `n`, named, before its run (`None`) and after.
pub type PairProgress<'a> = dyn FnMut(usize, usize, &str, Option<&PairResult>) + 'a;

/// Runs the estimator with `params` (named `label`) on every pair under `dir`, `repeat`
/// times each; `progress` is told each pair before (`None`) and after its run.
pub fn bench_dir(
    dir: &Path,
    params: &FlowParams,
    label: String,
    repeat: usize,
    progress: &mut PairProgress,
) -> Result<BenchReport> {
    let pairs = find_pairs(dir)?;
    let mut results = Vec::with_capacity(pairs.len());
    for (i, pair) in pairs.iter().enumerate() {
        progress(i, pairs.len(), &pair.name, None);
        let r = run_pair(pair, params, repeat)?;
        progress(i, pairs.len(), &pair.name, Some(&r));
        results.push(r);
    }
    Ok(BenchReport {
        label,
        repeat: repeat.max(1),
        results,
    })
}

impl BenchReport {
    fn mean(&self, f: impl Fn(&PairResult) -> f64) -> f64 {
        self.results.iter().map(f).sum::<f64>() / self.results.len().max(1) as f64
    }

    fn total_seconds(&self) -> f64 {
        self.results.iter().map(|r| r.seconds).sum()
    }

    /// As JSON (pretty).
    pub fn json(&self) -> String {
        let report = BenchJson {
            preset: &self.label,
            threads: threads(),
            repeat: self.repeat,
            sequences: self
                .results
                .iter()
                .map(|r| SequenceJson {
                    name: &r.name,
                    epe: r.errors.epe,
                    aae: r.errors.aae_deg,
                    fraction_above_1px: r.errors.fraction_above_1px,
                    seconds: r.seconds,
                })
                .collect(),
            mean_epe: self.mean(|r| r.errors.epe),
            mean_aae: self.mean(|r| r.errors.aae_deg),
            total_seconds: self.total_seconds(),
        };
        // Plain numbers and strings: serialising cannot fail.
        serde_json::to_value(&report)
            .and_then(|v| serde_json::to_string_pretty(&v))
            .unwrap_or_default()
    }

    /// As a table for a person, a line per sequence and their mean.
    pub fn table(&self) -> String {
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
#[allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test
mod tests {
    use std::path::Path;

    use frf_core::image::{Image, RgbImage};

    use super::*;
    use crate::presets::Preset;

    fn fast() -> FlowParams {
        FlowParams::preset(Preset::Fast)
    }

    fn quiet(_: usize, _: usize, _: &str, _: Option<&PairResult>) {}

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
        let p = |f: &str| dir.path().join(f);
        let (a, b, out, viz) = (p("frame10.png"), p("frame11.png"), p("f.flo"), p("f.png"));
        let files = FlowFiles {
            a: &a,
            b: &b,
            init: None,
            out: &out,
            viz: Some(&viz),
        };
        let summary = flow_files(&files, &fast(), |_| {}).unwrap();
        assert!(summary.largest_px > 1.0 && summary.seconds > 0.0);
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
        let p = |f: &str| dir.path().join(f);
        frf_core::io::write_png16_rgb(&p("a.png"), &texture(32, 32, [0.0, 0.0])).unwrap();
        frf_core::io::write_png16_rgb(&p("b.png"), &texture(32, 31, [0.0, 0.0])).unwrap();
        let (a, b, out) = (p("a.png"), p("b.png"), p("f.flo"));
        let files = FlowFiles {
            a: &a,
            b: &b,
            init: None,
            out: &out,
            viz: None,
        };
        let err = flow_files(&files, &fast(), |_| {}).unwrap_err().to_string();
        assert!(
            err.contains("b.png is 32x31") && err.contains("a.png is 32x32"),
            "{err}"
        );
        assert!(!dir.path().join("f.flo").exists());
        let err = fast().with_setting("lambda", "-3").unwrap_err().to_string();
        assert!(err.contains("lambda"), "{err}");
    }

    #[test]
    fn flow_bench_reports_every_sequence() {
        let dir = tempfile::tempdir().unwrap();
        write_pair(&dir.path().join("SeqA"), [0.5, 0.25]);
        write_pair(&dir.path().join("SeqB"), [-1.0, 0.75]);
        let balanced = FlowParams::preset(Preset::Balanced);
        let report = bench_dir(dir.path(), &balanced, "balanced".into(), 1, &mut quiet).unwrap();
        let json: serde_json::Value = serde_json::from_str(&report.json()).unwrap();
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
        let table = report.table();
        assert!(
            table.contains("EPE (px)") && table.contains("mean"),
            "{table}"
        );

        let empty = tempfile::tempdir().unwrap();
        let e = bench_dir(empty.path(), &balanced, "balanced".into(), 1, &mut quiet);
        assert!(e.err().unwrap().to_string().contains("no sequence found"));
    }
}
