//! A field's sun relit by its views' fitted normals ([`frf_reflectance::sun_light`]),
//! as every render does, against the same sun relit by its basis (integrated over its
//! condition's cell, as fields without normals are relit), at a pose's captured views,
//! both scored against the stage's truth: what the normals gain under a sun, judged
//! through the renderer in one run (`frf eval --sun-fit`).

use frf_core::light::DirLight;
use std::path::Path;

use frf_core::image::{Image, Rgba};
use frf_core::io::write_png8_srgba;
use frf_core::progress::Progress;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_render::morph::Variant;
use frf_render::renderer::Renderer;
use frf_render::resident::{Lighting, PoseSource};
use frf_stage::Stage;
use serde::Serialize;

use crate::error::{EvalError, Result};
use crate::views::{VariantScore, evaluate, grid_view_cameras, truth_frames};

/// The two relightings' scores at the captured views.
#[derive(Debug, Clone, Serialize)]
pub struct SunFitReport {
    /// The sun by the basis alone.
    pub basis: VariantScore,
    /// The sun by the views' fitted normals.
    pub fit: VariantScore,
    /// The suns found in the lighting and relit by the normals.
    pub suns: usize,
}

/// Scores `source` (pose `pose` of `field` under `lighting`, whose environment holds a
/// sun and whose views hold their normals) at `cameras` captured views, its sun by the
/// normals and by the basis, against the truth lit by `lights`; on the CPU reference
/// when `cpu`; each view's truth and both renders written as PNGs into `images` when
/// given (`view{i}_{truth,basis,fit}.png`).
#[allow(clippy::too_many_arguments)]
pub fn score_sun_fit<R: ReadAt>(
    field: &FieldFile<R>,
    source: &PoseSource,
    lighting: &Lighting,
    (stage, pose, lights): (&Stage, u32, &[DirLight]),
    cameras: usize,
    (cpu, images): (bool, Option<&Path>),
    progress: &dyn Progress,
) -> Result<SunFitReport> {
    if source.suns.is_empty() {
        let why = if source.holds_normals() {
            "an environment with a sun (--sun, or a map with one)"
        } else {
            "a field whose views hold fitted normals (written since they were; this one has none)"
        };
        return Err(EvalError::Argument(frf_core::BadArgument::new(
            "--sun-fit",
            field.path().display(),
            why,
        )));
    }
    let basis_only = PoseSource {
        normals: std::sync::Arc::new(vec![Vec::new(); source.normals.len()]),
        ..source.clone()
    }
    .relit(field, lighting, None)?;
    let at_views = grid_view_cameras(&source.geometry, cameras)?;
    let all: Vec<_> = at_views.iter().map(|c| c.camera).collect();
    progress.phase("truth frames", all.len());
    let (truths, _) = truth_frames(stage, pose, &all, lights, progress)?;
    progress.finish();
    let write = |i: usize, what: &str, img: &Image<Rgba>| match images {
        Some(dir) => Ok(write_png8_srgba(
            &dir.join(format!("view{i:02}_{what}.png")),
            img,
            1.0,
        )?),
        None => Ok(()),
    };
    for (i, t) in truths.iter().enumerate() {
        write(i, "truth", t)?;
    }
    let score = |src: &PoseSource, name: &str| -> Result<VariantScore> {
        let renderer = Renderer::open(src, cpu)?;
        let what = if name.contains("basis") {
            "basis"
        } else {
            "fit"
        };
        let mut s = evaluate(
            &renderer,
            &at_views,
            &truths,
            &[Variant::FourWay],
            &mut |i, _, img| write(i, what, img),
        )?
        .remove(0);
        s.name = name.into();
        Ok(s)
    };
    Ok(SunFitReport {
        basis: score(&basis_only, "sun by the basis")?,
        fit: score(source, "sun by the normals")?,
        suns: source.suns.len(),
    })
}
