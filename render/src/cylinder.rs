//! Light-field re-binning geometry (docs/design.md section 4.3): the capture cameras' centres,
//! seen from the subject frame, form a squashed cylinder of quads, `(u, v)` to
//! `(u + 1, v + 1)`. A virtual camera's pixel ray is intersected with it; the quad hit
//! and the bilinear position `(β, γ)` of the hit in it say which four images to morph and
//! how far toward each.
//!
//! - **Which intersection.** The ray's line meets the closed surface where it enters and
//!   where it leaves; the light reaching the virtual camera along the ray crossed the
//!   cylinder where it entered, on the viewer's side of the subject, where a real camera
//!   could have recorded it: the intersection with the smallest parameter along the ray.
//!   It lies in front of a virtual camera outside the cylinder and behind one inside. A
//!   line that meets the surface only behind a camera outside it (the camera looks away)
//!   sees nothing.
//! - **Above and below the grid.** Rays that pass above the top row or below the bottom
//!   row meet vertical walls extruded from that row's edges: they are clamped to the row
//!   (`γ` fixed), and reported as such.
//! - **Inverse bilinear map.** On a quad with corners `P00, P10, P01, P11`, the point
//!   `p = P00 + β e1 + γ e2 + βγ e3` is solved for `(β, γ)` in the quad's plane (a
//!   quadratic in `γ`; linear for parallelograms such as the walls).
//!
//! - **Which quads.** Only the quads of the column spans the ray's line can reach, seen
//!   from above, are solved ([`column_index`]); the loop over every quad
//!   ([`Cylinder::intersect_brute`]) gives the same hit and is kept as the reference.
//!
//! Every function here has a WGSL twin in `shaders/rebin.wgsl`; the GPU and CPU paths are
//! tested against each other.

pub mod column_index;

use std::cmp::Ordering;

use frf_core::camera::{Camera, Intrinsics, Rigid};
use glam::{Mat3, Quat, Vec2, Vec3};

use column_index::ColumnIndex;
use frf_shaders::types::GpuColumnIndex;

/// Height of the walls above and below the grid, metres: far beyond any scene.
const WALL_HEIGHT_M: f32 = 1.0e3;
/// Slack on the quad's edges when testing whether a point is inside (float rounding).
const EDGE_SLACK: f32 = 1e-4;

/// Where a ray crossed the cylinder, and how.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderHit {
    /// Column of the quad's left edge.
    pub u: usize,
    /// Row of the quad's lower edge.
    pub v: usize,
    /// Position toward column `u + 1`, in `[0, 1]`.
    pub beta: f32,
    /// Position toward row `v + 1`, in `[0, 1]`.
    pub gamma: f32,
    /// The intersection point (subject frame).
    pub point: Vec3,
    /// Its parameter along the ray (negative: behind the virtual camera).
    pub t: f32,
    /// Whether the ray passed above or below the grid and was clamped to a row.
    pub clamped: Clamp,
}

/// Whether a hit was clamped to a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clamp {
    /// Inside the grid.
    None,
    /// Above the top row.
    Above,
    /// Below the bottom row.
    Below,
}

#[derive(Debug, Clone, Copy)]
struct Quad {
    u: usize,
    v: usize,
    p00: Vec3,
    e1: Vec3,
    e2: Vec3,
    e3: Vec3,
    normal: Vec3,
    /// For walls: the fixed γ and which wall.
    wall: Option<(f32, Clamp)>,
}

impl Quad {
    fn new(u: usize, v: usize, p: [Vec3; 4], wall: Option<(f32, Clamp)>) -> Self {
        let [p00, p10, p01, p11] = p;
        let normal = (p11 - p00).cross(p01 - p10).normalize_or_zero();
        Self {
            u,
            v,
            p00,
            e1: p10 - p00,
            e2: p01 - p00,
            e3: p00 - p10 - p01 + p11,
            normal,
            wall,
        }
    }

