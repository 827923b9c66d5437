//! The edge-aware weighted median of Classic+NL (Sun, Roth & Black, CVPR 2010, §5):
//! near motion boundaries, each flow component is replaced by the weighted median of
//! its `(2r+1)²` neighbourhood, a neighbour `n` of `s` weighing
//! `exp(−|n − s|² / 2σ_s² − |I(n) − I(s)|² / 2σ_c²)` — pixels of similar colour in the
//! first image vote more, so flow edges snap to image edges. (Sun et al. also weigh by
//! an occlusion estimate; that factor is left out here.) As in their implementation, the
//! costly weighted median runs only in a band around motion boundaries; the plain 5x5
//! median ([`crate::median`]) handles the rest.

use frf_core::image::{FlowImage, Image};
use rayon::prelude::*;

/// Spatial σ_s of the weights, pixels (Sun et al.: σ₁ = 7).
const SIGMA_SPATIAL: f32 = 7.0;
/// Colour σ_c per channel, in the units of the normalised planes (Sun et al.: σ₂ = 7 on
/// the [0, 255] scale that [`crate::texture::DATA_SCALE`] mimics).
const SIGMA_COLOUR: f32 = 7.0;
/// A pixel is at a motion boundary when a 4-neighbour's flow differs by more than this
/// (pixels, `|Δu| + |Δv|`): a quarter pixel, below the EPE that matters at boundaries
/// yet above the smooth variation of most flow fields (measured on Middlebury GT:
/// <5% of pixels exceed it away from boundaries).
const BOUNDARY_STEP_PX: f32 = 0.25;

/// The first image of a level, as the colour guide of the weighted median.
pub(crate) struct Guide {
    pub width: usize,
    pub height: usize,
    /// Planes in the units of the normalised images.
    pub planes: Vec<Vec<f32>>,
}

/// The flow with pixels within `radius` of a motion boundary replaced by their
/// edge-aware weighted median.
pub(crate) fn weighted_median_near_edges(
    flow: &FlowImage,
    guide: &Guide,
    radius: usize,
) -> FlowImage {
    let (w, h) = flow.size();
    if (guide.width, guide.height) != (w, h) || w * h == 0 {
        return flow.clone();
    }
    let f = flow.pixels();
    let band = boundary_band(flow, radius);
    let channels = guide.planes.len().max(1) as f32;
    let colour_k = 1.0 / (2.0 * SIGMA_COLOUR * SIGMA_COLOUR * channels);
    let spatial_k = 1.0 / (2.0 * SIGMA_SPATIAL * SIGMA_SPATIAL);
    let mut out = f.to_vec();
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let mut cand: Vec<(f32, f32)> = Vec::new();
        let mut cand_v: Vec<(f32, f32)> = Vec::new();
        for (x, o) in row.iter_mut().enumerate() {
            if !band[y * w + x] {
                continue;
            }
            let s = y * w + x;
            cand.clear();
            cand_v.clear();
            let (y0, y1) = (y.saturating_sub(radius), (y + radius).min(h - 1));
            let (x0, x1) = (x.saturating_sub(radius), (x + radius).min(w - 1));
            for yy in y0..=y1 {
                for xx in x0..=x1 {
                    let n = yy * w + xx;
                    let (dx, dy) = (xx as f32 - x as f32, yy as f32 - y as f32);
                    let mut dc = 0.0;
                    for p in &guide.planes {
                        let d = p[n] - p[s];
                        dc += d * d;
                    }
                    let wgt = (-(dx * dx + dy * dy) * spatial_k - dc * colour_k).exp();
                    cand.push((f[n][0], wgt));
                    cand_v.push((f[n][1], wgt));
                }
            }
            *o = [weighted_median(&mut cand), weighted_median(&mut cand_v)];
        }
    });
    Image::from_vec(w, h, out).unwrap_or_else(|_| flow.clone())
}

/// The value where the cumulative weight of the sorted values first reaches half.
fn weighted_median(values: &mut [(f32, f32)]) -> f32 {
    values.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let total: f32 = values.iter().map(|v| v.1).sum();
    let mut acc = 0.0;
    for &(v, wgt) in values.iter() {
        acc += wgt;
        if acc >= 0.5 * total {
            return v;
        }
    }
    values.last().map_or(0.0, |v| v.0)
}

/// Pixels within `radius` (Chebyshev) of a motion boundary.
fn boundary_band(flow: &FlowImage, radius: usize) -> Vec<bool> {
    let (w, h) = flow.size();
    let f = flow.pixels();
    let step =
        |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() > BOUNDARY_STEP_PX;
    let edge: Vec<bool> = (0..w * h)
        .into_par_iter()
        .map(|s| {
            let (x, y) = (s % w, s / w);
            (x + 1 < w && step(f[s], f[s + 1])) || (y + 1 < h && step(f[s], f[s + w]))
        })
        .collect();
    // Separable dilation: rows, then columns.
    let mut rows = vec![false; w * h];
    rows.par_chunks_mut(w).enumerate().for_each(|(y, r)| {
        let e = &edge[y * w..(y + 1) * w];
        let mut last: Option<usize> = None;
        for x in 0..w {
            if e[x] {
                last = Some(x);
            }
            r[x] = last.is_some_and(|l| x - l <= radius);
        }
        let mut next: Option<usize> = None;
        for x in (0..w).rev() {
            if e[x] {
                next = Some(x);
            }
            r[x] |= next.is_some_and(|n| n - x <= radius);
        }
    });
    let mut band = vec![false; w * h];
    band.par_chunks_mut(w).enumerate().for_each(|(y, b)| {
        let (y0, y1) = (y.saturating_sub(radius), (y + radius).min(h - 1));
        for (x, o) in b.iter_mut().enumerate() {
            *o = (y0..=y1).any(|yy| rows[yy * w + x]);
        }
    });
    band
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flow_edge_snaps_to_the_image_edge() {
        // The image edge is at x = 10 | 11; the flow edge was estimated one pixel early.
        let (w, h) = (24, 12);
        let guide = Guide {
            width: w,
            height: h,
            planes: vec![
                (0..w * h)
                    .map(|i| if i % w <= 10 { 0.0 } else { 60.0 })
                    .collect(),
            ],
        };
        let flow = Image::from_fn(w, h, |x, _| if x <= 9 { [0.0f32, 0.0] } else { [2.0, 1.0] });
        let out = weighted_median_near_edges(&flow, &guide, 3);
        for y in 0..h {
            assert_eq!(out.get(10, y), [0.0, 0.0], "row {y}");
            assert_eq!(out.get(11, y), [2.0, 1.0]);
            assert_eq!(out.get(2, y), [0.0, 0.0]);
        }
    }

    #[test]
    fn weighted_median_follows_the_weights() {
        let mut v = vec![(1.0, 0.1), (5.0, 1.0), (3.0, 0.2)];
        assert_eq!(weighted_median(&mut v), 5.0);
        let mut v = vec![(1.0, 1.0), (5.0, 1.0), (3.0, 1.0)];
        assert_eq!(weighted_median(&mut v), 3.0);
    }
}
