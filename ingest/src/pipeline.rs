//! The ingest pipeline: capture in, flowed reflectance field out, pose by pose.
//!
//! For each pose: load the clean plates; for every view (in parallel) matte, register and
//! matte the basis frames ([`crate::views`]) and compress its images at once; measure
//! the flow from every view to each grid neighbour ([`crate::interview`]); fit the pose's
//! flow quantizer to its flows, compress them and write the pose to its own part file
//! `FIELD.parts/pNN.frf` (atomically), with its report beside it. A rerun skips poses
//! whose part is finished and made with the same settings, so an interrupted ingest
//! resumes; the field itself appears only when every pose is done, merged from the parts.
//! When the caller has a ground truth (the virtual stage's, in `frf-eval`), each pose is
//! also handed to its [`Evaluator`] and its errors recorded in the report.

use std::path::{Path, PathBuf};
use std::time::Instant;

use frf_core::camera::Camera;
use frf_core::capture::Capture;
use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_flow::{FlowParams, Preset};
use frf_reflectance::container::merge_fields;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::hull::VoxelHull;
use frf_reflectance::stats::FieldStats;
use frf_reflectance::store::{EncodedView, encode_flows, encode_images, encode_pose_flows};
use frf_reflectance::{FieldFile, FieldHeader, FieldWriter};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::edges::EdgeMethod;
use crate::error::{IngestError, Result};
use crate::evidence::{Evaluator, PoseErrors, PoseEvidence, SampledView};
use crate::guided::{InterViewFlow, flow_hull};
use crate::interview::{GridViews, grid_flows};
use crate::matte::MatteRule;
use crate::shadows::{PoseShadows, ShadowOptions, pose_shadows};
use crate::views::{ViewSeconds, ViewSettings, process_view};

/// What to ingest and how.
#[derive(Debug, Clone)]
pub struct IngestOptions {
    /// Poses to ingest (empty: every captured pose).
    pub poses: Vec<u32>,
    /// Optical-flow preset for registration and inter-view flow.
    pub flow_preset: Preset,
    /// Overrides of the preset's parameters, `(key, value)` as
    /// [`FlowParams::with_setting`] takes them.
    pub flow_settings: Vec<(String, String)>,
    /// JPEG quality of the basis mosaics.
    pub jpeg_quality: u8,
    /// Predict flow codes from their neighbours before Huffman coding.
    pub predict_flow: bool,
    /// Which pixels are foreground in the mattes.
    pub matte_rule: MatteRule,
    /// The visual hull and shadow maps of every pose (`None`: neither).
    pub shadows: Option<ShadowOptions>,
    /// Only these views and flows of each pose (`None`: all the capture filmed).
    pub selection: Option<Selection>,
    /// What to do about backdrop light at the subject's edges.
    pub edge: EdgeMethod,
    /// Also measure and store each view's flows to the next and previous captured pose
    /// ([`crate::poseflow`]).
    pub pose_flows: bool,
    /// How the flows between neighbouring views are measured.
    pub inter_view_flow: InterViewFlow,
}

impl IngestOptions {
    /// Checks the options that do not depend on the capture, naming the bad one: the
    /// JPEG quality and the flow parameters.
    pub fn validate(&self) -> Result<()> {
        frf_core::argument::within("--jpeg-quality", self.jpeg_quality, 1, 100, "")?;
        self.flow_params()?.validate()?;
        Ok(())
    }

    /// The flow parameters of registration and inter-view flow: the preset with its
    /// overrides.
    pub fn flow_params(&self) -> Result<FlowParams> {
        let mut params = FlowParams::preset(self.flow_preset);
        for (k, v) in &self.flow_settings {
            params = params.with_setting(k, v)?;
        }
        Ok(params)
    }
}

impl Default for IngestOptions {
    /// The options `frf ingest` takes by default: every pose, the `balanced` flow preset,
    /// JPEG quality 95, predicted flow codes, the half-clean-plate matte rule, edges
    /// solved, hulls and shadow maps, no pose-to-pose flow, inter-view flow guided by
    /// the hull.
    fn default() -> Self {
        Self {
            poses: Vec::new(),
            flow_preset: Preset::Balanced,
            flow_settings: Vec::new(),
            jpeg_quality: 95,
            predict_flow: true,
            matte_rule: MatteRule::MatteBelowHalfCleanPlate,
            shadows: Some(ShadowOptions::default()),
            selection: None,
            edge: EdgeMethod::Solve,
            pose_flows: false,
            inter_view_flow: InterViewFlow::Hull,
        }
    }
}

