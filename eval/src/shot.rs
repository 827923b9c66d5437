//! A scene's shot judged frame by frame against the virtual stage's truth: the frame the
//! renderer draws (walker, shadow and backdrop) against the true composite of the same
//! camera, time and lighting.
//!
//! The truth of a frame: the stage's true walker at the frame's instant of its walk
//! ([`TruthAt::Instant`], the default: between two captured poses the walker is in
//! between, which a render of the nearest pose is not) or at the instant of the pose the
//! plan draws ([`TruthAt::Pose`]: the renderer's view error alone), seen by the frame's
//! camera (moved into the walker's frame), lit by the frame's environment reduced to
//! median-cut lights; its true shadow traced against the true body; both composited over
//! the frame's own backdrop by the product's compositing
//! ([`frf_render::composite::compose`]), so that only the walker and its shadow differ.
//! Scenes of one walker only: the stage films one person.

use std::path::PathBuf;
use std::time::Instant;

use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_render::composite::compose;
use frf_render::renderer::Device;
use frf_scene::Scene;
use frf_scene::plan::ShotFrame;
use frf_scene::shot::{Shot, ShotOptions};
use frf_stage::Stage;
use frf_stage::ground::relative_irradiance;
use serde::{Deserialize, Serialize};

use crate::error::{EvalError, Result};
use crate::metrics::{psnr, ssim, subject_mask};
use frf_core::image::{Image, Rgba};
use frf_core::io::rgba_from;
use frf_core::progress::Progress;

/// Which instant of the walk a frame's truth shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TruthAt {
    /// The frame's own instant (what a viewer expects to see).
    Instant,
    /// The instant of the captured pose the frame draws (the view's error alone).
    Pose,
}

/// One frame of a shot against its truth.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShotFrameScore {
    /// Index in the shot.
    pub index: usize,
    /// Seconds into the shot.
    pub time: f64,
    /// The pose drawn (the earlier, between two).
    pub pose: u32,
    /// Between two poses: the later and the fraction of the way to it.
    pub between: Option<(u32, f32)>,
    /// The instant of the walk the truth shows, seconds into its cycle.
    pub truth_time_s: f64,
    /// How far the frame's instant is from the drawn pose's, seconds (wrapped to the
    /// nearest cycle; 0 when the truth is at the pose).
    pub time_from_pose_s: f64,
    /// PSNR of the whole frame (walker, shadow, backdrop) against the true composite, dB.
    pub psnr_frame: f64,
    /// PSNR of the walker layer where it or the truth covers the pixel, dB.
    pub psnr_subject: f64,
    /// SSIM of the walker layer over the same pixels.
    pub ssim_subject: f64,
    /// Seconds the renderer took for the frame (including making its pose resident).
    pub seconds_render: f64,
    /// Seconds the stage took for the true frame (CPU).
    pub seconds_truth: f64,
}

/// Scores `frame` of `shot` against the truth of `stage` under `lights` median-cut
/// lights of the frame's environment.
pub fn score_frame<R: ReadAt>(
    stage: &Stage,
    shot: &mut Shot<'_, R>,
    frame: &ShotFrame,
    lights: usize,
    truth_at: TruthAt,
) -> Result<ShotFrameScore> {
    Ok(score_frame_walkers(stage, shot, frame, lights, truth_at)?.0)
}

/// The rendered and the true walker of a frame (premultiplied RGBA).
type Walkers = (Image<Rgba>, Image<Rgba>);

