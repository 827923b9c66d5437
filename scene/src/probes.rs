//! Light probes placed in a scene, and the light at a point between them: a walker is
//! lit by the probes interpolated at its torso, frame by frame, so that it walks from
//! shade into sun.
//!
//! **Where.** Probes stand at points of the ground plane (their height is where they were
//! photographed, and is not used: walkers' torsos are all at one height). The weights of
//! a point are those of a piecewise-linear interpolation over the probes:
//! - one probe: weight 1 everywhere;
//! - probes on a line (two, or more in a row): linear between the two neighbours along
//!   the line that the point's projection falls between, the end probe beyond the ends;
//! - otherwise the Delaunay triangulation of the probes (Bowyer–Watson): the point's
//!   barycentric weights in the triangle that holds it; outside the probes' hull, the
//!   nearest point of the hull's boundary, linear along that edge.
//!
//! The weights are non-negative and sum to 1, and a point on a probe gets that probe
//! alone. Interpolating the probes' maps with them is light-linear: the relighting
//! coefficients of the weighted sum are the weighted sums of the probes' coefficients
//! ([`frf_reflectance::yaw_light::YawLight`]), so a walker's light between two probes is
//! exactly the light of the map that mixes them.

use glam::Vec2;

/// The most probes a scene may place: a triangulation of this many is made in
/// milliseconds, and a walker's light sums at most three.
pub const MAX_PROBES: usize = 256;

/// Probes closer than this (metres, on the ground) are one place: refused.
const SAME_PLACE_M: f32 = 1e-3;

/// How the probes' positions are interpolated (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeLayout {
    points: Vec<Vec2>,
    shape: Shape,
}

#[derive(Debug, Clone, PartialEq)]
enum Shape {
    /// One probe.
    Single,
    /// Probes in a row: their order along the line, from `origin` along `axis`.
    Line {
        origin: Vec2,
        axis: Vec2,
        order: Vec<usize>,
    },
    /// Triangles (counter-clockwise) and the hull's edges.
    Triangles {
        triangles: Vec<[usize; 3]>,
        hull: Vec<[usize; 2]>,
    },
}

/// Twice the signed area of the triangle `a, b, c` (positive counter-clockwise).
fn cross(a: Vec2, b: Vec2, c: Vec2) -> f32 {
    (b - a).perp_dot(c - a)
}

impl ProbeLayout {
    /// The layout of probes at `points` (`x`, `z` of their positions): at least one, at
    /// most [`MAX_PROBES`], finite, no two at one place. A refusal names the probe.
    pub fn new(points: Vec<Vec2>) -> Result<Self, (usize, String)> {
        if points.is_empty() || points.len() > MAX_PROBES {
            return Err((0, format!("1 to {MAX_PROBES} probes, not {}", points.len())));
        }
        for (i, p) in points.iter().enumerate() {
            if !p.is_finite() {
                return Err((i, "a position is not finite".into()));
            }
            if let Some(j) = points[..i]
                .iter()
                .position(|q| q.distance(*p) < SAME_PLACE_M)
            {
                return Err((i, format!("stands where probe {j} does")));
            }
        }
        let shape = if points.len() == 1 {
            Shape::Single
        } else {
            match line_of(&points) {
                Some((origin, axis)) => {
                    let mut order: Vec<usize> = (0..points.len()).collect();
                    order.sort_by(|&a, &b| {
                        (points[a] - origin)
                            .dot(axis)
                            .total_cmp(&(points[b] - origin).dot(axis))
                    });
                    Shape::Line {
                        origin,
                        axis,
                        order,
                    }
                }
                None => {
                    let triangles = delaunay(&points);
                    let hull = hull_edges(&triangles);
                    Shape::Triangles { triangles, hull }
                }
            }
        };
        Ok(Self { points, shape })
    }

    /// The probes' weights at `at` (`x`, `z`): `(probe, weight)`, weights positive and
    /// summing to 1 (see the module docs).
    pub fn weights(&self, at: Vec2) -> Vec<(usize, f32)> {
        let mut out = match &self.shape {
            Shape::Single => vec![(0, 1.0)],
            Shape::Line {
                origin,
                axis,
                order,
            } => {
                let s = |k: usize| (self.points[k] - *origin).dot(*axis);
                let x = (at - *origin).dot(*axis);
                let i = order.partition_point(|&k| s(k) <= x);
                if i == 0 {
                    vec![(order[0], 1.0)]
                } else if i == order.len() {
                    vec![(order[i - 1], 1.0)]
                } else {
                    let (a, b) = (order[i - 1], order[i]);
                    let f = (x - s(a)) / (s(b) - s(a));
                    vec![(a, 1.0 - f), (b, f)]
                }
            }
            Shape::Triangles { triangles, hull } => self
                .inside(triangles, at)
                .unwrap_or_else(|| self.on_hull(hull, at)),
        };
        out.retain(|&(_, w)| w > 0.0);
        let total: f32 = out.iter().map(|w| w.1).sum();
        for w in &mut out {
            w.1 /= total;
        }
        out
    }