/// The views and flows of each pose to ingest (a field made for one scene, `frf ingest
/// --for SCENE`): per pose, a flag per view (`u`-major) and per view and neighbour. Views
/// the capture did not film are left out whatever it says.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Selection {
    /// Per pose: the views wanted.
    pub views: std::collections::BTreeMap<u32, Vec<bool>>,
    /// Per pose: the flows wanted.
    pub flows: std::collections::BTreeMap<u32, Vec<[bool; 4]>>,
}

impl Selection {
    /// The selection of `poses`: per pose, the views and the flows (per view, toward
    /// each neighbour) wanted.
    pub fn of<'a>(poses: impl IntoIterator<Item = (u32, &'a [bool], &'a [[bool; 4]])>) -> Self {
        let (mut views, mut flows) = (
            std::collections::BTreeMap::new(),
            std::collections::BTreeMap::new(),
        );
        for (pose, v, f) in poses {
            views.insert(pose, v.to_vec());
            flows.insert(pose, f.to_vec());
        }
        Self { views, flows }
    }

    /// A short description for settings and reports: views and flows wanted per pose.
    pub fn describe(&self) -> String {
        self.views
            .iter()
            .map(|(p, v)| {
                let flows = self
                    .flows
                    .get(p)
                    .map_or(0, |f| f.iter().flatten().filter(|&&x| x).count());
                format!(
                    "p{p}: {} views, {flows} flows",
                    v.iter().filter(|&&x| x).count()
                )
            })
            .collect::<Vec<_>>()
            .join("; ")
    }
}

/// Progress of long steps: `begin` a named step of `total` units, `advance` by one; and
/// interruption: when `should_stop` turns true the ingest stops at the next view with
/// [`IngestError::Interrupted`], leaving the poses already finished in their parts.
pub trait Progress: Sync {
    /// A step of pose `pose` starts.
    fn begin(&self, pose: u32, step: &str, total: usize);
    /// One unit of the current step is done.
    fn advance(&self);
    /// Whether the user asked to stop.
    fn should_stop(&self) -> bool {
        false
    }
}

/// Every progress of phases ([`frf_core::progress::Progress`], e.g. bars) shows an
/// ingest: a phase per pose and step.
impl<T: frf_core::progress::Progress> Progress for T {
    fn begin(&self, pose: u32, step: &str, total: usize) {
        self.phase(&format!("pose {pose}: {step}"), total);
    }

    fn advance(&self) {
        self.step();
    }
}

fn check_stop(progress: &dyn Progress) -> Result<()> {
    if progress.should_stop() {
        return Err(IngestError::Interrupted);
    }
    Ok(())
}

/// Reports nothing.
pub struct Silent;

impl Progress for Silent {
    fn begin(&self, _: u32, _: &str, _: usize) {}
    fn advance(&self) {}
}

/// Wall-clock seconds of one step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Step {
    /// What the step does.
    pub name: String,
    /// Wall-clock seconds. Steps that run interleaved in one parallel phase share the
    /// phase's wall time in proportion to the thread time each took.
    pub seconds: f64,
}

/// The settings a part file was made with (a resumed pose must match them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Flow preset name, with its overrides.
    pub flow_preset: String,
    /// JPEG quality.
    pub jpeg_quality: u8,
    /// Flow prediction.
    pub predict_flow: bool,
    /// Matte rule.
    pub matte_rule: String,
    /// Hull and shadow maps.
    #[serde(default)]
    pub shadows: String,
    /// The views and flows selected (empty: all filmed).
    #[serde(default)]
    pub selection: String,
    /// Edge decontamination ([`EdgeMethod::name`]); parts written before it existed
    /// were made without.
    #[serde(default = "no_edge_method")]
    pub edge: String,
    /// Pose-to-pose flows measured; parts written before they existed have none.
    #[serde(default)]
    pub pose_flows: bool,
    /// The poses among which each pose's flows lead to its neighbours
    /// ([`pose_flow_poses`]); empty without pose flows.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pose_flows_among: Vec<u32>,
    /// How inter-view flow was measured ([`InterViewFlow::name`]); parts written before
    /// the hull guided it were matched on images alone.
    #[serde(default = "images_alone")]
    pub inter_view_flow: String,
}

