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
use frf_core::capture::Capture;
use frf_core::grid::Neighbour;
use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_core::progress::Progress;
use frf_ingest::interview::{GridViews, grid_flows};
use frf_ingest::pipeline::{IngestOptions, flow_guide, pose_header};
use frf_ingest::shadows::{PoseShadows, pose_shadows};
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::store::encode_flows;
use frf_reflectance::{FieldHeader, FieldWriter};
use frf_stage::Stage;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::Component;
use super::variants::{BudgetCapture, Images, ViewVariants, view_variants};
use crate::error::{EvalError, Result};

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

/// The fields in `dir`, when they were made as `made` says (the same capture, pose,
/// settings and files) and are all there.
fn reused(dir: &Path, made: &FieldsMade) -> Option<FieldsMade> {
    let text = std::fs::read_to_string(dir.join(MADE_FILE)).ok()?;
    let found: FieldsMade = serde_json::from_str(&text).ok()?;
    let same = FieldsMade {
        seconds: made.seconds,
        ..found.clone()
    } == *made;
    (same && found.fields.iter().all(|(_, f)| dir.join(f).exists())).then_some(found)
}

/// The capture in `capture_dir`, if it filmed every view of `pose`.
fn filmed(capture_dir: &Path, pose: u32) -> Result<Capture> {
    let capture = Capture::open(capture_dir)?;
    if !capture.poses().contains(&pose) {
        return Err(frf_reflectance::ReflectanceError::NoSuchPose {
            file: Some(capture_dir.to_path_buf()),
            within: "capture",
            pose,
            held: frf_reflectance::field::listed(capture.poses()),
        }
        .into());
    }
    let (columns, rows) = (capture.cycles(), capture.cameras().len());
    if let Some(i) = (0..columns * rows).find(|&i| !capture.is_filmed(pose, i / rows, i % rows)) {
        return Err(EvalError::NoTruth(format!(
            "{}: view ({}, {}) of pose {pose} was not filmed; the ingest budget needs every view",
            capture_dir.display(),
            i / rows,
            i % rows
        )));
    }
    Ok(capture)
}

/// The header of the budget's fields: the capture's, as ingest writes it, at the ingest's
/// JPEG quality and at the codec's best.
fn headers(
    capture: &Capture,
    pose: u32,
    options: &IngestOptions,
) -> Result<(FieldHeader, FieldHeader)> {
    let header = pose_header(capture, pose, options)?;
    let lossless = FieldHeader {
        jpeg_quality: LOSSLESS_JPEG_QUALITY,
        ..header.clone()
    };
    Ok((header, lossless))
}

/// Everything the components' fields are made of, once per view or pose.
struct Made<'a> {
    views: Vec<ViewVariants>,
    /// Per view, the estimated flows to the neighbours.
    flows: Vec<[Option<FlowImage>; 4]>,
    /// The hull and shadow maps carved from the estimated mattes, and from the true.
    shadows: (Option<PoseShadows>, Option<PoseShadows>),
    headers: (FieldHeader, FieldHeader),
    rows: usize,
    pose: u32,
    /// Where the fields came from, for their descriptions.
    capture: &'a Path,
}

