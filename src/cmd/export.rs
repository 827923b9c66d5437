//! `frf export FIELD --out walker.glb`: the walker as binary glTF for engines and the
//! web player (frf-export, docs/export.md), with what it wrote and how long it took; and
//! `frf export FIELD --sprites --out sheet.png`: a relit sprite sheet of the walk cycle.

use std::path::PathBuf;

use clap::Args;
use frf_export::{ExportOptions, Tier, ViewSelection};

use crate::CliResult;
use crate::cmd::args::{
    SunSpec, parse_env, parse_fov, parse_point, parse_radius_height, parse_size, parse_sun,
    poses_arg,
};
use frf_core::env::EnvSource;

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
    #[arg(long, default_value = "all", value_parser = parse_views, conflicts_with = "sprites")]
    views: ViewSelection,
    /// Voxel side of the hull meshes, metres (a walking silhouette for any viewer).
    #[arg(long, default_value_t = 0.02, conflicts_with = "sprites")]
    mesh_voxel: f32,
    /// The transfer's tier: `full` (nine RGB coefficients a texel) or `compact` (nine
    /// grey coefficients and a colour: a third of the transfer's bytes).
    #[arg(long, default_value = "full", value_parser = parse_tier, conflicts_with = "sprites")]
    tier: Tier,
    /// JPEG quality of the SH transfer atlases.
    #[arg(long, default_value_t = 95, conflicts_with = "sprites")]
    jpeg_quality: u8,
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

/// `--headings`: camera azimuths, degrees.
#[derive(Clone, Debug)]
pub struct Headings(Vec<f32>);

fn parse_headings(s: &str) -> Result<Headings, String> {
    if let Ok(n) = s.trim().parse::<usize>() {
        if !(1..=64).contains(&n) {
            return Err(format!("{n} headings: 1 to 64"));
        }
        return Ok(Headings(
            (0..n).map(|i| i as f32 * 360.0 / n as f32).collect(),
        ));
    }
    // A list of one heading ends with its comma (`90,`), where `90` alone is a count.
    let list = s
        .trim()
        .strip_suffix(',')
        .filter(|l| !l.contains(','))
        .unwrap_or(s);
    let headings: Vec<f32> = list
        .split(',')
        .map(|a| {
            a.trim()
                .parse::<f32>()
                .ok()
                .filter(|a| a.is_finite() && a.abs() <= 360.0)
                .ok_or_else(|| {
                    format!("{s:?}: a count of headings or a list of degrees from -360 to 360")
                })
        })
        .collect::<Result<_, _>>()?;
    // Two headings of one direction draw the same row twice.
    let turn = |a: f32| a.rem_euclid(360.0);
    for (k, &a) in headings.iter().enumerate() {
        if let Some(&b) = headings[..k].iter().find(|&&b| turn(b) == turn(a)) {
            return Err(format!("{s:?}: headings {b} and {a} are one direction"));
        }
    }
    Ok(Headings(headings))
}

/// `--sprite-size`: a frame's `WxH`, within what a sheet allows (named once, not first
/// by the general size parser's wider bound).
fn parse_sprite_size(s: &str) -> Result<(u32, u32), String> {
    let size = parse_size(s).map_err(|_| {
        format!(
            "{s:?}: expected WxH, 1 to {} pixels a side",
            frf_scene::sprites::MOST_FRAME_SIDE
        )
    })?;
    match frf_scene::sprites::frame_size_problem(size) {
        Some(problem) => Err(problem),
        None => Ok(size),
    }
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
    let views = s
        .split(';')
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
        .collect::<Result<Vec<(usize, usize)>, String>>()?;
    if let Some((k, v)) = (views.iter().enumerate()).find(|(k, v)| views[..*k].contains(v)) {
        return Err(format!(
            "{s:?}: view {},{} is given twice (the second time at place {})",
            v.0,
            v.1,
            k + 1
        ));
    }
    Ok(ViewSelection::List(views))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `--headings`: a number is a count, a list is degrees, and one heading is a list of
    /// one with its comma (`90,`: one whole-degree heading could not be asked for).
    #[test]
    fn headings_are_a_count_or_a_list_of_one_or_more() {
        assert_eq!(parse_headings("90,").unwrap().0, vec![90.0]);
        assert_eq!(parse_headings(" -45, ").unwrap().0, vec![-45.0]);
        assert_eq!(
            parse_headings("4").unwrap().0,
            vec![0.0, 90.0, 180.0, 270.0]
        );
        assert_eq!(parse_headings("0,90").unwrap().0, vec![0.0, 90.0]);
        assert!(parse_headings("0,90,").is_err());
        assert!(parse_headings(",").is_err());
    }
}
