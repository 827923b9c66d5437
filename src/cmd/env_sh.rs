//! `frf env-sh ENV --out SH.json`: an environment's nine RGB L2 coefficients in frf's
//! declared convention (`frf_core::sh`), the light a player's light probe takes; frf
//! renders with the file as its light (`--env SH.json`). It says how much of the map L2
//! keeps: the share of the map's energy (`∫ L² dω`) in the nine coefficients, and the
//! share of texels the L2 light rings below zero at.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use frf_core::env::{EnvMap, EnvSource, SH_MAP_HEIGHT};

use crate::CliResult;

/// Arguments of `frf env-sh`.
#[derive(Args)]
pub struct EnvShArgs {
    /// The environment: a latitude–longitude `.hdr` / `.exr`, or `sky`.
    env: EnvSource,
    /// Turn the map about the vertical axis first, degrees (as `frf render --yaw`).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = crate::cmd::args::parse_turn)]
    yaw: f64,
    /// Output SH light (`.json`).
    #[arg(long)]
    out: PathBuf,
}

/// Runs `frf env-sh`.
pub fn run(args: EnvShArgs) -> CliResult {
    let started = Instant::now();
    crate::cmd::args::expect_out_extension(&args.out, "json", "an SH light is a JSON file")?;
    if let EnvSource::File(map) = &args.env {
        frf_core::atomic::refuse_overwriting_inputs(&args.out, &[map.as_path()])?;
    }
    let env = args
        .env
        .load_required("the light to project")?
        .rotated(frf_core::light::turn_radians(args.yaw));
    let sh = env.to_sh();
    let kept = energy_kept(&env, &sh);
    let ringing = EnvMap::from_sh_clamped(&sh, SH_MAP_HEIGHT)?;
    let texels = ringing.image().pixels().len();
    sh.save(&args.out, &args.env.name())?;
    println!(
        "L2 light of {} written to {} in {:.2} s",
        args.env,
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    println!(
        "  band 0 (mean radiance x sqrt(4 pi)): {:.4} {:.4} {:.4}",
        sh.coefficients[0][0], sh.coefficients[0][1], sh.coefficients[0][2]
    );
    println!(
        "  energy kept by L2 (sum of squared coefficients / integral of squared radiance, luminance): {:.1} %",
        100.0 * kept
    );
    println!(
        "  texels where the L2 light rings below zero (kept when frf renders the file, as a player relights it): {:.1} %",
        100.0 * ringing.clamped_texels() as f64 / texels as f64
    );
    Ok(())
}

/// `Σ c_i² / ∫ L² dω` of the luminance: 1 for a light that is L2 already.
fn energy_kept(env: &EnvMap, sh: &frf_core::sh::ShLight) -> f64 {
    let lum = |c: [f32; 3]| frf_core::image::luminance(c) as f64;
    let img = env.image();
    let mut total = 0.0f64;
    for y in 0..img.height() {
        let omega = env.texel_solid_angle(y) as f64;
        total += img.row(y).iter().map(|&l| lum(l).powi(2)).sum::<f64>() * omega;
    }
    let kept: f64 = sh.coefficients.iter().map(|&c| lum(c).powi(2)).sum();
    if total > 0.0 { kept / total } else { 0.0 }
}
