//! Where a subject can show: the bounds a pose's subject keeps to in its own frame (a
//! cylinder round its visual hull, grown by the reach of its flows), whether a ray may
//! meet them, and the box of pixels where a camera sees them. The planner reads only the
//! views such rays reach ([`crate::scene::plan`]), and each walker's frame pass shades
//! only its box: outside it, the walker is transparent.

use frf_core::camera::Camera;
use frf_reflectance::field::PoseRecord;
use glam::{Vec2, Vec3};
use serde::Serialize;

use crate::error::{RenderError, Result};

/// Where on the subject's axis pixels per metre are measured (metres up: mid-body).
const AXIS_POINT_M: f32 = 1.0;

/// Pixels per metre `camera` (in the subject's frame) sees at the subject's axis.
pub fn pixels_per_metre(camera: &Camera) -> f32 {
    let d = (Vec3::new(0.0, AXIS_POINT_M, 0.0) - camera.centre()).length();
    camera.intrinsics.fx.abs().max(camera.intrinsics.fy.abs()) / d.max(1e-3)
}

/// Pixels per metre the pose's views captured the subject at: the median over its views
/// ([`pixels_per_metre`]).
pub fn captured_ppm(record: &PoseRecord) -> Result<f32> {
    let mut ppm = record
        .views
        .iter()
        .map(|v| {
            v.camera
                .to_camera()
                .map(|c| pixels_per_metre(&c))
                .map_err(RenderError::BadCamera)
        })
        .collect::<Result<Vec<f32>>>()?;
    ppm.sort_by(f32::total_cmp);
    Ok(ppm.get(ppm.len() / 2).copied().unwrap_or(0.0))
}

/// Where a subject can be when nothing more is known of it (a field without a visual
/// hull), in its own frame: within this distance of its axis (metres; a walker's reach,
/// 0.4 m, with its limbs' swing and a margin for the flows that carry its edges)...
pub const SUBJECT_RADIUS_M: f32 = 1.2;
/// ... and between these heights (metres).
pub const SUBJECT_HEIGHTS_M: (f32, f32) = (-0.2, 2.3);

/// Where a pose's subject can show, in its own frame: a vertical cylinder of `radius`
/// round the axis through `axis` (its x and z), between `heights`. Only a ray through it
/// can show the subject: the planner reads only the views such rays reach, and a
/// walker's frame pass shades only the pixels where its camera sees it.
///
/// Of a pose with a visual hull ([`SubjectBounds::of_pose`]): the cylinder round the
/// hull's box, grown by the reach of the pose's flows. The hull holds every view's
/// matte, and a rendered pixel is made of the views' samples where the morph's solve
/// puts them: from the ray's projection at the proxy's depth (the hull, or the point
/// nearest its axis), moved by the flows' displacements, each at most the quantizer's
/// range. Drawn with no margin at all, frames were identical on every camera tried
/// (docs/design.md section 6.4): the margin is a safety factor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SubjectBounds {
    /// `(x, z)` of the vertical axis, metres.
    pub axis: Vec2,
    /// Metres from the axis.
    pub radius: f32,
    /// Lowest and highest, metres.
    pub heights: (f32, f32),
}

impl SubjectBounds {
    /// Of a subject known only to be a person walking in place on the stage.
    pub const DESIGN: Self = Self {
        axis: Vec2::ZERO,
        radius: SUBJECT_RADIUS_M,
        heights: SUBJECT_HEIGHTS_M,
    };

    /// Of a pose of `record` whose visual hull spans `hull` (its box's corners, subject
    /// frame; none: [`SubjectBounds::DESIGN`]): [`SubjectBounds::round_box`] grown by
    /// [`flow_reach_m`].
    pub fn of_pose(record: &PoseRecord, hull: Option<(Vec3, Vec3)>) -> Result<Self> {
        let Some((lo, hi)) = hull else {
            return Ok(Self::DESIGN);
        };
        let margin = flow_reach_m(record)?;
        Ok(if margin.is_finite() {
            Self::round_box(lo, hi, margin)
        } else {
            Self::DESIGN
        })
    }

    /// The vertical cylinder round the box `lo..hi` (subject frame), grown by `margin`
    /// metres on every side.
    pub fn round_box(lo: Vec3, hi: Vec3, margin: f32) -> Self {
        let half = 0.5 * Vec2::new(hi.x - lo.x, hi.z - lo.z);
        Self {
            axis: 0.5 * Vec2::new(lo.x + hi.x, lo.z + hi.z),
            radius: half.length() + margin,
            heights: (lo.y - margin, hi.y + margin),
        }
    }

