//! `frf report --capture CAPTURE --out DIR [--quick]`: every stage's quality knobs swept
//! on a stage capture, each setting's error against the truth beside its run time
//! ([`frf_eval::report`] holds the rows, fronts, plots and page).
//!
//! Each measurement is a run of this binary's own verbs (`ingest`, `stage field`,
//! `stage codec-curve`, `eval`), so every row names the command that reproduces it. A
//! run's output is kept under `DIR/runs/`: an interrupted report resumes where it
//! stopped, and a finished one is re-plotted without measuring again.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use frf_core::capture::Capture;
use frf_core::grid::Neighbour;
use frf_eval::report::{Machine, Report, Row, STAGES};
use serde_json::Value;

use super::progress::bar;
use crate::CliResult;
use runner::Runner;
use write::{commit, peer_rows, write_report};

mod capture_size;
mod runner;
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

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// `frf ingest` of one pose of `cap` with a flow preset (and extra arguments), writing the
/// field and its JSON report.
fn ingest_args(
    cap: &str,
    pose: &str,
    preset: &str,
    extra: &[String],
    out: &Path,
    json: &Path,
) -> Vec<String> {
    let mut a: Vec<String> = ["ingest", cap, "--poses", pose, "--flow-preset", preset]
        .map(String::from)
        .to_vec();
    a.extend(extra.iter().cloned());
    a.extend(["--out".into(), s(out), "--report".into(), s(json)]);
    a
}

fn num(v: &Value, key: &str, what: &str) -> CliResult<f64> {
    v[key]
        .as_f64()
        .ok_or_else(|| format!("{what}: no number `{key}` in its output").into())
}

/// A row builder for one stage and knob.
struct Rows<'a> {
    rows: &'a mut Vec<Row>,
    stage: &'static str,
    knob: &'static str,
}