    /// The corners of the patch the inverse bilinear map solves on: `P00, P10, P01, P11`
    /// carried into the quad's plane along the direction its in-plane frame ignores (the
    /// corners themselves for a planar quad, such as a wall). The point of a hit at
    /// `(β, γ)` is their bilinear blend. `None` when that frame is degenerate.
    fn plane_corners(&self) -> Option<[Vec3; 4]> {
        let (x_axis, y_axis) = plane_frame(self.e1, self.normal);
        let along = x_axis.cross(y_axis);
        let across = self.normal.dot(along);
        if across.abs() < 1e-3 {
            return None;
        }
        let into_plane = |p: Vec3| p - along * (self.normal.dot(p - self.p00) / across);
        let (p10, p01) = (self.p00 + self.e1, self.p00 + self.e2);
        Some([self.p00, p10, p01, p10 + self.e2 + self.e3].map(into_plane))
    }

    /// Where the ray `origin + t dir` meets this quad (any `t`), if it does.
    fn hit(&self, origin: Vec3, dir: Vec3) -> Option<CylinderHit> {
        let denom = self.normal.dot(dir);
        if denom.abs() < 1e-9 {
            return None;
        }
        let t = self.normal.dot(self.p00 - origin) / denom;
        let p = origin + dir * t;
        let bg = inverse_bilinear(p, self.p00, self.e1, self.e2, self.e3, self.normal)?;
        if outside(bg) > EDGE_SLACK {
            return None;
        }
        let beta = bg.x.clamp(0.0, 1.0);
        let (gamma, clamped) = match self.wall {
            Some((g, c)) => (g, c),
            None => (bg.y.clamp(0.0, 1.0), Clamp::None),
        };
        Some(CylinderHit {
            u: self.u,
            v: self.v,
            beta,
            gamma,
            point: p,
            t,
            clamped,
        })
    }
}

/// The 2D frame of a quad's plane in which the inverse bilinear map is solved: `e1`'s
/// direction, and the normal crossed with it.
fn plane_frame(e1: Vec3, normal: Vec3) -> (Vec3, Vec3) {
    let x_axis = e1.normalize_or_zero();
    (x_axis, normal.cross(x_axis))
}

/// What the search over quads keeps: the hit of smallest `t` (of equal ones, that of the
/// first quad in the cylinder's order, whatever order they are offered in), and whether
/// any hit lies ahead of the ray's origin.
#[derive(Debug, Default)]
struct Nearest {
    best: Option<(usize, CylinderHit)>,
    any_ahead: bool,
}

impl Nearest {
    /// Takes the hit, if any, of quad `index`.
    fn offer(&mut self, index: usize, hit: Option<CylinderHit>) {
        let Some(hit) = hit else { return };
        self.any_ahead |= hit.t >= 0.0 || hit.t.is_nan();
        let better = match &self.best {
            None => true,
            Some((i, best)) => match hit.t.total_cmp(&best.t) {
                Ordering::Less => true,
                Ordering::Equal => index < *i,
                Ordering::Greater => false,
            },
        };
        if better {
            self.best = Some((index, hit));
        }
    }

    /// The entry, unless every hit lies behind the origin (or there is none).
    fn entry(self) -> Option<CylinderHit> {
        self.best.filter(|_| self.any_ahead).map(|(_, hit)| hit)
    }
}

