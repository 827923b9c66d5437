//! `frf export FIELD --out walker.glb`: the walker as binary glTF for engines and the
//! web player (frf-export, docs/export.md), with what it wrote and how long it took; and
//! `frf export FIELD --sprites --out sheet.png`: a relit sprite sheet of the walk cycle.

use std::path::PathBuf;

use clap::Args;
use frf_export::{ExportOptions, Textures, Tier, ViewSelection};

use crate::CliResult;
use crate::cmd::args::{
    SunSpec, parse_env, parse_fov, parse_point, parse_radius_height, parse_sun, poses_arg,
};
use frf_core::env::EnvSource;
use frf_scene::text::{Headings, parse_headings, parse_sprite_size};

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
    #[arg(long, default_value = "all", value_parser = <ViewSelection as std::str::FromStr>::from_str, conflicts_with = "sprites")]
    views: ViewSelection,
    /// Voxel side of the hull meshes, metres (a walking silhouette for any viewer).
    #[arg(long, default_value_t = 0.02, conflicts_with = "sprites")]
    mesh_voxel: f32,
    /// The transfer's tier: `full` (nine RGB coefficients a texel) or `compact` (nine
    /// grey coefficients and a colour: a third of the transfer's bytes).
    #[arg(long, default_value = "full", value_parser = <Tier as std::str::FromStr>::from_str, conflicts_with = "sprites")]
    tier: Tier,
    /// How the SH transfer atlases are stored: `jpeg` (grey JPEGs, one a
    /// channel: the smallest file) or `ktx2` (one GPU-compressed KTX2 image of UASTC
    /// blocks a view, which a player keeps compressed on its GPU).
    #[arg(long, default_value = "jpeg", value_parser = <Textures as std::str::FromStr>::from_str, conflicts_with = "sprites")]
    textures: Textures,
    /// How the basis atlases are stored (`--basis`): `jpeg` or `ktx2`, as `--textures`.
    #[arg(long, default_value = "jpeg", value_parser = <Textures as std::str::FromStr>::from_str, requires = "basis", conflicts_with = "sprites")]
    basis_textures: Textures,
    /// JPEG quality of the SH transfer atlases (and the basis'), `--textures jpeg`.
    #[arg(long, default_value_t = 95, conflicts_with = "sprites")]
    jpeg_quality: u8,
    /// Also write each view's basis images (one per lighting condition, about three
    /// times the transfer's bytes): what a player relights a sun by as frf does, with
    /// frf's trust, instead of the albedo and normal alone.
    #[arg(long, conflicts_with = "sprites")]
    basis: bool,
    /// Also print the report as JSON.
    #[arg(long)]
    json: bool,
    /// Write a relit sprite sheet instead (`--out` the PNG; its JSON beside it): the
    /// walk cycle's poses in columns, one row per heading.
    #[arg(long)]
    sprites: bool,
    /// Sprites: the light, an environment (.hdr/.exr), `sky`, `uniform` or an L2 file
    /// of `frf env-sh`.
    #[arg(long, value_parser = parse_env, default_value = "sky", requires = "sprites")]
    env: EnvSource,
    /// Sprites: a sun added to the light, `AZ,EL[,DIAM[,E]]` as `frf render --sun`.
    #[arg(long, value_parser = parse_sun, allow_hyphen_values = true, value_name = "AZ,EL[,DIAM[,E]]", requires = "sprites")]
    sun: Option<SunSpec>,
    /// Sprites: `N` headings evenly round the walker from azimuth 0, or a list of camera
    /// azimuths in degrees (`0,90,180,270`; one heading as a list of one: `90,`; 0 on +z,
    /// 90 on +x: the stage's walker walks toward +x, so 0 sees its right side and 90 its
    /// front).
    #[arg(long, default_value = "8", value_parser = parse_headings, requires = "sprites")]
    headings: Headings,
    /// Sprites: a frame's size `WxH`.
    #[arg(long, default_value = "128x180", value_parser = parse_sprite_size, requires = "sprites")]
    sprite_size: (u32, u32),
    /// Sprites: the cameras' `RADIUS,HEIGHT` about the walker, metres.
    #[arg(long, default_value = "3.2,1.1", value_parser = parse_radius_height, requires = "sprites")]
    sprite_orbit: (f32, f32),
    /// Sprites: the point looked at, `x,y,z` metres.
    #[arg(long, default_value = "0,0.9,0", value_parser = parse_point, allow_hyphen_values = true, requires = "sprites")]
    look_at: [f32; 3],
    /// Sprites: vertical field of view, degrees.
    #[arg(long, default_value_t = 35.0, value_parser = parse_fov, requires = "sprites")]
    fov: f32,
    /// Sprites: exposure of the sheet, stops.
    #[arg(
        long,
        default_value_t = 0.0,
        allow_negative_numbers = true,
        requires = "sprites"
    )]
    exposure: f32,
    /// Sprites: render with the CPU reference instead of the GPU.
    #[arg(long, requires = "sprites")]
    cpu: bool,
}

/// Runs `frf export`.
pub fn run(args: ExportArgs) -> CliResult {
    let poses = (args.poses.as_deref())
        .map(|p| poses_arg("--poses", p))
        .transpose()?;
    // An output named for the other mode's file (a sheet written as walk.glb, a glTF as
    // sheet.png) is refused; a name without an extension (a device) is taken as it is.
    let (wanted, other) = if args.sprites {
        ("png", "a sprite sheet is a PNG (drop --sprites for a .glb)")
    } else {
        (
            "glb",
            "a walker is written as binary glTF (add --sprites for a PNG sheet)",
        )
    };
    crate::cmd::args::expect_out_extension(&args.out, wanted, other)?;
    if args.sprites {
        return sprites(&args, poses);
    }
    let options = ExportOptions {
        tier: args.tier,
        poses,
        views: args.views,
        mesh_voxel_m: args.mesh_voxel,
        textures: args.textures,
        basis_textures: args.basis_textures,
        jpeg_quality: args.jpeg_quality,
        basis: args.basis,
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
    for e in &report.atlas_error {
        println!(
            "  {} atlases ({}) as a reader decodes them: {:.2} codes RMS ({:.1} dB PSNR, the worst view's {:.1}), at most {} codes off",
            e.atlas, e.mime, e.rms_codes, e.psnr_db, e.worst_view_psnr_db, e.largest_codes
        );
    }
    for note in &report.notes {
        eprintln!("note: {note}");
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}

/// `frf export --sprites`.
fn sprites(args: &ExportArgs, poses: Option<Vec<u32>>) -> CliResult {
    let options = frf_scene::sprites::SpriteOptions {
        env: args.env.clone(),
        sun: args.sun.as_ref().map(SunSpec::sun).transpose()?,
        headings_deg: args.headings.0.clone(),
        poses,
        frame_size: args.sprite_size,
        radius_m: args.sprite_orbit.0,
        height_m: args.sprite_orbit.1,
        look_at: glam::Vec3::from_array(args.look_at),
        fov_deg: args.fov,
        exposure_stops: args.exposure,
        cpu: args.cpu,
    };
    let r = frf_scene::sprites::sprite_sheet(&args.field, &args.out, &options)?;
    println!(
        "{} written ({}x{} pixels: {} heading(s) x {} pose(s) of {}x{}) and {}, in {:.1} s",
        r.image.display(),
        r.width,
        r.height,
        r.rows,
        r.columns,
        args.sprite_size.0,
        args.sprite_size.1,
        r.json.display(),
        r.seconds
    );
    if args.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    }
    Ok(())
}
