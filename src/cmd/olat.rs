//! `frf eval-olat DIR [--use K] [--images OUT] [--json]`: relighting scored on a calibrated
//! one-light-at-a-time set of photographs ([`frf_eval::olat`]).

use std::path::PathBuf;

use clap::Args;
use frf_eval::olat::{evaluate_olat, olat_table};
use frf_ingest::olat::OlatSet;

use crate::CliResult;

/// Arguments of `frf eval-olat`.
#[derive(Args)]
pub struct EvalOlatArgs {
    /// The set: `NNN.png` (8- or 16-bit, linear), `light_directions.txt` (unit vectors,
    /// camera frame: x right, y up, z toward the camera), optional `light_intensities.txt`
    /// (`r g b` a line) and `mask.png`.
    pub dir: PathBuf,
    /// Lights kept (farthest-point sampling from the one nearest the camera); the others
    /// are predicted from them and scored. Default: half of the set.
    #[arg(long = "use", value_name = "K")]
    pub keep: Option<usize>,
    /// Write each held-out light's photograph and predictions here
    /// (`light_NNN_{photo,fit,nearest,interpolated}.png`, 16-bit, values as the photographs
    /// store them).
    #[arg(long, value_name = "OUT")]
    pub images: Option<PathBuf>,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: EvalOlatArgs) -> CliResult {
    let set = OlatSet::read(&args.dir)?;
    let keep = args.keep.unwrap_or(set.directions.len() / 2);
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
    }
    let report = evaluate_olat(&set, keep, args.images.as_deref())?;
    eprintln!("{}", olat_table(&report));
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}
