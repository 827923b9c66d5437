//! `frf info FIELD [--json]`: what a field file holds, bytes by kind, and its
//! compression ratios; `frf info FIELD --check`: every chunk read, its checksum compared
//! and decoded (exit 3 naming the first damaged chunk and counting the rest); `frf info
//! --gpu [--json]`: the GPU adapters, what each lacks to run
//! the renderer's passes, and which one renders and why.

use std::path::PathBuf;

use clap::Args;
use frf_reflectance::FieldFile;
use frf_render::gpu::adapter;

use crate::CliResult;

/// Arguments of `frf info`.
#[derive(Args)]
pub struct InfoArgs {
    /// A field file.
    #[arg(required_unless_present = "gpu")]
    field: Option<PathBuf>,
    /// List the GPU adapters, what each lacks to run the renderer's passes, and which one
    /// renders and why.
    #[arg(long, conflicts_with = "field")]
    gpu: bool,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Read every chunk of the field, compare its checksum and decode it: exit 3 naming
    /// the first damaged chunk (and counting the others) if any is.
    #[arg(long, conflicts_with = "gpu")]
    check: bool,
}

/// `frf info FIELD --check`.
fn check(path: &std::path::Path, field: &FieldFile, json: bool) -> CliResult {
    let bar = frf_core::bars::bar("chunks checked");
    bar.set_length(field.chunks().count() as u64);
    let v = field.verify(&|| bar.inc(1))?;
    bar.finish_and_clear();
    if json {
        println!("{}", serde_json::to_string_pretty(&v)?);
    }
    if let Some(e) = v.error(path) {
        return Err(e.into());
    }
    if !json {
        println!(
            "{}: all {} chunks whole ({:.2} MB read, checksums compared, each decoded)",
            path.display(),
            v.chunks,
            v.bytes as f64 / 1e6
        );
    }
    Ok(())
}

/// Runs `frf info`.
pub fn run(args: InfoArgs) -> CliResult {
    let Some(path) = &args.field else {
        return gpu(args.json);
    };
    let field = FieldFile::open(path)?;
    if args.check {
        return check(path, &field, args.json);
    }
    let s = field.stats();
    if args.json {
        println!("{}", serde_json::to_string_pretty(&s)?);
        return Ok(());
    }
    println!("{}", field.describe());
    Ok(())
}

/// `frf info --gpu`: the adapters and the choice (or why none can render, with a failing
/// status).
fn gpu(json: bool) -> CliResult {
    let (found, choice) = adapter::survey();
    if !json {
        println!("GPU adapters, preferred first:");
        for c in &found {
            if c.lacks.is_empty() {
                println!("  {}: can run every pass", c.adapter);
            } else {
                println!("  {}: lacks {}", c.adapter, c.lacks.join(", "));
            }
        }
    }
    let report = choice?;
    if json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!(
            "renders on: {} ({}, {}), driver {}; {}",
            report.name, report.backend, report.device_type, report.driver, report.why
        );
    }
    Ok(())
}