/// The inverse bilinear map on a quad, in its plane: `(β, γ)` with `p = P00 + β e1 +
/// γ e2 + βγ e3`, or `None` if there is no solution.
pub fn inverse_bilinear(
    p: Vec3,
    p00: Vec3,
    e1: Vec3,
    e2: Vec3,
    e3: Vec3,
    normal: Vec3,
) -> Option<Vec2> {
    // 2D basis in the plane.
    let (x_axis, y_axis) = plane_frame(e1, normal);
    let flat = |v: Vec3| Vec2::new(v.dot(x_axis), v.dot(y_axis));
    let (q, a, b, c) = (flat(p - p00), flat(e1), flat(e2), flat(e3));
    // q = β a + γ b + βγ c. Eliminating β: (a + γ c) × (q − γ b) = 0 (2D cross).
    let cross = |m: Vec2, n: Vec2| m.x * n.y - m.y * n.x;
    let k2 = cross(c, b);
    let k1 = cross(a, b) - cross(c, q);
    let k0 = -cross(a, q);
    let scale = k1.abs().max(k0.abs()).max(1e-30);
    // At most two roots, without allocating (this runs per quad per pixel).
    let mut roots = [0.0f32; 2];
    let count = if k2.abs() <= 1e-6 * scale {
        if k1.abs() < 1e-30 {
            return None;
        }
        roots[0] = -k0 / k1;
        1
    } else {
        let disc = k1 * k1 - 4.0 * k2 * k0;
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        // Numerically stable roots.
        let qq = -0.5 * (k1 + k1.signum() * s);
        roots[0] = qq / k2;
        if qq.abs() > 1e-30 {
            roots[1] = k0 / qq;
            2
        } else {
            1
        }
    };
    // Of the roots, the one inside (or nearest to) the unit square.
    roots[..count]
        .iter()
        .filter_map(|&g| {
            let d = a + c * g;
            let beta = if d.x.abs() >= d.y.abs() {
                (q.x - g * b.x) / d.x
            } else {
                (q.y - g * b.y) / d.y
            };
            beta.is_finite().then_some(Vec2::new(beta, g))
        })
        .min_by(|m, n| outside(*m).total_cmp(&outside(*n)))
}

/// How far `(β, γ)` lies outside the unit square (0 inside).
fn outside(bg: Vec2) -> f32 {
    let d = |x: f32| (-x).max(x - 1.0).max(0.0);
    d(bg.x) + d(bg.y)
}

/// One quad of the cylinder: `p = p00 + β e1 + γ e2 + βγ e3`, its plane's normal, its
/// grid position, and for the walls above and below the grid (`wall` 1 and 2; 0 inside)
/// the `γ` rays are clamped to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadData {
    /// Column.
    pub u: u32,
    /// Row.
    pub v: u32,
    /// Corner `(u, v)`.
    pub p00: Vec3,
    /// Toward `(u + 1, v)`.
    pub e1: Vec3,
    /// Toward `(u, v + 1)`.
    pub e2: Vec3,
    /// The twist `P00 − P10 − P01 + P11`.
    pub e3: Vec3,
    /// Unit normal.
    pub normal: Vec3,
    /// 0 inside the grid, 1 above, 2 below.
    pub wall: u32,
    /// The clamped `γ` of a wall.
    pub wall_gamma: f32,
}

/// The cylinder of a pose's camera centres.
#[derive(Debug, Clone)]
pub struct Cylinder {
    columns: usize,
    rows: usize,
    /// Column spans of quads: `columns` round a ring, one fewer on an open grid.
    spans: usize,
    quads: Vec<Quad>,
    /// Which spans a ray's line can reach; `None` where the grid does not allow it.
    index: Option<ColumnIndex>,
}

impl Cylinder {
    /// The cylinder of `centres` (`u`-major, `columns x rows`; subject frame). Columns
    /// close into a ring when `wraps`.
    pub fn new(centres: &[Vec3], columns: usize, rows: usize, wraps: bool) -> Self {
        let c = |u: usize, v: usize| centres[(u % columns) * rows + v];
        let spans = if wraps {
            columns
        } else {
            columns.saturating_sub(1)
        };
        let up = Vec3::Y * WALL_HEIGHT_M;
        let mut quads = Vec::new();
        for u in 0..spans {
            for v in 0..rows.saturating_sub(1) {
                quads.push(Quad::new(
                    u,
                    v,
                    [c(u, v), c(u + 1, v), c(u, v + 1), c(u + 1, v + 1)],
                    None,
                ));
            }
            let top = rows - 1;
            let (vt, gt) = if rows >= 2 { (rows - 2, 1.0) } else { (0, 0.0) };
            quads.push(Quad::new(
                u,
                vt,
                [c(u, top), c(u + 1, top), c(u, top) + up, c(u + 1, top) + up],
                Some((gt, Clamp::Above)),
            ));
            quads.push(Quad::new(
                u,
                0,
                [c(u, 0), c(u + 1, 0), c(u, 0) - up, c(u + 1, 0) - up],
                Some((0.0, Clamp::Below)),
            ));
        }
        let index = ColumnIndex::new(&quads, rows + 1, centres, rows);
        Self {
            columns,
            rows,
            spans,
            quads,
            index,
        }
    }