fn images_alone() -> String {
    InterViewFlow::Images.name().into()
}

fn no_edge_method() -> String {
    EdgeMethod::None.name().into()
}

/// What happened to one pose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseReport {
    /// The pose.
    pub pose: u32,
    /// Settings it was ingested with.
    pub settings: Settings,
    /// Whether this run found it finished and skipped it.
    #[serde(skip_deserializing)]
    pub resumed: bool,
    /// Time per step.
    pub steps: Vec<Step>,
    /// Errors against the truth, when there is one.
    pub errors: Option<PoseErrors>,
}

/// The result of an ingest (`frf ingest --report`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct IngestReport {
    /// The capture directory.
    pub capture: String,
    /// Settings.
    pub settings: Settings,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Views per pose.
    pub views: usize,
    /// Time per step, summed over poses.
    pub steps: Vec<Step>,
    /// Mean over poses of the per-pose figures (null without truth).
    pub alpha_iou: Option<f64>,
    /// See [`PoseErrors::alpha_mae`].
    pub alpha_mae: Option<f64>,
    /// See [`PoseErrors::registration_psnr`].
    pub registration_psnr: Option<f64>,
    /// See [`PoseErrors::unregistered_psnr`].
    pub unregistered_psnr: Option<f64>,
    /// See [`PoseErrors::flow_epe_horizontal`].
    pub flow_epe_horizontal: Option<f64>,
    /// See [`PoseErrors::flow_epe_vertical`].
    pub flow_epe_vertical: Option<f64>,
    /// See [`PoseErrors::pose_flow_epe`].
    #[serde(default)]
    pub pose_flow_epe: Option<f64>,
    /// See [`PoseErrors::pose_flow_motion`].
    #[serde(default)]
    pub pose_flow_motion: Option<f64>,
    /// See [`PoseErrors::hull_iou`].
    pub hull_iou: Option<f64>,
    /// See [`PoseErrors::edge_band_error_dark`].
    pub edge_band_error_dark: Option<f64>,
    /// See [`PoseErrors::edge_band_error_bright`].
    pub edge_band_error_bright: Option<f64>,
    /// See [`PoseErrors::edge_band_error_dark_raw`].
    pub edge_band_error_dark_raw: Option<f64>,
    /// See [`PoseErrors::edge_band_error_bright_raw`].
    pub edge_band_error_bright_raw: Option<f64>,
    /// Per pose.
    pub poses: Vec<PoseReport>,
    /// The field's size and compression.
    pub field: FieldStats,
    /// Wall-clock seconds of this run.
    pub seconds: f64,
}

/// The directory of per-pose parts of field `out`.
pub fn parts_dir(out: &Path) -> PathBuf {
    let mut name = out
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(".parts");
    out.with_file_name(name)
}

fn part_paths(out: &Path, pose: u32) -> (PathBuf, PathBuf) {
    let dir = parts_dir(out);
    (
        dir.join(format!("p{pose:02}.frf")),
        dir.join(format!("p{pose:02}.json")),
    )
}

fn settings(capture: &Capture, options: &IngestOptions) -> Settings {
    Settings {
        flow_preset: std::iter::once(options.flow_preset.name().to_string())
            .chain(
                options
                    .flow_settings
                    .iter()
                    .map(|(k, v)| format!("{k}={v}")),
            )
            .collect::<Vec<_>>()
            .join(" "),
        jpeg_quality: options.jpeg_quality,
        predict_flow: options.predict_flow,
        matte_rule: format!("{:?}", options.matte_rule),
        shadows: options.shadows.map_or_else(
            || "none".to_string(),
            |s| {
                let voxel = s
                    .hull_voxel_m
                    .map_or("half a pixel".into(), |v| format!("{v} m"));
                format!(
                    "hull {voxel}, {} misses; ground {} texels over {} m, {} samples per light",
                    s.hull_misses, s.ground.texels, s.ground.extent_m, s.light_samples
                )
            },
        ),
        edge: options.edge.name().into(),
        pose_flows: options.pose_flows,
        pose_flows_among: match options.pose_flows {
            true => pose_flow_poses(capture, options),
            false => Vec::new(),
        },
        inter_view_flow: options.inter_view_flow.name().into(),
        selection: options
            .selection
            .as_ref()
            .map_or(String::new(), Selection::describe),
    }
}

