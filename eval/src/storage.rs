//! Evaluations of the storage and relighting against the virtual stage's ground truth:
//!
//! - [`projection_error`]: how far relighting a view's (perfect) basis images with an
//!   environment's projection is from the true image of that view under the environment
//!   itself. This is the error of representing the environment by 26 conditions, before
//!   any compression or interpolation.
//! - [`codec_curve`]: compression ratio of the basis images against 16-bit linear RGB,
//!   and the relit PSNR it costs, over JPEG quality.

use std::time::Instant;

use frf_core::env::EnvMap;
use frf_core::image::RgbImage;
use frf_core::light::DirLight;
use frf_reflectance::imagecodec::{decode_basis, encode_basis};
use frf_reflectance::project::{FloorModel, Projector};
use frf_reflectance::relight::relight;
use frf_stage::Stage;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{EvalError, Result};
use crate::metrics::{ImageError, alpha_mask, compare};
use crate::oracle::oracle_view;

/// The stage's basis as field conditions (what a projector needs).
pub fn stage_projector(stage: &Stage) -> Result<Projector> {
    let capture =
        frf_core::capture::Capture::from_manifest(std::path::Path::new("."), stage.manifest())?;
    let header = frf_reflectance::FieldHeader::from_capture(
        &capture,
        &stage.config().poses[..1],
        frf_reflectance::flowcodec::quant::LogQuantizer::new(1.0, 1.0)?,
        90,
    )?;
    Ok(Projector::new(&header.conditions)?)
}

/// Turntable angle of view column `u` of `pose`.
fn view_angle(stage: &Stage, pose: u32, u: usize) -> f32 {
    stage.turntable_angle(u, stage.pose_time_s(pose))
}

/// The environment's lights (median cut, subject frame) as the dome frame of view column
/// `u` sees them: turned by `+θ`.
pub fn env_lights_for_view(
    stage: &Stage,
    lights: &[DirLight],
    pose: u32,
    u: usize,
) -> Vec<DirLight> {
    let r = glam::Mat3::from_rotation_y(view_angle(stage, pose, u));
    lights.iter().map(|l| l.rotated(r)).collect()
}

/// The basis-projection error of one view under one environment.
#[derive(Debug, Clone, Serialize)]
pub struct ProjectionError {
    /// The view `(u, v)`.
    pub view: (usize, usize),
    /// PSNR over the subject (alpha ≥ 0.5), dB, peak = the truth's brightest value there.
    pub psnr_subject_db: f64,
    /// Mean absolute error over the subject relative to the truth's mean.
    pub relative_mae: f64,
}

/// Relights the true basis images of view `(u, v)` of `pose` with the projection of
/// `env` and compares with the true image under `env` (reduced to `lights` median-cut
/// lights), over the subject.
pub fn projection_error(
    stage: &Stage,
    projector: &Projector,
    env: &EnvMap,
    lights: usize,
    floor: FloorModel,
    pose: u32,
    views: &[(usize, usize)],
) -> Result<Vec<ProjectionError>> {
    let env_lights = env.median_cut(lights);
    views
        .par_iter()
        .map(|&(u, v)| {
            let truth = stage.true_view_image(
                pose,
                u,
                v,
                &env_lights_for_view(stage, &env_lights, pose, u),
            )?;
            let basis = oracle_view(stage, pose, u, v)?.basis;
            let coefficients = projector.project(env, view_angle(stage, pose, u), floor);
            let relit = relight(&basis, &coefficients)?;
            let e = compare(&truth.color, &relit, Some(&alpha_mask(&truth.alpha)));
            Ok(ProjectionError {
                view: (u, v),
                psnr_subject_db: e.psnr_db,
                relative_mae: e.relative_mae,
            })
        })
        .collect()
}

/// One point of the compression curve (`frf stage codec-curve --json`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CodecPoint {
    /// JPEG quality.
    pub quality: u8,
    /// 16-bit linear RGB size of the basis images divided by the coded size.
    pub ratio_vs_16bit: f64,
    /// Worst relit PSNR over the views (subject, dB), relit with the environment.
    pub min_relit_psnr_db: f64,
    /// Mean relit PSNR over the views (subject, dB).
    pub mean_relit_psnr_db: f64,
    /// Seconds to encode and decode one view's mosaic.
    pub seconds_per_view: f64,
}

/// A view's uncompressed basis, its relit reference, alpha and coefficients.
struct PreparedView {
    basis: Vec<RgbImage>,
    reference: RgbImage,
    subject: Vec<bool>,
    coefficients: Vec<[f32; 3]>,
}

