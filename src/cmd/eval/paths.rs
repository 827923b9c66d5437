//! `frf eval FIELD --capture C --env E (--orbit R,H[,SWEEP] | --camera PATH.toml | --suite)`:
//! frames along camera paths rendered by every variant and scored against the stage's
//! true frames from the same cameras ([`frf_eval::paths`]): PSNR and SSIM on the subject
//! and the frame, alpha error, the share of pixels clamped to a row, the largest
//! row-to-row jump of the subject (a seam) beside the truth's, and seconds per frame.

use frf_eval::paths::{NamedPath, PathOptions, evaluate_paths, suite};
use frf_render::renderer::Renderer;
use frf_stage::truth::environment_lights;

use super::args::EvalArgs;
use super::input::EvalInput;
use crate::CliResult;
use frf_core::bars::Bars;

/// Frames along each path, by default.
const DEFAULT_FRAMES: usize = 8;

/// Runs `frf eval` along a path or the suite.
pub fn run(args: &EvalArgs, input: &EvalInput) -> CliResult {
    let geometry = &input.source.geometry;
    let frames = args.frames.unwrap_or(DEFAULT_FRAMES);
    frf_core::argument::within("--frames", frames, 1, 10_000, "")?;
    let (w, h) = args.size.unwrap_or(geometry.image_size);
    let paths: Vec<NamedPath> = if args.suite {
        suite(geometry)?
    } else {
        vec![NamedPath {
            name: "path",
            about: "the path given",
            trajectory: args.path.trajectory()?,
        }]
    };
    let lights = environment_lights(&input.env, args.lights);
    let renderer = Renderer::open(&input.source, args.compare.cpu)?;
    let variants = args.compare.variants();
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
    }
    let options = PathOptions {
        names: (
            args.field.clone(),
            args.capture.clone(),
            args.lighting.name()?,
        ),
        frames,
        size: (w, h),
        variants: &variants,
        lights: &lights,
        light_count: args.lights,
        images: args.images.as_deref(),
    };
    let report = evaluate_paths(
        &renderer,
        &input.stage,
        input.pose,
        &paths,
        &options,
        &Bars::default(),
    )?;
    let header = format!(
        "{} pose {} under {} (truth: {} median-cut lights, {:.2} s/frame on the CPU), {} \
         path(s) of {frames} frames at {w}x{h}, {}:",
        args.field.display(),
        input.pose,
        args.lighting.name()?,
        args.lights,
        report.header.truth_seconds_per_frame,
        paths.len(),
        report.header.device
    );
    eprintln!("{header}\n{}", report.describe());
    if args.compare.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}