    /// Column spans of quads (`columns` round a ring, one fewer on an open grid).
    pub fn spans(&self) -> usize {
        self.spans
    }

    /// Columns.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Where the ray `origin + t dir` enters the cylinder (see the module docs): the
    /// quads of the spans its line can reach are solved, all of them where the grid has no
    /// column index. The same hit as [`Cylinder::intersect_brute`].
    pub fn intersect(&self, origin: Vec3, dir: Vec3) -> Option<CylinderHit> {
        self.intersect_counted(origin, dir).0
    }

    /// Where the ray `origin + t dir` enters the cylinder, every quad solved: the
    /// reference for [`Cylinder::intersect`].
    pub fn intersect_brute(&self, origin: Vec3, dir: Vec3) -> Option<CylinderHit> {
        let mut nearest = Nearest::default();
        for (i, q) in self.quads.iter().enumerate() {
            nearest.offer(i, q.hit(origin, dir));
        }
        nearest.entry()
    }

    /// How many quads [`Cylinder::intersect`] solves for the ray `origin + t dir`.
    pub fn quads_tested(&self, origin: Vec3, dir: Vec3) -> usize {
        self.intersect_counted(origin, dir).1
    }

    /// [`Cylinder::intersect`], and the number of quads it solved.
    fn intersect_counted(&self, origin: Vec3, dir: Vec3) -> (Option<CylinderHit>, usize) {
        let index = match &self.index {
            Some(index) if origin.is_finite() && dir.is_finite() => index,
            _ => return (self.intersect_brute(origin, dir), self.quads.len()),
        };
        let per_span = index.quads_per_span();
        let mut nearest = Nearest::default();
        let mut tested = 0;
        index.spans_along(origin, dir, |span| {
            let first = span * per_span;
            for (i, q) in self.quads[first..first + per_span].iter().enumerate() {
                nearest.offer(first + i, q.hit(origin, dir));
            }
            tested += per_span;
        });
        (nearest.entry(), tested)
    }

    /// Whether [`Cylinder::intersect`] looks the quads up (else it solves them all).
    pub fn has_column_index(&self) -> bool {
        self.index.is_some()
    }

    /// The column index as the GPU reads it: its header (disabled where the grid has
    /// none) and per span its range of azimuths (at least one entry).
    pub fn column_index_gpu(&self) -> (GpuColumnIndex, Vec<[f32; 2]>) {
        ColumnIndex::gpu(self.index.as_ref())
    }

    /// Quads (and walls) it holds.
    pub fn quad_count(&self) -> usize {
        self.quads.len()
    }

    /// Bytes [`Cylinder::column_index_gpu`] makes, without making them.
    pub fn column_index_gpu_bytes(&self) -> usize {
        ColumnIndex::gpu_bytes(self.index.as_ref())
    }

    /// The quads and walls, as the GPU needs them.
    pub fn quads(&self) -> Vec<QuadData> {
        self.quads
            .iter()
            .map(|q| QuadData {
                u: q.u as u32,
                v: q.v as u32,
                p00: q.p00,
                e1: q.e1,
                e2: q.e2,
                e3: q.e3,
                normal: q.normal,
                wall: match q.wall {
                    None => 0,
                    Some((_, Clamp::Above)) => 1,
                    Some(_) => 2,
                },
                wall_gamma: q.wall.map_or(0.0, |w| w.0),
            })
            .collect()
    }