    /// A cylinder holding both (a walker between two poses).
    pub fn union(self, other: Self) -> Self {
        Self {
            axis: self.axis,
            radius: self
                .radius
                .max(self.axis.distance(other.axis) + other.radius),
            heights: (
                self.heights.0.min(other.heights.0),
                self.heights.1.max(other.heights.1),
            ),
        }
    }

    /// Whether the ray from `origin` along `dir` passes through the bounds: only such
    /// rays can show the subject.
    pub fn may_see(&self, origin: Vec3, dir: Vec3) -> bool {
        let o = Vec2::new(origin.x, origin.z) - self.axis;
        let (a, b) = (dir.x * dir.x + dir.z * dir.z, o.x * dir.x + o.y * dir.z);
        let c = o.length_squared() - self.radius * self.radius;
        let (t0, t1) = if a < 1e-12 {
            // Along the axis: inside the cylinder or never.
            if c > 0.0 {
                return false;
            }
            (0.0, f32::INFINITY)
        } else {
            let disc = b * b - a * c;
            if disc < 0.0 {
                return false;
            }
            let r = disc.sqrt();
            ((-b - r) / a, (-b + r) / a)
        };
        let t0 = t0.max(0.0);
        if t1 < t0 {
            return false;
        }
        // Heights over the span inside the cylinder.
        let (lo, hi) = self.heights;
        let y0 = origin.y + dir.y * t0;
        let y1 = if t1.is_finite() {
            origin.y + dir.y * t1
        } else if dir.y > 0.0 {
            f32::INFINITY
        } else if dir.y < 0.0 {
            f32::NEG_INFINITY
        } else {
            y0
        };
        y0.min(y1) <= hi && y0.max(y1) >= lo
    }

    /// The pixel box where `camera` (in the subject's frame) sees the bounds: outside it
    /// no ray can show the subject. The whole frame when part of the bounds is behind the
    /// camera; `None` when the camera sees none of them.
    pub fn pixel_box(&self, camera: &Camera) -> Option<PixelBox> {
        let (lo, hi) = self.heights;
        // The polygon's circumradius, so that it holds the circle.
        let r = self.radius / (std::f32::consts::PI / 16.0).cos();
        let mut corners = Vec::with_capacity(32);
        for k in 0..16 {
            let a = k as f32 * std::f32::consts::TAU / 16.0;
            let (x, z) = (self.axis.x + r * a.cos(), self.axis.y + r * a.sin());
            for y in [lo, hi] {
                corners.push(Vec3::new(x, y, z));
            }
        }
        box_of(camera, &corners)
    }
}

/// How far (metres, at the subject's axis) a pose's flows can carry a sample: the
/// largest displacement its quantizer represents (`M` each component, so `M √2`) at the
/// pixels per metre its views captured the subject at (their median), and one more
/// pixel for the bilinear footprint.
pub fn flow_reach_m(record: &PoseRecord) -> Result<f32> {
    let reach_px = record.flow_quantizer.range * std::f32::consts::SQRT_2 + 1.0;
    Ok(reach_px / captured_ppm(record)?)
}

/// A box of pixels: columns `x0..x1` and rows `y0..y1` (ends exclusive).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelBox {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl PixelBox {
    /// No pixels.
    pub const EMPTY: Self = Self {
        x0: 0,
        y0: 0,
        x1: 0,
        y1: 0,
    };

    /// The whole of a `width x height` frame.
    pub fn whole(width: u32, height: u32) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// Width and height.
    pub fn size(&self) -> (u32, u32) {
        (self.x1 - self.x0, self.y1 - self.y0)
    }

    /// Pixels in the box.
    pub fn pixels(&self) -> usize {
        let (w, h) = self.size();
        w as usize * h as usize
    }

    /// Whether pixel `(x, y)` is in the box.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// The smallest box holding both (an empty box holds nothing).
    pub fn union(self, other: Self) -> Self {
        match (self.pixels(), other.pixels()) {
            (0, _) => other,
            (_, 0) => self,
            _ => Self {
                x0: self.x0.min(other.x0),
                y0: self.y0.min(other.y0),
                x1: self.x1.max(other.x1),
                y1: self.y1.max(other.y1),
            },
        }
    }

    /// As the shaders read it: `[x0, y0, x1, y1]`.
    pub fn to_array(self) -> [u32; 4] {
        [self.x0, self.y0, self.x1, self.y1]
    }
}

