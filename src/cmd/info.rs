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
    let bar = crate::cmd::progress::bar("chunks checked");
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
    let h = field.header();
    let mb = |b: u64| b as f64 / 1e6;
    println!("{}", path.display());
    println!("  source: {}", h.description);
    println!(
        "  grid: {} x {} views ({}), {}x{} pixels, {} basis conditions ({} floor)",
        h.columns,
        h.rows,
        if h.wraps { "closed ring" } else { "open" },
        h.width,
        h.height,
        h.conditions.len(),
        h.conditions.iter().filter(|c| c.floor).count()
    );
    println!(
        "  poses: {:?}",
        h.poses.iter().map(|p| p.pose).collect::<Vec<_>>()
    );
    for p in &h.poses {
        println!(
            "  pose {}: flow log quantizer s = {:.4} px, M = {:.2} px",
            p.pose, p.flow_quantizer.scale, p.flow_quantizer.range
        );
    }
    let predicted = if h.flow_predicted {
        "predicted from neighbours"
    } else {
        "not predicted"
    };
    println!("  flow codes: {predicted}");
    println!("  JPEG quality: {}", h.jpeg_quality);
    println!("  bytes by kind (MB):");
    for (kind, b) in [
        ("basis images", s.bytes.images),
        ("flow maps", s.bytes.flow),
        ("pose flow maps", s.bytes.pose_flow),
        ("alpha", s.bytes.alpha),
        ("shadow maps", s.bytes.shadows),
        ("visual hulls", s.bytes.hulls),
        ("index and framing", s.bytes.other),
    ] {
        println!("    {kind:<18} {:>10.3}", mb(b));
    }
    println!(
        "  flow: {} maps, {:.1} % of their 8-bit quantized size",
        s.flow_maps,
        100.0 * s.flow_ratio_vs_8bit
    );
    println!(
        "  pose-to-pose flow: {} maps (to the next and the previous captured pose of each view)",
        s.pose_flow_maps
    );
    println!(
        "  basis images: {} images, {:.1}:1 against 16-bit linear RGB",
        s.basis_images, s.image_ratio_vs_16bit
    );
    match &h.shadows {
        Some(spec) => println!(
            "  shadows: {} maps ({} conditions per pose), {} x {} texels over {} m x {} m",
            s.shadow_maps,
            spec.conditions.len(),
            spec.ground.texels,
            spec.ground.texels,
            spec.ground.extent_m,
            spec.ground.extent_m
        ),
        None => println!("  shadows: none"),
    }
    match &h.hulls {
        Some(spec) => println!(
            "  visual hulls: {} ({} m voxels, {} views may disagree)",
            s.hulls, spec.voxel_m, spec.misses
        ),
        None => println!("  visual hulls: none"),
    }
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
