//! The sweep of `frf report`, one function per stage: each runs this binary's verbs with
//! the stage's settings ([`super::runner`]), reads their reports as the structs the
//! libraries define (`IngestReport`, `CodecPoint`, `QuadsReport`, `PathsReport`), and adds
//! one row per setting and metric.

use std::path::{Path, PathBuf};

use crate::paths::PathsReport;
use crate::quads::QuadsReport;
use crate::report::Row;
use crate::storage::CodecPoint;
use crate::views::VariantScore;
use frf_core::capture::Capture;
use frf_core::grid::Neighbour;
use frf_ingest::pipeline::IngestReport;
use frf_stage::config::StageConfig;
use serde::de::DeserializeOwned;

use super::capture_size;
use super::runner::{Ran, Runner};
use crate::error::{EvalError, Result};

/// The morph variants the sweep compares.
const VARIANTS: &str =
    "nearest,linear,twoway,fourway-e06,fourway,fourway-occlusion,fourway-no-proxy";

/// What a sweep measures with: the runner, the capture, and its settings.
pub struct Sweep<'a> {
    /// Runs this binary's verbs.
    pub runner: &'a Runner,
    /// The capture directory.
    pub cap: String,
    /// Its first pose.
    pub pose: u32,
    /// The environment renders are relit by.
    pub env: String,
    /// `--cpu` for every render, when asked.
    pub cpu: Vec<String>,
    /// The reduced sweep.
    pub quick: bool,
    /// The rows measured so far.
    pub rows: Vec<Row>,
    /// The renderer's device, as the evaluations name it.
    pub adapter: String,
}

/// A run's report, read as `T`.
pub(super) fn parse<T: DeserializeOwned>(text: &str, ran: &str) -> Result<T> {
    serde_json::from_str(text)
        .map_err(|e| EvalError::run(ran, format!("its report does not read: {e}")))
}

/// A run's report file.
pub(super) fn read(path: &Path) -> Result<String> {
    Ok(std::fs::read_to_string(path).map_err(|e| frf_core::CoreError::io(path, e))?)
}

/// A figure a report may lack (no truth to judge by).
fn need(value: Option<f64>, what: &str, ran: &str) -> Result<f64> {
    value.ok_or_else(|| EvalError::run(ran, format!("no {what} in its report")))
}

pub(super) fn s(p: &Path) -> String {
    p.display().to_string()
}

