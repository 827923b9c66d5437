//! `frf eval SCENE.toml --capture CAPTURE`: frames of a scene's shot, spread over it,
//! rendered as `frf render SCENE.toml` renders them and scored against their true
//! composites from the virtual stage ([`frf_eval::shot`]).

use frf_eval::shot::{ShotEval, evaluate_shot};
use frf_reflectance::FieldFile;
use frf_scene::Scene;

use super::args::EvalArgs;
use crate::CliResult;
use frf_core::bars::Bars;

/// Frames scored by default.
const DEFAULT_FRAMES: usize = 4;

/// Runs `frf eval SCENE.toml`.
pub fn run(args: &EvalArgs) -> CliResult {
    let env = args.lighting.env.as_ref();
    let (scene, field_path) =
        Scene::load_overridden(&args.field, env, args.scene_field.as_deref())?;
    frf_core::argument::within("--lights", args.lights, 1, 65536, "")?;
    let field = FieldFile::open(&field_path)?;
    frf_render::resident::check_renderable(&field)?;
    let stage = frf_stage::open_stage(&args.capture)?;
    let how = ShotEval {
        frames: args.frames.unwrap_or(DEFAULT_FRAMES),
        lights: args.lights,
        truth_at: args.truth_at,
        light_tolerance: args
            .light_tolerance
            .unwrap_or(frf_scene::shot::LightTolerance::DEFAULT),
        standing: args.standing,
        walker_shadows: !args.no_walker_shadows,
        cpu: args.compare.cpu,
    };
    let report = evaluate_shot(
        &scene,
        &field,
        &stage,
        (&how, args.images.as_deref()),
        (args.field.clone(), field_path, args.capture.clone()),
        &Bars::default(),
    )?;
    if args.compare.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    println!("{}", report.describe(args.lights));
    Ok(())
}
