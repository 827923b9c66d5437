//! The fields of the ingest budget: one pose of a stage capture ingested as `frf ingest`
//! does, and again with one component at a time taken from the stage's truth
//! ([`Component`]), each written as a field file of its own.
//!
//! Every view is processed once: its set is matted, its motion measured and its basis
//! frames registered by ingest's own steps ([`frf_ingest::views`]); the same steps then
//! run again with one input replaced (the true alpha, the true motion of each frame, the
//! frames as the lens forms them, before the sensor's noise, quantization and clipping), and the oracle view ([`crate::oracle::oracle_view`])
//! gives the true basis images and flows. Each variant's images are encoded at once, so
//! that only compressed views are held; the flows are measured once over the grid, as
//! ingest measures them, and stored with each field's own quantizer.

use std::path::{Path, PathBuf};

use frf_core::camera::Camera;
use frf_core::capture::{Capture, SlotKind};
use frf_core::filter::extend_nearest;
use frf_core::grid::Neighbour;
use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_core::progress::Progress;
use frf_ingest::interview::{GridViews, grid_flows};
use frf_ingest::pipeline::{IngestOptions, flow_guide};
use frf_ingest::shadows::{PoseShadows, pose_shadows};
use frf_ingest::views::{SetFrames, SetRegistration, load_set, register_basis, register_set};
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::store::{EncodedView, encode_flows, encode_images};
use frf_reflectance::{FieldHeader, FieldWriter};
use frf_stage::Stage;
use frf_stage::truth::flow_between;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::Component;
use crate::error::{EvalError, Result};
use crate::oracle::oracle_view;

/// Which images a field holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Images {
    /// As ingested.
    Ingested,
    /// As ingested, encoded at JPEG quality 100.
    IngestedLossless,
    /// Registered and matted with the true alpha (and the true alpha stored).
    TrueMattes,
    /// Registered by the true motion of each frame.
    TrueMotion,
    /// Registered from frames as the lens forms them (no sensor).
    NoSensor,
    /// Registered by the true motion from frames as the lens forms them, matted with the
    /// true alpha (and the true alpha stored).
    TrueSteps,
    /// The true basis images, with the estimated alpha.
    TrueBasis,
    /// The true basis images and alpha (the oracle's).
    Oracle,
}

impl Images {
    const ALL: [Images; 8] = [
        Images::Ingested,
        Images::IngestedLossless,
        Images::TrueMattes,
        Images::TrueMotion,
        Images::NoSensor,
        Images::TrueSteps,
        Images::TrueBasis,
        Images::Oracle,
    ];

    fn index(self) -> usize {
        Self::ALL
            .iter()
            .position(|&i| i == self)
            .expect("every variant is listed")
    }
}

/// What a component's field is made of: its images, and whether its horizontal and its
/// vertical flows are the true ones.
fn recipe(c: Component) -> (Images, bool, bool) {
    match c {
        Component::Ingested => (Images::Ingested, false, false),
        Component::Mattes => (Images::TrueMattes, false, false),
        Component::Registration => (Images::TrueMotion, false, false),
        Component::Sensor => (Images::NoSensor, false, false),
        Component::Steps => (Images::TrueSteps, false, false),
        Component::BasisImages => (Images::TrueBasis, false, false),
        Component::HorizontalFlows => (Images::Ingested, true, false),
        Component::VerticalFlows => (Images::Ingested, false, true),
        Component::Codecs => (Images::IngestedLossless, false, false),
        Component::Oracle => (Images::Oracle, true, true),
    }
}

/// JPEG quality of the [`Component::Codecs`] field: the codec's best, so what remains of
/// its loss is the 8-bit sRGB storage every field shares (and the flows' 8-bit
/// logarithmic codes, which the renderer reads as they are).
const LOSSLESS_JPEG_QUALITY: u8 = 100;

/// What the fields in a directory were made from, checked before they are reused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FieldsMade {
    /// The capture.
    pub capture: String,
    /// The pose.
    pub pose: u32,
    /// The ingest settings ([`describe`]).
    pub settings: String,
    /// Components, with their files' names.
    pub fields: Vec<(Component, String)>,
    /// Wall seconds it took to make them.
    pub seconds: f64,
}

