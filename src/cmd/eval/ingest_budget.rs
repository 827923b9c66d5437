//! `frf eval FIELD --capture C --env E --ingest-budget [--fields DIR] [--plot F] [--json]`:
//! the error budget of ingest ([`frf_eval::ingest_budget`]), printed as a table, drawn
//! with its Markdown table beside the plot.

use frf_eval::ingest_budget::{self, BudgetScoring, IngestBudgetReport, fields};
use frf_stage::truth::environment_lights;

use super::args::EvalArgs;
use super::input::EvalInput;
use crate::CliResult;
use frf_core::bars::Bars;
use frf_eval::report::plot::{plot_format, write_plot};

/// Runs the ingest budget.
pub fn run(args: &EvalArgs, input: &EvalInput) -> CliResult {
    let plot_png = plot_format(args.plot.as_deref())?;
    let options = args.method.options()?;
    let (lighting, _) = args
        .lighting
        .lighting(input.field.header().conditions.len())?;
    let bars = Bars::default();
    let temporary;
    let dir = match &args.fields {
        Some(d) => d.clone(),
        None => {
            temporary =
                tempfile::tempdir().map_err(crate::context::context("a temporary directory"))?;
            temporary.path().to_path_buf()
        }
    };
    let made = fields::write_fields(
        &input.stage,
        &args.capture,
        input.pose,
        &options,
        &dir,
        &bars,
    )?;
    let lights = environment_lights(&input.env, args.lights);
    let scoring = BudgetScoring {
        stage: &input.stage,
        pose: input.pose,
        lighting: &lighting,
        lights: &lights,
        cameras: args.cameras,
        cpu: args.compare.cpu,
        images: args.images.as_deref(),
    };
    let (rows, given, device) =
        ingest_budget::evaluate_fields(&made, Some(&args.field), &scoring, &bars)?;
    let report = IngestBudgetReport {
        capture: args.capture.display().to_string(),
        env: args.lighting.name()?,
        pose: input.pose,
        device,
        truth_lights: args.lights,
        cameras: args.cameras,
        settings: fields::describe(&options),
        given,
        rows,
    };
    eprintln!("{}", report.header());
    eprint!("{}", ingest_budget::table(&report));
    if let (Some(path), Some(png)) = (&args.plot, plot_png) {
        write_plot(
            path,
            png,
            &|| ingest_budget::plot::png(&report),
            &|| ingest_budget::plot::svg(&report),
            &ingest_budget::markdown(&report),
        )?;
    }
    if args.compare.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}
