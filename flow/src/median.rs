//! Median filtering of the flow between warps, the step Sun, Roth & Black ("Secrets of
//! optical flow", CVPR 2010) found to matter most: a 5x5 median of each component
//! after every warp removes the outliers that the linearisation produces and that
//! robust penalties alone leave in place.
//!
//! The window is clipped at the image edges (the median of the pixels inside). Each
//! component is filtered on its own, as in Sun et al.
//!
//! Speed: a general selection costs a few hundred cycles per pixel, which made the 5x5
//! median a quarter of the estimator's time (measured with `perf` on Middlebury).
//! Interior pixels of the 3x3 and 5x5 cases therefore go through a fixed compare-exchange
//! network, eight pixels at a time so that the compiler vectorises it: Batcher's
//! odd–even merge sort of 16 or 32 wires (Knuth, TAOCP vol. 3, §5.3.4), the padding wires
//! held at +∞, pruned at compile time to the comparators that can reach the middle
//! output. Edge pixels use the general selection.

use frf_core::image::{FlowImage, Image};
use rayon::prelude::*;

/// Pixels filtered together by a network.
const LANES: usize = 8;

/// Batcher's odd–even merge sort on `wires` wires (a power of two), then pruned for the
/// median of `window` values: comparators whose upper wire holds +∞ (a padding wire
/// never moved) do nothing, and comparators that cannot influence wire `window / 2` are
/// dropped. Returns the comparators and their count.
const fn median_network(window: usize, wires: usize) -> ([(u8, u8); 256], usize) {
    let mut all = [(0u8, 0u8); 256];
    let mut n = 0;
    let mut p = 1;
    while p < wires {
        let mut k = p;
        while k >= 1 {
            let mut j = k % p;
            while j + k < wires {
                let mut i = 0;
                while i < k && i + j + k < wires {
                    if (i + j) / (2 * p) == (i + j + k) / (2 * p) {
                        all[n] = ((i + j) as u8, (i + j + k) as u8);
                        n += 1;
                    }
                    i += 1;
                }
                j += 2 * k;
            }
            k /= 2;
        }
        p *= 2;
    }
    // Forward: which wires still hold +∞ padding.
    let mut infinite = [false; 32];
    let mut w = window;
    while w < wires {
        infinite[w] = true;
        w += 1;
    }
    let mut keep = [true; 256];
    let mut c = 0;
    while c < n {
        let (a, b) = (all[c].0 as usize, all[c].1 as usize);
        if infinite[b] {
            keep[c] = false; // min(a, +∞) = a, max = +∞: no change.
        } else if infinite[a] {
            infinite[a] = false; // The exchange moves the finite value down.
            infinite[b] = true;
        }
        c += 1;
    }
    // Backward: only comparators that reach the median wire matter.
    let mut needed = [false; 32];
    needed[window / 2] = true;
    let mut c = n;
    while c > 0 {
        c -= 1;
        let (a, b) = (all[c].0 as usize, all[c].1 as usize);
        if keep[c] && (needed[a] || needed[b]) {
            needed[a] = true;
            needed[b] = true;
        } else {
            keep[c] = false;
        }
    }
    let mut out = [(0u8, 0u8); 256];
    let mut m = 0;
    let mut c = 0;
    while c < n {
        if keep[c] {
            out[m] = all[c];
            m += 1;
        }
        c += 1;
    }
    (out, m)
}

/// The pruned network of the 3x3 median (9 values on 16 wires).
const NETWORK_3X3: ([(u8, u8); 256], usize) = median_network(9, 16);
/// The pruned network of the 5x5 median (25 values on 32 wires).
const NETWORK_5X5: ([(u8, u8); 256], usize) = median_network(25, 32);

/// Medians of [`LANES`] windows at once: `wires[i][l]` is value `i` of window `l`.
#[inline]
fn network_median<const WIRES: usize>(
    network: &[(u8, u8)],
    wires: &mut [[f32; LANES]; WIRES],
    middle: usize,
) -> [f32; LANES] {
    for &(a, b) in network {
        let (x, y) = (wires[a as usize], wires[b as usize]);
        let mut lo = [0.0f32; LANES];
        let mut hi = [0.0f32; LANES];
        for l in 0..LANES {
            // Plain comparisons (not f32::min) so that they compile to minps/maxps.
            lo[l] = if x[l] < y[l] { x[l] } else { y[l] };
            hi[l] = if x[l] < y[l] { y[l] } else { x[l] };
        }
        wires[a as usize] = lo;
        wires[b as usize] = hi;
    }
    wires[middle]
}

