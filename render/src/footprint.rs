//! Where a subject can show: the bounds a walker keeps to in its own frame (a cylinder
//! round its axis), whether a ray may meet them, and the box of pixels where a camera
//! sees them. The planner reads only the views such rays reach
//! ([`crate::scene::plan`]), and each walker's frame pass shades only its box: outside
//! it, the walker is transparent.

use frf_core::camera::Camera;
use glam::{Vec2, Vec3};

/// Where the subject can be, in its own frame: within this distance of its axis (metres;
/// a walker's reach, 0.4 m, with its limbs' swing and a margin for the flows that carry
/// its edges)...
pub const SUBJECT_RADIUS_M: f32 = 1.2;
/// ... and between these heights (metres).
pub const SUBJECT_HEIGHTS_M: (f32, f32) = (-0.2, 2.3);

/// Whether the ray from `origin` along `dir` passes through the cylinder
/// [`SUBJECT_RADIUS_M`] round the subject's axis between [`SUBJECT_HEIGHTS_M`]: only such
/// rays can show the subject.
pub fn may_see_subject(origin: Vec3, dir: Vec3) -> bool {
    let (a, b) = (
        dir.x * dir.x + dir.z * dir.z,
        origin.x * dir.x + origin.z * dir.z,
    );
    let c = origin.x * origin.x + origin.z * origin.z - SUBJECT_RADIUS_M * SUBJECT_RADIUS_M;
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
    let (lo, hi) = SUBJECT_HEIGHTS_M;
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

    /// As the shaders read it: `[x0, y0, x1, y1]`.
    pub fn to_array(self) -> [u32; 4] {
        [self.x0, self.y0, self.x1, self.y1]
    }
}

/// The pixel box where `camera` (in the subject's frame) sees the subject's bounds
/// ([`may_see_subject`]): outside it no ray can show the subject. The whole frame when
/// part of the bounds is behind the camera; `None` when the camera sees none of them.
pub fn subject_box(camera: &Camera) -> Option<PixelBox> {
    let (lo, hi) = SUBJECT_HEIGHTS_M;
    let mut corners = Vec::new();
    for k in 0..16 {
        let a = k as f32 * std::f32::consts::TAU / 16.0;
        // The polygon's circumradius, so that it holds the circle.
        let r = SUBJECT_RADIUS_M / (std::f32::consts::PI / 16.0).cos();
        for y in [lo, hi] {
            corners.push(Vec3::new(r * a.cos(), y, r * a.sin()));
        }
    }
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
