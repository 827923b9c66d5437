//! The column index of a cylinder: which column spans a ray's line can reach, looked up
//! in the top view, so that [`super::Cylinder::intersect`] solves the inverse bilinear
//! map on the few quads of those spans (`rows + 1` each, the walls included) rather than
//! on all of them (144 per pixel on the stage's 36 x 3 grid: the main cost of a frame).
//! It only skips quads no hit can lie on, so the hit, and which of equal ones, is that of
//! the loop over every quad ([`super::Cylinder::intersect_brute`]).
//!
//! - **Footprints.** Seen from above (the xz plane), a hit on a quad lies in the convex
//!   hull of its corners as the inverse bilinear map sees them (carried into the quad's
//!   plane; the corners themselves for planar quads), grown by what the edge slack lets
//!   `(β, γ)` leave the unit square; a wall is vertical and projects onto its row's edge.
//!   About the axis point `A`, the mean of the camera centres, each span's footprint
//!   covers a range of azimuths `s`, measured from column 0 in the direction the columns
//!   run and unwrapped along them, and every footprint lies in one annulus
//!   `[r_min, r_max]` (the least distance from `A` to a segment between a quad's corners
//!   bounds the distance to its hull from below; the largest corner distance bounds it
//!   from above). Ranges and radii are widened by a margin for rounding.
//! - **Query.** The ray's line (every `t`: hits behind the origin count too) crosses the
//!   annulus in one segment, or in two when it passes within `r_min` of `A`; a vertical
//!   line is a point. Along a segment that keeps away from `A` the azimuth is monotone and
//!   turns by less than π, so each segment sweeps `[a, a + len]`; the candidates are the
//!   spans whose ranges meet it, found by walking from the first whose range ends after
//!   `a`, and, past the last span, from span 0 a turn later.
//! - **When it does not apply.** The index is built only when each span's footprint
//!   subtends less than π (so `A` lies outside it), the ranges' ends increase strictly
//!   along the columns, the whole grid turns less than 2π past its first span, and the
//!   annulus has a hole; otherwise every quad is solved.
//!
//! The GPU reads the same index from the pose's binding 7 (`ColumnIndex` and its ranges
//! in `shaders/common.wgsl`; `intersect` in `shaders/rebin.wgsl`).

use std::f32::consts::{PI, TAU};

use bytemuck::Zeroable;
use glam::{Vec2, Vec3};

use super::{EDGE_SLACK, Quad};
use frf_shaders::types::GpuColumnIndex;

/// Angle every span's range is widened by, radians (rounding of the query's angles).
const ANGLE_MARGIN: f32 = 1e-3;
/// Width the annulus is widened by on each side, relative to its outer radius.
const RADIUS_MARGIN: f32 = 1e-3;
/// The least inner radius of the annulus, relative to the outer, the index is built for.
const MIN_HOLE: f32 = 1e-2;

/// See the module docs.
#[derive(Debug, Clone)]
pub(super) struct ColumnIndex {
    /// `A`, the axis point (x, z).
    axis: Vec2,
    /// Unit direction from `A` of azimuth 0 (column 0).
    reference: Vec2,
    /// 1 when the columns run counterclockwise in (x, z), −1 otherwise.
    orientation: f32,
    r_min: f32,
    r_max: f32,
    /// Per span, `[lo, hi]` of its azimuths.
    ranges: Vec<[f32; 2]>,
    quads_per_span: usize,
}

/// One span seen from above: its quads' corners relative to `A`, how far a hit may lie
/// outside their hulls, and their hulls' distances from `A`.
struct Footprint {
    corners: Vec<Vec2>,
    reach: f32,
    near: f32,
    far: f32,
}

fn xz(p: Vec3) -> Vec2 {
    Vec2::new(p.x, p.z)
}

/// The signed angle turning `start` into `end`, in `(−π, π]`.
fn turn(start: Vec2, end: Vec2) -> f32 {
    start.perp_dot(end).atan2(start.dot(end))
}