/// The poses among which a pose's flows to the next and the previous pose are measured:
/// those this run ingests when it ingests several (the field's consecutive poses, between
/// which a shot morphs), the capture's when it ingests one (a part of a field to be
/// merged from one-pose parts, whose poses are the capture's). Sorted.
pub fn pose_flow_poses(capture: &Capture, options: &IngestOptions) -> Vec<u32> {
    let mut poses = match options.poses.len() {
        0 | 1 => capture.poses().to_vec(),
        _ => options.poses.clone(),
    };
    poses.sort_unstable();
    poses.dedup();
    poses
}

/// A finished part of this pose made with these settings, if there is one.
fn finished_part(out: &Path, pose: u32, wanted: &Settings) -> Result<Option<PoseReport>> {
    let (part, json) = part_paths(out, pose);
    if !(part.exists() && json.exists()) {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&json).map_err(|e| frf_core::CoreError::io(&json, e))?;
    let mut report: PoseReport = serde_json::from_str(&text)
        .map_err(|e| frf_core::CoreError::bad_file(&json, format!("not a pose report: {e}")))?;
    if &report.settings != wanted {
        return Err(IngestError::SettingsChanged {
            part,
            pose,
            was: format!("{:?}", report.settings),
            wanted: format!("{wanted:?}"),
            parts: parts_dir(out),
        });
    }
    FieldFile::open(&part)?;
    report.resumed = true;
    Ok(Some(report))
}

/// Wall time of a parallel phase shared among its steps by thread time.
fn share(phase_wall: f64, steps: &[(&str, f64)]) -> Vec<Step> {
    let total: f64 = steps.iter().map(|s| s.1).sum();
    steps
        .iter()
        .map(|(name, t)| Step {
            name: name.to_string(),
            seconds: if total > 0.0 {
                phase_wall * t / total
            } else {
                0.0
            },
        })
        .collect()
}

/// A view's flows to its grid neighbours ([`frf_core::grid::Neighbour::ALL`] order).
type ViewFlows = [Option<FlowImage>; 4];
/// A view's flows to the next and previous pose ([`frf_core::grid::PoseStep::ALL`] order).
type ViewPoseFlows = [Option<FlowImage>; 2];

struct ViewOut {
    images: EncodedView,
    alpha: GrayImage,
    summed: RgbImage,
    seconds: ViewSeconds,
    encode_seconds: f64,
    registered: Option<SampledView>,
}