impl Rows<'_> {
    #[allow(clippy::too_many_arguments)] // one row's fields
    fn push(
        &mut self,
        value: impl Into<String>,
        metric: &str,
        error: f64,
        seconds: f64,
        timed: &str,
        default: bool,
        command: &str,
    ) {
        self.rows.push(Row {
            stage: self.stage.into(),
            knob: self.knob.into(),
            value: value.into(),
            metric: metric.into(),
            error,
            seconds,
            timed: timed.into(),
            default,
            command: command.into(),
        });
    }
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
    std::fs::create_dir_all(&runs)
        .map_err(|e| format!("{}: cannot create it: {e}", runs.display()))?;
    let quick = args.quick;
    let presets: &[&str] = if quick {
        &["fast", "balanced"]
    } else {
        &["fast", "balanced", "accurate"]
    };
    let lambdas: &[&str] = if quick { &[] } else { &["6", "48"] };
    let qualities = if quick {
        "50,80,95"
    } else {
        "50,60,70,80,85,90,95,98"
    };
    let variants = "nearest,linear,twoway,fourway,fourway-occlusion,fourway-no-proxy";
    let cameras = if quick { "2" } else { "8" };
    let frames = if quick { "2" } else { "6" };
    let shadow_settings: &[(&str, &str)] = if quick {
        &[("0.04", "64"), ("0.02", "128")]
    } else {
        &[
            ("0.04", "64"),
            ("0.04", "128"),
            ("0.02", "64"),
            ("0.02", "128"),
            ("0.02", "256"),
            ("0.01", "256"),
        ]
    };
    let (w, h) = (capture.cameras()[0].width, capture.cameras()[0].height);
    let sizes: Vec<(u32, u32)> = if quick {
        vec![(w, h), (2 * w, 2 * h)]
    } else {
        vec![(w / 2, h / 2), (w, h), (2 * w, 2 * h), (4 * w, 4 * h)]
    };
    // The capture filmed again at smaller sizes (a capture of every view only: one made
    // for a scene films a subset).
    let stage_config = frf_stage::writer::read_stage_config(&args.capture)?;
    let smaller = if stage_config.filmed.is_empty() {
        capture_size::smaller_sizes(w, h, quick)
    } else {
        Vec::new()
    };
    // Runs: ingests, codec curve, views and suite, renderers, a field and an eval per
    // shadow setting, an eval per frame size, and filming, ingest and eval per capture size.
    let total = presets.len()
        + lambdas.len()
        + 1
        + 2
        + 2
        + 2 * shadow_settings.len()
        + sizes.len()
        + 3 * smaller.len();
    let runner = Runner {
        exe: std::env::current_exe()?,
        runs: runs.clone(),
        bar: bar("report"),
        measured: std::cell::Cell::new(0.0),
    };
    runner.bar.set_length(total as u64);
    let cap = s(&args.capture);
    let pose_arg = pose.to_string();
    let cpu: Vec<String> = args.cpu.then(|| "--cpu".to_string()).into_iter().collect();
    let mut rows = Vec::new();
    let mut adapter = String::from("none (CPU reference)");

    // Ingest: registration, mattes and inter-view flow, per flow preset (and λ).
    let mut ingests: Vec<(String, Vec<String>, bool)> = presets
        .iter()
        .map(|p| (p.to_string(), vec![], *p == "balanced"))
        .collect();
    for l in lambdas {
        ingests.push((
            format!("balanced λ={l}"),
            vec!["--flow-set".into(), format!("lambda={l}")],
            false,
        ));
    }
    let mut default_field = None;
    for (i, (label, extra, default)) in ingests.iter().enumerate() {
        let field = runs.join(format!("ingest_{i}.frf"));
        let json = runs.join(format!("ingest_{i}.json"));
        let preset = label.split(' ').next().unwrap_or(label);
        let a = ingest_args(&cap, &pose_arg, preset, extra, &field, &json);
        let ran = runner.run(&format!("ingest_{i}"), &a, &[&field, &json])?;
        let r: Value = serde_json::from_slice(&std::fs::read(&json)?)?;
        let step = |name: &str| -> f64 {
            r["steps"]
                .as_array()
                .into_iter()
                .flatten()
                .filter(|s| s["name"].as_str().is_some_and(|n| n.starts_with(name)))
                .filter_map(|s| s["seconds"].as_f64())
                .sum()
        };
        let what = format!("ingest ({label})");
        let mut flow = Rows {
            rows: &mut rows,
            stage: "inter-view flow",
            knob: "flow preset",
        };
        flow.push(
            label,
            "EPE px, horizontal pairs",
            num(&r, "flow_epe_horizontal", &what)?,
            step("inter-view flow, horizontal"),
            "flow of one pose's horizontal pairs",
            *default,
            &ran.command,
        );
        flow.push(
            label,
            "EPE px, vertical pairs",
            num(&r, "flow_epe_vertical", &what)?,
            step("inter-view flow, vertical"),
            "flow of one pose's vertical pairs",
            *default,
            &ran.command,
        );
        let mut reg = Rows {
            rows: &mut rows,
            stage: "registration and mattes",
            knob: "flow preset",
        };
        reg.push(
            label,
            "registered-basis PSNR dB",
            num(&r, "registration_psnr", &what)?,
            step("registration"),
            "registration of one pose",
            *default,
            &ran.command,
        );
        reg.push(
            label,
            "alpha IoU",
            num(&r, "alpha_iou", &what)?,
            step("registration") + step("mattes"),
            "mattes and registration of one pose",
            *default,
            &ran.command,
        );
        if *default {
            let seconds = num(&r, "seconds", &what)?;
            default_field = Some((field, seconds, ran.command.clone()));
        }
    }
    let (field, ingest_seconds, ingest_command) = default_field.ok_or("no default ingest")?;

    // Flow storage: the log quantizer's scale on the true inter-view flows.
    let flows: Vec<_> = (0..capture.cycles())
        .step_by((capture.cycles() / 6).max(1))
        .map(|cycle| {
            let path = frf_stage::writer::truth_flow_path(
                &args.capture,
                pose,
                cycle,
                1.min(capture.cameras().len() - 1),
                Neighbour::Right,
            );
            frf_core::flo::read_flo(&path)
        })
        .collect::<Result<_, _>>()?;
    let mut storage = Rows {
        rows: &mut rows,
        stage: "flow storage",
        knob: "quantizer scale",
    };
    for scale in [
        None,
        Some(0.01),
        Some(0.05),
        Some(0.2),
        Some(1.0),
        Some(5.0),
    ] {
        let q = frf_eval::storage::flow_quantization(&flows, scale)?;
        let value = match scale {
            None => format!("{:.3} (fitted)", q.scale),
            Some(v) => format!("{v}"),
        };
        storage.push(
            format!("{value}, {:.1} bits", q.bits_per_vector),
            "EPE px added",
            q.epe,
            q.seconds_per_map,
            "encode and decode one map",
            scale.is_none(),
            "(in process: frf_eval::storage::flow_quantization on true flows)",
        );
    }

    // Basis compression: JPEG quality against relit PSNR.
    let a: Vec<String> = [
        "stage",
        "codec-curve",
        "--capture",
        &cap,
        "--env",
        &args.env,
        "--qualities",
        qualities,
        "--json",
    ]
    .map(String::from)
    .to_vec();
    let ran = runner.run("codec_curve", &a, &[])?;
    let curve: Value = serde_json::from_str(&ran.stdout)?;
    let mut jpeg = Rows {
        rows: &mut rows,
        stage: "basis compression",
        knob: "jpeg quality",
    };
    for p in curve.as_array().into_iter().flatten() {
        let q = p["quality"].as_u64().unwrap_or(0);
        jpeg.push(
            format!(
                "{q} ({:.0}:1)",
                p["ratio_vs_16bit"].as_f64().unwrap_or(f64::NAN)
            ),
            "relit PSNR dB",
            num(p, "mean_relit_psnr_db", "codec-curve")?,
            num(p, "seconds_per_view", "codec-curve")?,
            "encode and decode one view's basis",
            q == 95,
            &ran.command,
        );
    }

    // Novel views at quad centres, every variant, from the default ingest.
    let eval = |id: &str, field: &Path, extra: &[&str]| -> CliResult<(Value, String)> {
        let mut a: Vec<String> = ["eval", &s(field), "--capture", &cap, "--env", &args.env]
            .map(String::from)
            .to_vec();
        a.extend(extra.iter().map(|x| x.to_string()));
        a.extend(cpu.iter().cloned());
        a.push("--json".into());
        let ran = runner.run(id, &a, &[])?;
        Ok((serde_json::from_str(&ran.stdout)?, ran.command))
    };
    let (views, command) = eval(
        "eval_views",
        &field,
        &["--cameras", cameras, "--variants", variants],
    )?;
    if let Some(d) = views["device"].as_str() {
        adapter = d.to_string();
    }
    let mut novel = Rows {
        rows: &mut rows,
        stage: "novel views",
        knob: "morph variant",
    };
    for v in views["variants"].as_array().into_iter().flatten() {
        let name = v["name"].as_str().unwrap_or("?");
        let secs = num(v, "seconds_per_frame", "eval")?;
        for (metric, key) in [
            ("subject PSNR dB", "psnr_subject"),
            ("subject SSIM", "ssim_subject"),
        ] {
            novel.push(
                name,
                metric,
                num(v, key, "eval")?,
                secs,
                "per frame",
                name == "fourway",
                &command,
            );
        }
    }

    // The path suite (inside, near, outside, above, below the grid).
    let (suite, command) = eval(
        "eval_suite",
        &field,
        &["--suite", "--frames", frames, "--variants", variants],
    )?;
    let mut paths = Rows {
        rows: &mut rows,
        stage: "camera paths",
        knob: "morph variant",
    };
    for pair in suite["mean_psnr_subject"].as_array().into_iter().flatten() {
        let (Some(name), Some(psnr)) = (pair[0].as_str(), pair[1].as_f64()) else {
            continue;
        };
        let secs: Vec<f64> = suite["paths"]
            .as_array()
            .into_iter()
            .flatten()
            .flat_map(|p| p["variants"].as_array().into_iter().flatten())
            .filter(|v| v["name"] == name)
            .filter_map(|v| v["seconds_per_frame"].as_f64())
            .collect();
        let mean = secs.iter().sum::<f64>() / secs.len().max(1) as f64;
        paths.push(
            name,
            "subject PSNR dB (mean of the suite)",
            psnr,
            mean,
            "per frame",
            name == "fourway",
            &command,
        );
    }

    // Frame size along an orbit inside the cylinder of cameras.
    let orbit_eval = |id: &str, field: &Path, size: &str| {
        let a = ["--orbit", "3,1.2", "--frames", frames, "--size", size];
        eval(id, field, &[&a[..], &["--variants", "fourway"]].concat())
    };
    let own_size = format!("{w}x{h}");
    // The capture size knob's runs: (size, its field's score at the capture's size, ingest
    // seconds, the commands that filmed and ingested it).
    let mut filmed = Vec::new();
    for (i, (fw, fh)) in sizes.iter().enumerate() {
        let size = format!("{fw}x{fh}");
        let (o, command) = orbit_eval(&format!("eval_size_{i}"), &field, &size)?;
        let v = &o["paths"][0]["variants"][0];
        let mut sized = Rows {
            rows: &mut rows,
            stage: "frame size",
            knob: "frame size",
        };
        sized.push(
            &size,
            "subject PSNR dB",
            num(v, "psnr_subject", "eval --size")?,
            num(v, "seconds_per_frame", "eval --size")?,
            "per frame",
            size == own_size,
            &command,
        );
        if size == own_size {
            filmed.push((size, (o, command), ingest_seconds, ingest_command.clone()));
        }
    }

    // Capture size: the capture filmed smaller, each ingested and scored at its own size.
    for (i, &(cw, ch)) in smaller.iter().enumerate() {
        let dir = runs.join(format!("capture_{i}"));
        let a = capture_size::stage_args(&stage_config, pose, (cw, ch), &dir);
        let staged = runner.run(&format!("capture_{i}"), &a, &[&dir])?;
        let f = runs.join(format!("capture_{i}.frf"));
        let json = runs.join(format!("capture_{i}.json"));
        let a = ingest_args(&s(&dir), &pose_arg, "balanced", &[], &f, &json);
        let ingested = runner.run(&format!("capture_{i}_ingest"), &a, &[&f, &json])?;
        let r: Value = serde_json::from_slice(&std::fs::read(&json)?)?;
        let seconds = num(&r, "seconds", &format!("ingest of the {cw}x{ch} capture"))?;
        let scored = orbit_eval(&format!("eval_capture_{i}"), &f, &own_size)?;
        let made = format!("{}; {}", staged.command, ingested.command);
        filmed.push((format!("{cw}x{ch}"), scored, seconds, made));
    }
    for (value, (o, scored), seconds, made) in filmed {
        let mut sized = Rows {
            rows: &mut rows,
            stage: "capture size",
            knob: "capture size",
        };
        // SSIM beside PSNR: a blurrier field from a smaller capture can score a higher
        // PSNR than a sharper one whose details are slightly misplaced; SSIM sees the loss.
        for (metric, key) in [("PSNR dB", "psnr_subject"), ("SSIM", "ssim_subject")] {
            sized.push(
                &value,
                &format!("subject {metric} at {own_size}"),
                num(&o["paths"][0]["variants"][0], key, "eval --size")?,
                seconds,
                "ingest of one pose",
                value == own_size,
                &format!("{made}; {scored}"),
            );
        }
    }

    // The GPU renderer against the CPU reference, same cameras.
    let renderers: &[(&str, bool)] = if args.cpu {
        &[("cpu", true)]
    } else {
        &[("gpu", false), ("cpu", true)]
    };
    for (name, on_cpu) in renderers {
        let mut extra = vec!["--cameras", cameras, "--variants", "fourway"];
        if *on_cpu && !args.cpu {
            extra.push("--cpu");
        }
        let (o, command) = eval(&format!("eval_renderer_{name}"), &field, &extra)?;
        let v = &o["variants"][0];
        let mut r = Rows {
            rows: &mut rows,
            stage: "renderer",
            knob: "renderer",
        };
        r.push(
            *name,
            "subject PSNR dB",
            num(v, "psnr_subject", "eval")?,
            num(v, "seconds_per_frame", "eval")?,
            "per frame",
            !on_cpu || args.cpu,
            &command,
        );
    }

    // Shadows: hull voxel and shadow-map texels, on oracle fields (perfect mattes), timed
    // as `stage field` times its hulls and maps.
    let field_args = |extra: &[&str], out: &Path| -> Vec<String> {
        ["stage", "field", "--capture", &cap, "--poses", &pose_arg]
            .iter()
            .chain(extra)
            .map(|a| a.to_string())
            .chain(["--out".into(), s(out)])
            .collect()
    };
    for (i, (voxel, texels)) in shadow_settings.iter().enumerate() {
        let f = runs.join(format!("oracle_shadows_{i}.frf"));
        let a = field_args(&["--hull-voxel", voxel, "--shadow-texels", texels], &f);
        let built = runner.run(&format!("oracle_shadows_{i}"), &a, &[&f])?;
        let (o, scored) = eval(
            &format!("eval_shadows_{i}"),
            &f,
            &["--shadows", "--cameras", cameras, "--variants", "fourway"],
        )?;
        let value = format!("{voxel} m, {texels}²");
        let default = (*voxel, *texels) == ("0.02", "128");
        let build = built
            .stdout
            .lines()
            .find_map(|l| l.strip_prefix(super::stage_field::SHADOW_TIME_LINE))
            .and_then(|t| t.trim_end_matches(" s").parse::<f64>().ok())
            .ok_or_else(|| format!("{}: no time of the hulls and shadow maps", built.command))?;
        let command = format!("{}; {scored}", built.command);
        let mut sh = Rows {
            rows: &mut rows,
            stage: "shadows",
            knob: "hull voxel, shadow texels",
        };
        sh.push(
            &value,
            "shadow MAE",
            num(&o, "shadow_mae", "eval --shadows")?,
            build,
            "hull and maps of one pose",
            default,
            &command,
        );
        sh.push(
            &value,
            "hull IoU",
            num(&o, "hull_iou", "eval --shadows")?,
            build,
            "hull and maps of one pose",
            default,
            &command,
        );
        let mut comp = Rows {
            rows: &mut rows,
            stage: "composite",
            knob: "hull voxel, shadow texels",
        };
        comp.push(
            &value,
            "composite PSNR dB",
            num(&o, "psnr_composite", "eval --shadows")?,
            num(&o, "seconds_per_composite", "eval --shadows")?,
            "per composite",
            default,
            &command,
        );
    }
    runner.bar.finish_and_clear();

    rows.extend(peer_flow_rows);
    let report = Report {
        capture: cap,
        commit: commit(),
        machine: Machine {
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            adapter,
            os: format!("{} {}", std::env::consts::OS, std::env::consts::ARCH),
        },
        quick,
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