    /// The barycentric weights of `at` in the triangle holding it, if one does.
    fn inside(&self, triangles: &[[usize; 3]], at: Vec2) -> Option<Vec<(usize, f32)>> {
        let p = |k: usize| self.points[k];
        triangles.iter().find_map(|&[a, b, c]| {
            let area = cross(p(a), p(b), p(c));
            let wa = cross(at, p(b), p(c)) / area;
            let wb = cross(p(a), at, p(c)) / area;
            let wc = 1.0 - wa - wb;
            // A point on a shared edge may round out of both triangles by a hair.
            let eps = -1e-6;
            (wa >= eps && wb >= eps && wc >= eps)
                .then(|| vec![(a, wa.max(0.0)), (b, wb.max(0.0)), (c, wc.max(0.0))])
        })
    }

    /// The weights of the hull's boundary point nearest `at`: linear along its edge.
    fn on_hull(&self, hull: &[[usize; 2]], at: Vec2) -> Vec<(usize, f32)> {
        let mut best = (f32::INFINITY, vec![(hull[0][0], 1.0)]);
        for &[a, b] in hull {
            let (pa, pb) = (self.points[a], self.points[b]);
            let d = pb - pa;
            let f = ((at - pa).dot(d) / d.length_squared()).clamp(0.0, 1.0);
            let distance = (pa + d * f).distance(at);
            if distance < best.0 {
                best = (distance, vec![(a, 1.0 - f), (b, f)]);
            }
        }
        best.1
    }
}

/// The line the points lie on (within a millimetre over their extent), as a point and a
/// unit direction; `None` when they span an area.
fn line_of(points: &[Vec2]) -> Option<(Vec2, Vec2)> {
    let origin = points[0];
    let far = points
        .iter()
        .copied()
        .max_by(|a, b| a.distance(origin).total_cmp(&b.distance(origin)))?;
    let axis = (far - origin).normalize_or_zero();
    let off = points
        .iter()
        .map(|p| (*p - origin).perp_dot(axis).abs())
        .fold(0.0f32, f32::max);
    (off < SAME_PLACE_M).then_some((origin, axis))
}

/// The Delaunay triangles of `points` (not all on a line), counter-clockwise, by
/// Bowyer–Watson from a triangle far around them.
fn delaunay(points: &[Vec2]) -> Vec<[usize; 3]> {
    let n = points.len();
    let (lo, hi) = points.iter().fold(
        (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let centre = 0.5 * (lo + hi);
    let span = (hi - lo).max_element().max(1.0) * 20.0;
    let mut all: Vec<Vec2> = points.to_vec();
    all.extend([
        centre + Vec2::new(-span, -span),
        centre + Vec2::new(span, -span),
        centre + Vec2::new(0.0, span),
    ]);
    let mut triangles: Vec<[usize; 3]> = vec![[n, n + 1, n + 2]];
    // Whether `p` lies inside the circle through the (counter-clockwise) triangle.
    let in_circle = |t: &[usize; 3], p: Vec2| -> bool {
        let [a, b, c] = t.map(|k| all[k] - p);
        let det = (a.length_squared() as f64) * (b.x as f64 * c.y as f64 - c.x as f64 * b.y as f64)
            - (b.length_squared() as f64) * (a.x as f64 * c.y as f64 - c.x as f64 * a.y as f64)
            + (c.length_squared() as f64) * (a.x as f64 * b.y as f64 - b.x as f64 * a.y as f64);
        det > 0.0
    };
    for (i, &p) in points.iter().enumerate() {
        let (bad, kept): (Vec<[usize; 3]>, Vec<[usize; 3]>) =
            triangles.into_iter().partition(|t| in_circle(t, p));
        // The boundary of the hole: edges of bad triangles that no other bad one shares.
        let mut edges: Vec<[usize; 2]> = Vec::new();
        for t in &bad {
            for e in [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]] {
                if let Some(k) = edges.iter().position(|f| *f == [e[1], e[0]]) {
                    edges.swap_remove(k);
                } else {
                    edges.push(e);
                }
            }
        }
        triangles = kept;
        triangles.extend(edges.into_iter().map(|[a, b]| [a, b, i]));
    }
    triangles.retain(|t| t.iter().all(|&k| k < n));
    triangles
}

/// The edges of the triangulation's boundary: those of one triangle only.
fn hull_edges(triangles: &[[usize; 3]]) -> Vec<[usize; 2]> {
    let mut edges: Vec<[usize; 2]> = Vec::new();
    for t in triangles {
        for e in [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]] {
            if let Some(k) = edges.iter().position(|f| *f == [e[1], e[0]]) {
                edges.swap_remove(k);
            } else {
                edges.push(e);
            }
        }
    }
    edges
}

