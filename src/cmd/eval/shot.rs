//! `frf eval SCENE.toml --capture CAPTURE`: frames of a scene's shot, spread over it,
//! rendered as `frf render SCENE.toml` renders them and scored against their true
//! composites from the virtual stage ([`frf_eval::shot`]).

use frf_eval::shot::evaluate_shot;
use frf_reflectance::FieldFile;
use frf_render::renderer::Device;
use frf_scene::Scene;

use super::args::EvalArgs;
use crate::CliResult;
use crate::cmd::progress::Bars;

/// Frames scored by default.
const DEFAULT_FRAMES: usize = 4;

/// Runs `frf eval SCENE.toml`.
pub fn run(args: &EvalArgs) -> CliResult {
    let mut scene = Scene::load(&args.field)?;
    if let Some(env) = &args.lighting.env {
        for k in &mut scene.lighting {
            k.env = env.clone();
        }
    }
    let field_path = scene.field_or(args.scene_field.as_deref())?;
    if !(1..=65536).contains(&args.lights) {
        return Err(format!("--lights {} (1 to 65536)", args.lights).into());
    }
    let field = FieldFile::open(&field_path)?;
    let stage = frf_stage::open_stage(&args.capture)?;
    let report = evaluate_shot(
        &scene,
        &field,
        Device::open(args.compare.cpu)?,
        &stage,
        args.frames.unwrap_or(DEFAULT_FRAMES),
        (args.lights, args.truth_at.into()),
        (args.field.clone(), field_path, args.capture.clone()),
        &Bars::default(),
    )?;
    if args.compare.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    println!(
        "{}: {} of {} frames against the stage's truth ({} median-cut lights, the walker at {}), {}",
        report.scene.display(),
        report.frames.len(),
        report.frames_total,
        args.lights,
        match report.truth_at {
            frf_eval::shot::TruthAt::Instant => "each frame's instant",
            frf_eval::shot::TruthAt::Pose => "the instant of the pose drawn",
        },
        report.device
    );
    println!(
        "frame   time  pose  from pose  PSNR frame  PSNR walker  SSIM walker  render s  truth s"
    );
    for s in &report.frames {
        // Between two poses: both, the earlier first.
        let pose = match s.between {
            Some((after, _)) => format!("{}-{after}", s.pose),
            None => s.pose.to_string(),
        };
        println!(
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
    if let Some(m) = &report.steadiness {
        println!(
            "motion: the walker's largest change between consecutive frames {:.5} (mean |ΔRGBA| a pixel), \
             the truth's {:.5}: {:.2}x ({} pairs)",
            m.largest_change, m.truth_largest_change, m.ratio, m.pairs
        );
    }
    Ok(())
}