fn ingest_pose(
    capture: &Capture,
    pose: u32,
    out: &Path,
    options: &IngestOptions,
    evaluator: Option<&dyn Evaluator>,
    progress: &dyn Progress,
) -> Result<PoseReport> {
    let (columns, rows) = (capture.cycles(), capture.cameras().len());
    let params = options.flow_params()?;
    let mut steps = Vec::new();

    let start = Instant::now();
    let clean = clean_plates(capture)?;
    steps.push(Step {
        name: "load clean plates".into(),
        seconds: start.elapsed().as_secs_f64(),
    });

    let mut header = pose_header(capture, pose, options)?;
    header.description = format!(
        "ingested from {} with flow {}, inter-view flow {}",
        capture.dir().display(),
        settings(capture, options).flow_preset,
        options.inter_view_flow.name()
    );

    let selected = options.selection.as_ref();
    let present = views_present(capture, pose, selected)?;
    let views = views_step(
        capture,
        pose,
        (&header, &present, &clean),
        (options, &params, evaluator),
        progress,
        &mut steps,
    )?;

    let images: Vec<Option<&RgbImage>> = views
        .iter()
        .map(|v| v.as_ref().map(|v| &v.summed))
        .collect();
    let alphas: Vec<Option<&GrayImage>> =
        views.iter().map(|v| v.as_ref().map(|v| &v.alpha)).collect();
    let cameras: Vec<Camera> = (0..columns * rows)
        .map(|i| capture.subject_camera(i / rows, i % rows, pose))
        .collect();
    let guide = match options.inter_view_flow {
        InterViewFlow::Hull => {
            guide_step(pose, options, (&cameras, &alphas), progress, &mut steps)?
        }
        InterViewFlow::Images => None,
    };
    progress.begin(pose, "inter-view flow", columns * rows);
    let start = Instant::now();
    let grid = grid_flows(
        &GridViews {
            columns,
            rows,
            wraps: header.wraps,
            images: &images,
            alphas: &alphas,
            cameras: &cameras,
            wanted: selected
                .and_then(|s| s.flows.get(&pose))
                .map(|f| f.as_slice()),
            hull: guide.as_ref(),
        },
        &params,
        &|| {
            check_stop(progress)?;
            progress.advance();
            Ok(())
        },
    )?;
    steps.extend(share(
        start.elapsed().as_secs_f64(),
        &[
            ("inter-view flow, horizontal pairs", grid.horizontal_seconds),
            ("inter-view flow, vertical pairs", grid.vertical_seconds),
        ],
    ));
    let flows = grid.flows;

    let among = pose_flow_poses(capture, options);
    let pose_flows = match options.pose_flows {
        true => pose_flow_step(
            capture,
            (pose, &among),
            (&header, &alphas, guide.as_ref()),
            (&clean, options.matte_rule, &params),
            progress,
            &mut steps,
        )?,
        false => vec![Default::default(); columns * rows],
    };

    let shadows = match &options.shadows {
        Some(s) => Some(shadow_step(
            pose,
            (&cameras, &alphas),
            (&header, s),
            progress,
            &mut steps,
        )?),
        None => None,
    };

    let start = Instant::now();
    if options.pose_flows {
        header.record_pose_flows(pose, &among)?;
    }
    let (part, json) = part_paths(out, pose);
    write_part(
        &part,
        (header, pose),
        &views,
        &flows,
        &pose_flows,
        shadows.as_ref(),
    )?;
    steps.push(Step {
        name: "compress flows and write".into(),
        seconds: start.elapsed().as_secs_f64(),
    });

    let errors = match evaluator {
        Some(evaluator) => Some(evaluate_step(
            evaluator,
            (pose, views),
            (&flows, &pose_flows, &among),
            shadows.as_ref(),
            progress,
        )?),
        None => None,
    };
    let report = PoseReport {
        pose,
        settings: settings(capture, options),
        resumed: false,
        steps,
        errors,
    };
    let text = serde_json::to_string_pretty(&report)
        .map_err(|e| IngestError::Internal(format!("a pose report as JSON: {e}")))?;
    frf_core::atomic::write_bytes_atomic(&json, text.as_bytes())?;
    Ok(report)
}

/// Every camera's clean plates, by slot.
fn clean_plates(capture: &Capture) -> Result<Vec<Vec<RgbImage>>> {
    Ok((0..capture.cameras().len())
        .map(|v| {
            (0..capture.slots().len())
                .map(|s| capture.load_clean_plate(v, s))
                .collect()
        })
        .collect::<frf_core::Result<_>>()?)
}

/// Per view of `pose` (`u`-major), whether it is ingested: filmed, and selected; refused
/// when none is.
fn views_present(capture: &Capture, pose: u32, selected: Option<&Selection>) -> Result<Vec<bool>> {
    let rows = capture.cameras().len();
    let present: Vec<bool> = (0..capture.cycles() * rows)
        .map(|i| {
            capture.is_filmed(pose, i / rows, i % rows)
                && selected.is_none_or(|s| s.views.get(&pose).is_some_and(|v| v[i]))
        })
        .collect();
    if !present.iter().any(|&p| p) {
        return Err(IngestError::Degenerate(format!(
            "pose {pose}: no view of it is both filmed and selected"
        )));
    }
    Ok(present)
}

