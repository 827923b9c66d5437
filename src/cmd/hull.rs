//! `frf hull FIELD [--pose P] --out HULL.ply`: a pose's visual hull as a mesh for other
//! tools (the surface of its voxels, binary PLY, metres, subject frame, `+y` up), with
//! its size.

use std::path::PathBuf;

use clap::Args;
use frf_reflectance::{FieldFile, ReflectanceError};

use crate::CliResult;

/// Arguments of `frf hull`.
#[derive(Args)]
pub struct HullArgs {
    /// A field file with visual hulls (`frf ingest`, `frf stage field`).
    field: PathBuf,
    /// Pose (default: the field's first).
    #[arg(long)]
    pose: Option<u32>,
    /// Output mesh (`.ply`).
    #[arg(long)]
    out: PathBuf,
}

/// Runs `frf hull`.
pub fn run(args: HullArgs) -> CliResult {
    let field = FieldFile::open(&args.field)?;
    let pose = field.pose_or_first(args.pose)?;
    let hull = field.hull(pose)?.ok_or_else(|| ReflectanceError::Missing {
        file: args.field.clone(),
        what: format!("pose {pose} has no visual hull (ingest it without --no-shadows)"),
    })?;
    hull.write_ply(&args.out)?;
    println!(
        "visual hull of pose {pose}: {}; mesh written to {}",
        hull.describe(),
        args.out.display()
    );
    Ok(())
}