#[cfg(test)]
mod tests {
    use super::*;

    fn weight_of(w: &[(usize, f32)], k: usize) -> f32 {
        w.iter().find(|p| p.0 == k).map_or(0.0, |p| p.1)
    }

    #[test]
    fn one_probe_lights_everywhere() {
        let l = ProbeLayout::new(vec![Vec2::new(3.0, -1.0)]).unwrap();
        assert_eq!(l.weights(Vec2::new(-50.0, 7.0)), vec![(0, 1.0)]);
    }

    #[test]
    fn two_probes_interpolate_linearly_and_hold_beyond_their_ends() {
        let l = ProbeLayout::new(vec![Vec2::new(-2.0, 0.0), Vec2::new(2.0, 0.0)]).unwrap();
        let w = l.weights(Vec2::new(1.0, 5.0));
        assert!((weight_of(&w, 0) - 0.25).abs() < 1e-6 && (weight_of(&w, 1) - 0.75).abs() < 1e-6);
        assert_eq!(l.weights(Vec2::new(-9.0, 0.0)), vec![(0, 1.0)]);
        assert_eq!(l.weights(Vec2::new(9.0, 1.0)), vec![(1, 1.0)]);
        // Three in a row: piecewise linear between neighbours.
        let l = ProbeLayout::new(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(4.0, 4.0),
            Vec2::new(2.0, 2.0),
        ])
        .unwrap();
        let w = l.weights(Vec2::new(3.0, 3.0));
        assert!((weight_of(&w, 2) - 0.5).abs() < 1e-5 && (weight_of(&w, 1) - 0.5).abs() < 1e-5);
    }

    #[test]
    fn a_field_of_probes_is_barycentric_inside_and_on_its_edge_outside() {
        let points = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(4.0, 0.0),
            Vec2::new(0.0, 4.0),
            Vec2::new(4.0, 4.0),
            Vec2::new(2.0, 1.0),
        ];
        let l = ProbeLayout::new(points.clone()).unwrap();
        // At each probe, that probe alone.
        for (k, p) in points.iter().enumerate() {
            let w = l.weights(*p);
            assert!((weight_of(&w, k) - 1.0).abs() < 1e-5, "{k}: {w:?}");
        }
        // Anywhere: the weights sum to 1 and reproduce the point (linear precision).
        for at in [
            Vec2::new(1.0, 2.5),
            Vec2::new(3.1, 0.4),
            Vec2::new(2.0, 3.9),
        ] {
            let w = l.weights(at);
            let sum: f32 = w.iter().map(|p| p.1).sum();
            let back: Vec2 = w.iter().map(|&(k, x)| points[k] * x).sum();
            assert!(
                (sum - 1.0).abs() < 1e-5 && back.distance(at) < 1e-4,
                "{at}: {w:?}"
            );
        }
        // Outside: the nearest edge's two probes.
        let w = l.weights(Vec2::new(2.0, -3.0));
        assert!((weight_of(&w, 0) - 0.5).abs() < 1e-5 && (weight_of(&w, 1) - 0.5).abs() < 1e-5);
    }

    #[test]
    fn bad_layouts_are_refused_naming_the_probe() {
        assert!(ProbeLayout::new(vec![]).is_err());
        let e = ProbeLayout::new(vec![Vec2::ZERO, Vec2::new(1.0, 1.0), Vec2::new(1.0, 1.0)])
            .unwrap_err();
        assert_eq!(e.0, 2);
        assert!(e.1.contains("probe 1"), "{e:?}");
        let e = ProbeLayout::new(vec![Vec2::new(f32::NAN, 0.0)]).unwrap_err();
        assert_eq!(e.0, 0);
    }
}
