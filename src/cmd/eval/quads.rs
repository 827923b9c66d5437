//! `frf eval FIELD --capture C --env E [--shadows]`: cameras at quad centres
//! ([`frf_eval::quads`]), printed as a table (and the scene's scores), or as JSON.

use frf_eval::quads::{QuadsOptions, evaluate_quads};
use frf_eval::views::{TABLE_HEADER, table_row};
use frf_render::composite::GroundLook;
use frf_render::renderer::Renderer;
use frf_render::shadow::ShadowMaps;
use frf_stage::truth::environment_lights;

use super::args::EvalArgs;
use super::input::EvalInput;
use crate::CliResult;
use crate::cmd::args::GroundArg;
use frf_core::bars::Bars;

/// Runs `frf eval` at quad centres.
pub fn run(args: &EvalArgs, input: &EvalInput) -> CliResult {
    let lights = environment_lights(&input.env, args.lights);
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
    }
    let mut renderer = Renderer::open(&input.source, args.compare.cpu)?;
    let variants = args.compare.variants();
    let options = QuadsOptions {
        names: (
            args.field.clone(),
            args.capture.clone(),
            args.lighting.name()?,
        ),
        cameras: args.cameras,
        variants: &variants,
        env: &input.env,
        lights: &lights,
        light_count: args.lights,
        images: args.images.as_deref(),
        scene: args.shadows.then_some(match args.ground {
            GroundArg::Env => GroundLook::Environment,
            GroundArg::Albedo(a) => GroundLook::Albedo(a),
        }),
    };
    let report = evaluate_quads(
        &input.field,
        &input.source.geometry,
        &mut renderer,
        &input.stage,
        input.pose,
        &options,
        &Bars::default(),
    )?;
    eprintln!(
        "{} pose {} under {} (truth: {} median-cut lights, {:.2} s/frame on the CPU), {} \
         cameras at quad centres, {}:",
        args.field.display(),
        input.pose,
        args.lighting.name()?,
        args.lights,
        report.header.truth_seconds_per_frame,
        report.cameras.len(),
        report.header.device
    );
    eprintln!("{TABLE_HEADER}");
    for s in report.variants.iter().chain([&report.at_captured_views]) {
        eprintln!("{}", table_row(s));
    }
    if report.scene.is_some() {
        let maps = ShadowMaps::load(&input.field, input.pose)?;
        let extent = maps.map_or(0.0, |m| m.spec.ground.extent_m);
        eprintln!("{}", report.scene_line(extent).unwrap_or_default());
    }
    if args.compare.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}
