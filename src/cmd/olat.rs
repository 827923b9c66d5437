//! `frf ingest-olat DIR --out F.frf [--use K]`: a calibrated one-light-at-a-time set as a
//! one-view field whose basis is its lights ([`frf_ingest::olat_field`]); and
//! `frf eval-olat DIR|F.frf [--photos DIR] [--use K] [--images OUT] [--json] [--diffuse]`: relighting
//! scored on the set's photographs ([`frf_eval::olat`]), from the set's own kept lights
//! or from such a field.

use std::path::PathBuf;

use clap::Args;
use frf_eval::olat::{evaluate_olat, evaluate_olat_field, olat_table};
use frf_ingest::olat::OlatSet;
use frf_reflectance::FieldFile;

use crate::CliResult;

/// What a set's directory holds, for the help of both commands.
const SET_LAYOUT: &str = "`NNN.png` (8- or 16-bit, linear), `light_directions.txt` (unit vectors, camera frame: x right, y up, z toward the camera), optional `light_intensities.txt` (`r g b` a line) and `mask.png`";

/// Arguments of `frf ingest-olat`.
#[derive(Args)]
pub struct IngestOlatArgs {
    /// The set's directory (see `frf eval-olat --help` for its layout).
    pub dir: PathBuf,
    /// The field file to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Lights kept as the basis (farthest-point sampling from the one nearest the
    /// camera); the others are held out for `frf eval-olat F.frf --photos DIR`. Default:
    /// every light.
    #[arg(long = "use", value_name = "K")]
    pub keep: Option<usize>,
    /// JPEG quality of the basis images.
    #[arg(long, default_value_t = 95, value_parser = clap::value_parser!(u8).range(1..=100))]
    pub jpeg_quality: u8,
}

/// Runs `frf ingest-olat`.
pub fn run_ingest(args: IngestOlatArgs) -> CliResult {
    let _claim = crate::cmd::claim::claim(&args.out, &[])?;
    let set = OlatSet::read(&args.dir)?;
    let r = frf_ingest::olat_field::ingest_olat(&set, &args.out, args.keep, args.jpeg_quality)?;
    println!(
        "{} of {} lights ({:?}) written to {} as one view's basis with its fitted normals: {:.2} MB in {:.1} s (wall)",
        r.kept.len(),
        r.lights,
        r.kept,
        args.out.display(),
        r.bytes as f64 / 1e6,
        r.seconds
    );
    Ok(())
}

/// Arguments of `frf eval-olat`.
#[derive(Args)]
#[command(after_help = format!("A set's directory holds {SET_LAYOUT}."))]
pub struct EvalOlatArgs {
    /// The set's directory (its kept lights predict the others), or a field written by
    /// `frf ingest-olat` (its basis predicts the lights of `--photos` it does not hold).
    pub source: PathBuf,
    /// With a field: the set's directory, whose photographs the predictions are scored
    /// against.
    #[arg(long, value_name = "DIR")]
    pub photos: Option<PathBuf>,
    /// With a directory: lights kept (farthest-point sampling from the one nearest the
    /// camera); the others are predicted from them and scored. Default: half of the set.
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
    /// With a directory: fit the diffuse model alone, without the glossy lobe (what a
    /// field's stored normals relight by).
    #[arg(long)]
    pub diffuse: bool,
}

/// Runs `frf eval-olat`.
pub fn run(args: EvalOlatArgs) -> CliResult {
    let images = args.images.as_deref();
    let report = if args.source.is_dir() {
        if let Some(photos) = &args.photos {
            return Err(format!(
                "--photos {}: scores a field file's predictions, but the first argument ({}) is \
                 a set's directory, whose own kept lights predict the others: give the set \
                 alone, or the field first (frf eval-olat F.frf --photos DIR)",
                photos.display(),
                args.source.display()
            )
            .into());
        }
        let set = OlatSet::read(&args.source)?;
        let n = set.directions.len();
        // Three kept lights fix a normal, and one light at least is held out.
        if args.keep.is_none() && n < 4 {
            return Err(frf_core::CoreError::bad_file(
                &args.source,
                format!("holds {n} lights: scoring keeps 3 (to fix a normal) and holds out the rest, so it needs 4 or more"),
            )
            .into());
        }
        let keep = args.keep.unwrap_or((n / 2).max(3));
        evaluate_olat(&set, keep, images, !args.diffuse)?
    } else {
        let Some(photos) = &args.photos else {
            return Err(format!(
                "{} is not a set's directory; as a field file it needs --photos DIR, the set \
                 whose photographs score its predictions",
                args.source.display()
            )
            .into());
        };
        if let Some(k) = args.keep {
            return Err(format!(
                "--use {k}: chooses the lights kept from a set's directory, but the first \
                 argument ({}) is a field file, whose kept lights were chosen when it was made \
                 (frf ingest-olat --use)",
                args.source.display()
            )
            .into());
        }
        let field = FieldFile::open(&args.source)?;
        evaluate_olat_field(&field, &OlatSet::read(photos)?, images)?
    };
    eprintln!("{}", olat_table(&report));
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}
