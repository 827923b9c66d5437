//! `frf merge PART... --out FIELD`: fields holding disjoint poses of the same capture and
//! settings (e.g. `frf ingest --poses P` on the machines of a farm) joined into one
//! field, chunks copied byte for byte, in pose order: the same bytes as one ingest of
//! every pose.

use std::path::PathBuf;

use clap::Args;
use frf_reflectance::FieldFile;
use frf_reflectance::container::merge_fields;

use crate::CliResult;

/// Arguments of `frf merge`.
#[derive(Args)]
pub struct MergeArgs {
    /// The parts (field files).
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// The field to write.
    #[arg(long)]
    out: PathBuf,
}

/// Runs `frf merge`.
pub fn run(args: MergeArgs) -> CliResult {
    let mut parts = Vec::with_capacity(args.parts.len());
    for p in &args.parts {
        let f = FieldFile::open(p)?;
        let first = f
            .header()
            .poses
            .iter()
            .map(|r| r.pose)
            .min()
            .ok_or_else(|| format!("{}: holds no pose", p.display()))?;
        parts.push((first, p.clone()));
    }
    parts.sort();
    let paths: Vec<PathBuf> = parts.into_iter().map(|(_, p)| p).collect();
    merge_fields(&paths, &args.out)?;
    let s = FieldFile::open(&args.out)?.stats();
    println!(
        "{} parts merged into {}: {} poses, {:.2} MB",
        paths.len(),
        args.out.display(),
        s.poses,
        std::fs::metadata(&args.out)?.len() as f64 / 1e6
    );
    Ok(())
}