/// [`score_frame`], with the frame's rendered and true walker.
fn score_frame_walkers<R: ReadAt>(
    stage: &Stage,
    shot: &mut Shot<'_, R>,
    frame: &ShotFrame,
    lights: usize,
    truth_at: TruthAt,
) -> Result<(ShotFrameScore, Walkers)> {
    let scene = shot.scene();
    if scene.instances.len() != 1 {
        return Err(EvalError::NoTruth(format!(
            "a scene of {} walkers: the stage's truth has one",
            scene.instances.len()
        )));
    }
    let placement = scene.placement(0, frame.time);
    let cycle = stage.config().gait.cycle_seconds();
    let instant = scene.phase_at(0, frame.time, &shot.plan().gait) * cycle;
    let world = shot.lighting_at(frame.time)?.ok_or_else(|| {
        EvalError::NoTruth("an unlit scene has no true lighting to compare with".into())
    })?;
    let backdrop = shot.backdrop_of(Some(&world))?;

    let t = Instant::now();
    let rendered = shot.render(frame, true)?;
    let seconds_render = t.elapsed().as_secs_f64();
    let pose = rendered.poses[0];
    let layers = rendered
        .frame
        .layers
        .ok_or_else(|| EvalError::Misuse("the renderer returned no layers".into()))?;

    // The truth, in the walker's frame: its camera and its lighting.
    let t = Instant::now();
    let subject_camera = placement.camera_in_subject_frame(&frame.camera);
    let lights = world.rotated(-placement.heading).median_cut(lights);
    let pose_time = stage.pose_time_s(pose);
    let truth_time_s = match truth_at {
        TruthAt::Pose => pose_time,
        TruthAt::Instant => instant,
    };
    let time_from_pose_s = {
        let d = (truth_time_s - pose_time).rem_euclid(cycle);
        let d = if d > 0.5 * cycle { d - cycle } else { d };
        // Rounding at a pose's own instant is no time at all (not -0.0 ms).
        if d.abs() < 1e-9 { 0.0 } else { d }
    };
    let truth = stage.truth_image_at(truth_time_s, &subject_camera, &lights);
    let subject = rgba_from(&truth.color, &truth.alpha)?;
    let actor = stage.true_actor_at(truth_time_s);
    let subject_from_world = placement.world_from_subject().inverse();
    let shadow =
        |p: glam::Vec3| relative_irradiance(&actor, &lights, subject_from_world.transform_point(p));
    let (truth, _) = compose(subject.clone(), &frame.camera, &backdrop, &shadow)?;
    let seconds_truth = t.elapsed().as_secs_f64();

    let mask = subject_mask(&subject, &layers.subject);
    let score = ShotFrameScore {
        index: frame.index,
        time: frame.time,
        pose,
        between: rendered.between[0],
        truth_time_s,
        time_from_pose_s,
        psnr_frame: psnr(&truth, &rendered.frame.composite, None),
        psnr_subject: psnr(&subject, &layers.subject, Some(&mask)),
        ssim_subject: ssim(&subject, &layers.subject, Some(&mask)),
        seconds_render,
        seconds_truth,
    };
    Ok((score, (layers.subject, subject)))
}

/// How the walker changes from frame to frame, against how the true walker does: over
/// the pairs of consecutive frames scored, the mean absolute change of its premultiplied
/// RGBA per pixel. A shot that steps from pose to pose changes by nothing, then by a
/// whole pose's step: its largest change is about twice the truth's.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct Steadiness {
    /// Pairs of consecutive frames compared.
    pub pairs: usize,
    /// The rendered walker's largest change between two consecutive frames.
    pub largest_change: f64,
    /// The true walker's largest change.
    pub truth_largest_change: f64,
    /// The first over the second (1: as steady as the truth).
    pub ratio: f64,
}

/// The mean absolute difference per pixel of two images (all channels summed).
fn change(a: &Image<Rgba>, b: &Image<Rgba>) -> f64 {
    let sum: f64 = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| {
            p.iter()
                .zip(q)
                .map(|(x, y)| (x - y).abs() as f64)
                .sum::<f64>()
        })
        .sum();
    sum / a.pixels().len().max(1) as f64
}

