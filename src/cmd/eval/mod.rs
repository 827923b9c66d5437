//! `frf eval FIELD --capture CAPTURE`: renders between the grid's views, along camera
//! paths (`--orbit`, `--camera`, `--suite`), as an error budget of view interpolation
//! (`--budget`) or of ingest (`--ingest-budget`), or a scene's
//! shot (`SCENE.toml`), scored against the virtual stage's truth; `frf eval-ring FIELD
//! --par PAR --stride S`: views held out of a ring of photographs rendered from their
//! neighbours and scored against the photographs. The evaluations are `frf_eval`'s; each
//! module here parses, calls one and prints its report.

mod args;
mod budget;
mod ingest_budget;
mod input;
mod paths;
mod quads;
pub mod ring;
mod shot;
mod sun_fit;

pub use args::{EvalArgs, RingEvalArgs};

use crate::CliResult;

/// Runs `frf eval`.
pub fn run(args: EvalArgs) -> CliResult {
    if frf_scene::Scene::is_scene_file(&args.field) {
        return shot::run(&args);
    }
    if args.plot.is_some() && !(args.budget || args.ingest_budget) {
        return Err("--plot draws a budget: give --budget or --ingest-budget".into());
    }
    let input = input::load(&args)?;
    if args.sun_fit {
        sun_fit::run(&args, &input)
    } else if args.ingest_budget {
        ingest_budget::run(&args, &input)
    } else if args.budget {
        budget::run(&args, &input)
    } else if args.suite || args.path.orbit.is_some() || args.path.camera.is_some() {
        paths::run(&args, &input)
    } else {
        quads::run(&args, &input)
    }
}