    /// Index of view `(u, v)` (`u` taken modulo the columns).
    pub fn view(&self, u: usize, v: usize) -> usize {
        (u % self.columns) * self.rows + v
    }
}

/// The camera at bilinear position `(β, γ)` between four cameras `[A, B, C, D]`
/// (`(u, v)`, `(u + 1, v)`, `(u, v + 1)`, `(u + 1, v + 1)`), centred at `centre`:
/// intrinsics interpolated bilinearly, orientations by normalized bilinear blending of
/// their quaternions (signs aligned to A's).
pub fn interpolate_camera(cams: [&Camera; 4], beta: f32, gamma: f32, centre: Vec3) -> Camera {
    let w = bilinear_weights(beta, gamma);
    let q0 = Quat::from_mat3(&cams[0].world_from_camera.rotation);
    let mut q = glam::Vec4::ZERO;
    let (mut fx, mut fy, mut cx, mut cy) = (0.0, 0.0, 0.0, 0.0);
    for (c, wi) in cams.iter().zip(w) {
        let mut qi = Quat::from_mat3(&c.world_from_camera.rotation);
        if qi.dot(q0) < 0.0 {
            qi = -qi;
        }
        q += glam::Vec4::from(qi) * wi;
        let k = &c.intrinsics;
        fx += k.fx * wi;
        fy += k.fy * wi;
        cx += k.cx * wi;
        cy += k.cy * wi;
    }
    let rotation = Mat3::from_quat(Quat::from_vec4(q).normalize());
    Camera {
        width: cams[0].width,
        height: cams[0].height,
        intrinsics: Intrinsics { fx, fy, cx, cy },
        world_from_camera: Rigid {
            rotation,
            translation: centre,
        },
    }
}

