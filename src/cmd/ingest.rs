//! `frf ingest CAPTURE --out FIELD`: capture to flowed reflectance field, with a report
//! of time per step and, for virtual-stage captures, each step's error against the truth.

use std::path::PathBuf;

use clap::Args;
use frf_eval::ingest::StageEvaluator;
use frf_ingest::edges::EdgeMethod;
use frf_ingest::evidence::Evaluator;
use frf_ingest::guided::InterViewFlow;
use frf_ingest::pipeline::{IngestOptions, ingest};

use crate::CliResult;
use crate::cmd::args::{ShadowArgs, poses_arg};
use frf_core::bars::Bars;

/// Arguments of `frf ingest`.
#[derive(Args)]
pub struct IngestArgs {
    /// A capture directory (with `capture.toml`).
    capture: PathBuf,
    /// Output field file (a rerun with the same settings resumes from finished poses).
    #[arg(long)]
    out: PathBuf,
    /// Poses to ingest, e.g. `0,1` or `0..4` (default: all captured).
    #[arg(long)]
    poses: Option<String>,
    #[command(flatten)]
    method: IngestMethodArgs,
    /// Skip the evaluation against the virtual stage's truth.
    #[arg(long)]
    no_eval: bool,
    /// Also measure and store each view's flow to the capture's next and previous pose,
    /// which shots between two poses morph by (docs/design.md §4.7). A field of every
    /// second pose is made from a capture filmed at those poses (`frf stage --poses
    /// 0,2,4,...`), so that the field's neighbouring poses are the capture's.
    #[arg(long)]
    pose_flow: bool,
    /// Ingest only the poses, views and flows this scene file needs (`frf render
    /// SCENE.toml` renders from the field).
    #[arg(long = "for", value_name = "SCENE")]
    for_scene: Option<PathBuf>,
    /// Write the report as JSON here.
    #[arg(long)]
    report: Option<PathBuf>,
    #[command(flatten)]
    shadows: ShadowArgs,
}

/// How ingest processes a capture: flow, codecs, mattes and edges (`frf ingest`, and the
/// fields of `frf eval --ingest-budget`).
#[derive(Args)]
pub struct IngestMethodArgs {
    /// Optical-flow preset for registration and inter-view flow.
    #[arg(long, value_enum, default_value = "balanced")]
    flow_preset: frf_flow::Preset,
    /// Override a flow parameter, `key=value` (repeatable; keys as `frf flow --set`).
    #[arg(long = "flow-set", value_name = "KEY=VALUE")]
    flow_set: Vec<String>,
    /// JPEG quality of the basis mosaics (95 keeps relit PSNR above 40 dB on stage data).
    #[arg(long, default_value_t = 95, value_parser = clap::value_parser!(u8).range(1..=100))]
    jpeg_quality: u8,
    /// Do not predict flow codes from their neighbours.
    #[arg(long)]
    no_flow_prediction: bool,
    /// Matte rule: `half-clean` (the matte frame darker than half its clean plate;
    /// unbiased at silhouettes) or `paper` (the track frame brighter than the matte frame).
    #[arg(long, value_enum, default_value = "half-clean")]
    matte_rule: frf_ingest::matte::MatteRule,
    /// Backdrop light at the subject's edges: `solve` (alpha of edge pixels solved from
    /// the matte frame, then matted with it), `extend` (the interior's colour extended
    /// under the edge) or `none` (the blurred binary matte, as the original).
    #[arg(long, value_enum, default_value = "solve")]
    edge: EdgeMethod,
    /// Flow between neighbouring views: `hull` (the reprojection of the pose's visual
    /// hull, refined on the images) or `images` (image matching alone, through the plane
    /// of the turntable's axis, as before).
    #[arg(long, value_enum, default_value = "hull")]
    inter_view_flow: InterViewFlow,
}

