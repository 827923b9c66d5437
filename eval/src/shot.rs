//! A scene's shot judged frame by frame against the virtual stage's truth: the frame the
//! renderer draws (walker, shadow and backdrop) against the true composite of the same
//! camera, time and lighting.
//!
//! The truth of a frame: the stage's true walker in the pose the plan draws, seen by the
//! frame's camera (moved into the walker's frame), lit by the frame's environment reduced
//! to median-cut lights; its true shadow traced against the true body; both composited
//! over the frame's own backdrop by the product's compositing
//! ([`frf_render::composite::compose`]), so that only the walker and its shadow differ.
//! Scenes of one walker only: the stage films one person.

use std::time::Instant;

use frf_reflectance::container::ReadAt;
use frf_render::composite::compose;
use frf_render::scene::plan::ShotFrame;
use frf_render::scene::shot::Shot;
use frf_stage::Stage;
use frf_stage::ground::relative_irradiance;
use serde::Serialize;

use crate::error::{EvalError, Result};
use crate::metrics::{psnr, ssim, subject_mask};
use crate::views::truth_frame;

/// One frame of a shot against its truth.
#[derive(Debug, Clone, Serialize)]
pub struct ShotFrameScore {
    /// Index in the shot.
    pub index: usize,
    /// Seconds into the shot.
    pub time: f32,
    /// The pose drawn.
    pub pose: u32,
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
) -> Result<ShotFrameScore> {
    let scene = shot.scene();
    if scene.instances.len() != 1 {
        return Err(EvalError::BadParameter(format!(
            "a scene of {} walkers: the stage's truth has one",
            scene.instances.len()
        )));
    }
    let instance = scene.instances[0];
    let world = shot.lighting_at(frame.time)?.ok_or_else(|| {
        EvalError::BadParameter("an unlit scene has no true lighting to compare with".into())
    })?;
    let backdrop = shot.backdrop_of(Some(&world))?;

    let t = Instant::now();
    let rendered = shot.render(frame, true)?;
    let seconds_render = t.elapsed().as_secs_f64();
    let pose = rendered.poses[0];
    let layers = rendered
        .frame
        .layers
        .ok_or_else(|| EvalError::BadParameter("the renderer returned no layers".into()))?;

    // The truth, in the walker's frame: its camera and its lighting.
    let t = Instant::now();
    let subject_camera = instance.camera_in_subject_frame(&frame.camera);
    let lights = world.rotated(-instance.heading).median_cut(lights);
    let subject = truth_frame(stage, pose, &subject_camera, &lights)?;
    let actor = stage.true_actor(pose);
    let subject_from_world = instance.world_from_subject().inverse();
    let shadow =
        |p: glam::Vec3| relative_irradiance(&actor, &lights, subject_from_world.transform_point(p));
    let (truth, _) = compose(subject.clone(), &frame.camera, &backdrop, &shadow)?;
    let seconds_truth = t.elapsed().as_secs_f64();

    let mask = subject_mask(&subject, &layers.subject);
    Ok(ShotFrameScore {
        index: frame.index,
        time: frame.time,
        pose,
        psnr_frame: psnr(&truth, &rendered.frame.composite, None),
        psnr_subject: psnr(&subject, &layers.subject, Some(&mask)),
        ssim_subject: ssim(&subject, &layers.subject, Some(&mask)),
        seconds_render,
        seconds_truth,
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
