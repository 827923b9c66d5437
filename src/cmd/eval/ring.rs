//! `frf eval-ring FIELD --par PAR --stride S`: views held out of a ring of photographs
//! rendered from their neighbours and scored against the photographs
//! ([`frf_eval::ring`]).

use frf_eval::ring::{held_out_views, ring_table, score_held_out};
use frf_reflectance::FieldFile;
use frf_render::renderer::Renderer;
use frf_render::resident::{Lighting, PoseSource};

use super::args::RingEvalArgs;
use crate::CliResult;

pub fn run(args: RingEvalArgs) -> CliResult {
    let field = FieldFile::open(&args.field)?;
    let (views, cameras, _) = frf_ingest::ring::ring_views(&args.par)?;
    let s = args.stride;
    let wraps = field.header().wraps;
    if s < 2 || views.len().div_ceil(s) != field.header().columns {
        return Err(format!(
            "{}: {} views do not come from {} views at stride {s}",
            args.field.display(),
            field.header().columns,
            views.len()
        )
        .into());
    }
    let held = held_out_views(views.len(), s, wraps)?;
    let source = PoseSource::load(&field, 0, &Lighting::Unlit)?;
    let renderer = Renderer::open(&source, args.compare.cpu)?;
    let scores = score_held_out(&renderer, &views, &cameras, &held, &args.compare.variants())?;
    let gap = if wraps {
        format!("{} apart", views.len() - (views.len() - 1) / s * s)
    } else {
        "open".into()
    };
    eprintln!(
        "{}: {} held-out views, each rendered from the kept views either side ({} apart, \
         the last gap {gap}), {}:",
        args.field.display(),
        held.len(),
        s,
        renderer.device()
    );
    eprintln!("{}", ring_table(&scores));
    if args.compare.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "field": args.field,
                "par": args.par,
                "stride": s,
                "device": renderer.device(),
                "variants": scores,
            }))?
        );
    }
    Ok(())
}