/// Every view of `pose` that `present` marks matted, registered and its basis images
/// encoded with `header`'s codecs (in parallel), timed into `steps`.
fn views_step(
    capture: &Capture,
    pose: u32,
    (header, present, clean): (&FieldHeader, &[bool], &[Vec<RgbImage>]),
    (options, params, evaluator): (&IngestOptions, &FlowParams, Option<&dyn Evaluator>),
    progress: &dyn Progress,
    steps: &mut Vec<Step>,
) -> Result<Vec<Option<ViewOut>>> {
    let rows = capture.cameras().len();
    progress.begin(
        pose,
        "mattes and registration",
        present.iter().filter(|&&p| p).count(),
    );
    let start = Instant::now();
    let views: Vec<Option<ViewOut>> = (0..present.len())
        .into_par_iter()
        .map(|i| {
            if !present[i] {
                return Ok(None);
            }
            check_stop(progress)?;
            let (u, v) = (i / rows, i % rows);
            let settings = ViewSettings {
                flow: *params,
                matte_rule: options.matte_rule,
                keep_unregistered: evaluator.is_some_and(|e| e.wants_unregistered(u, v)),
                edge: options.edge,
            };
            let r = process_view(capture, pose, u, v, &clean[v], &settings)?;
            let t = Instant::now();
            let images = encode_images(header, &r.basis, &r.alpha)?;
            progress.advance();
            Ok(Some(ViewOut {
                images,
                encode_seconds: t.elapsed().as_secs_f64(),
                registered: r.kept.map(|k| SampledView {
                    u,
                    v,
                    basis: r.basis,
                    unregistered: k.unregistered,
                    raw_basis: k.raw_basis,
                    raw_alpha: k.raw_alpha,
                }),
                alpha: r.alpha,
                summed: r.summed,
                seconds: r.seconds,
            }))
        })
        .collect::<Result<_>>()?;
    let mut seconds = ViewSeconds::default();
    for v in views.iter().flatten() {
        seconds += v.seconds;
    }
    let encode: f64 = views.iter().flatten().map(|v| v.encode_seconds).sum();
    steps.extend(share(
        start.elapsed().as_secs_f64(),
        &[
            ("load frames", seconds.load),
            ("mattes", seconds.matte),
            ("registration flow", seconds.registration_flow),
            ("registration warp and matte", seconds.registration_warp),
            ("compress basis images", encode),
        ],
    ));

    Ok(views)
}

/// The errors of pose `pose` against the ground truth, from what ingest computed.
fn evaluate_step(
    evaluator: &dyn Evaluator,
    (pose, views): (u32, Vec<Option<ViewOut>>),
    (flows, pose_flows, among): (&[ViewFlows], &[ViewPoseFlows], &[u32]),
    shadows: Option<&PoseShadows>,
    progress: &dyn Progress,
) -> Result<PoseErrors> {
    progress.begin(pose, "evaluation against the ground truth", 1);
    let alphas: Vec<Option<GrayImage>> = views
        .iter()
        .map(|v| v.as_ref().map(|v| v.alpha.clone()))
        .collect();
    let registered: Vec<SampledView> = views
        .into_iter()
        .flatten()
        .filter_map(|v| v.registered)
        .collect();
    let e = evaluator
        .evaluate(
            pose,
            &PoseEvidence {
                alphas: &alphas,
                flows,
                pose_flows,
                pose_flows_among: among,
                registered: &registered,
                hull: shadows.map(|s| &s.hull),
            },
        )
        .map_err(IngestError::Evaluation)?;
    progress.advance();
    Ok(e)
}

/// The hull that guides `pose`'s inter-view flows ([`flow_guide`]), timed into `steps`.
fn guide_step(
    pose: u32,
    options: &IngestOptions,
    (cameras, alphas): (&[Camera], &[Option<&GrayImage>]),
    progress: &dyn Progress,
    steps: &mut Vec<Step>,
) -> Result<Option<VoxelHull>> {
    progress.begin(pose, "hull of the flows", 1);
    let start = Instant::now();
    let hull = flow_guide(options, cameras, alphas)?;
    steps.push(Step {
        name: "hull of the flows".into(),
        seconds: start.elapsed().as_secs_f64(),
    });
    progress.advance();
    Ok(hull)
}

/// The pose-to-pose flows of every view of `pose` to its neighbours among `among`
/// ([`crate::poseflow::pose_flows`]), timed into `steps`.
fn pose_flow_step(
    capture: &Capture,
    (pose, among): (u32, &[u32]),
    (header, alphas, guide): (&FieldHeader, &[Option<&GrayImage>], Option<&VoxelHull>),
    (clean, rule, params): (&[Vec<RgbImage>], MatteRule, &FlowParams),
    progress: &dyn Progress,
    steps: &mut Vec<Step>,
) -> Result<Vec<ViewPoseFlows>> {
    progress.begin(
        pose,
        "pose-to-pose flow",
        alphas.iter().filter(|a| a.is_some()).count(),
    );
    let start = Instant::now();
    let pose_flows = crate::poseflow::pose_flows(
        capture,
        (pose, among),
        header.wraps,
        alphas,
        guide,
        clean,
        rule,
        params,
        &|| {
            check_stop(progress)?;
            progress.advance();
            Ok(())
        },
    )?;
    steps.push(Step {
        name: "pose-to-pose flow".into(),
        seconds: start.elapsed().as_secs_f64(),
    });
    Ok(pose_flows)
}

