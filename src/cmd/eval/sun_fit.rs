//! `frf eval FIELD --capture C --env E [--sun ...] --sun-fit`: the field's sun relit by
//! its views' normals against the same sun relit by its basis, at the captured views
//! ([`frf_eval::sun_fit`]).

use frf_core::bars::Bars;
use frf_eval::sun_fit::score_sun_fit;
use frf_eval::views::{TABLE_HEADER, table_row};
use frf_stage::truth::environment_lights;

use super::args::EvalArgs;
use super::input::EvalInput;
use crate::CliResult;

/// Runs `frf eval --sun-fit`.
pub fn run(args: &EvalArgs, input: &EvalInput) -> CliResult {
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
    }
    let lights = environment_lights(&input.env, args.lights);
    let (lighting, _) = args
        .lighting
        .lighting(input.field.header().conditions.len())?;
    let r = score_sun_fit(
        &input.field,
        &input.source,
        &lighting,
        (&input.stage, input.pose, &lights),
        args.cameras,
        (args.compare.cpu, args.images.as_deref()),
        &Bars::default(),
    )?;
    eprintln!(
        "{} pose {} under {} ({} sun{}) at {} captured views (truth: {} lights):",
        args.field.display(),
        input.pose,
        args.lighting.name()?,
        r.suns,
        if r.suns == 1 { "" } else { "s" },
        r.fit.frames.len(),
        args.lights
    );
    eprintln!("{TABLE_HEADER}");
    eprintln!("{}", table_row(&r.basis));
    eprintln!("{}", table_row(&r.fit));
    if args.compare.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "field": args.field,
                "env": args.lighting.name()?,
                "pose": input.pose,
                "suns": r.suns,
                "basis": r.basis,
                "fit": r.fit,
            }))?
        );
    }
    Ok(())
}
