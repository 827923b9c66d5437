//! `frf eval FIELD --capture C --env E --budget [--plot F.svg|F.png] [--json]`: the
//! error budget of view interpolation ([`frf_eval::budget`]), printed as a table, and
//! drawn with its Markdown table beside the plot.

use frf_core::image::{Image, Rgba};
use frf_core::io::write_png8_srgba;
use frf_eval::budget::{self, BudgetInputs, BudgetReport};
use frf_eval::report::plot::{plot_format, write_plot};
use frf_render::renderer::Renderer;
use frf_render::resident::ResidentPose;
use frf_stage::truth::environment_lights;

use super::args::EvalArgs;
use super::input::EvalInput;
use crate::CliResult;
use frf_core::bars::Bars;

/// Runs the budget.
pub fn run(args: &EvalArgs, input: &EvalInput) -> CliResult {
    let (source, stage, env, pose) = (&input.source, &input.stage, &input.env, input.pose);
    let plot_png = plot_format(args.plot.as_deref())?;
    let renderer = Renderer::open(source, args.compare.cpu)?;
    let resident = ResidentPose::relight_cpu(source);
    let lights = environment_lights(env, args.lights);
    let variants = args.compare.variants();
    let keep = |offset: &budget::Offset, name: &str, frame: &Image<Rgba>| {
        let Some(dir) = &args.images else {
            return Ok(());
        };
        let file = format!(
            "{}_{:.2}_{:.2}_{}.png",
            offset.direction.name(),
            offset.beta,
            offset.gamma,
            name.replace([':', ' '], "_").replace("__", "_")
        );
        write_png8_srgba(&dir.join(file), frame, 1.0)?;
        Ok(())
    };
    let inputs = BudgetInputs {
        renderer: &renderer,
        resident: &resident,
        stage,
        pose,
        lights: &lights,
        keep: Some(&keep),
    };
    let rows = budget::run(&inputs, args.cameras, &variants, &Bars::default())?;
    eprintln!(
        "{} pose {pose} under {}: subject PSNR (dB) / SSIM, {} cameras per offset, variants on {} \
         (truth: {} median-cut lights)",
        args.field.display(),
        args.lighting.name()?,
        args.cameras,
        renderer.device(),
        args.lights
    );
    eprint!("{}", budget::table(&rows));
    if let (Some(path), Some(png)) = (&args.plot, plot_png) {
        write_plot(
            path,
            png,
            &|| budget::plot::png(&rows),
            &|| budget::plot::svg(&rows),
            &budget::markdown(&rows),
        )?;
    }
    if args.compare.json {
        let report = BudgetReport {
            field: args.field.display().to_string(),
            capture: args.capture.display().to_string(),
            env: args.lighting.name()?,
            pose,
            device: renderer.device(),
            truth_lights: args.lights,
            quads: args.cameras,
            rows,
        };
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}