/// Compression ratio and relit PSNR of the basis mosaic over JPEG `qualities`, on the
/// oracle basis images of `views` of `pose`, relit with `env`.
pub fn codec_curve(
    stage: &Stage,
    env: &EnvMap,
    pose: u32,
    views: &[(usize, usize)],
    qualities: &[u8],
) -> Result<Vec<CodecPoint>> {
    if views.is_empty() || qualities.is_empty() {
        return Err(EvalError::Misuse(
            "codec curve needs views and qualities".into(),
        ));
    }
    let projector = stage_projector(stage)?;
    let prepared: Vec<PreparedView> = views
        .par_iter()
        .map(|&(u, v)| {
            let view = oracle_view(stage, pose, u, v)?;
            let coefficients =
                projector.project(env, view_angle(stage, pose, u), FloorModel::Environment);
            let reference = relight(&view.basis, &coefficients)?;
            Ok(PreparedView {
                basis: view.basis,
                reference,
                subject: alpha_mask(&view.alpha),
                coefficients,
            })
        })
        .collect::<Result<_>>()?;
    qualities
        .iter()
        .map(|&quality| {
            let start = Instant::now();
            let results: Vec<(usize, ImageError)> = prepared
                .iter()
                .map(|p| {
                    let bytes = encode_basis(&p.basis, quality)?;
                    let decoded = decode_basis(&bytes)?;
                    let relit = relight(&decoded, &p.coefficients)?;
                    Ok((bytes.len(), compare(&p.reference, &relit, Some(&p.subject))))
                })
                .collect::<Result<_>>()?;
            let seconds = start.elapsed().as_secs_f64() / prepared.len() as f64;
            let raw: usize = prepared
                .iter()
                .map(|p| p.basis.len() * p.basis[0].pixels().len() * 6)
                .sum();
            let coded: usize = results.iter().map(|r| r.0).sum();
            let psnrs: Vec<f64> = results.iter().map(|r| r.1.psnr_db).collect();
            Ok(CodecPoint {
                quality,
                ratio_vs_16bit: raw as f64 / coded as f64,
                min_relit_psnr_db: psnrs.iter().copied().fold(f64::INFINITY, f64::min),
                mean_relit_psnr_db: psnrs.iter().sum::<f64>() / psnrs.len() as f64,
                seconds_per_view: seconds,
            })
        })
        .collect()
}

/// One flow quantizer measured on true flows ([`flow_quantization`]).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct QuantizationScore {
    /// Scale `s` of the log quantizer, pixels.
    pub scale: f32,
    /// Range `M`, pixels (the largest magnitude among the flows).
    pub range: f32,
    /// Mean end-point error the codes add to the true flow, pixels.
    pub epe: f64,
    /// Coded size per known vector, bits (Huffman-coded, left-predicted codes).
    pub bits_per_vector: f64,
    /// Encoding and decoding time per map, seconds.
    pub seconds_per_map: f64,
}