impl IngestMethodArgs {
    /// These settings over `frf ingest`'s other defaults.
    pub fn options(&self) -> CliResult<IngestOptions> {
        Ok(IngestOptions {
            flow_preset: self.flow_preset,
            flow_settings: self
                .flow_set
                .iter()
                .map(|kv| {
                    kv.split_once('=')
                        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
                        .ok_or_else(|| format!("--flow-set {kv:?}: expected KEY=VALUE"))
                })
                .collect::<Result<_, _>>()?,
            jpeg_quality: self.jpeg_quality,
            predict_flow: !self.no_flow_prediction,
            matte_rule: self.matte_rule,
            edge: self.edge,
            inter_view_flow: self.inter_view_flow,
            ..IngestOptions::default()
        })
    }
}

/// Runs `frf ingest`.
pub fn run(args: IngestArgs) -> CliResult {
    let _claim =
        crate::cmd::claim::claim(&args.out, &[&frf_ingest::pipeline::parts_dir(&args.out)])?;
    let mut options = IngestOptions {
        poses: args
            .poses
            .as_deref()
            .map(|p| poses_arg("--poses", p))
            .transpose()?
            .unwrap_or_default(),
        shadows: args.shadows.options()?,
        pose_flows: args.pose_flow,
        ..args.method.options()?
    };
    let bars = Bars::default();
    let judge = if args.no_eval {
        None
    } else {
        StageEvaluator::open_if_stage(&args.capture)?
    };
    let evaluator = judge.as_ref().map(|j| j as &dyn Evaluator);
    if let Some(scene) = &args.for_scene {
        let capture = frf_core::capture::Capture::open_manifest(&args.capture)?;
        if let Some((side, elevation)) = frf_scene::Scene::load(scene)?.shadow_patch()? {
            options.shadows = args.shadows.options_for(Some(side))?;
            if let Some(s) = &options.shadows {
                println!(
                    "shadow maps: a {:.1} m patch of {} texels (the scene's shadow-making lights \
                     reach down to {elevation:.0}°{})",
                    s.ground.extent_m,
                    s.ground.texels,
                    if side >= frf_scene::plan::MAX_SCENE_PATCH_M {
                        ": their shadow is longer than the largest patch made unasked"
                    } else {
                        ""
                    }
                );
            }
        }
        let plan = crate::cmd::for_scene::plan(scene, &capture, options.shadows.as_ref())?;
        println!("{}", plan.summary());
        let wanted: Vec<u32> = plan.poses.iter().map(|p| p.pose).collect();
        options.poses = if options.poses.is_empty() {
            wanted
        } else {
            options
                .poses
                .iter()
                .copied()
                .filter(|p| wanted.contains(p))
                .collect()
        };
        options.selection = Some(crate::cmd::for_scene::selection(&plan));
    }
    let report = ingest(&args.capture, &args.out, &options, evaluator, &bars)?;
    drop(bars);
    println!("{}", report.describe(&args.out));
    if let Some(path) = &args.report {
        let text = serde_json::to_string_pretty(&report)?;
        frf_core::atomic::write_bytes_atomic(path, text.as_bytes())?;
        println!("report written to {}", path.display());
    }
    Ok(())
}

/// Arguments of `frf ingest-ring`.
#[derive(Args)]
pub struct RingArgs {
    /// The ring's calibration, a Middlebury `*_par.txt` file beside its images.
    par: PathBuf,
    /// Output field file.
    #[arg(long)]
    out: PathBuf,
    /// Optical-flow preset for the flow between neighbouring photographs.
    #[arg(long, value_enum, default_value = "accurate")]
    flow_preset: frf_flow::Preset,
    /// JPEG quality of the images.
    #[arg(long, default_value_t = 95, value_parser = clap::value_parser!(u8).range(1..=100))]
    jpeg_quality: u8,
    /// Keep every n-th view in azimuth order (the others are held out for
    /// `frf eval-ring`).
    #[arg(long, default_value_t = 1)]
    stride: usize,
}

/// Runs `frf ingest-ring`.
pub fn run_ring(args: RingArgs) -> CliResult {
    let _claim = crate::cmd::claim::claim(&args.out, &[])?;
    let r = frf_ingest::ring::ingest_ring(
        &args.par,
        &args.out,
        &frf_flow::FlowParams::preset(args.flow_preset),
        args.jpeg_quality,
        args.stride,
    )?;
    println!("{}", r.describe(&args.out));
    Ok(())
}
