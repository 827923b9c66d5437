//! `frf eval SCENE.toml --capture CAPTURE`: frames of a scene's shot, spread over it,
//! rendered as `frf render SCENE.toml` renders them and scored against their true
//! composites from the virtual stage ([`frf_eval::shot`]).

use std::time::Instant;

use frf_eval::shot::{ShotFrameScore, score_frame, spread_frames};
use frf_reflectance::FieldFile;
use frf_render::renderer::Device;
use frf_render::scene::Scene;
use frf_render::scene::plan::ShotFrame;
use frf_render::scene::shot::{Shot, ShotOptions};
use serde::Serialize;

use crate::CliResult;
use crate::cmd::eval::EvalArgs;

/// Memory budget of the poses kept resident while scoring, bytes (a few frames only).
const BUDGET_BYTES: u64 = 4_000_000_000;

#[derive(Serialize)]
struct ShotReport {
    scene: std::path::PathBuf,
    field: std::path::PathBuf,
    capture: std::path::PathBuf,
    device: String,
    truth_lights: usize,
    frames_total: usize,
    frames: Vec<ShotFrameScore>,
    psnr_frame_mean: f64,
    psnr_subject_mean: f64,
    ssim_subject_mean: f64,
    seconds_render_mean: f64,
    seconds_truth_mean: f64,
    seconds: f64,
}

/// Runs `frf eval SCENE.toml`.
pub fn run(args: &EvalArgs) -> CliResult {
    let start = Instant::now();
    let mut scene = Scene::load(&args.field)?;
    if let Some(env) = &args.lighting.env {
        for k in &mut scene.lighting {
            k.env = env.clone();
        }
    }
    let field_path =
        crate::cmd::render::scene_field(&scene, &args.field, args.scene_field.as_ref())?;
    if !(1..=65536).contains(&args.lights) {
        return Err(format!("--lights {} (1 to 65536)", args.lights).into());
    }
    let field = FieldFile::open(&field_path)?;
    let stage = frf_stage::open_stage(&args.capture)?;
    let h = field.header();
    let size = scene.size.unwrap_or((h.width, h.height));
    let total = scene.frame_times().len();
    let frames: Vec<ShotFrame> = spread_frames(total, args.frames.unwrap_or(4))
        .into_iter()
        .map(|i| Ok(scene.shot_frames(i..i + 1, size)?[0]))
        .collect::<CliResult<_>>()?;
    let options = ShotOptions {
        memory_budget: BUDGET_BYTES,
        planned: true,
        traced_lights: args.lights,
    };
    let mut shot = Shot::new(
        &scene,
        &field,
        Device::open(args.compare.cpu)?,
        &frames,
        options,
    )?;
    for f in &shot.plan().frames {
        if let Some(p) = f.poses.iter().find(|p| !stage.config().poses.contains(p)) {
            return Err(format!(
                "{}: frame {} draws pose {p}, which the capture did not film",
                args.capture.display(),
                f.index
            )
            .into());
        }
    }
    let bar = crate::cmd::progress::bar("frames scored");
    bar.set_length(frames.len() as u64);
    let mut scores = Vec::new();
    for f in &frames {
        scores.push(score_frame(&stage, &mut shot, f, args.lights)?);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let mean =
        |g: fn(&ShotFrameScore) -> f64| scores.iter().map(g).sum::<f64>() / scores.len() as f64;
    let report = ShotReport {
        scene: args.field.clone(),
        field: field_path,
        capture: args.capture.clone(),
        device: shot.device(),
        truth_lights: args.lights,
        frames_total: total,
        psnr_frame_mean: mean(|s| s.psnr_frame),
        psnr_subject_mean: mean(|s| s.psnr_subject),
        ssim_subject_mean: mean(|s| s.ssim_subject),
        seconds_render_mean: mean(|s| s.seconds_render),
        seconds_truth_mean: mean(|s| s.seconds_truth),
        frames: scores,
        seconds: start.elapsed().as_secs_f64(),
    };
    if args.compare.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    println!(
        "{}: {} of {} frames against the stage's truth ({} median-cut lights), {}",
        report.scene.display(),
        report.frames.len(),
        total,
        args.lights,
        report.device
    );
    println!("frame   time  pose  PSNR frame  PSNR walker  SSIM walker  render s  truth s");
    for s in &report.frames {
        println!(
            "{:>5} {:>6.2} {:>5} {:>8.2} dB {:>9.2} dB {:>12.4} {:>9.3} {:>8.2}",
            s.index,
            s.time,
            s.pose,
            s.psnr_frame,
            s.psnr_subject,
            s.ssim_subject,
            s.seconds_render,
            s.seconds_truth
        );
    }
    println!(
        "mean: frame {:.2} dB, walker {:.2} dB (SSIM {:.4}); {:.3} s a frame rendered (first frames make their poses resident), {:.2} s a true frame",
        report.psnr_frame_mean,
        report.psnr_subject_mean,
        report.ssim_subject_mean,
        report.seconds_render_mean,
        report.seconds_truth_mean
    );
    Ok(())
}