impl Made<'_> {
    /// Writes `component`'s field to `path`.
    fn write(&self, component: Component, path: &Path) -> Result<()> {
        let (images, true_h, true_v) = recipe(component);
        let flows: Vec<[Option<&FlowImage>; 4]> = self
            .views
            .iter()
            .zip(&self.flows)
            .map(|(view, estimated)| {
                Neighbour::ALL.map(|n| {
                    let horizontal = matches!(n, Neighbour::Left | Neighbour::Right);
                    if (horizontal && true_h) || (!horizontal && true_v) {
                        view.true_flows[n.index()].as_ref()
                    } else {
                        estimated[n.index()].as_ref()
                    }
                })
            })
            .collect();
        let mut h = if images == Images::IngestedLossless {
            self.headers.1.clone()
        } else {
            self.headers.0.clone()
        };
        h.description = format!(
            "ingest budget of {}, pose {}: {}",
            self.capture.display(),
            self.pose,
            component.what()
        );
        h.pose_mut(self.pose)?.flow_quantizer = LogQuantizer::fit(
            flows
                .iter()
                .flatten()
                .flatten()
                .flat_map(|f| f.pixels().iter().flatten().copied()),
        );
        let mut writer = FieldWriter::create(path, h.clone())?;
        for (i, (view, flows)) in self.views.iter().zip(&flows).enumerate() {
            let mut e = view.encoded[images.index()].clone();
            e.extend(encode_flows(&h, self.pose, &flows.map(|f| f.cloned()))?);
            writer.add_view(self.pose, i / self.rows, i % self.rows, &e)?;
        }
        let shadows = if images.true_alpha() {
            &self.shadows.1
        } else {
            &self.shadows.0
        };
        if let Some(s) = shadows {
            writer.add_hull(self.pose, &s.hull)?;
            writer.add_shadows(self.pose, &s.maps)?;
        }
        writer.finish()?;
        Ok(())
    }
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
    // The fields are scored against the unperturbed walker: on a capture whose cycles
    // differ, even the oracle field scores below the renderer's floor and the shares come
    // out negative.
    let perturbation = stage.config().perturbation;
    if perturbation != 0.0 {
        return Err(frf_core::BadArgument::new(
            "--capture",
            capture_dir.display(),
            format!(
                "for the ingest budget, a capture whose walk cycles repeat exactly (`frf stage \
                 --perturbation 0`); this one was filmed with perturbation {perturbation} (its \
                 stage.toml)"
            ),
        )
        .into());
    }
    options.validate()?;
    let made = FieldsMade {
        capture: capture_dir.display().to_string(),
        pose,
        settings: describe(options),
        fields: Component::ALL
            .iter()
            .map(|&c| (c, format!("{}.frf", c.name())))
            .collect(),
        seconds: 0.0,
    };
    let paths = |m: &FieldsMade| m.fields.iter().map(|(c, f)| (*c, dir.join(f))).collect();
    if let Some(found) = reused(dir, &made) {
        progress.note(&format!(
            "ingest budget: reusing the fields in {} (made in {:.0} s)",
            dir.display(),
            found.seconds
        ));
        return Ok(paths(&found));
    }
    let start = std::time::Instant::now();
    let capture = filmed(capture_dir, pose)?;
    std::fs::create_dir_all(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
    let (columns, rows) = (capture.cycles(), capture.cameras().len());
    let at = BudgetCapture::new(&capture, stage, pose, options)?;
    let (header, lossless) = headers(&capture, pose, options)?;
    progress.phase(
        "ingest budget: views ingested, and with each component true",
        columns * rows,
    );
    let views: Vec<ViewVariants> = (0..columns * rows)
        .into_par_iter()
        .map(|i| {
            let view = view_variants(&at, (i / rows, i % rows), (&header, &lossless));
            progress.step();
            view
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
    let grid = GridViews {
        columns,
        rows,
        wraps: header.wraps,
        images: &images,
        alphas: &alphas,
        cameras: &cameras,
        wanted: None,
        hull: guide.as_ref(),
    };
    let step = || {
        progress.step();
        Ok(())
    };
    let flows = grid_flows(&grid, &at.params, &step)?.flows;
    progress.finish();

    let carve = |mattes: Vec<&GrayImage>| -> Result<Option<PoseShadows>> {
        options
            .shadows
            .map(|s| {
                Ok(pose_shadows(
                    &cameras,
                    &mattes,
                    &header.conditions,
                    s.hull(capture.cameras()),
                    &s,
                )?)
            })
            .transpose()
    };
    let shadows = (
        carve(views.iter().map(|v| &v.alpha).collect())?,
        carve(views.iter().map(|v| &v.true_alpha).collect())?,
    );
    let all = Made {
        views,
        flows,
        shadows,
        headers: (header, lossless),
        rows,
        pose,
        capture: capture_dir,
    };
    progress.phase("ingest budget: fields written", made.fields.len());
    for (component, path) in paths(&made) {
        all.write(component, &path)?;
        progress.step();
    }
    progress.finish();
    let made = FieldsMade {
        seconds: start.elapsed().as_secs_f64(),
        ..made
    };
    let text = serde_json::to_string_pretty(&made)
        .map_err(|e| EvalError::Misuse(format!("the budget's record as JSON: {e}")))?;
    frf_core::atomic::write_bytes_atomic(&dir.join(MADE_FILE), text.as_bytes())?;
    Ok(paths(&made))
}
