//! Rendering judged against the virtual light stage's truth: for virtual cameras between
//! the grid's views, the stage renders the true image and alpha of the pose under the
//! same environment (median-cut lights, subject frame), and each interpolation variant
//! is scored by PSNR and SSIM on the subject and on the whole frame, alpha error, and
//! the seconds it took per frame.
//!
//! The cameras sit at the centre of grid quads (`β = γ = ½`): on the cylinder of camera
//! centres, as far from every captured view as the grid allows, with orientation and
//! intrinsics interpolated as the renderer does ([`interpolate_camera`]).
//! The truth shows the unperturbed walker at the pose's instant, while each captured view
//! shows that cycle's perturbed walker (docs/design.md section 5.2): captures with perturbation 0
//! isolate the interpolation error.

use std::path::PathBuf;
use std::time::Instant;

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgba};
use frf_core::io::rgba_from;
use frf_core::light::DirLight;
use frf_render::cpu::FrameStats;
use frf_render::cylinder::interpolate_camera;
use frf_render::geometry::PoseGeometry;
use frf_render::morph::Variant;
use frf_render::renderer::Renderer;
use frf_stage::Stage;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{EvalError, Result};
use crate::metrics::{alpha_mae, alpha_of, max_row_jump, psnr, ssim, subject_mask};
use frf_core::progress::Progress;

/// The scores of one frame.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FrameScore {
    /// Which camera.
    pub camera: String,
    /// PSNR (dB) where either alpha is at least ½.
    pub psnr_subject: f64,
    /// SSIM of luminance there.
    pub ssim_subject: f64,
    /// PSNR (dB) over the whole frame (premultiplied colour on black).
    pub psnr_frame: f64,
    /// SSIM over the whole frame.
    pub ssim_frame: f64,
    /// Mean absolute alpha error over the frame.
    pub alpha_mae: f64,
    /// Share of the frame's pixels whose rays passed above or below the grid's rows.
    pub clamped_share: f64,
    /// The largest jump between neighbouring rows of the subject ([`max_row_jump`]).
    pub max_row_jump: f64,
    /// Seconds to render the frame (after a warm-up frame).
    pub seconds: f64,
}

/// One variant: means over the frames, and the frames.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct VariantScore {
    /// `nearest`, `linear`, `twoway` or `fourway`.
    pub name: String,
    /// Mean of the frames' subject PSNR, dB.
    pub psnr_subject: f64,
    /// Mean subject SSIM.
    pub ssim_subject: f64,
    /// Mean frame PSNR, dB.
    pub psnr_frame: f64,
    /// Mean frame SSIM.
    pub ssim_frame: f64,
    /// Mean alpha error.
    pub alpha_mae: f64,
    /// Mean share of pixels clamped to a row.
    pub clamped_share: f64,
    /// Mean seconds per frame.
    pub seconds_per_frame: f64,
    /// Each frame.
    pub frames: Vec<FrameScore>,
}

/// What every report of renders against the truth begins with: what was rendered, from
/// which capture's truth, under which environment, on which device.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ReportHeader {
    /// The field.
    pub field: PathBuf,
    /// The capture whose stage gave the truth.
    pub capture: PathBuf,
    /// The environment.
    pub env: String,
    /// The pose.
    pub pose: u32,
    /// The renderer's device.
    pub device: String,
    /// Median-cut lights of the truth.
    pub truth_lights: usize,
    /// Seconds per true frame (CPU).
    pub truth_seconds_per_frame: f64,
}

/// A camera to evaluate at, named.
#[derive(Debug, Clone)]
pub struct EvalCamera {
    /// Name in reports.
    pub name: String,
    /// The camera (subject frame).
    pub camera: Camera,
    /// The captured view `(u, v)` it is, if it is one.
    pub view: Option<(usize, usize)>,
}

/// The first corners `(u, v)` of `count` grid quads, spread over the columns and
/// alternating over the row gaps; refuses a grid without quads and absurd counts.
pub(crate) fn quad_corners(geometry: &PoseGeometry, count: usize) -> Result<Vec<(usize, usize)>> {
    let (columns, rows, wraps) = (geometry.columns, geometry.rows, geometry.wraps);
    let quads_u = if wraps {
        columns
    } else {
        columns.saturating_sub(1)
    };
    if quads_u == 0 || geometry.cameras.len() != columns * rows {
        return Err(EvalError::NoTruth(format!(
            "a {columns}x{rows} grid has no quad between views"
        )));
    }
    if count == 0 || count > quads_u * rows.max(2) {
        let allowed = format!("1 to {} cameras between views", quads_u * rows.max(2));
        return Err(frf_core::BadArgument::new("--cameras", count, allowed).into());
    }
    let gaps = rows.saturating_sub(1).max(1);
    Ok((0..count)
        .map(|k| ((k * quads_u) / count, k % gaps))
        .collect())
}

/// `count` cameras at the centres of grid quads of a pose, spread over the columns and
/// alternating over the row gaps.
pub fn between_view_cameras(geometry: &PoseGeometry, count: usize) -> Result<Vec<EvalCamera>> {
    Ok(quad_corners(geometry, count)?
        .into_iter()
        .map(|(u, v)| {
            let at = |u: usize, v: usize| &geometry.cameras[geometry.view(u, v)];
            let quad = [at(u, v), at(u + 1, v), at(u, v + 1), at(u + 1, v + 1)];
            let centre = quad.iter().map(|c| c.centre()).sum::<glam::Vec3>() / 4.0;
            EvalCamera {
                name: format!("u {u}.5, v {v}.5"),
                camera: interpolate_camera(quad, 0.5, 0.5, centre),
                view: None,
            }
        })
        .collect())
}

