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
//! Interior pixels of the 5x5 case therefore go through a fixed compare-exchange
//! network, eight pixels at a time so that the compiler vectorises it: Batcher's
//! odd–even merge sort of 32 wires (Knuth, TAOCP vol. 3, §5.3.4), the 7 padding wires
//! held at +∞, pruned at compile time to the comparators that can reach the middle
//! output. Edge pixels use the general selection.

use frf_core::image::{FlowImage, Image};
use rayon::prelude::*;

/// Wires of the sorting network (the next power of two above 25).
const WIRES: usize = 32;
/// Values in a 5x5 window.
const WINDOW: usize = 25;
/// Pixels filtered together by the network.
const LANES: usize = 8;

/// Batcher's odd–even merge sort on [`WIRES`] wires, then pruned: comparators whose
/// upper wire holds +∞ (a padding wire never moved) do nothing, and comparators that
/// cannot influence wire `WINDOW / 2` are dropped. Returns the comparators and their
/// count.
const fn median_network() -> ([(u8, u8); 256], usize) {
    let mut all = [(0u8, 0u8); 256];
    let mut n = 0;
    let mut p = 1;
    while p < WIRES {
        let mut k = p;
        while k >= 1 {
            let mut j = k % p;
            while j + k < WIRES {
                let mut i = 0;
                while i < k && i + j + k < WIRES {
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
    let mut infinite = [false; WIRES];
    let mut w = WINDOW;
    while w < WIRES {
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
    let mut needed = [false; WIRES];
    needed[WINDOW / 2] = true;
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

const NETWORK: ([(u8, u8); 256], usize) = median_network();

/// Medians of [`LANES`] windows at once: `wires[i][l]` is value `i` of window `l`.
#[inline]
fn network_median(wires: &mut [[f32; LANES]; WIRES]) -> [f32; LANES] {
    for &(a, b) in &NETWORK.0[..NETWORK.1] {
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
    wires[WINDOW / 2]
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
            // Interior run handled by the network: x in [2, w − 2), 8 at a time.
            let fast = radius == 2 && y >= 2 && y + 2 < h && w >= 4 + LANES;
            let mut x_fast = 2..2;
            if fast {
                let lanes_end = 2 + (w - 4) / LANES * LANES;
                x_fast = 2..lanes_end;
                for x0 in x_fast.clone().step_by(LANES) {
                    for c in 0..2 {
                        let mut wires = [[f32::INFINITY; LANES]; WIRES];
                        for dy in 0..5 {
                            let base = (y + dy - 2) * w + x0 - 2;
                            for dx in 0..5 {
                                let wire = &mut wires[dy * 5 + dx];
                                for (l, v) in wire.iter_mut().enumerate() {
                                    *v = src[base + dx + l][c];
                                }
                            }
                        }
                        let m = network_median(&mut wires);
                        for l in 0..LANES {
                            row[x0 + l][c] = m[l];
                        }
                    }
                }
            }
            for (x, o) in row.iter_mut().enumerate() {
                if x_fast.contains(&x) {
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
        assert!(NETWORK.1 < 191, "pruning removed nothing: {}", NETWORK.1);
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            (state >> 40) as f32
        };
        let (w, h) = (23, 9);
        for round in 0..40 {
            let modulus = if round % 2 == 0 { 5.0 } else { 1e6 };
            let flow = Image::from_fn(w, h, |_, _| [next() % modulus, -(next() % modulus)]);
            let fast = median_filter(&flow, 2);
            for y in 0..h {
                for x in 0..w {
                    let mut us = Vec::new();
                    let mut vs = Vec::new();
                    for yy in y.saturating_sub(2)..=(y + 2).min(h - 1) {
                        for xx in x.saturating_sub(2)..=(x + 2).min(w - 1) {
                            us.push(flow.get(xx, yy)[0]);
                            vs.push(flow.get(xx, yy)[1]);
                        }
                    }
                    let want = [median_in_place(&mut us), median_in_place(&mut vs)];
                    assert_eq!(fast.get(x, y), want, "({x}, {y})");
                }
            }
        }
    }
}