/// The file `dir` keeps [`FieldsMade`] in.
pub const MADE_FILE: &str = "ingest-budget.json";

/// The ingest settings in a line (what a reused directory must have been made with).
pub fn describe(options: &IngestOptions) -> String {
    format!(
        "flow {} {:?}, inter-view {}; JPEG {}; predicted flow {}; matte {:?}; edge {}; shadows {:?}",
        options.flow_preset.name(),
        options.flow_settings,
        options.inter_view_flow.name(),
        options.jpeg_quality,
        options.predict_flow,
        options.matte_rule,
        options.edge.name(),
        options.shadows
    )
}

/// One view's encoded images, per [`Images`] variant, and what the grid's steps need.
struct ViewOut {
    encoded: Vec<EncodedView>,
    summed: RgbImage,
    alpha: GrayImage,
    true_alpha: GrayImage,
    true_flows: [Option<FlowImage>; 4],
}

/// The fields of every component of pose `pose` of the capture in `capture_dir` (written
/// by `stage`), made with `options` and written to `dir` (created); a directory that
/// already holds them, made from the same capture, pose and settings, is reused. Returns
/// each component's field.
pub fn write_fields(
    stage: &Stage,
    capture_dir: &Path,
    pose: u32,
    options: &IngestOptions,
    dir: &Path,
    progress: &dyn Progress,
) -> Result<Vec<(Component, PathBuf)>> {
    options.validate()?;
    let settings = describe(options);
    let made_path = dir.join(MADE_FILE);
    let made = FieldsMade {
        capture: capture_dir.display().to_string(),
        pose,
        settings: settings.clone(),
        fields: Component::ALL
            .iter()
            .map(|&c| (c, format!("{}.frf", c.name())))
            .collect(),
        seconds: 0.0,
    };
    if let Ok(text) = std::fs::read_to_string(&made_path)
        && let Ok(found) = serde_json::from_str::<FieldsMade>(&text)
        && (FieldsMade {
            seconds: 0.0,
            ..found.clone()
        }) == made
        && found.fields.iter().all(|(_, f)| dir.join(f).exists())
    {
        progress.note(&format!(
            "ingest budget: reusing the fields in {} (made in {:.0} s)",
            dir.display(),
            found.seconds
        ));
        return Ok(found
            .fields
            .into_iter()
            .map(|(c, f)| (c, dir.join(f)))
            .collect());
    }
    let start = std::time::Instant::now();
    std::fs::create_dir_all(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
    let capture = Capture::open(capture_dir)?;
    if !capture.poses().contains(&pose) {
        return Err(EvalError::BadParameter(format!(
            "{}: pose {pose} was not filmed (the capture has {:?})",
            capture_dir.display(),
            capture.poses()
        )));
    }
    let (columns, rows) = (capture.cycles(), capture.cameras().len());
    if let Some(i) = (0..columns * rows).find(|&i| !capture.is_filmed(pose, i / rows, i % rows)) {
        return Err(EvalError::BadParameter(format!(
            "{}: view ({}, {}) of pose {pose} was not filmed; the ingest budget needs every view",
            capture_dir.display(),
            i / rows,
            i % rows
        )));
    }
    let params = options.flow_params()?;
    let slots = capture.slots().len();
    let is_basis = |s: usize| matches!(capture.slots()[s].kind, SlotKind::Basis(_));
    let clean: Vec<Vec<RgbImage>> = (0..rows)
        .map(|v| {
            (0..slots)
                .map(|s| Ok(capture.load_clean_plate(v, s)?))
                .collect::<Result<_>>()
        })
        .collect::<Result<_>>()?;
    let quiet_clean: Vec<Vec<RgbImage>> = (0..rows)
        .map(|v| {
            (0..slots)
                .map(|s| {
                    if is_basis(s) {
                        Ok(stage.render_clean_plate(v, s)?)
                    } else {
                        Ok(clean[v][s].clone())
                    }
                })
                .collect::<Result<_>>()
        })
        .collect::<Result<_>>()?;
    let mut header = FieldHeader::from_capture(
        &capture,
        &[pose],
        LogQuantizer::new(1.0, 1.0)?,
        options.jpeg_quality,
    )?;
    header.flow_predicted = options.predict_flow;
    header.shadows = options.shadows.map(|s| s.spec(&header.conditions));
    header.hulls = options.shadows.map(|s| s.hull);
    let lossless = FieldHeader {
        jpeg_quality: LOSSLESS_JPEG_QUALITY,
        ..header.clone()
    };

    progress.phase(
        "ingest budget: views ingested, and with each component true",
        columns * rows,
    );
    let views: Vec<ViewOut> = (0..columns * rows)
        .into_par_iter()
        .map(|i| {
            let (u, v) = (i / rows, i % rows);
            let frames = load_set(&capture, pose, u, v)?;
            let set = SetFrames {
                capture: &capture,
                frames: &frames,
                clean: &clean[v],
            };
            let SetRegistration { mattes, motion, .. } =
                register_set(&set, options.matte_rule, options.edge, &params)?;
            let estimated = |slot: usize| Ok(motion.at(set.offset_s(slot)));
            let register = |set: &SetFrames, alpha: &GrayImage, raw: &GrayImage, edge, motion| {
                register_basis(set, alpha, raw, edge, motion, false)
            };
            let (a, raw) = (&mattes.alpha, &mattes.raw_alpha);
            let ingested = register(&set, a, raw, options.edge, &estimated)?;

            let (surface, true_alpha) = stage.reference_surface(pose, u, v)?;
            let mattes_true = register(
                &set,
                &true_alpha,
                &true_alpha,
                frf_ingest::edges::EdgeMethod::None,
                &estimated,
            )?;
            // The true motion of every basis frame: where each point of the reference
            // frame is at the frame's instant.
            let true_motion: Vec<Option<FlowImage>> = (0..slots)
                .map(|s| {
                    if !is_basis(s) {
                        return Ok(None);
                    }
                    let offset = frf_stage::rig::slot_time_offset_s(s);
                    let to = stage.view_setup(pose, u, v, offset)?;
                    Ok(Some(filled(flow_between(&surface, &to).flow)))
                })
                .collect::<Result<_>>()?;
            let true_motion =
                |slot: usize| Ok(true_motion[slot].clone().expect("a basis slot's motion"));
            let motion_true = register(&set, a, raw, options.edge, &true_motion)?;
            let quiet_frames: Vec<RgbImage> = (0..slots)
                .map(|s| {
                    if is_basis(s) {
                        Ok(stage.render_frame(pose, u, v, s)?.color)
                    } else {
                        Ok(frames[s].clone())
                    }
                })
                .collect::<Result<_>>()?;
            let quiet_set = SetFrames {
                capture: &capture,
                frames: &quiet_frames,
                clean: &quiet_clean[v],
            };
            let no_sensor = register(&quiet_set, a, raw, options.edge, &estimated)?;
            let steps = register(
                &quiet_set,
                &true_alpha,
                &true_alpha,
                frf_ingest::edges::EdgeMethod::None,
                &true_motion,
            )?;
            let oracle = oracle_view(stage, pose, u, v)?;

            let encoded = Images::ALL
                .iter()
                .map(|&k| {
                    let (h, basis, alpha) = match k {
                        Images::Ingested => (&header, &ingested.basis, a),
                        Images::IngestedLossless => (&lossless, &ingested.basis, a),
                        Images::TrueMattes => (&header, &mattes_true.basis, &true_alpha),
                        Images::TrueMotion => (&header, &motion_true.basis, a),
                        Images::NoSensor => (&header, &no_sensor.basis, a),
                        Images::TrueSteps => (&header, &steps.basis, &true_alpha),
                        Images::TrueBasis => (&header, &oracle.basis, a),
                        Images::Oracle => (&header, &oracle.basis, &oracle.alpha),
                    };
                    Ok(encode_images(h, basis, alpha)?)
                })
                .collect::<Result<Vec<_>>>()?;
            progress.step();
            Ok(ViewOut {
                encoded,
                summed: ingested.summed,
                alpha: mattes.alpha,
                true_alpha,
                true_flows: oracle.flows,
            })
        })
        .collect::<Result<_>>()?;
    progress.finish();

    progress.phase("ingest budget: inter-view flow", columns * rows);
    let images: Vec<Option<&RgbImage>> = views.iter().map(|v| Some(&v.summed)).collect();
    let alphas: Vec<Option<&GrayImage>> = views.iter().map(|v| Some(&v.alpha)).collect();
    let cameras: Vec<Camera> = (0..columns * rows)
        .map(|i| capture.subject_camera(i / rows, i % rows, pose))
        .collect();
    let guide = flow_guide(options, &cameras, &alphas)?;
    let estimated_flows = grid_flows(
        &GridViews {
            columns,
            rows,
            wraps: header.wraps,
            images: &images,
            alphas: &alphas,
            cameras: &cameras,
            wanted: None,
            hull: guide.as_ref(),
        },
        &params,
        &|| {
            progress.step();
            Ok(())
        },
    )?
    .flows;
    progress.finish();

    // Hulls and shadow maps from the estimated and from the true mattes.
    let carve = |mattes: Vec<&GrayImage>| -> Result<Option<PoseShadows>> {
        options
            .shadows
            .map(|s| Ok(pose_shadows(&cameras, &mattes, &header.conditions, &s)?))
            .transpose()
    };
    let shadows_estimated = carve(views.iter().map(|v| &v.alpha).collect())?;
    let shadows_true = carve(views.iter().map(|v| &v.true_alpha).collect())?;

    progress.phase("ingest budget: fields written", Component::ALL.len());
    let mut out = Vec::new();
    for (component, file) in &made.fields {
        let (images, true_h, true_v) = recipe(*component);
        let flows: Vec<[Option<&FlowImage>; 4]> = views
            .iter()
            .zip(&estimated_flows)
            .map(|(view, estimated)| {
                Neighbour::ALL.map(|n| {
                    let horizontal = matches!(n, Neighbour::Left | Neighbour::Right);
                    let truth = if horizontal { true_h } else { true_v };
                    if truth {
                        view.true_flows[n.index()].as_ref()
                    } else {
                        estimated[n.index()].as_ref()
                    }
                })
            })
            .collect();
        let mut h = if images == Images::IngestedLossless {
            lossless.clone()
        } else {
            header.clone()
        };
        h.description = format!(
            "ingest budget of {}, pose {pose}: {}",
            capture_dir.display(),
            component.what()
        );
        h.pose_mut(pose)?.flow_quantizer = LogQuantizer::fit(
            flows
                .iter()
                .flatten()
                .flatten()
                .flat_map(|f| f.pixels().iter().flatten().copied()),
        );
        let path = dir.join(file);
        let mut writer = FieldWriter::create(&path, h.clone())?;
        for (i, (view, flows)) in views.iter().zip(&flows).enumerate() {
            let mut e = view.encoded[images.index()].clone();
            e.extend(encode_flows(&h, pose, &flows.map(|f| f.cloned()))?);
            writer.add_view(pose, i / rows, i % rows, &e)?;
        }
        let shadows = if matches!(
            images,
            Images::TrueMattes | Images::TrueSteps | Images::Oracle
        ) {
            &shadows_true
        } else {
            &shadows_estimated
        };
        if let Some(s) = shadows {
            writer.add_hull(pose, &s.hull)?;
            writer.add_shadows(pose, &s.maps)?;
        }
        writer.finish()?;
        progress.step();
        out.push((*component, path));
    }
    progress.finish();
    let made = FieldsMade {
        seconds: start.elapsed().as_secs_f64(),
        ..made
    };
    let text = serde_json::to_string_pretty(&made)
        .map_err(|e| EvalError::BadParameter(format!("the budget's record: {e}")))?;
    frf_core::atomic::write_bytes_atomic(&made_path, text.as_bytes())?;
    Ok(out)
}

/// A true motion field with its unknown pixels (where the reference pixel sees no part
/// of the walker) given the nearest known motion, so that a silhouette pixel whose
/// centre misses the walker moves with the limb it partly covers; with nothing known,
/// no motion.
fn filled(mut flow: FlowImage) -> FlowImage {
    let (w, h) = flow.size();
    let pixels = flow.pixels_mut();
    extend_nearest(pixels, w, h, |f| frf_core::flo::is_known(*f));
    for p in pixels.iter_mut() {
        if !frf_core::flo::is_known(*p) {
            *p = [0.0; 2];
        }
    }
    flow
}
