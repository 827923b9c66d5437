//! `frf merge PART... --out FIELD`: fields holding disjoint poses of the same capture and
//! settings (e.g. `frf ingest --poses P` on the machines of a farm) joined into one
//! field, chunks copied byte for byte, in pose order: the same bytes as one ingest of
//! every pose. It says which poses the result holds; with `--expect` (a pose list, or the
//! capture directory the parts were ingested from) a missing pose is refused by number
//! before anything is written.

use std::path::PathBuf;

use clap::Args;
use frf_reflectance::FieldFile;
use frf_reflectance::merge::merge_parts;

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
    /// The poses the result must hold: `0,3,6`, `0..30`, or a capture directory (its
    /// poses, or those it filmed).
    #[arg(long)]
    expect: Option<String>,
}

/// The poses `--expect` names, and where they come from.
fn expected(spec: &str) -> CliResult<(Vec<u32>, String)> {
    let dir = std::path::Path::new(spec);
    if dir.is_dir() {
        let capture = frf_core::capture::Capture::open_manifest(dir)?;
        return Ok((capture.poses().to_vec(), format!("the capture {spec}")));
    }
    let poses = crate::cmd::args::parse_poses(spec).map_err(|e| {
        frf_core::BadArgument::new("--expect", spec, e + ", or a capture directory")
    })?;
    Ok((poses, format!("--expect {spec}")))
}

/// Runs `frf merge`.
pub fn run(args: MergeArgs) -> CliResult {
    let expect = args.expect.as_deref().map(expected).transpose()?;
    let _claim = crate::cmd::claim::claim(&args.out, &[])?;
    let expected = expect
        .as_ref()
        .map(|(p, from)| (p.as_slice(), from.as_str()));
    let held = merge_parts(&args.parts, &args.out, expected)?;
    let s = FieldFile::open(&args.out)?.stats();
    println!(
        "{} parts merged into {}: {} poses {held:?}{}, {:.2} MB",
        args.parts.len(),
        args.out.display(),
        s.poses,
        match &expect {
            Some((poses, from)) => format!(" (every one of the {} {from} expects)", poses.len()),
            None => " (give --expect to check that none is missing)".into(),
        },
        std::fs::metadata(&args.out)?.len() as f64 / 1e6
    );
    Ok(())
}