/// Weights of `[A, B, C, D]` at `(β, γ)`: `[b g, β g, b γ, β γ]` with `b = 1 − β`,
/// `g = 1 − γ`.
pub fn bilinear_weights(beta: f32, gamma: f32) -> [f32; 4] {
    let (b, g) = (1.0 - beta, 1.0 - gamma);
    [b * g, beta * g, b * gamma, beta * gamma]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stage-like grid: 36 columns 10° apart, rows at 0°, 17°, 34° elevation.
    pub(super) fn grid() -> (Vec<Vec3>, usize, usize) {
        let mut centres = Vec::new();
        for u in 0..36 {
            for e in [0.0f32, 17.0, 34.0] {
                let d = frf_core::light::direction_from_azimuth_elevation(
                    -(u as f32 * 10.0).to_radians(),
                    e.to_radians(),
                );
                centres.push(Vec3::new(0.0, 0.9, 0.0) + d * 4.5);
            }
        }
        (centres, 36, 3)
    }

    /// What the GPU is given is counted without being made: the same bytes.
    #[test]
    fn the_gpu_bytes_are_counted_as_made() {
        let (centres, cols, rows) = grid();
        let cyl = Cylinder::new(&centres, cols, rows, true);
        assert_eq!(cyl.quad_count(), cyl.quads().len());
        let (index, ranges) = cyl.column_index_gpu();
        assert!(ranges.len() > 1, "an index of one range tells nothing");
        let made = std::mem::size_of_val(&index) + std::mem::size_of_val(ranges.as_slice());
        assert_eq!(cyl.column_index_gpu_bytes(), made);
    }

    #[test]
    fn inverse_bilinear_inverts_the_bilinear_map() {
        let p = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.3, 1.0, 0.0),
            Vec3::new(1.6, 1.2, 0.0),
        ];
        let q = Quad::new(0, 0, p, None);
        for (b, g) in [(0.0, 0.0), (1.0, 1.0), (0.25, 0.7), (0.9, 0.1)] {
            let x = q.p00 + q.e1 * b + q.e2 * g + q.e3 * (b * g);
            let bg = inverse_bilinear(x, q.p00, q.e1, q.e2, q.e3, q.normal).unwrap();
            assert!((bg - Vec2::new(b, g)).length() < 1e-5, "{bg} vs {b}, {g}");
        }
    }

    #[test]
    fn a_ray_through_a_camera_centre_hits_its_vertex() {
        let (centres, cols, rows) = grid();
        let cyl = Cylinder::new(&centres, cols, rows, true);
        // From outside, through the centre of camera (5, 1), toward the axis.
        let target = centres[5 * 3 + 1];
        let origin = target * 1.5 - Vec3::new(0.0, 0.45, 0.0);
        let hit = cyl
            .intersect(origin, (target - origin).normalize())
            .unwrap();
        let (u, v) = (hit.u as f32 + hit.beta, hit.v as f32 + hit.gamma);
        assert!(
            (u - 5.0).abs() < 1e-3 && (v - 1.0).abs() < 1e-3,
            "u {u} v {v}"
        );
        assert!((hit.point - target).length() < 1e-3 && hit.t > 0.0 && hit.clamped == Clamp::None);
    }

    #[test]
    fn inside_cameras_take_the_entry_behind_them_and_outside_ones_looking_away_see_nothing() {
        let (centres, cols, rows) = grid();
        let cyl = Cylinder::new(&centres, cols, rows, true);
        let inside = Vec3::new(0.5, 1.5, 0.3);
        let hit = cyl.intersect(inside, Vec3::NEG_Z).unwrap();
        assert!(hit.t < 0.0, "the entry is behind an inside camera");
        let outside = Vec3::new(0.0, 1.2, 9.0);
        assert!(cyl.intersect(outside, Vec3::Z).is_none());
        assert!(cyl.intersect(outside, Vec3::NEG_Z).unwrap().t > 0.0);
    }

    #[test]
    fn rays_above_and_below_are_clamped_to_a_row() {
        let (centres, cols, rows) = grid();
        let cyl = Cylinder::new(&centres, cols, rows, true);
        let above = cyl
            .intersect(Vec3::new(0.0, 8.0, 9.0), Vec3::NEG_Z)
            .unwrap();
        assert_eq!(
            (above.clamped, above.v, above.gamma),
            (Clamp::Above, 1, 1.0)
        );
        let below = cyl
            .intersect(Vec3::new(0.0, -5.0, 9.0), Vec3::NEG_Z)
            .unwrap();
        assert_eq!(
            (below.clamped, below.v, below.gamma),
            (Clamp::Below, 0, 0.0)
        );
        // A vertical line on the axis meets nothing (parallel to the walls).
        assert!(
            cyl.intersect(Vec3::new(0.0, 9.0, 0.0), Vec3::NEG_Y)
                .is_none()
        );
    }

    #[test]
    fn the_interpolated_camera_is_the_vertex_camera_at_a_vertex() {
        let cams: Vec<Camera> = (0..4)
            .map(|i| {
                let eye = Vec3::new(i as f32, 1.0 + (i / 2) as f32, 4.0);
                Camera::look_at(
                    eye,
                    Vec3::new(0.0, 0.9, 0.0),
                    Vec3::Y,
                    0.5 + i as f32 * 0.01,
                    64,
                    90,
                )
                .unwrap()
            })
            .collect();
        let refs = [&cams[0], &cams[1], &cams[2], &cams[3]];
        for (k, (b, g)) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
            .into_iter()
            .enumerate()
        {
            let c = interpolate_camera(refs, b, g, cams[k].centre());
            assert!(
                c.world_from_camera
                    .rotation
                    .abs_diff_eq(cams[k].world_from_camera.rotation, 1e-5)
            );
            assert!((c.intrinsics.fy - cams[k].intrinsics.fy).abs() < 1e-3);
        }
        let w = bilinear_weights(0.3, 0.6);
        assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }
}
