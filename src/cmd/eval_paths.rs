//! `frf eval FIELD --capture C --env E (--orbit R,H[,SWEEP] | --camera PATH.toml | --suite)`:
//! frames along camera paths rendered by every variant and scored against the stage's
//! true frames from the same cameras: PSNR and SSIM on the subject and the frame, alpha
//! error, the share of pixels clamped to a row, the largest row-to-row jump of the
//! subject (a seam) beside the truth's, and seconds per frame.

use std::time::Instant;

use frf_core::env::EnvMap;
use frf_eval::metrics::max_row_jump;
use frf_eval::paths::{NamedPath, suite};
use frf_eval::views::{EvalCamera, VariantScore, evaluate, truth_frame};
use frf_render::resident::PoseSource;
use frf_stage::Stage;
use frf_stage::truth::environment_lights;
use rayon::prelude::*;
use serde::Serialize;

use crate::CliResult;
use crate::cmd::eval::EvalArgs;
use crate::cmd::progress::bar;
use crate::cmd::render::open_renderer;

/// Frames along each path, by default.
const DEFAULT_FRAMES: usize = 8;

/// The header of the variants' table (`frf eval` prints the same for quad centres).
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

#[derive(Serialize)]
struct PathScore {
    name: String,
    about: String,
    /// The truth's largest row-to-row jump, per frame (the scale of a seam).
    truth_max_row_jump: Vec<f64>,
    variants: Vec<VariantScore>,
}

#[derive(Serialize)]
struct PathsReport {
    field: std::path::PathBuf,
    capture: std::path::PathBuf,
    env: String,
    pose: u32,
    device: String,
    truth_lights: usize,
    truth_seconds_per_frame: f64,
    width: u32,
    height: u32,
    frames_per_path: usize,
    paths: Vec<PathScore>,
    /// Per variant: the mean over the paths of their mean subject PSNR, dB.
    mean_psnr_subject: Vec<(String, f64)>,
}

/// Runs `frf eval` along a path or the suite.
pub fn run(args: &EvalArgs, source: &PoseSource, stage: &Stage, env: &EnvMap) -> CliResult {
    let pose = source.geometry.pose;
    let frames = args.frames.unwrap_or(DEFAULT_FRAMES);
    if !(1..=10_000).contains(&frames) {
        return Err(format!("--frames {frames} (1 to 10000)").into());
    }
    let (w, h) = args.size.unwrap_or(source.geometry.image_size);
    let paths: Vec<NamedPath> = if args.suite {
        suite(&source.geometry)?
    } else {
        vec![NamedPath {
            name: "path",
            about: "the path given",
            trajectory: args.path.trajectory()?,
        }]
    };
    let lights = environment_lights(env, args.lights);
    let renderer = open_renderer(source, args.compare.cpu)?;
    let variants = args.compare.variants();
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let mut scores = Vec::new();
    let mut truth_seconds = 0.0;
    for p in &paths {
        let cameras: Vec<EvalCamera> = p
            .trajectory
            .cameras(frames, w, h)?
            .into_iter()
            .enumerate()
            .map(|(i, camera)| EvalCamera {
                name: format!("{} frame {i}", p.name),
                camera,
                view: None,
            })
            .collect();
        let truth_bar = bar(&format!("{}: truth frames", p.name));
        truth_bar.set_length(cameras.len() as u64);
        let t = Instant::now();
        let truths = cameras
            .par_iter()
            .map(|c| {
                let t = truth_frame(stage, pose, &c.camera, &lights);
                truth_bar.inc(1);
                t
            })
            .collect::<Result<Vec<_>, _>>()?;
        truth_seconds += t.elapsed().as_secs_f64();
        truth_bar.finish_and_clear();
        let bar = bar(&format!("{}: rendered frames", p.name));
        bar.set_length((cameras.len() * variants.len()) as u64);
        let variant_scores =
            evaluate(&renderer, &cameras, &truths, &variants, &mut |i, v, img| {
                bar.inc(1);
                if let Some(dir) = &args.images {
                    let name = format!("{}_{i:02}_{}.png", p.name, v.name());
                    frf_core::io::write_png8_srgba(&dir.join(name), img, 1.0)?;
                }
                Ok(())
            })?;
        bar.finish_and_clear();
        if let Some(dir) = &args.images {
            for (i, t) in truths.iter().enumerate() {
                let name = format!("{}_{i:02}_truth.png", p.name);
                frf_core::io::write_png8_srgba(&dir.join(name), t, 1.0)?;
            }
        }
        scores.push(PathScore {
            name: p.name.to_string(),
            about: p.about.to_string(),
            truth_max_row_jump: truths.iter().map(max_row_jump).collect(),
            variants: variant_scores,
        });
    }
    let truth_frames = (paths.len() * frames).max(1) as f64;
    eprintln!(
        "{} pose {pose} under {} (truth: {} median-cut lights, {:.2} s/frame on the CPU), {} \
         path(s) of {frames} frames at {w}x{h}, {}:",
        args.field.display(),
        args.lighting.source()?,
        args.lights,
        truth_seconds / truth_frames,
        paths.len(),
        renderer.device()
    );
    for p in &scores {
        let jump = p.truth_max_row_jump.iter().cloned().fold(0.0, f64::max);
        eprintln!(
            "{} ({}; the truth's largest row jump {jump:.3}):",
            p.name, p.about
        );
        eprintln!("  {TABLE_HEADER}");
        for s in &p.variants {
            let worst = s.frames.iter().map(|f| f.max_row_jump).fold(0.0, f64::max);
            eprintln!("  {}  row jump {worst:.3}", table_row(s));
        }
    }
    let mean_psnr_subject: Vec<(String, f64)> = variants
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let m = scores
                .iter()
                .map(|p| p.variants[k].psnr_subject)
                .sum::<f64>()
                / scores.len().max(1) as f64;
            (v.name().to_string(), m)
        })
        .collect();
    if scores.len() > 1 {
        eprintln!("mean subject PSNR over the paths:");
        for (name, m) in &mean_psnr_subject {
            eprintln!("  {name:<21} {m:.2} dB");
        }
    }
    if args.compare.json {
        let report = PathsReport {
            field: args.field.clone(),
            capture: args.capture.clone(),
            env: args.lighting.source()?.to_string(),
            pose,
            device: renderer.device(),
            truth_lights: args.lights,
            truth_seconds_per_frame: truth_seconds / truth_frames,
            width: w,
            height: h,
            frames_per_path: frames,
            paths: scores,
            mean_psnr_subject,
        };
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}