/// The captured cameras at the first corner of the quads of [`between_view_cameras`]:
/// rendering there involves no interpolation, so their error is that of relighting
/// through the basis and of storage alone, the floor under the variants' error.
pub fn grid_view_cameras(geometry: &PoseGeometry, count: usize) -> Result<Vec<EvalCamera>> {
    Ok(quad_corners(geometry, count)?
        .into_iter()
        .map(|(u, v)| EvalCamera {
            name: format!("u {u}, v {v}"),
            camera: geometry.cameras[geometry.view(u, v)],
            view: Some((u, v)),
        })
        .collect())
}

/// The stage's true frame of `pose` from `camera` under `lights`, as premultiplied RGBA.
pub fn truth_frame(
    stage: &Stage,
    pose: u32,
    camera: &Camera,
    lights: &[DirLight],
) -> Result<Image<Rgba>> {
    let t = stage.truth_image(pose, camera, lights);
    Ok(rgba_from(&t.color, &t.alpha)?)
}

/// The stage's true frames of `cameras` (in parallel, one progress step each) and the
/// seconds they took together.
pub fn truth_frames(
    stage: &Stage,
    pose: u32,
    cameras: &[Camera],
    lights: &[DirLight],
    progress: &dyn Progress,
) -> Result<(Vec<Image<Rgba>>, f64)> {
    let start = Instant::now();
    let frames = cameras
        .par_iter()
        .map(|c| {
            let t = truth_frame(stage, pose, c, lights);
            progress.step();
            t
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((frames, start.elapsed().as_secs_f64()))
}

/// The header of the variants' table ([`table_row`]).
pub const TABLE_HEADER: &str = "variant                 PSNR subject  SSIM subject  PSNR frame  \
                                SSIM frame  alpha MAE  clamped  s/frame";

/// One row of the variants' table.
pub fn table_row(s: &VariantScore) -> String {
    format!(
        "{:<21} {:>11.2} dB {:>13.4} {:>8.2} dB {:>11.4} {:>10.4} {:>7.1}% {:>8.4}",
        s.name,
        s.psnr_subject,
        s.ssim_subject,
        s.psnr_frame,
        s.ssim_frame,
        s.alpha_mae,
        100.0 * s.clamped_share,
        s.seconds_per_frame
    )
}

/// Scores `test` against `truth`; `stats` says how its pixels were re-binned.
pub fn score(
    camera: &str,
    truth: &Image<Rgba>,
    test: &Image<Rgba>,
    stats: &FrameStats,
    seconds: f64,
) -> FrameScore {
    let mask = subject_mask(truth, test);
    let pixels = (test.width() * test.height()).max(1) as f64;
    FrameScore {
        camera: camera.to_string(),
        psnr_subject: psnr(truth, test, Some(&mask)),
        ssim_subject: ssim(truth, test, Some(&mask)),
        psnr_frame: psnr(truth, test, None),
        ssim_frame: ssim(truth, test, None),
        alpha_mae: alpha_mae(&alpha_of(truth), &alpha_of(test)),
        clamped_share: (stats.clamped_above + stats.clamped_below) as f64 / pixels,
        max_row_jump: max_row_jump(test),
        seconds,
    }
}

/// What [`evaluate`] calls with each frame: camera index, variant, the frame.
pub type OnFrame<'a> = dyn FnMut(usize, Variant, &Image<Rgba>) -> Result<()> + 'a;

/// Renders every camera with every variant and scores them against `truths` (one per
/// camera); `on_frame(camera index, variant, frame)` sees each frame once scored (to show
/// progress or keep it).
pub fn evaluate(
    renderer: &Renderer,
    cameras: &[EvalCamera],
    truths: &[Image<Rgba>],
    variants: &[Variant],
    on_frame: &mut OnFrame,
) -> Result<Vec<VariantScore>> {
    // One untimed frame first: pipeline compilation and caches.
    if let Some(c) = cameras.first() {
        renderer.render(&c.camera, Variant::FourWay)?;
    }
    variants
        .iter()
        .map(|&variant| {
            let frames = cameras
                .iter()
                .zip(truths)
                .enumerate()
                .map(|(i, (c, truth))| {
                    let t = Instant::now();
                    let (img, stats) = renderer.render(&c.camera, variant)?;
                    let seconds = t.elapsed().as_secs_f64();
                    let scored = score(&c.name, truth, &img, &stats, seconds);
                    on_frame(i, variant, &img)?;
                    Ok(scored)
                })
                .collect::<Result<Vec<_>>>()?;
            let n = frames.len().max(1) as f64;
            let mean = |f: &dyn Fn(&FrameScore) -> f64| frames.iter().map(f).sum::<f64>() / n;
            Ok(VariantScore {
                name: variant.name().to_string(),
                psnr_subject: mean(&|f| f.psnr_subject),
                ssim_subject: mean(&|f| f.ssim_subject),
                psnr_frame: mean(&|f| f.psnr_frame),
                ssim_frame: mean(&|f| f.ssim_frame),
                alpha_mae: mean(&|f| f.alpha_mae),
                clamped_share: mean(&|f| f.clamped_share),
                seconds_per_frame: mean(&|f| f.seconds),
                frames,
            })
        })
        .collect()
}