/// Distance from the origin to the segment `a`–`b`.
fn distance_to_segment(a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let k = if len2 > 0.0 {
        (-a.dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * k).length()
}

impl Footprint {
    /// The footprint of `quads` about `axis`; `None` if a quad's plane frame is degenerate.
    fn new(quads: &[Quad], axis: Vec2) -> Option<Self> {
        let mut f = Self {
            corners: Vec::new(),
            reach: 0.0,
            near: f32::INFINITY,
            far: 0.0,
        };
        // A quad without a normal is never hit.
        for q in quads.iter().filter(|q| q.normal != Vec3::ZERO) {
            let c = q.plane_corners()?.map(|p| xz(p) - axis);
            // (β, γ) up to EDGE_SLACK outside the unit square moves the point by at most
            // that much of the longest edge and of the twist (doubled for safety).
            let [p00, p10, p01, p11] = c;
            let longest = [p10 - p00, p11 - p01, p01 - p00, p11 - p10]
                .iter()
                .fold(0.0f32, |m, e| m.max(e.length()));
            let twist = (p00 - p10 - p01 + p11).length();
            f.reach = f.reach.max(2.0 * EDGE_SLACK * (longest + twist));
            for i in 0..4 {
                f.far = f.far.max(c[i].length());
                for j in i + 1..4 {
                    f.near = f.near.min(distance_to_segment(c[i], c[j]));
                }
            }
            f.corners.extend(c);
        }
        (!f.corners.is_empty()).then_some(f)
    }

    /// The direction from `A` of the corners' mean, inside the footprint's hull.
    fn centre(&self) -> Vec2 {
        self.corners.iter().sum::<Vec2>() / self.corners.len() as f32
    }
}

impl ColumnIndex {
    /// The index of `quads` (`quads_per_span` of them per span, spans in column order) of
    /// the grid of camera `centres` (`u`-major, `rows` per column); `None` where it does
    /// not apply (see the module docs).
    pub(super) fn new(
        quads: &[Quad],
        quads_per_span: usize,
        centres: &[Vec3],
        rows: usize,
    ) -> Option<Self> {
        if quads.is_empty() || centres.len() < rows || rows == 0 {
            return None;
        }
        let mean =
            |points: &[Vec3]| points.iter().map(|&p| xz(p)).sum::<Vec2>() / points.len() as f32;
        let axis = mean(centres);
        let footprints = quads
            .chunks(quads_per_span)
            .map(|span| Footprint::new(span, axis))
            .collect::<Option<Vec<_>>>()?;
        let reference = (mean(&centres[..rows]) - axis).try_normalize()?;
        let first = turn(reference, footprints[0].centre());
        if first == 0.0 {
            return None;
        }
        let orientation = first.signum();

        let reach = footprints.iter().fold(0.0f32, |m, f| m.max(f.reach));
        let far = footprints.iter().fold(0.0f32, |m, f| m.max(f.far));
        let near = footprints.iter().fold(f32::INFINITY, |m, f| m.min(f.near));
        let r_max = far + reach + RADIUS_MARGIN * far;
        let r_min = near - reach - RADIUS_MARGIN * far;
        if !(r_min > MIN_HOLE * r_max && r_max.is_finite()) {
            return None;
        }

        let mut ranges = Vec::with_capacity(footprints.len());
        // Azimuth of the previous span's centre, unwrapped, and its direction.
        let mut previous = (0.0f32, reference);
        for f in &footprints {
            let centre = f.centre();
            let s = previous.0 + orientation * turn(previous.1, centre);
            previous = (s, centre);
            let (lo, hi) = f.corners.iter().fold((0.0f32, 0.0f32), |(lo, hi), &c| {
                let a = orientation * turn(centre, c);
                (lo.min(a), hi.max(a))
            });
            if f.reach >= 0.5 * f.near {
                return None;
            }
            let margin = ANGLE_MARGIN + 2.0 * f.reach / f.near;
            let range = [s + lo - margin, s + hi + margin];
            // Also false for NaN.
            let narrow = range[1] - range[0] < PI;
            if !narrow {
                return None;
            }
            ranges.push(range);
        }
        let increasing = ranges
            .windows(2)
            .all(|w| w[0][0] < w[1][0] && w[0][1] < w[1][1]);
        let (first, last) = (ranges[0], ranges[ranges.len() - 1]);
        if !(increasing && last[1] - first[1] < TAU && last[1] - first[0] < 3.0 * PI) {
            return None;
        }
        Some(Self {
            axis,
            reference,
            orientation,
            r_min,
            r_max,
            ranges,
            quads_per_span,
        })
    }

    /// Quads per span.
    pub(super) fn quads_per_span(&self) -> usize {
        self.quads_per_span
    }

    /// Calls `visit` with every span whose quads the line of the ray `origin + t dir`
    /// may meet (any `t`); a span may come twice. `origin` and `dir` must be finite.
    pub(super) fn spans_along(&self, origin: Vec3, dir: Vec3, mut visit: impl FnMut(usize)) {
        let o = xz(origin) - self.axis;
        let d = xz(dir);
        let m = d.x.abs().max(d.y.abs());
        if m == 0.0 {
            // Vertical: a point.
            let r = o.length();
            if r >= self.r_min && r <= self.r_max {
                self.walk(o, o, &mut visit);
            }
            return;
        }
        // Scaled first: tiny components would underflow when squared.
        let d = (d / m).normalize();
        let n = d.perp();
        let h = o.dot(n);
        if h.abs() > self.r_max {
            return;
        }
        let foot = n * h;
        let outer = (self.r_max * self.r_max - h * h).sqrt();
        if h.abs() >= self.r_min {
            self.walk(foot - d * outer, foot + d * outer, &mut visit);
        } else {
            let inner = (self.r_min * self.r_min - h * h).sqrt();
            self.walk(foot - d * outer, foot - d * inner, &mut visit);
            self.walk(foot + d * inner, foot + d * outer, &mut visit);
        }
    }

    /// Azimuth of `v` (relative to `A`), in `[0, 2π)`.
    fn azimuth(&self, v: Vec2) -> f32 {
        let s = self.orientation * turn(self.reference, v);
        if s < 0.0 { s + TAU } else { s }
    }

    /// Visits the spans whose ranges meet the azimuths swept from `start` to `end`
    /// (relative to `A`, the ends of a segment that keeps away from it).
    fn walk(&self, start: Vec2, end: Vec2, visit: &mut impl FnMut(usize)) {
        let sweep = self.orientation * turn(start, end);
        let (mut a, len) = if sweep >= 0.0 {
            (self.azimuth(start), sweep)
        } else {
            (self.azimuth(end), -sweep)
        };
        // Into (hi_last − 2π, hi_last]: no span's range reaches a turn above `a`.
        let last = self.ranges[self.ranges.len() - 1][1];
        a -= TAU * ((a - last) / TAU).ceil();
        if a > last {
            a -= TAU;
        }
        if a <= last - TAU {
            a += TAU;
        }
        let b = a + len;
        let first = self.ranges.partition_point(|r| r[1] < a);
        for (u, r) in self.ranges.iter().enumerate().skip(first) {
            if r[0] > b {
                break;
            }
            visit(u);
        }
        // The same spans a turn later.
        for (u, r) in self.ranges.iter().enumerate() {
            if r[0] + TAU > b {
                break;
            }
            visit(u);
        }
    }

    /// Bytes [`ColumnIndex::gpu`] makes (its header and ranges), without making them.
    pub(super) fn gpu_bytes(index: Option<&Self>) -> usize {
        std::mem::size_of::<GpuColumnIndex>()
            + std::mem::size_of::<[f32; 2]>() * index.map_or(1, |c| c.ranges.len())
    }

    /// The index as the GPU reads it: header and ranges (`index` `None`: disabled, one
    /// empty range).
    pub(super) fn gpu(index: Option<&Self>) -> (GpuColumnIndex, Vec<[f32; 2]>) {
        match index {
            Some(c) => (
                GpuColumnIndex {
                    axis: c.axis.to_array(),
                    reference: c.reference.to_array(),
                    orientation: c.orientation,
                    r_min: c.r_min,
                    r_max: c.r_max,
                    spans: c.ranges.len() as u32,
                    quads_per_span: c.quads_per_span as u32,
                    enabled: 1,
                },
                c.ranges.clone(),
            ),
            None => (GpuColumnIndex::zeroed(), vec![[0.0; 2]]),
        }
    }
}

#[cfg(test)]
mod tests {
    use std::ops::Range;

    use frf_core::camera::Camera;
    use frf_core::light::direction_from_azimuth_elevation;
    use glam::Vec2;
    use proptest::prelude::RngExt;
    use proptest::test_runner::{RngAlgorithm, TestRng};

    use super::*;
    use crate::cylinder::tests::grid;
    use crate::cylinder::{Clamp, Cylinder, CylinderHit};

    /// A single-row ring of 48 cameras 7.5° apart, running the other way round from the
    /// stage's, off the origin.
    fn ring() -> (Vec<Vec3>, Cylinder) {
        let centres: Vec<Vec3> = (0..48)
            .map(|u| {
                let d = direction_from_azimuth_elevation((u as f32 * 7.5).to_radians(), 0.0);
                Vec3::new(0.4, 1.3, -0.7) + d * 3.0
            })
            .collect();
        let cyl = Cylinder::new(&centres, 48, 1, true);
        (centres, cyl)
    }

    /// An open arc of 18 cameras over 130°, one row.
    fn arc() -> (Vec<Vec3>, Cylinder) {
        let centres: Vec<Vec3> = (0..18)
            .map(|u| {
                let a = (-25.0 + u as f32 * 130.0 / 17.0).to_radians();
                Vec3::new(0.0, 1.2, 0.0) + direction_from_azimuth_elevation(a, 0.0) * 3.5
            })
            .collect();
        let cyl = Cylinder::new(&centres, 18, 1, false);
        (centres, cyl)
    }

    /// The stage grid with every centre moved by up to 12 cm: quads no longer planar.
    fn jittered() -> (Vec<Vec3>, Cylinder) {
        let (mut centres, cols, rows) = grid();
        let mut rng = TestRng::deterministic_rng(RngAlgorithm::ChaCha);
        for c in &mut centres {
            *c += Vec3::new(
                rng.random_range(-0.12..0.12),
                rng.random_range(-0.12..0.12),
                rng.random_range(-0.12..0.12),
            );
        }
        let cyl = Cylinder::new(&centres, cols, rows, true);
        (centres, cyl)
    }

    fn stage() -> (Vec<Vec3>, Cylinder) {
        let (centres, cols, rows) = grid();
        let cyl = Cylinder::new(&centres, cols, rows, true);
        (centres, cyl)
    }

    /// A uniformly random unit vector.
    fn direction(rng: &mut TestRng) -> Vec3 {
        let y: f32 = rng.random_range(-1.0..1.0);
        let a: f32 = rng.random_range(0.0..TAU);
        let r = (1.0 - y * y).sqrt();
        Vec3::new(r * a.cos(), y, r * a.sin())
    }

    /// A point at a random azimuth about `axis`, at a random distance of `radii` from it
    /// and height of `heights`.
    fn around(rng: &mut TestRng, axis: Vec2, radii: Range<f32>, heights: Range<f32>) -> Vec3 {
        let (a, r, y) = (
            rng.random_range(0.0..TAU),
            rng.random_range(radii),
            rng.random_range(heights),
        );
        Vec3::new(axis.x + r * a.cos(), y, axis.y + r * a.sin())
    }

    /// Random rays of each kind about the cylinder of camera `centres` (`u`-major,
    /// `rows` per column): from inside, outside, above and below it, near-vertical ones,
    /// and ones aimed at points of the grid (its vertices and edges among them).
    fn rays(
        rng: &mut TestRng,
        cyl: &Cylinder,
        centres: &[Vec3],
    ) -> Vec<(&'static str, Vec3, Vec3)> {
        let index = cyl.index.as_ref().expect("the grid has a column index");
        let (axis, r) = (index.axis, index.r_max);
        let lo = centres.iter().fold(f32::INFINITY, |m, c| m.min(c.y));
        let hi = centres.iter().fold(f32::NEG_INFINITY, |m, c| m.max(c.y));
        let mut out = Vec::new();
        for _ in 0..1500 {
            // Toward the subject, or anywhere.
            let aim = |rng: &mut TestRng, from: Vec3| {
                if rng.random_range(0.0..1.0f32) < 0.6 {
                    let target = around(rng, axis, 0.0..1.2 * r, lo - 1.5..hi + 1.5);
                    (target - from).normalize()
                } else {
                    direction(rng)
                }
            };
            let o = around(rng, axis, 0.0..0.75 * r, lo - 1.0..hi + 1.0);
            out.push(("inside", o, direction(rng)));
            let o = around(rng, axis, 1.2 * r..4.0 * r, lo - 3.0..hi + 3.0);
            out.push(("outside", o, aim(rng, o)));
            let o = around(rng, axis, 0.0..2.5 * r, hi + 0.3..hi + 10.0);
            out.push(("above", o, aim(rng, o)));
            let o = around(rng, axis, 0.0..2.5 * r, lo - 10.0..lo - 0.3);
            out.push(("below", o, aim(rng, o)));
            // Near-vertical, some of them through the walls.
            let o = around(rng, axis, 0.0..1.6 * r, lo - 4.0..hi + 4.0);
            let tilt = [0.0, 1e-9, 1e-6, 1e-3, 3e-2, 0.3][rng.random_range(0..6usize)];
            let a: f32 = rng.random_range(0.0..TAU);
            let up = if rng.random_range(0.0..1.0f32) < 0.5 {
                1.0
            } else {
                -1.0
            };
            let d = Vec3::new(tilt * a.cos(), up, tilt * a.sin()).normalize();
            out.push(("near-vertical", o, d));
            // Through a point of the grid: a vertex, an edge or inside a quad.
            let rows = centres.len() / cyl.columns();
            let u = rng.random_range(0..cyl.columns());
            let v = rng.random_range(0..rows);
            let pick = |rng: &mut TestRng| match rng.random_range(0..3u32) {
                0 => 0.0,
                1 => rng.random_range(0.0..1.0f32),
                _ => 1.0,
            };
            let (b, g) = (pick(rng), pick(rng));
            let c = |u: usize, v: usize| centres[cyl.view(u, v.min(rows - 1))];
            let target = c(u, v) * (1.0 - b) * (1.0 - g)
                + c(u + 1, v) * b * (1.0 - g)
                + c(u, v + 1) * (1.0 - b) * g
                + c(u + 1, v + 1) * b * g;
            let o = around(rng, axis, 0.0..3.0 * r, lo - 3.0..hi + 3.0);
            out.push(("grid point", o, (target - o).normalize()));
        }
        out
    }

    /// The indexed intersection is the loop's on every ray; returns the hits, per kind.
    fn check(name: &str, cyl: &Cylinder, centres: &[Vec3]) -> Vec<(&'static str, CylinderHit)> {
        assert!(cyl.has_column_index(), "{name}: no column index");
        let mut rng = TestRng::deterministic_rng(RngAlgorithm::ChaCha);
        let mut hits = Vec::new();
        for (kind, o, d) in rays(&mut rng, cyl, centres) {
            let brute = cyl.intersect_brute(o, d);
            let indexed = cyl.intersect(o, d);
            assert_eq!(indexed, brute, "{name}, {kind}: origin {o}, dir {d}");
            hits.extend(brute.map(|h| (kind, h)));
        }
        hits
    }

    #[test]
    fn the_lookup_finds_the_hit_of_the_loop_on_every_grid() {
        let grids = [
            ("stage", stage()),
            ("jittered stage", jittered()),
            ("ring of 48", ring()),
            ("arc of 130 degrees", arc()),
        ];
        for (name, (centres, cyl)) in &grids {
            let hits = check(name, cyl, centres);
            // Every kind of ray, every kind of hit, entries behind inside cameras.
            for kind in [
                "inside",
                "outside",
                "above",
                "below",
                "near-vertical",
                "grid point",
            ] {
                let n = hits.iter().filter(|(k, _)| *k == kind).count();
                assert!(n > 100, "{name}: {n} hits of {kind} rays");
            }
            // A single row is all walls.
            let inside = (cyl.rows() > 1).then_some(Clamp::None);
            for clamp in [Clamp::Above, Clamp::Below].into_iter().chain(inside) {
                assert!(
                    hits.iter().any(|(_, h)| h.clamped == clamp),
                    "{name}: {clamp:?}"
                );
            }
            assert!(
                hits.iter().any(|(_, h)| h.t < 0.0),
                "{name}: no entry behind"
            );
        }
        // Both ways round.
        let o = |c: &Cylinder| c.index.as_ref().unwrap().orientation;
        assert_eq!(o(&grids[0].1.1), -o(&grids[2].1.1));
    }

    #[test]
    fn a_vertical_line_at_a_column_reaches_the_spans_either_side() {
        for (name, (centres, cyl)) in [("stage", stage()), ("ring", ring()), ("arc", arc())] {
            let index = cyl.index.as_ref().unwrap();
            let spans = index.ranges.len();
            let rows = cyl.rows();
            let radius = 0.5 * (index.r_min + index.r_max);
            for c in 0..cyl.columns() {
                let column = &centres[c * rows..(c + 1) * rows];
                let centre = column.iter().map(|&p| xz(p)).sum::<Vec2>() / rows as f32;
                let towards = (centre - index.axis).normalize();
                // Either side of the column, well within the ranges' margins.
                for turn in [-5e-4f32, 0.0, 5e-4] {
                    let d = Vec2::from_angle(turn).rotate(towards) * radius + index.axis;
                    let mut visited = Vec::new();
                    index.spans_along(Vec3::new(d.x, 1.0, d.y), Vec3::Y, |u| visited.push(u));
                    // The span after the column, and the one before (across the seam
                    // of a ring).
                    let wraps = spans == cyl.columns();
                    let after = (c < spans).then_some(c);
                    let before = match c {
                        0 => wraps.then_some(spans - 1),
                        _ => Some(c - 1),
                    };
                    for u in after.into_iter().chain(before) {
                        assert!(visited.contains(&u), "{name}, column {c}: {visited:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_grid_the_index_does_not_fit_solves_every_quad() {
        // A straight rig: the axis point lies on its footprint.
        let centres: Vec<Vec3> = (0..10)
            .flat_map(|u| [0.0, 0.6].map(|y| Vec3::new(u as f32 * 0.3, 1.0 + y, 2.0)))
            .collect();
        let cyl = Cylinder::new(&centres, 10, 2, false);
        assert!(!cyl.has_column_index());
        let (header, ranges) = cyl.column_index_gpu();
        assert_eq!((header.enabled, ranges.len()), (0, 1));
        let mut rng = TestRng::deterministic_rng(RngAlgorithm::ChaCha);
        let mut hits = 0;
        for _ in 0..500 {
            let o = Vec3::new(1.4, 1.3, -2.0) + direction(&mut rng);
            let target = Vec3::new(
                rng.random_range(-1.0..4.0),
                rng.random_range(-1.0..3.0),
                2.0,
            );
            let d = (target - o).normalize();
            assert_eq!(cyl.intersect(o, d), cyl.intersect_brute(o, d));
            assert_eq!(cyl.quads_tested(o, d), cyl.quads.len());
            hits += cyl.intersect(o, d).is_some() as usize;
        }
        assert!(hits > 100, "{hits}");
    }

    #[test]
    fn the_stage_index_is_what_the_gpu_reads() {
        let (_, cyl) = stage();
        let (header, ranges) = cyl.column_index_gpu();
        assert_eq!(
            (header.enabled, header.spans, header.quads_per_span),
            (1, 36, 4)
        );
        assert_eq!(ranges.len(), 36);
        // Spans 10° wide, a little more with the margins; the annulus about the rows.
        for r in &ranges {
            let width = (r[1] - r[0]).to_degrees();
            assert!((10.0..10.5).contains(&width), "{width}");
        }
        assert!(
            header.r_min > 3.6 && header.r_min < 3.75,
            "{}",
            header.r_min
        );
        assert!(
            header.r_max > 4.5 && header.r_max < 4.52,
            "{}",
            header.r_max
        );
        // A non-finite ray is left to the loop.
        assert_eq!(cyl.quads_tested(Vec3::NAN, Vec3::Z), 144);
    }

    #[test]
    fn few_quads_are_solved_per_pixel() {
        let (_, cyl) = stage();
        let target = Vec3::new(0.0, 0.9, 0.0);
        for (name, eye, fov) in [
            ("outside, between views", Vec3::new(2.2, 1.4, 3.0), 0.55),
            ("outside, far", Vec3::new(0.0, 1.5, 9.0), 0.5),
            ("above the grid", Vec3::new(0.8, 6.0, 1.5), 0.7),
            ("inside the cylinder", Vec3::new(0.9, 1.1, 1.2), 1.0),
            ("below the grid", Vec3::new(0.5, -3.0, 1.0), 0.9),
        ] {
            let cam = Camera::look_at(eye, target, Vec3::Y, fov, 120, 160).unwrap();
            let (mut tested, mut pixels) = (0, 0);
            for y in 0..cam.height {
                for x in 0..cam.width {
                    let d = cam.ray_direction(Vec2::new(x as f32, y as f32));
                    tested += cyl.quads_tested(cam.centre(), d);
                    pixels += 1;
                }
            }
            let mean = tested as f32 / pixels as f32;
            println!("{name}: {mean:.1} quads per pixel (of {})", cyl.quads.len());
            assert!(mean < 24.0, "{name}: {mean} quads per pixel");
        }
    }
}