/// The pixel box where `camera` (in the subject's frame) sees the square of ground
/// within `half` metres of the subject's axis along both of its axes (where its shadow
/// map lies), as [`SubjectBounds::pixel_box`].
pub fn ground_box(camera: &Camera, half: f32) -> Option<PixelBox> {
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .map(|(x, z)| Vec3::new(x * half, 0.0, z * half));
    box_of(camera, &corners)
}

/// The pixel box holding `corners` (of a convex body, subject frame) as `camera` sees
/// them, with a pixel's bilinear footprint either side: the whole frame when one is
/// behind the camera, `None` when the box misses the frame.
fn box_of(camera: &Camera, corners: &[Vec3]) -> Option<PixelBox> {
    let projected: Vec<Vec2> = corners.iter().filter_map(|&p| camera.project(p)).collect();
    if projected.len() < corners.len() {
        return Some(PixelBox::whole(camera.width, camera.height));
    }
    let (mut x0, mut y0, mut x1, mut y1) = (f32::MAX, f32::MAX, f32::MIN, f32::MIN);
    for p in projected {
        (x0, y0, x1, y1) = (x0.min(p.x), y0.min(p.y), x1.max(p.x), y1.max(p.y));
    }
    let (w, h) = (camera.width as f32, camera.height as f32);
    if x1 < 0.0 || y1 < 0.0 || x0 > w - 1.0 || y0 > h - 1.0 {
        return None;
    }
    // A pixel's centre is at its integer coordinates; one more either side for the
    // bilinear footprint.
    let clamp = |v: f32, max: f32| v.clamp(0.0, max) as u32;
    Some(PixelBox {
        x0: clamp(x0.floor() - 1.0, w),
        y0: clamp(y0.floor() - 1.0, h),
        x1: clamp(x1.ceil() + 2.0, w),
        y1: clamp(y1.ceil() + 2.0, h),
    })
}

/// Side of the square tiles the composite pass finds its walkers by, pixels.
pub const TILE: u32 = 16;

/// Per tile of a frame ([`TILE`] pixels square, row after row), the walkers whose pixel
/// boxes meet it, in their order: the composite pass reads only those at a pixel, where
/// every other walker is transparent and casts no shadow.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TileLists {
    /// Tiles in a row.
    pub columns: u32,
    /// Per tile, the index in `words` of its first walker and their count; then the
    /// lists, walker indices in the order given.
    pub words: Vec<u32>,
}