/// The steadiness of `frames` (scores and walkers, in shot order): `None` without two
/// consecutive frames.
fn steadiness(frames: &[(ShotFrameScore, Walkers)]) -> Option<Steadiness> {
    let (mut pairs, mut largest, mut truth_largest) = (0, 0.0f64, 0.0f64);
    for w in frames.windows(2) {
        let ((a, (ra, ta)), (b, (rb, tb))) = (&w[0], &w[1]);
        if b.index != a.index + 1 || ra.size() != rb.size() {
            continue;
        }
        pairs += 1;
        largest = largest.max(change(ra, rb));
        truth_largest = truth_largest.max(change(ta, tb));
    }
    (pairs > 0).then(|| Steadiness {
        pairs,
        largest_change: largest,
        truth_largest_change: truth_largest,
        ratio: largest / truth_largest.max(1e-12),
    })
}

/// Memory budget of the poses kept resident while scoring a shot, bytes (a few frames
/// only).
const BUDGET_BYTES: u64 = 4_000_000_000;

/// What `frf eval SCENE.toml --json` prints.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShotReport {
    /// The scene file.
    pub scene: PathBuf,
    /// The field rendered.
    pub field: PathBuf,
    /// The capture whose stage gave the truth.
    pub capture: PathBuf,
    /// The renderer's device.
    pub device: String,
    /// Median-cut lights of the truth.
    pub truth_lights: usize,
    /// Which instant the truth shows.
    pub truth_at: TruthAt,
    /// Frames of the shot.
    pub frames_total: usize,
    /// Each frame scored.
    pub frames: Vec<ShotFrameScore>,
    /// Mean PSNR of the whole frames, dB.
    pub psnr_frame_mean: f64,
    /// Mean PSNR of the walker, dB.
    pub psnr_subject_mean: f64,
    /// Mean SSIM of the walker.
    pub ssim_subject_mean: f64,
    /// Mean seconds to render a frame.
    pub seconds_render_mean: f64,
    /// Mean seconds for a true frame.
    pub seconds_truth_mean: f64,
    /// How the walker changes from frame to frame against the truth (consecutive frames
    /// only).
    pub steadiness: Option<Steadiness>,
    /// Seconds in all.
    pub seconds: f64,
}

