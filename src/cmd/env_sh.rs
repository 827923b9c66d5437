//! `frf env-sh ENV --out SH.json`: an environment's nine RGB L2 coefficients in frf's
//! declared convention (`frf_core::sh`), the light a player's light probe takes; frf
//! renders with the file as its light (`--env SH.json`). It says how much of the map L2
//! keeps: the share of the map's energy (`∫ L² dω`) in the nine coefficients, and the
//! share of texels the L2 light rings below zero at.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use frf_core::env::{EnvMap, EnvSource, SH_MAP_HEIGHT};
use frf_core::sh::ShSun;
use frf_core::sun::Sun;
use frf_reflectance::sun_light::MAX_SUNS;

use crate::CliResult;

/// Arguments of `frf env-sh`.
#[derive(Args)]
pub struct EnvShArgs {
    /// The environment: a latitude–longitude `.hdr` / `.exr`, or `sky`.
    env: EnvSource,
    /// Turn the map about the vertical axis first, degrees (as `frf render --yaw`).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = crate::cmd::args::parse_turn)]
    yaw: f64,
    /// Take the map's suns out first (up to frf's 4, brightest first, as frf finds them
    /// when it relights by the map) and write them beside the L2 coefficients of what is
    /// left: a player relights them sharply, and frf paints them back (`--env SH.json`).
    #[arg(long)]
    suns: bool,
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
    let (env, suns) = if args.suns {
        found_suns(env)?
    } else {
        (env, Vec::new())
    };
    let sh = env.to_sh();
    let kept = energy_kept(&env, &sh);
    let ringing = EnvMap::from_sh_clamped(&sh, SH_MAP_HEIGHT)?;
    let texels = ringing.image().pixels().len();
    sh.save_with_suns(&args.out, &args.env.name(), &suns)?;
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
    for (k, s) in suns.iter().enumerate() {
        let d = glam::Vec3::from(s.direction);
        println!(
            "  sun {k}: azimuth {:.1}°, elevation {:.1}°, {:.2}° across, illuminance {:.3} {:.3} {:.3} (taken out of the L2 light)",
            d.x.atan2(d.z).to_degrees(),
            d.y.clamp(-1.0, 1.0).asin().to_degrees(),
            s.diameter_deg,
            s.illuminance[0],
            s.illuminance[1],
            s.illuminance[2]
        );
    }
    if args.suns && suns.is_empty() {
        println!(
            "  no sun found in the map (none compact and {}x its mean)",
            frf_core::sun::SUN_CONTRAST
        );
    }
    println!(
        "  texels where the L2 light rings below zero (kept when frf renders the file, as a player relights it): {:.1} %",
        100.0 * ringing.clamped_texels() as f64 / texels as f64
    );
    Ok(())
}

/// The map's suns (up to [`MAX_SUNS`], each found in what the last left, as frf's
/// relighting finds them) and the map less them.
fn found_suns(env: EnvMap) -> CliResult<(EnvMap, Vec<ShSun>)> {
    let (suns, rest) = Sun::extract_all(&env, MAX_SUNS)?;
    let suns = (suns.iter())
        .map(|sun| ShSun {
            direction: sun.direction().to_array(),
            diameter_deg: 2.0 * sun.radius().to_degrees(),
            illuminance: sun.illuminance(),
        })
        .collect();
    Ok((rest.unwrap_or(env), suns))
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
