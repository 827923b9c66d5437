//! Views held out of a ring of real photographs (Middlebury multi-view), rendered from
//! their neighbours and scored against the photographs inside the photograph's
//! silhouette: the renderer judged on real data. The field is ingested with
//! `frf ingest-ring --stride S`, which keeps every `S`-th view; the view halfway between
//! two kept views is the one held out.

use std::time::Instant;

use frf_core::camera::Camera;
use frf_core::io::rgba_from;
use frf_ingest::ring::{RingView, photo_and_alpha};
use frf_render::morph::Variant;
use frf_render::renderer::Renderer;
use rayon::prelude::*;
use serde::Serialize;

use crate::error::{EvalError, Result};
use crate::metrics::{alpha_mask, psnr, ssim};

/// One variant's scores over the held-out views.
#[derive(Debug, Clone, Serialize)]
pub struct RingScore {
    /// The variant.
    pub name: String,
    /// Mean PSNR (dB) inside the photographs' silhouettes.
    pub psnr_silhouette: f64,
    /// Mean SSIM there.
    pub ssim_silhouette: f64,
    /// Mean seconds per frame.
    pub seconds_per_frame: f64,
    /// The held-out views (indices in azimuth order).
    pub views: Vec<usize>,
    /// PSNR per held-out view.
    pub psnr_per_view: Vec<f64>,
}

/// The views held out of a ring of `views` views ingested at `stride` (kept: every
/// `stride`-th view from the first): between each two successive kept views (and, when
/// the ring closes, between the last and the first) that have views between them, the
/// one halfway (the earlier of two at odd strides). Any number of views and any stride
/// from 2: an uneven last gap gets its own halfway view.
pub fn held_out_views(views: usize, stride: usize, wraps: bool) -> Result<Vec<usize>> {
    if stride < 2 || views.div_ceil(stride.max(1)) < 2 {
        let allowed = format!("2 or more, leaving a view out between two kept ones of {views}");
        return Err(frf_core::BadArgument::new("--stride", stride, allowed).into());
    }
    let kept: Vec<usize> = (0..views).step_by(stride).collect();
    let mut held = Vec::new();
    for (j, &k) in kept.iter().enumerate() {
        let next = match kept.get(j + 1) {
            Some(&n) => n,
            None if wraps => views,
            None => break,
        };
        if next - k >= 2 {
            held.push(k + (next - k) / 2);
        }
    }
    Ok(held)
}

/// Renders each held-out view `held` (indices into `views` and `cameras`, the whole
/// ring's) with every variant and scores it against its photograph.
pub fn score_held_out(
    renderer: &Renderer,
    views: &[RingView],
    cameras: &[Camera],
    held: &[usize],
    variants: &[Variant],
) -> Result<Vec<RingScore>> {
    let Some(&first) = held.first() else {
        return Err(EvalError::NoTruth("no view is held out".into()));
    };
    let photos = held
        .par_iter()
        .map(|&i| {
            let (photo, alpha) = photo_and_alpha(&views[i].path)?;
            Ok((rgba_from(&photo, &alpha)?, alpha_mask(&alpha)))
        })
        .collect::<Result<Vec<_>>>()?;
    // One untimed frame first: pipeline compilation and caches.
    renderer.render(&cameras[first], Variant::FourWay)?;
    variants
        .iter()
        .map(|&v| {
            let (mut psnrs, mut ssims, mut seconds) = (Vec::new(), Vec::new(), 0.0);
            for (&i, (photo, mask)) in held.iter().zip(&photos) {
                let t = Instant::now();
                let (img, _) = renderer.render(&cameras[i], v)?;
                seconds += t.elapsed().as_secs_f64();
                psnrs.push(psnr(photo, &img, Some(mask)));
                ssims.push(ssim(photo, &img, Some(mask)));
            }
            let n = held.len() as f64;
            Ok(RingScore {
                name: v.name().to_string(),
                psnr_silhouette: psnrs.iter().sum::<f64>() / n,
                ssim_silhouette: ssims.iter().sum::<f64>() / n,
                seconds_per_frame: seconds / n,
                views: held.to_vec(),
                psnr_per_view: psnrs,
            })
        })
        .collect()
}

/// The held-out views' scores as a table for a person, a line per variant.
pub fn ring_table(scores: &[RingScore]) -> String {
    let mut lines = Vec::new();
    lines.push(format!(
        "{:<18} {:>17} {:>17} {:>9}",
        "variant", "PSNR silhouette", "SSIM silhouette", "s/frame"
    ));
    for r in scores {
        lines.push(format!(
            "{:<18} {:>14.2} dB {:>17.4} {:>9.4}",
            r.name, r.psnr_silhouette, r.ssim_silhouette, r.seconds_per_frame
        ));
    }
    lines.join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_out_views_lie_halfway_between_kept_ones() {
        assert_eq!(held_out_views(48, 2, true).unwrap().len(), 24);
        assert_eq!(&held_out_views(48, 4, true).unwrap()[..3], &[2, 6, 10]);
        // An open ring of 10 views at stride 4 keeps 0, 4, 8: 2 and 6 lie between them.
        assert_eq!(held_out_views(10, 4, false).unwrap(), vec![2, 6]);
        // Any stride, any number of views: odd strides take the earlier middle view, an
        // uneven closing gap its own.
        assert_eq!(held_out_views(9, 3, true).unwrap(), vec![1, 4, 7]);
        assert_eq!(held_out_views(11, 4, true).unwrap(), vec![2, 6, 9]);
        assert_eq!(held_out_views(11, 4, false).unwrap(), vec![2, 6]);
        assert_eq!(held_out_views(9, 2, true).unwrap(), vec![1, 3, 5, 7]);
        let e = held_out_views(48, 1, true).unwrap_err().to_string();
        assert!(e.contains("stride 1"), "{e}");
    }
}