impl TileLists {
    /// The lists of a `width x height` frame whose walker `i` may touch only the pixels
    /// of `boxes[i]`.
    pub fn new(width: u32, height: u32, boxes: &[PixelBox]) -> Self {
        let (columns, rows) = (width.div_ceil(TILE), height.div_ceil(TILE));
        let tiles = (columns * rows) as usize;
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); tiles];
        for (i, b) in boxes.iter().enumerate() {
            if b.pixels() == 0 {
                continue;
            }
            for ty in b.y0 / TILE..b.y1.div_ceil(TILE).min(rows) {
                for tx in b.x0 / TILE..b.x1.div_ceil(TILE).min(columns) {
                    lists[(ty * columns + tx) as usize].push(i as u32);
                }
            }
        }
        let mut words = Vec::with_capacity(2 * tiles + lists.iter().map(Vec::len).sum::<usize>());
        let mut next = 2 * tiles as u32;
        for l in &lists {
            words.extend([next, l.len() as u32]);
            next += l.len() as u32;
        }
        words.extend(lists.into_iter().flatten());
        Self { columns, words }
    }

    /// The most words the lists of a `width x height` frame of `walkers` can take.
    pub fn capacity(width: u32, height: u32, walkers: u32) -> usize {
        let tiles = (width.div_ceil(TILE) * height.div_ceil(TILE)) as usize;
        tiles * (2 + walkers as usize)
    }

    /// The walkers listed for the tile of pixel `(x, y)`.
    pub fn at(&self, x: u32, y: u32) -> &[u32] {
        let t = ((y / TILE) * self.columns + x / TILE) as usize;
        let (first, count) = (self.words[2 * t] as usize, self.words[2 * t + 1] as usize);
        &self.words[first..first + count]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    /// A 64x48 camera 5 m from the axis, 1.5 m up, looking at the ground by the subject.
    fn camera() -> Camera {
        let eye = Vec3::new(0.0, 1.5, 5.0);
        Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 60f32.to_radians(), 64, 48).expect("a camera")
    }

    #[test]
    fn the_ground_box_holds_every_ray_that_meets_the_patch() {
        let cam = camera();
        let half = 1.5;
        let b = ground_box(&cam, half).expect("the patch is in view");
        assert!(b.pixels() < 64 * 48, "{b:?} is the whole frame");
        // Every pixel whose ray meets the ground inside the patch is in the box.
        let mut met = 0;
        for y in 0..cam.height {
            for x in 0..cam.width {
                let (o, d) = (
                    cam.centre(),
                    cam.ray_direction(Vec2::new(x as f32, y as f32)),
                );
                if d.y >= 0.0 {
                    continue;
                }
                let p = o + d * (-o.y / d.y);
                if p.x.abs() <= half && p.z.abs() <= half {
                    met += 1;
                    assert!(
                        b.contains(x, y),
                        "pixel ({x}, {y}) meets the patch outside {b:?}"
                    );
                }
            }
        }
        assert!(met > 100);
    }

    #[test]
    fn bounds_round_a_box_hold_every_ray_through_it_in_their_pixel_box() {
        let (lo, hi) = (Vec3::new(-0.4, 0.0, -0.1), Vec3::new(0.1, 1.8, 0.3));
        let bounds = SubjectBounds::round_box(lo, hi, 0.05);
        // Between poses: a cylinder holding both.
        let other = SubjectBounds::round_box(lo + Vec3::X, hi + Vec3::X, 0.0);
        let both = bounds.union(other);
        for camera in [
            camera(),
            Camera::look_at(Vec3::new(2.0, 3.0, 1.0), Vec3::Y, Vec3::Y, 1.0, 64, 48).unwrap(),
        ] {
            let b = bounds.pixel_box(&camera).expect("in view");
            assert!(b.pixels() < 64 * 48 / 2, "{b:?} is loose");
            let (mut through, mut seen) = (0, 0);
            for y in 0..camera.height {
                for x in 0..camera.width {
                    let (o, d) = (
                        camera.centre(),
                        camera.ray_direction(Vec2::new(x as f32, y as f32)),
                    );
                    // The ray's span inside the box (slabs).
                    let (t0, t1) = (0..3).fold((0.0f32, f32::INFINITY), |(t0, t1), k| {
                        let (a, b) = ((lo[k] - o[k]) / d[k], (hi[k] - o[k]) / d[k]);
                        (t0.max(a.min(b)), t1.min(a.max(b)))
                    });
                    if t0 <= t1 {
                        through += 1;
                        assert!(bounds.may_see(o, d), "ray ({x}, {y}) through the box");
                        assert!(both.may_see(o, d), "ray ({x}, {y}) between poses");
                    }
                    if bounds.may_see(o, d) {
                        seen += 1;
                        assert!(b.contains(x, y), "pixel ({x}, {y}) sees it outside {b:?}");
                    }
                    if other.may_see(o, d) {
                        assert!(both.may_see(o, d), "ray ({x}, {y}) of the other pose");
                    }
                }
            }
            assert!(
                through > 20 && seen > through,
                "{through} through, {seen} seen"
            );
        }
    }

    #[test]
    fn tile_lists_name_each_walker_where_its_box_is() {
        let boxes = [
            PixelBox {
                x0: 0,
                y0: 0,
                x1: 20,
                y1: 10,
            },
            PixelBox {
                x0: 0,
                y0: 0,
                x1: 0,
                y1: 0,
            },
            PixelBox {
                x0: 15,
                y0: 5,
                x1: 40,
                y1: 33,
            },
        ];
        let lists = TileLists::new(40, 33, &boxes);
        assert_eq!(lists.columns, 3);
        assert!(lists.words.len() <= TileLists::capacity(40, 33, 3));
        for y in 0..33 {
            for x in 0..40 {
                let listed = lists.at(x, y);
                // In order, no empty box, and every walker whose box holds the pixel.
                assert!(listed.windows(2).all(|w| w[0] < w[1]));
                assert!(!listed.contains(&1));
                for (i, b) in boxes.iter().enumerate() {
                    if b.contains(x, y) {
                        assert!(listed.contains(&(i as u32)), "({x}, {y}) lacks {i}");
                    }
                }
            }
        }
        // A tile the first box misses does not list it.
        assert_eq!(lists.at(39, 32), &[2]);
    }

    #[test]
    fn a_union_holds_both_boxes_and_ignores_an_empty_one() {
        let a = PixelBox {
            x0: 1,
            y0: 2,
            x1: 5,
            y1: 6,
        };
        let b = PixelBox {
            x0: 4,
            y0: 0,
            x1: 9,
            y1: 3,
        };
        let empty = PixelBox {
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
        };
        assert_eq!(
            a.union(b),
            PixelBox {
                x0: 1,
                y0: 0,
                x1: 9,
                y1: 6
            }
        );
        assert_eq!(a.union(empty), a);
        assert_eq!(empty.union(b), b);
    }
}
