//! `frf eval FIELD --capture C --env E --budget [--plot F.svg|F.png] [--json]`: the
//! error budget of view interpolation ([`frf_eval::budget`]), printed as a table, and
//! drawn with its Markdown table beside the plot.

use frf_core::atomic::write_bytes_atomic;
use frf_core::image::{Image, Rgba};
use frf_core::io::write_png8_srgba;
use frf_eval::budget::{self, BudgetInputs, BudgetReport};
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
        args.lighting.source()?,
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
            env: args.lighting.source()?.to_string(),
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

/// Whether `--plot PATH` asks for a PNG (`Some(true)`) or an SVG (`Some(false)`);
/// `None` without `--plot`; any other extension is refused.
pub(super) fn plot_format(plot: Option<&std::path::Path>) -> CliResult<Option<bool>> {
    let Some(p) = plot else {
        return Ok(None);
    };
    match p.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("svg") => Ok(Some(false)),
        Some(e) if e.eq_ignore_ascii_case("png") => Ok(Some(true)),
        _ => Err(format!("--plot {}: expected a .svg or .png file", p.display()).into()),
    }
}

/// Writes a budget's plot to `path` (PNG or SVG, atomically) and its Markdown table
/// beside it (`.md`).
pub(super) fn write_plot(
    path: &std::path::Path,
    png: bool,
    draw_png: &dyn Fn() -> frf_eval::Result<Option<Vec<u8>>>,
    draw_svg: &dyn Fn() -> frf_eval::Result<String>,
    markdown: &str,
) -> CliResult {
    let bytes = if png {
        draw_png()?.ok_or("no system font for the plot's text: draw it as .svg")?
    } else {
        draw_svg()?.into_bytes()
    };
    write_bytes_atomic(path, &bytes)?;
    write_bytes_atomic(&path.with_extension("md"), markdown.as_bytes())?;
    Ok(())
}