/// Filters the interior run `[R, R + k·LANES)` of row `y` with the network of radius
/// `R` and returns the run; `None` where the row is too close to an edge.
fn network_row<const R: usize, const WIRES: usize>(
    src: &[[f32; 2]],
    w: usize,
    h: usize,
    y: usize,
    row: &mut [[f32; 2]],
    network: &[(u8, u8)],
) -> Option<std::ops::Range<usize>> {
    let side = 2 * R + 1;
    if y < R || y + R >= h || w < 2 * R + LANES {
        return None;
    }
    let run = R..R + (w - 2 * R) / LANES * LANES;
    for x0 in run.clone().step_by(LANES) {
        for c in 0..2 {
            let mut wires = [[f32::INFINITY; LANES]; WIRES];
            for dy in 0..side {
                let base = (y + dy - R) * w + x0 - R;
                for dx in 0..side {
                    let wire = &mut wires[dy * side + dx];
                    for (l, v) in wire.iter_mut().enumerate() {
                        *v = src[base + dx + l][c];
                    }
                }
            }
            let m = network_median(network, &mut wires, side * side / 2);
            for l in 0..LANES {
                row[x0 + l][c] = m[l];
            }
        }
    }
    Some(run)
}

/// The `(2r+1)²` median of each flow component; `radius = 0` copies.
pub(crate) fn median_filter(flow: &FlowImage, radius: usize) -> FlowImage {
    if radius == 0 {
        return flow.clone();
    }
    let (w, h) = flow.size();
    let src = flow.pixels();
    let side = 2 * radius + 1;
    let mut out = vec![[0.0f32; 2]; w * h];
    out.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            let mut us = Vec::with_capacity(side * side);
            let mut vs = Vec::with_capacity(side * side);
            let (y0, y1) = (y.saturating_sub(radius), (y + radius).min(h - 1));
            let (n3, n5) = (NETWORK_3X3, NETWORK_5X5);
            let done = match radius {
                1 => network_row::<1, 16>(src, w, h, y, row, &n3.0[..n3.1]),
                2 => network_row::<2, 32>(src, w, h, y, row, &n5.0[..n5.1]),
                _ => None,
            }
            .unwrap_or(0..0);
            for (x, o) in row.iter_mut().enumerate() {
                if done.contains(&x) {
                    continue;
                }
                let (x0, x1) = (x.saturating_sub(radius), (x + radius).min(w - 1));
                us.clear();
                vs.clear();
                for yy in y0..=y1 {
                    for p in &src[yy * w + x0..=yy * w + x1] {
                        us.push(p[0]);
                        vs.push(p[1]);
                    }
                }
                *o = [median_in_place(&mut us), median_in_place(&mut vs)];
            }
        });
    Image::from_vec(w, h, out).unwrap_or_else(|_| flow.clone())
}

/// The upper median of a non-empty slice (reorders it).
#[inline]
pub(crate) fn median_in_place(values: &mut [f32]) -> f32 {
    let k = values.len() / 2;
    *values.select_nth_unstable_by(k, f32::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_removes_an_outlier_and_keeps_an_edge() {
        let mut flow = Image::from_fn(9, 9, |x, _| if x < 4 { [1.0f32, 0.0] } else { [3.0, -1.0] });
        flow.set(2, 2, [50.0, 50.0]);
        let m = median_filter(&flow, 2);
        assert_eq!(m.get(2, 2), [1.0, 0.0]);
        for y in 0..9 {
            assert_eq!(m.get(3, y)[0], 1.0);
            assert_eq!(m.get(4, y)[0], 3.0);
        }
        let tiny = median_filter(&Image::new(1, 1, [0.5f32, 0.25]), 2);
        assert_eq!(tiny.get(0, 0), [0.5, 0.25]);
    }

    #[test]
    fn network_agrees_with_selection_on_random_windows() {
        // The pruned network must be an exact median for every input; random windows
        // with many ties (values from a small set) exercise the exchanges.
        // Batcher's full networks have 63 (16 wires) and 191 (32 wires) comparators.
        assert!(
            NETWORK_3X3.1 < 63 && NETWORK_5X5.1 < 191,
            "{} {}",
            NETWORK_3X3.1,
            NETWORK_5X5.1
        );
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            (state >> 40) as f32
        };
        let (w, h) = (23, 9);
        for round in 0..40 {
            let modulus = if round % 2 == 0 { 5.0 } else { 1e6 };
            let flow = Image::from_fn(w, h, |_, _| [next() % modulus, -(next() % modulus)]);
            for r in [1usize, 2] {
                let fast = median_filter(&flow, r);
                for y in 0..h {
                    for x in 0..w {
                        let mut us = Vec::new();
                        let mut vs = Vec::new();
                        for yy in y.saturating_sub(r)..=(y + r).min(h - 1) {
                            for xx in x.saturating_sub(r)..=(x + r).min(w - 1) {
                                us.push(flow.get(xx, yy)[0]);
                                vs.push(flow.get(xx, yy)[1]);
                            }
                        }
                        let want = [median_in_place(&mut us), median_in_place(&mut vs)];
                        assert_eq!(fast.get(x, y), want, "r = {r} at ({x}, {y})");
                    }
                }
            }
        }
    }
}
