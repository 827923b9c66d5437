//! `frf stage field | projection-error | codec-curve`: the oracle field of a stage
//! capture (built from its ground truth), and the storage and relighting errors measured
//! against that truth.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use frf_core::env::EnvSource;
use frf_eval::oracle::{OracleOptions, write_oracle_field};
use frf_eval::storage::{ProjectionTable, codec_curve, codec_table, sample_views};
use frf_reflectance::project::FloorModel;

use crate::CliResult;
use crate::cmd::args::{FloorArg, parse_env};
use frf_core::bars::bar;

/// Arguments of `frf stage field`.
#[derive(Args)]
pub struct FieldArgs {
    /// A capture directory written by `frf stage`.
    #[arg(long)]
    capture: PathBuf,
    /// Output field file.
    #[arg(long)]
    out: PathBuf,
    /// JPEG quality of the basis mosaics (1-100); 95 keeps relit PSNR above 40 dB on
    /// the stage's data (see `frf stage codec-curve`).
    #[arg(long, default_value_t = 95, value_parser = clap::value_parser!(u8).range(1..=100))]
    jpeg_quality: u8,
    /// Do not left-predict flow codes before Huffman coding.
    #[arg(long)]
    no_flow_prediction: bool,
    /// Poses to include, e.g. `0,1` (default: all of the capture's).
    #[arg(long, value_delimiter = ',')]
    poses: Vec<u32>,
    /// Store the true flows between consecutive poses too (time between poses, as
    /// `frf ingest --pose-flow` stores estimated ones).
    #[arg(long)]
    pose_flow: bool,
    #[command(flatten)]
    shadows: crate::cmd::args::ShadowArgs,
}

/// Runs `frf stage field`.
pub fn field(args: FieldArgs) -> CliResult {
    let _claim = crate::cmd::claim::claim(&args.out, &[])?;
    let stage = frf_stage::open_stage(&args.capture)?;
    let poses = if args.poses.is_empty() {
        stage.config().poses.clone()
    } else {
        args.poses
    };
    let start = Instant::now();
    let bar = bar("oracle field: views (flows, then images)");
    let written = write_oracle_field(
        &stage,
        &args.out,
        &OracleOptions {
            poses,
            jpeg_quality: args.jpeg_quality,
            predict_flow: !args.no_flow_prediction,
            shadows: args.shadows.options()?,
            pose_flows: args.pose_flow,
        },
        &|done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        },
    )?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    println!("{}", written.describe(&args.out, seconds)?);
    Ok(())
}

/// Arguments of `frf stage projection-error`.
#[derive(Args)]
pub struct ProjectionArgs {
    /// A capture directory written by `frf stage`.
    #[arg(long)]
    capture: PathBuf,
    /// Environments (lat-long .hdr/.exr, `sky` or `uniform`); repeat for several.
    #[arg(long, required = true, value_parser = parse_env)]
    env: Vec<EnvSource>,
    /// Median-cut lights of the true image under each environment.
    #[arg(long, default_value_t = 512)]
    lights: usize,
    /// Where the floor conditions' light comes from.
    #[arg(long, value_enum, default_value = "env")]
    floor: FloorArg,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// Runs `frf stage projection-error`.
pub fn projection(args: ProjectionArgs) -> CliResult {
    let stage = frf_stage::open_stage(&args.capture)?;
    let mut envs = Vec::new();
    for source in &args.env {
        envs.push((
            source.name(),
            source.load_required("these measures relight with it")?,
        ));
    }
    let floor = FloorModel::from(args.floor);
    let table = ProjectionTable::measure(&stage, &envs, args.lights, floor)?;
    match args.json {
        true => println!("{}", table.json()),
        false => print!("{}", table.text()),
    }
    Ok(())
}

/// Arguments of `frf stage codec-curve`.
#[derive(Args)]
pub struct CodecArgs {
    /// A capture directory written by `frf stage`.
    #[arg(long)]
    capture: PathBuf,
    /// Environment to relight with (lat-long .hdr/.exr, `sky` or `uniform`).
    #[arg(long, default_value = "sky", value_parser = parse_env)]
    env: EnvSource,
    /// JPEG qualities to measure.
    #[arg(long, value_delimiter = ',', default_value = "50,60,70,80,85,90,95,98")]
    qualities: Vec<u8>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// Runs `frf stage codec-curve`.
pub fn codec(args: CodecArgs) -> CliResult {
    let stage = frf_stage::open_stage(&args.capture)?;
    let env = args.env.load_required("these measures relight with it")?;
    let views = sample_views(&stage);
    let pose = stage.config().poses[0];
    let curve = codec_curve(&stage, &env, pose, &views, &args.qualities)?;
    match args.json {
        true => println!("{}", serde_json::to_string_pretty(&curve)?),
        false => print!(
            "{}",
            codec_table(&curve, &args.env.to_string(), views.len())
        ),
    }
    Ok(())
}