/// The cameras and mattes of the views ingested (those `alphas` holds).
fn ingested_views<'a>(
    cameras: &[Camera],
    alphas: &[Option<&'a GrayImage>],
) -> (Vec<Camera>, Vec<&'a GrayImage>) {
    cameras
        .iter()
        .zip(alphas)
        .filter_map(|(c, a)| a.map(|a| (*c, a)))
        .unzip()
}

/// The visual hull and shadow maps of `pose`, carved from the views ingested, timed into
/// `steps`.
fn shadow_step(
    pose: u32,
    (cameras, alphas): (&[Camera], &[Option<&GrayImage>]),
    (header, options): (&FieldHeader, &ShadowOptions),
    progress: &dyn Progress,
    steps: &mut Vec<Step>,
) -> Result<PoseShadows> {
    progress.begin(pose, "visual hull and shadow maps", 1);
    let (cams, mattes) = ingested_views(cameras, alphas);
    // The header's, which every part of the field agrees on.
    let mut hull = header.hulls.unwrap_or_else(|| options.hull(cameras));
    hull.misses = crate::shadows::misses_for(hull.misses, cams.len(), cameras.len());
    let r = pose_shadows(&cams, &mattes, &header.conditions, hull, options)?;
    steps.push(Step {
        name: "visual hull".into(),
        seconds: r.hull_seconds,
    });
    steps.push(Step {
        name: "shadow maps".into(),
        seconds: r.map_seconds,
    });
    progress.advance();
    Ok(r)
}

/// Writes pose `pose`'s part to `part`: its views' images, their flows and pose-to-pose
/// flows under a quantizer fitted to both, its hull and shadow maps.
fn write_part(
    part: &Path,
    (mut header, pose): (FieldHeader, u32),
    views: &[Option<ViewOut>],
    flows: &[ViewFlows],
    pose_flows: &[ViewPoseFlows],
    shadows: Option<&PoseShadows>,
) -> Result<()> {
    let rows = header.rows;
    header.pose_mut(pose)?.flow_quantizer = LogQuantizer::fit(
        flows
            .iter()
            .flat_map(|f| f.iter().flatten())
            .chain(pose_flows.iter().flat_map(|f| f.iter().flatten()))
            .flat_map(|f| f.pixels().iter().flatten().copied()),
    );
    let encoded: Vec<EncodedView> = flows
        .par_iter()
        .zip(pose_flows)
        .map(|(f, p)| {
            let mut e = encode_flows(&header, pose, f)?;
            e.extend(encode_pose_flows(&header, pose, p)?);
            Ok(e)
        })
        .collect::<Result<_>>()?;
    let mut writer = FieldWriter::create(part, header)?;
    for (i, (view, flow)) in views.iter().zip(&encoded).enumerate() {
        if let Some(view) = view {
            writer.add_view(pose, i / rows, i % rows, &view.images)?;
            writer.add_view(pose, i / rows, i % rows, flow)?;
        }
    }
    if let Some(s) = shadows {
        writer.add_hull(pose, &s.hull)?;
        writer.add_shadows(pose, &s.maps)?;
    }
    writer.finish()?;
    Ok(())
}

/// The header of the field of pose `pose` ingested with `options`: the capture's, with
/// the options' codecs, hulls and shadow maps (the pose's flow quantizer is fitted once
/// its flows are known).
pub fn pose_header(capture: &Capture, pose: u32, options: &IngestOptions) -> Result<FieldHeader> {
    let mut header = FieldHeader::from_capture(
        capture,
        &[pose],
        LogQuantizer::new(1.0, 1.0)?,
        options.jpeg_quality,
    )?;
    header.flow_predicted = options.predict_flow;
    header.shadows = options.shadows.map(|s| s.spec(&header.conditions));
    header.hulls = options.shadows.map(|s| s.hull(capture.cameras()));
    Ok(header)
}

