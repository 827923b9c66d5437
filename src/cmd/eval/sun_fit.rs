//! `frf eval FIELD --capture C --env E [--sun ...] --sun-fit`: the basis against the
//! light fit under a sun at the captured views ([`frf_eval::sun_fit`]).

use frf_eval::sun_fit::score_sun_fit;
use frf_eval::views::grid_view_cameras;
use frf_stage::truth::environment_lights;

use super::args::EvalArgs;
use super::input::EvalInput;
use crate::CliResult;

/// Runs `frf eval --sun-fit`.
pub fn run(args: &EvalArgs, input: &EvalInput) -> CliResult {
    let lights = environment_lights(&input.env, args.lights);
    let views: Vec<_> = grid_view_cameras(&input.source.geometry, args.cameras)?
        .into_iter()
        .filter_map(|c| c.view.map(|v| (v, c.camera)))
        .collect();
    let scores = score_sun_fit(
        &input.field,
        &input.stage,
        input.pose,
        (&input.env, args.lighting.floor.into()),
        &views,
        &lights,
    )?;
    let mean = |f: &dyn Fn(&frf_eval::sun_fit::SunFitScore) -> f64| {
        scores.iter().map(f).sum::<f64>() / scores.len().max(1) as f64
    };
    eprintln!(
        "{} pose {} under {}: subject PSNR dB / SSIM at the captured views (truth: {} lights)",
        args.field.display(),
        input.pose,
        args.lighting.name()?,
        args.lights
    );
    eprintln!("view        basis            basis less the sun + the sun by the light fit");
    for s in &scores {
        eprintln!(
            "u {:2} v {:2}  {:6.2} / {:.4}  {:6.2} / {:.4}",
            s.view.0, s.view.1, s.basis_psnr, s.basis_ssim, s.fit_psnr, s.fit_ssim
        );
    }
    eprintln!(
        "mean        {:6.2} / {:.4}  {:6.2} / {:.4}",
        mean(&|s| s.basis_psnr),
        mean(&|s| s.basis_ssim),
        mean(&|s| s.fit_psnr),
        mean(&|s| s.fit_ssim)
    );
    if args.compare.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "field": args.field,
                "env": args.lighting.name()?,
                "pose": input.pose,
                "mean_basis_psnr": mean(&|s| s.basis_psnr),
                "mean_fit_psnr": mean(&|s| s.fit_psnr),
                "views": scores,
            }))?
        );
    }
    Ok(())
}
