//! `frf export FIELD --out walker.glb`: the walker as binary glTF for engines and the
//! web player (frf-export, docs/export.md), with what it wrote and how long it took.

use std::path::PathBuf;

use clap::Args;
use frf_export::{ExportOptions, Tier, ViewSelection};

use crate::CliResult;
use crate::cmd::args::parse_poses;

/// Arguments of `frf export`.
#[derive(Args)]
pub struct ExportArgs {
    /// A field file (`frf ingest`, `frf stage field`).
    field: PathBuf,
    /// Output `.glb`.
    #[arg(long)]
    out: PathBuf,
    /// Poses, e.g. `0,1` or `0..4` (default: all of the field's).
    #[arg(long)]
    poses: Option<String>,
    /// Views: `all`, `ring:V` (camera row V all the way round) or a list `U,V;U,V;...`.
    #[arg(long, default_value = "all", value_parser = parse_views)]
    views: ViewSelection,
    /// Voxel side of the hull meshes, metres (a walking silhouette for any viewer).
    #[arg(long, default_value_t = 0.02)]
    mesh_voxel: f32,
    /// The transfer's tier: `full` (nine RGB coefficients a texel) or `compact` (nine
    /// grey coefficients and a colour: a third of the transfer's bytes).
    #[arg(long, default_value = "full", value_parser = parse_tier)]
    tier: Tier,
    /// JPEG quality of the SH transfer atlases.
    #[arg(long, default_value_t = 95)]
    jpeg_quality: u8,
    /// Also print the report as JSON.
    #[arg(long)]
    json: bool,
}

fn parse_tier(s: &str) -> Result<Tier, String> {
    match s {
        "full" => Ok(Tier::Full),
        "compact" => Ok(Tier::Compact),
        other => Err(format!("{other:?}: expected full or compact")),
    }
}

fn parse_views(s: &str) -> Result<ViewSelection, String> {
    if s == "all" {
        return Ok(ViewSelection::All);
    }
    if let Some(v) = s.strip_prefix("ring:") {
        return v
            .parse()
            .map(ViewSelection::Ring)
            .map_err(|_| format!("ring:{v}: expected a camera row number"));
    }
    s.split(';')
        .map(|p| {
            let (u, v) = p
                .split_once(',')
                .ok_or_else(|| format!("{p:?}: expected U,V"))?;
            Ok((
                u.trim()
                    .parse()
                    .map_err(|_| format!("{p:?}: expected U,V"))?,
                v.trim()
                    .parse()
                    .map_err(|_| format!("{p:?}: expected U,V"))?,
            ))
        })
        .collect::<Result<Vec<_>, String>>()
        .map(ViewSelection::List)
}

/// Runs `frf export`.
pub fn run(args: ExportArgs) -> CliResult {
    let poses = args
        .poses
        .as_deref()
        .map(parse_poses)
        .transpose()
        .map_err(|e| {
            frf_core::BadArgument::new("--poses", args.poses.as_deref().unwrap_or(""), e)
        })?;
    let options = ExportOptions {
        tier: args.tier,
        poses,
        views: args.views,
        mesh_voxel_m: args.mesh_voxel,
        jpeg_quality: args.jpeg_quality,
    };
    let report = frf_export::export(&args.field, &args.out, &options)?;
    let field_bytes = std::fs::metadata(&args.field).map(|m| m.len()).unwrap_or(0);
    println!(
        "{} written: {} pose(s), {} view(s) in all, {:.2} MB ({:.2}x the field's {:.2} MB), in {:.1} s",
        args.out.display(),
        report.poses,
        report.views,
        report.bytes as f64 / 1e6,
        report.bytes as f64 / field_bytes.max(1) as f64,
        field_bytes as f64 / 1e6,
        report.seconds
    );
    for (name, bytes) in &report.section_bytes {
        println!("  {name:<9} {:>8.2} MB", *bytes as f64 / 1e6);
    }
    println!("  hull meshes: {} triangles", report.triangles);
    for note in &report.notes {
        eprintln!("note: {note}");
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}