/// The error and size of storing `flows` (true flows, unknown pixels skipped) with a log
/// quantizer of scale `scale` (`None`: the scale ingest fits to them) and the flows' own
/// range: each map is encoded as a field stores it and decoded again.
pub fn flow_quantization(
    flows: &[frf_core::image::FlowImage],
    scale: Option<f32>,
) -> Result<QuantizationScore> {
    use frf_core::flo::is_known;
    use frf_reflectance::flowcodec::{self, quant::LogQuantizer};
    if flows.is_empty() {
        return Err(EvalError::Misuse("no flows to quantize".into()));
    }
    let values = || {
        flows.iter().flat_map(|f| {
            f.pixels()
                .iter()
                .filter(|v| is_known(**v))
                .flatten()
                .copied()
        })
    };
    let fitted = LogQuantizer::fit(values());
    let q = match scale {
        Some(s) => LogQuantizer::new(s, fitted.range)?,
        None => fitted,
    };
    let (mut sum, mut known, mut bytes) = (0.0f64, 0usize, 0usize);
    let start = Instant::now();
    for f in flows {
        let coded = flowcodec::encode(f, &q, true)?;
        let back = flowcodec::decode(&coded, &q)?;
        bytes += coded.len();
        for (t, b) in f.pixels().iter().zip(back.pixels()) {
            if is_known(*t) {
                sum += f64::from((t[0] - b[0]).hypot(t[1] - b[1]));
                known += 1;
            }
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    if known == 0 {
        return Err(EvalError::NoTruth("the flows hold no known vector".into()));
    }
    Ok(QuantizationScore {
        scale: q.scale,
        range: q.range,
        epe: sum / known as f64,
        bits_per_vector: bytes as f64 * 8.0 / known as f64,
        seconds_per_map: seconds / flows.len() as f64,
    })
}
/// Views used by the stage's storage measures: every ninth column, all cameras.
pub fn sample_views(stage: &Stage) -> Vec<(usize, usize)> {
    (0..stage.cycles())
        .step_by(9)
        .flat_map(|u| (0..stage.cameras().len()).map(move |v| (u, v)))
        .collect()
}

/// The basis-projection error under each of several environments (`frf stage
/// projection-error`): a row per environment over [`sample_views`] of the first pose.
pub struct ProjectionTable {
    /// The pose measured.
    pub pose: u32,
    /// Views per environment.
    pub views: usize,
    /// Per environment.
    pub rows: Vec<ProjectionRow>,
}

/// One environment's projection error.
#[derive(Debug, Clone, Serialize)]
pub struct ProjectionRow {
    /// Its name.
    pub env: String,
    /// Views measured.
    pub views: usize,
    /// Mean PSNR over the subject, dB.
    pub mean_psnr_subject_db: f64,
    /// Least PSNR of a view, dB.
    pub min_psnr_subject_db: f64,
    /// Mean relative absolute error.
    pub relative_mae: f64,
    /// Wall seconds.
    pub seconds: f64,
}

impl ProjectionTable {
    /// Measures the projection error of `stage`'s first pose under each named
    /// environment, its truth from `lights` median-cut lights, the floor as `floor`.
    pub fn measure(
        stage: &Stage,
        envs: &[(String, EnvMap)],
        lights: usize,
        floor: FloorModel,
    ) -> Result<Self> {
        let projector = stage_projector(stage)?;
        let views = sample_views(stage);
        let pose = stage.config().poses[0];
        let mut rows = Vec::new();
        for (name, env) in envs {
            let start = std::time::Instant::now();
            let errors = projection_error(stage, &projector, env, lights, floor, pose, &views)?;
            let n = errors.len() as f64;
            rows.push(ProjectionRow {
                env: name.clone(),
                views: errors.len(),
                mean_psnr_subject_db: errors.iter().map(|e| e.psnr_subject_db).sum::<f64>() / n,
                min_psnr_subject_db: errors
                    .iter()
                    .map(|e| e.psnr_subject_db)
                    .fold(f64::INFINITY, f64::min),
                relative_mae: errors.iter().map(|e| e.relative_mae).sum::<f64>() / n,
                seconds: start.elapsed().as_secs_f64(),
            });
        }
        Ok(Self {
            pose,
            views: views.len(),
            rows,
        })
    }

    /// The rows as JSON (pretty, keys in order).
    pub fn json(&self) -> String {
        serde_json::to_value(&self.rows)
            .and_then(|v| serde_json::to_string_pretty(&v))
            .unwrap_or_default()
    }

    /// The table for a person.
    pub fn text(&self) -> String {
        let mut out = format!(
            "basis-projection error: relit true basis images vs true image under the environment ({} views of pose {}, subject pixels, peak = brightest true value)\n",
            self.views, self.pose
        );
        out += &format!(
            "{:<24} {:>12} {:>12} {:>10} {:>9}\n",
            "environment", "mean PSNR dB", "min PSNR dB", "rel. MAE", "seconds"
        );
        for r in &self.rows {
            out += &format!(
                "{:<24} {:>12.2} {:>12.2} {:>9.2}% {:>9.1}\n",
                r.env,
                r.mean_psnr_subject_db,
                r.min_psnr_subject_db,
                100.0 * r.relative_mae,
                r.seconds
            );
        }
        out
    }
}

/// The codec curve (`frf stage codec-curve`) as a table for a person: relit under the
/// environment named `env`, over `views` views.
pub fn codec_table(curve: &[CodecPoint], env: &str, views: usize) -> String {
    let mut out = format!(
        "basis mosaic (gamma 2.2 JPEG) over quality: ratio against 16-bit linear RGB, and PSNR of the view relit under {env} against the uncompressed basis ({views} views, subject pixels)\n"
    );
    out += &format!(
        "{:>8} {:>14} {:>16} {:>16} {:>14}\n",
        "quality", "ratio (x:1)", "min PSNR (dB)", "mean PSNR (dB)", "ms per view"
    );
    for p in curve {
        out += &format!(
            "{:>8} {:>14.1} {:>16.2} {:>16.2} {:>14.1}\n",
            p.quality,
            p.ratio_vs_16bit,
            p.min_relit_psnr_db,
            p.mean_relit_psnr_db,
            1e3 * p.seconds_per_view
        );
    }
    out
}