/// The hull a pose's inter-view flows are guided by (`None` when `options` do not ask
/// for one, or nothing survives the carve): carved from the views ingested (`cameras`
/// and `alphas` of the whole grid, `None` for a view not ingested), allowing the views
/// of the shadow hull's tolerance to disagree, in proportion to the views there are.
pub fn flow_guide(
    options: &IngestOptions,
    cameras: &[Camera],
    alphas: &[Option<&GrayImage>],
) -> Result<Option<frf_reflectance::hull::VoxelHull>> {
    if options.inter_view_flow != InterViewFlow::Hull {
        return Ok(None);
    }
    let (cams, mattes) = ingested_views(cameras, alphas);
    let asked = options
        .shadows
        .map_or(crate::shadows::DEFAULT_MISSES, |s| s.hull_misses);
    let misses = crate::shadows::misses_for(asked, cams.len(), cameras.len());
    flow_hull(&cams, &mattes, misses)
}

/// Ingests the capture in `capture_dir` into the field file `out`; each pose is judged by
/// `evaluator` when there is one (a capture with a ground truth).
pub fn ingest(
    capture_dir: &Path,
    out: &Path,
    options: &IngestOptions,
    evaluator: Option<&dyn Evaluator>,
    progress: &dyn Progress,
) -> Result<IngestReport> {
    let start = Instant::now();
    let capture = Capture::open(capture_dir)?;
    let poses = if options.poses.is_empty() {
        capture.poses().to_vec()
    } else {
        options.poses.clone()
    };
    if let Some(p) = poses.iter().find(|p| !capture.poses().contains(p)) {
        return Err(frf_reflectance::ReflectanceError::NoSuchPose {
            file: Some(capture.dir().to_path_buf()),
            within: "capture",
            pose: *p,
            held: frf_reflectance::field::listed(capture.poses()),
        }
        .into());
    }
    options.validate()?;
    let wanted = settings(&capture, options);
    let mut reports = Vec::new();
    for &pose in &poses {
        let report = match finished_part(out, pose, &wanted)? {
            Some(r) => r,
            None => ingest_pose(&capture, pose, out, options, evaluator, progress)?,
        };
        reports.push(report);
    }
    let parts: Vec<PathBuf> = poses.iter().map(|&p| part_paths(out, p).0).collect();
    merge_fields(&parts, out)?;
    let field = FieldFile::open(out)?.stats();
    let _ = std::fs::remove_dir_all(parts_dir(out));

    let mut steps: Vec<Step> = Vec::new();
    for r in reports.iter().filter(|r| !r.resumed) {
        for s in &r.steps {
            match steps.iter_mut().find(|t| t.name == s.name) {
                Some(t) => t.seconds += s.seconds,
                None => steps.push(s.clone()),
            }
        }
    }
    let mean = |f: fn(&PoseErrors) -> Option<f64>| {
        let values: Vec<f64> = reports
            .iter()
            .filter_map(|r| r.errors.as_ref().and_then(f))
            .collect();
        (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
    };
    Ok(IngestReport {
        capture: capture_dir.display().to_string(),
        settings: wanted,
        width: capture.cameras()[0].width,
        height: capture.cameras()[0].height,
        views: capture.cycles() * capture.cameras().len(),
        steps,
        alpha_iou: mean(|e| e.alpha_iou),
        alpha_mae: mean(|e| Some(e.alpha_mae)),
        registration_psnr: mean(|e| e.registration_psnr),
        unregistered_psnr: mean(|e| e.unregistered_psnr),
        flow_epe_horizontal: mean(|e| e.flow_epe_horizontal),
        flow_epe_vertical: mean(|e| e.flow_epe_vertical),
        pose_flow_epe: mean(|e| e.pose_flow_epe),
        pose_flow_motion: mean(|e| e.pose_flow_motion),
        hull_iou: mean(|e| e.hull_iou),
        edge_band_error_dark: mean(|e| e.edge_band_error_dark),
        edge_band_error_bright: mean(|e| e.edge_band_error_bright),
        edge_band_error_dark_raw: mean(|e| e.edge_band_error_dark_raw),
        edge_band_error_bright_raw: mean(|e| e.edge_band_error_bright_raw),
        poses: reports,
        field,
        seconds: start.elapsed().as_secs_f64(),
    })
}