/// `frf ingest` of one pose of `cap` with a flow preset (and extra arguments), writing the
/// field and its JSON report.
pub(super) fn ingest_args(
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

/// The one variant of an evaluation of one variant.
fn only(variants: &[VariantScore], ran: &str) -> Result<VariantScore> {
    variants
        .first()
        .cloned()
        .ok_or_else(|| EvalError::run(ran, "no variant in its report"))
}

impl Sweep<'_> {
    fn quick_or<T>(&self, quick: T, full: T) -> T {
        if self.quick { quick } else { full }
    }

    fn cameras(&self) -> &'static str {
        self.quick_or("2", "8")
    }

    fn frames(&self) -> &'static str {
        self.quick_or("2", "6")
    }

    #[allow(clippy::too_many_arguments)] // one row's fields
    pub(super) fn push(
        &mut self,
        (stage, knob): (&str, &str),
        value: impl Into<String>,
        metric: &str,
        error: f64,
        seconds: f64,
        timed: &str,
        default: bool,
        command: &str,
    ) {
        self.rows.push(Row {
            stage: stage.into(),
            knob: knob.into(),
            value: value.into(),
            metric: metric.into(),
            error,
            seconds,
            timed: timed.into(),
            default,
            command: command.into(),
        });
    }

    /// `frf eval` of `field` with `extra` arguments, read as `T`.
    fn eval<T: DeserializeOwned>(
        &self,
        id: &str,
        field: &Path,
        extra: &[&str],
    ) -> Result<(T, Ran)> {
        let mut a: Vec<String> = [
            "eval",
            &s(field),
            "--capture",
            &self.cap,
            "--env",
            &self.env,
        ]
        .map(String::from)
        .to_vec();
        a.extend(extra.iter().map(|x| x.to_string()));
        a.extend(self.cpu.iter().cloned());
        a.push("--json".into());
        let ran = self.runner.run(id, &a, &[])?;
        Ok((parse(&ran.stdout, &ran.command)?, ran))
    }

    /// `frf eval` of `field` along the orbit inside the cylinder at `size`, four-way.
    fn orbit_eval(&self, id: &str, field: &Path, size: &str) -> Result<(VariantScore, Ran)> {
        let a = [
            "--orbit",
            "3,1.2",
            "--frames",
            self.frames(),
            "--size",
            size,
        ];
        let (o, ran) =
            self.eval::<PathsReport>(id, field, &[&a[..], &["--variants", "fourway"]].concat())?;
        let path = o
            .paths
            .first()
            .ok_or_else(|| EvalError::run(&ran.command, "no path in its report"))?;
        Ok((only(&path.variants, &ran.command)?, ran))
    }

    /// Ingest: registration, mattes and inter-view flow, per flow preset (and λ). Returns
    /// the default ingest's field, seconds and command.
    pub fn ingest(&mut self, runs: &Path) -> Result<(PathBuf, f64, String)> {
        let presets: &[&str] =
            self.quick_or(&["fast", "balanced"], &["fast", "balanced", "accurate"]);
        let lambdas: &[&str] = self.quick_or(&[], &["6", "48"]);
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
        let pose = self.pose.to_string();
        let mut default_field = None;
        for (i, (label, extra, default)) in ingests.iter().enumerate() {
            let field = runs.join(format!("ingest_{i}.frf"));
            let json = runs.join(format!("ingest_{i}.json"));
            let preset = label.split(' ').next().unwrap_or(label);
            let a = ingest_args(&self.cap, &pose, preset, extra, &field, &json);
            let ran = self
                .runner
                .run(&format!("ingest_{i}"), &a, &[&field, &json])?;
            let r: IngestReport = parse(&read(&json)?, &ran.command)?;
            let step = |name: &str| -> f64 {
                r.steps
                    .iter()
                    .filter(|s| s.name.starts_with(name))
                    .map(|s| s.seconds)
                    .sum()
            };
            let c = &ran.command;
            let flow = ("inter-view flow", "flow preset");
            self.push(
                flow,
                label,
                "EPE px, horizontal pairs",
                need(r.flow_epe_horizontal, "horizontal flow EPE", c)?,
                step("inter-view flow, horizontal"),
                "flow of one pose's horizontal pairs",
                *default,
                c,
            );
            self.push(
                flow,
                label,
                "EPE px, vertical pairs",
                need(r.flow_epe_vertical, "vertical flow EPE", c)?,
                step("inter-view flow, vertical"),
                "flow of one pose's vertical pairs",
                *default,
                c,
            );
            let reg = ("registration and mattes", "flow preset");
            self.push(
                reg,
                label,
                "registered-basis PSNR dB",
                need(r.registration_psnr, "registration PSNR", c)?,
                step("registration"),
                "registration of one pose",
                *default,
                c,
            );
            self.push(
                reg,
                label,
                "alpha IoU",
                need(r.alpha_iou, "alpha IoU", c)?,
                step("registration") + step("mattes"),
                "mattes and registration of one pose",
                *default,
                c,
            );
            if *default {
                default_field = Some((field, r.seconds, ran.command.clone()));
            }
        }
        default_field.ok_or(EvalError::Misuse("no default ingest".into()))
    }

    /// Flow storage: the log quantizer's scale on the true inter-view flows (in process).
    pub fn flow_storage(&mut self, capture: &Capture, capture_dir: &Path) -> Result<()> {
        let flows: Vec<_> = (0..capture.cycles())
            .step_by((capture.cycles() / 6).max(1))
            .map(|cycle| {
                let path = frf_stage::writer::truth_flow_path(
                    capture_dir,
                    self.pose,
                    cycle,
                    1.min(capture.cameras().len() - 1),
                    Neighbour::Right,
                );
                frf_core::flo::read_flo(&path)
            })
            .collect::<Result<_, _>>()?;
        for scale in [
            None,
            Some(0.01),
            Some(0.05),
            Some(0.2),
            Some(1.0),
            Some(5.0),
        ] {
            let q = crate::storage::flow_quantization(&flows, scale)?;
            let value = match scale {
                None => format!("{:.3} (fitted)", q.scale),
                Some(v) => format!("{v}"),
            };
            self.push(
                ("flow storage", "quantizer scale"),
                format!("{value}, {:.1} bits", q.bits_per_vector),
                "EPE px added",
                q.epe,
                q.seconds_per_map,
                "encode and decode one map",
                scale.is_none(),
                "(in process: crate::storage::flow_quantization on true flows)",
            );
        }
        Ok(())
    }

    /// Basis compression: JPEG quality against relit PSNR.
    pub fn basis_compression(&mut self) -> Result<()> {
        let qualities = self.quick_or("50,80,95", "50,60,70,80,85,90,95,98");
        let a: Vec<String> = [
            "stage",
            "codec-curve",
            "--capture",
            &self.cap,
            "--env",
            &self.env,
            "--qualities",
            qualities,
            "--json",
        ]
        .map(String::from)
        .to_vec();
        let ran = self.runner.run("codec_curve", &a, &[])?;
        let curve: Vec<CodecPoint> = parse(&ran.stdout, &ran.command)?;
        for p in curve {
            self.push(
                ("basis compression", "jpeg quality"),
                format!("{} ({:.0}:1)", p.quality, p.ratio_vs_16bit),
                "relit PSNR dB",
                p.mean_relit_psnr_db,
                p.seconds_per_view,
                "encode and decode one view's basis",
                p.quality == 95,
                &ran.command,
            );
        }
        Ok(())
    }

    /// Novel views at quad centres, every variant.
    pub fn novel_views(&mut self, field: &Path) -> Result<()> {
        let (views, ran) = self.eval::<QuadsReport>(
            "eval_views",
            field,
            &["--cameras", self.cameras(), "--variants", VARIANTS],
        )?;
        self.adapter = views.header.device.clone();
        for v in &views.variants {
            for (metric, error) in [
                ("subject PSNR dB", v.psnr_subject),
                ("subject SSIM", v.ssim_subject),
            ] {
                self.push(
                    ("novel views", "morph variant"),
                    &v.name,
                    metric,
                    error,
                    v.seconds_per_frame,
                    "per frame",
                    v.name == "fourway",
                    &ran.command,
                );
            }
        }
        Ok(())
    }

    /// The path suite (inside, near, outside, above, below the grid), every variant.
    pub fn camera_paths(&mut self, field: &Path) -> Result<()> {
        let (suite, ran) = self.eval::<PathsReport>(
            "eval_suite",
            field,
            &["--suite", "--frames", self.frames(), "--variants", VARIANTS],
        )?;
        for (name, psnr) in &suite.mean_psnr_subject {
            let secs: Vec<f64> = suite
                .paths
                .iter()
                .flat_map(|p| &p.variants)
                .filter(|v| &v.name == name)
                .map(|v| v.seconds_per_frame)
                .collect();
            let mean = secs.iter().sum::<f64>() / secs.len().max(1) as f64;
            self.push(
                ("camera paths", "morph variant"),
                name,
                "subject PSNR dB (mean of the suite)",
                *psnr,
                mean,
                "per frame",
                name == "fourway",
                &ran.command,
            );
        }
        Ok(())
    }

    /// Frame size along the orbit inside the cylinder, then the capture filmed smaller,
    /// each ingested and scored at the capture's own size.
    pub fn sizes(
        &mut self,
        field: &Path,
        runs: &Path,
        stage_config: &StageConfig,
        (w, h): (u32, u32),
        default_ingest: (f64, &str),
    ) -> Result<()> {
        let sizes: Vec<(u32, u32)> = self.quick_or(
            vec![(w, h), (2 * w, 2 * h)],
            vec![(w / 2, h / 2), (w, h), (2 * w, 2 * h), (4 * w, 4 * h)],
        );
        let own_size = format!("{w}x{h}");
        // The capture size knob's runs: (size, its field's score at the capture's size,
        // ingest seconds, the commands that filmed and ingested it).
        let mut filmed = Vec::new();
        for (i, (fw, fh)) in sizes.iter().enumerate() {
            let size = format!("{fw}x{fh}");
            let (v, ran) = self.orbit_eval(&format!("eval_size_{i}"), field, &size)?;
            self.push(
                ("frame size", "frame size"),
                &size,
                "subject PSNR dB",
                v.psnr_subject,
                v.seconds_per_frame,
                "per frame",
                size == own_size,
                &ran.command,
            );
            if size == own_size {
                filmed.push((
                    size,
                    v,
                    ran.command,
                    default_ingest.0,
                    default_ingest.1.to_string(),
                ));
            }
        }
        for (i, &(cw, ch)) in self.smaller(stage_config, w, h).iter().enumerate() {
            let dir = runs.join(format!("capture_{i}"));
            let a = capture_size::stage_args(stage_config, self.pose, (cw, ch), &dir);
            let staged = self.runner.run(&format!("capture_{i}"), &a, &[&dir])?;
            let f = runs.join(format!("capture_{i}.frf"));
            let json = runs.join(format!("capture_{i}.json"));
            let a = ingest_args(&s(&dir), &self.pose.to_string(), "balanced", &[], &f, &json);
            let ingested = self
                .runner
                .run(&format!("capture_{i}_ingest"), &a, &[&f, &json])?;
            let r: IngestReport = parse(&read(&json)?, &ingested.command)?;
            let (v, scored) = self.orbit_eval(&format!("eval_capture_{i}"), &f, &own_size)?;
            let made = format!("{}; {}", staged.command, ingested.command);
            filmed.push((format!("{cw}x{ch}"), v, scored.command, r.seconds, made));
        }
        for (value, v, scored, seconds, made) in filmed {
            // SSIM beside PSNR: a blurrier field from a smaller capture can score a higher
            // PSNR than a sharper one whose details are slightly misplaced; SSIM sees it.
            for (metric, error) in [("PSNR dB", v.psnr_subject), ("SSIM", v.ssim_subject)] {
                self.push(
                    ("capture size", "capture size"),
                    &value,
                    &format!("subject {metric} at {own_size}"),
                    error,
                    seconds,
                    "ingest of one pose",
                    value == own_size,
                    &format!("{made}; {scored}"),
                );
            }
        }
        Ok(())
    }

    /// The capture sizes the capture-size knob films (a capture of every view only: one
    /// made for a scene films a subset).
    pub fn smaller(&self, stage_config: &StageConfig, w: u32, h: u32) -> Vec<(u32, u32)> {
        if stage_config.filmed.is_empty() {
            capture_size::smaller_sizes(w, h, self.quick)
        } else {
            Vec::new()
        }
    }

    /// The GPU renderer against the CPU reference, same cameras.
    pub fn renderers(&mut self, field: &Path, cpu_only: bool) -> Result<()> {
        let renderers: &[(&str, bool)] = if cpu_only {
            &[("cpu", true)]
        } else {
            &[("gpu", false), ("cpu", true)]
        };
        for (name, on_cpu) in renderers {
            let mut extra = vec!["--cameras", self.cameras(), "--variants", "fourway"];
            if *on_cpu && !cpu_only {
                extra.push("--cpu");
            }
            let (o, ran) =
                self.eval::<QuadsReport>(&format!("eval_renderer_{name}"), field, &extra)?;
            let v = only(&o.variants, &ran.command)?;
            self.push(
                ("renderer", "renderer"),
                *name,
                "subject PSNR dB",
                v.psnr_subject,
                v.seconds_per_frame,
                "per frame",
                !on_cpu || cpu_only,
                &ran.command,
            );
        }
        Ok(())
    }

    /// The settings of the shadows knob: hull voxel and shadow-map texels.
    pub fn shadow_settings(&self) -> &'static [(&'static str, &'static str)] {
        self.quick_or(
            &[("0.04", "64"), ("0.02", "128")],
            &[
                ("0.04", "64"),
                ("0.04", "128"),
                ("0.02", "64"),
                ("0.02", "128"),
                ("0.02", "256"),
                ("0.01", "256"),
            ],
        )
    }

    /// Shadows: hull voxel and shadow-map texels, on oracle fields (perfect mattes),
    /// timed as `stage field` times its hulls and maps.
    pub fn shadows(&mut self, runs: &Path) -> Result<()> {
        let (cap, pose) = (self.cap.clone(), self.pose.to_string());
        let field_args = |extra: &[&str], out: &Path| -> Vec<String> {
            ["stage", "field", "--capture", &cap, "--poses", &pose]
                .iter()
                .map(|a| a.to_string())
                .chain(extra.iter().map(|a| a.to_string()))
                .chain(["--out".into(), s(out)])
                .collect()
        };
        for (i, (voxel, texels)) in self.shadow_settings().iter().enumerate() {
            let f = runs.join(format!("oracle_shadows_{i}.frf"));
            let a = field_args(&["--hull-voxel", voxel, "--shadow-texels", texels], &f);
            let built = self.runner.run(&format!("oracle_shadows_{i}"), &a, &[&f])?;
            let (o, scored) = self.eval::<QuadsReport>(
                &format!("eval_shadows_{i}"),
                &f,
                &[
                    "--shadows",
                    "--cameras",
                    self.cameras(),
                    "--variants",
                    "fourway",
                ],
            )?;
            let value = format!("{voxel} m, {texels}²");
            let default = (*voxel, *texels) == ("0.02", "128");
            let build = built
                .stdout
                .lines()
                .find_map(|l| l.strip_prefix(crate::oracle::SHADOW_TIME_LINE))
                .and_then(|t| t.trim_end_matches(" s").parse::<f64>().ok())
                .ok_or_else(|| {
                    EvalError::run(&built.command, "no time of the hulls and shadow maps")
                })?;
            let command = format!("{}; {}", built.command, scored.command);
            let scene = o
                .scene
                .ok_or_else(|| EvalError::run(&scored.command, "no scene scores in its report"))?;
            let c = &scored.command;
            let sh = ("shadows", "hull voxel, shadow texels");
            self.push(
                sh,
                &value,
                "shadow MAE",
                need(scene.shadow_mae, "shadow MAE", c)?,
                build,
                "hull and maps of one pose",
                default,
                &command,
            );
            self.push(
                sh,
                &value,
                "hull IoU",
                need(scene.hull_iou, "hull IoU", c)?,
                build,
                "hull and maps of one pose",
                default,
                &command,
            );
            self.push(
                ("composite", "hull voxel, shadow texels"),
                &value,
                "composite PSNR dB",
                scene.psnr_composite,
                scene.seconds_per_composite,
                "per composite",
                default,
                &command,
            );
        }
        Ok(())
    }
}