/// Scores `count` frames spread over the shot of `scene` (rendered from `field`, which
/// `paths.1` names, on `device`) against the truth of `stage` under `lights` median-cut
/// lights; `paths` = (scene file, field, capture) for the report.
#[allow(clippy::too_many_arguments)]
pub fn evaluate_shot<R: ReadAt>(
    scene: &Scene,
    field: &FieldFile<R>,
    device: Device,
    stage: &Stage,
    count: usize,
    (lights, truth_at): (usize, TruthAt),
    paths: (PathBuf, PathBuf, PathBuf),
    progress: &dyn Progress,
) -> Result<ShotReport> {
    let start = Instant::now();
    let h = field.header();
    let size = scene.size.unwrap_or((h.width, h.height));
    let total = scene.frame_times().len();
    let frames: Vec<ShotFrame> = spread_frames(total, count)
        .into_iter()
        .map(|i| Ok(scene.shot_frames(i..i + 1, size)?[0]))
        .collect::<Result<_>>()?;
    let options = ShotOptions {
        memory_budget: BUDGET_BYTES,
        planned: true,
        traced_lights: lights,
        detail: None,
    };
    let mut shot = Shot::new(scene, field, device, &frames, options)?;
    for f in &shot.plan().frames {
        if let Some(p) = f.poses.iter().find(|p| !stage.config().poses.contains(p)) {
            return Err(EvalError::NoTruth(format!(
                "{}: frame {} draws pose {p}, which the capture did not film",
                paths.2.display(),
                f.index
            )));
        }
    }
    progress.phase("frames scored", frames.len());
    let mut scored = Vec::new();
    for f in &frames {
        scored.push(score_frame_walkers(stage, &mut shot, f, lights, truth_at)?);
        progress.step();
    }
    progress.finish();
    let steadiness = steadiness(&scored);
    let scores: Vec<ShotFrameScore> = scored.into_iter().map(|(s, _)| s).collect();
    let mean =
        |g: fn(&ShotFrameScore) -> f64| scores.iter().map(g).sum::<f64>() / scores.len() as f64;
    let (scene_path, field_path, capture) = paths;
    Ok(ShotReport {
        scene: scene_path,
        field: field_path,
        capture,
        device: shot.device(),
        truth_lights: lights,
        truth_at,
        frames_total: total,
        psnr_frame_mean: mean(|s| s.psnr_frame),
        psnr_subject_mean: mean(|s| s.psnr_subject),
        ssim_subject_mean: mean(|s| s.ssim_subject),
        seconds_render_mean: mean(|s| s.seconds_render),
        seconds_truth_mean: mean(|s| s.seconds_truth),
        frames: scores,
        steadiness,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// `count` frame indices spread evenly over a shot of `total` frames (first and last
/// included).
pub fn spread_frames(total: usize, count: usize) -> Vec<usize> {
    let count = count.clamp(1, total.max(1));
    if count == 1 {
        return vec![0];
    }
    let mut out: Vec<usize> = (0..count)
        .map(|k| (k * (total - 1) + (count - 1) / 2) / (count - 1))
        .collect();
    out.dedup();
    out
}

impl ShotReport {
    /// The report for a person: a line per frame and their means (`lights`: the truth's
    /// median-cut lights).
    pub fn describe(&self, lights: usize) -> String {
        let mut lines = Vec::new();
        lines.push(format!(
            "{}: {} of {} frames against the stage's truth ({} median-cut lights, the walker at {}), {}",
            self.scene.display(),
            self.frames.len(),
            self.frames_total,
            lights,
            match self.truth_at {
                TruthAt::Instant => "each frame's instant",
                TruthAt::Pose => "the instant of the pose drawn",
            },
            self.device
        ));
        lines.push("frame   time  pose  from pose  PSNR frame  PSNR walker  SSIM walker  render s  truth s".to_string());
        for s in &self.frames {
            // Between two poses: both, the earlier first.
            let pose = match s.between {
                Some((after, _)) => format!("{}-{after}", s.pose),
                None => s.pose.to_string(),
            };
            lines.push(format!(
                "{:>5} {:>6.2} {:>5} {:>7.1} ms {:>8.2} dB {:>9.2} dB {:>12.4} {:>9.3} {:>8.2}",
                s.index,
                s.time,
                pose,
                1e3 * s.time_from_pose_s,
                s.psnr_frame,
                s.psnr_subject,
                s.ssim_subject,
                s.seconds_render,
                s.seconds_truth
            ));
        }
        lines.push(format!(
            "mean: frame {:.2} dB, walker {:.2} dB (SSIM {:.4}); {:.3} s a frame rendered (first frames make their poses resident), {:.2} s a true frame",
            self.psnr_frame_mean,
            self.psnr_subject_mean,
            self.ssim_subject_mean,
            self.seconds_render_mean,
            self.seconds_truth_mean
        ));
        if let Some(m) = &self.steadiness {
            lines.push(format!(
                "motion: the walker's largest change between consecutive frames {:.5} (mean |ΔRGBA| a pixel), \
                 the truth's {:.5}: {:.2}x ({} pairs)",
                m.largest_change, m.truth_largest_change, m.ratio, m.pairs
            ));
        }
        lines.join("\n")
    }
}

#[cfg(test)]
mod tests {
    use super::spread_frames;

    #[test]
    fn spread_frames_cover_the_shot_without_repeats() {
        assert_eq!(spread_frames(20, 4), vec![0, 6, 13, 19]);
        assert_eq!(spread_frames(3, 10), vec![0, 1, 2]);
        assert_eq!(spread_frames(1, 3), vec![0]);
        assert_eq!(spread_frames(10, 1), vec![0]);
    }
}
