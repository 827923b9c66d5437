//! Ray–primitive intersection for the stage's ray tracer: capsules, ellipsoids, spheres
//! and axis-aligned boxes. All are analytic; distances are along unit directions.

use glam::Vec3;

/// A ray with unit direction.
#[derive(Debug, Clone, Copy)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
}

/// A primitive shape in its part's local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// The points within `radius` of the segment `a`–`b`.
    Capsule {
        /// Segment start.
        a: Vec3,
        /// Segment end.
        b: Vec3,
        /// Radius, metres.
        radius: f32,
    },
    /// An axis-aligned ellipsoid.
    Ellipsoid {
        /// Centre.
        centre: Vec3,
        /// Semi-axes along x, y, z, metres.
        radii: Vec3,
    },
}

impl Shape {
    /// Distance to the nearest intersection in `(t_min, t_max)`, and the outward unit
    /// normal there (local frame).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<(f32, Vec3)> {
        match *self {
            Shape::Capsule { a, b, radius } => capsule(ray, a, b, radius, t_min, t_max),
            Shape::Ellipsoid { centre, radii } => ellipsoid(ray, centre, radii, t_min, t_max),
        }
    }

    /// Whether `p` (local frame) lies inside the shape or on its surface.
    pub fn contains(&self, p: Vec3) -> bool {
        match *self {
            Shape::Capsule { a, b, radius } => {
                let ab = b - a;
                let t =
                    ((p - a).dot(ab) / ab.length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
                (p - (a + ab * t)).length_squared() <= radius * radius
            }
            Shape::Ellipsoid { centre, radii } => ((p - centre) / radii).length_squared() <= 1.0,
        }
    }

    /// A sphere (centre, radius) that contains the shape.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        match *self {
            Shape::Capsule { a, b, radius } => ((a + b) * 0.5, (b - a).length() * 0.5 + radius),
            Shape::Ellipsoid { centre, radii } => (centre, radii.max_element()),
        }
    }
}

/// Nearest root of `a t² + 2 b t + c = 0` (with `a > 0`) inside `(t_min, t_max)`.
#[inline]
fn nearest_root(a: f32, b: f32, c: f32, t_min: f32, t_max: f32) -> Option<f32> {
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    let t0 = (-b - s) / a;
    if t0 > t_min && t0 < t_max {
        return Some(t0);
    }
    let t1 = (-b + s) / a;
    (t1 > t_min && t1 < t_max).then_some(t1)
}

fn sphere(ray: &Ray, centre: Vec3, r: f32, t_min: f32, t_max: f32) -> Option<f32> {
    let oc = ray.origin - centre;
    nearest_root(
        1.0,
        oc.dot(ray.dir),
        oc.length_squared() - r * r,
        t_min,
        t_max,
    )
}

fn capsule(ray: &Ray, a: Vec3, b: Vec3, r: f32, t_min: f32, t_max: f32) -> Option<(f32, Vec3)> {
    // The infinite cylinder around the axis, restricted to the segment, then the two
    // end spheres; the nearest valid hit wins.
    let axis = b - a;
    let len2 = axis.length_squared();
    let mut best: Option<f32> = None;
    let oa = ray.origin - a;
    let d_par = ray.dir.dot(axis) / len2;
    let o_par = oa.dot(axis) / len2;
    let d_perp = ray.dir - axis * d_par;
    let o_perp = oa - axis * o_par;
    let qa = d_perp.length_squared();
    if qa > 1e-12
        && let Some(t) = nearest_root(
            qa,
            d_perp.dot(o_perp),
            o_perp.length_squared() - r * r,
            t_min,
            t_max,
        )
    {
        let s = o_par + t * d_par;
        if (0.0..=1.0).contains(&s) {
            best = Some(t);
        }
    }
    for end in [a, b] {
        if let Some(t) = sphere(ray, end, r, t_min, best.unwrap_or(t_max)) {
            best = Some(t);
        }
    }
    let t = best?;
    let p = ray.origin + ray.dir * t;
    let s = ((p - a).dot(axis) / len2).clamp(0.0, 1.0);
    let normal = (p - (a + axis * s)).normalize_or_zero();
    Some((t, normal))
}

fn ellipsoid(ray: &Ray, c: Vec3, radii: Vec3, t_min: f32, t_max: f32) -> Option<(f32, Vec3)> {
    let inv = radii.recip();
    let o = (ray.origin - c) * inv;
    let d = ray.dir * inv;
    let t = nearest_root(
        d.length_squared(),
        o.dot(d),
        o.length_squared() - 1.0,
        t_min,
        t_max,
    )?;
    let p = ray.origin + ray.dir * t - c;
    Some((t, (p * inv * inv).normalize_or_zero()))
}

/// Whether the ray meets the sphere within `(0, t_max)`, conservatively (tangent rays
/// count as meeting).
#[inline]
pub fn hits_sphere(ray: &Ray, centre: Vec3, radius: f32, t_max: f32) -> bool {
    let oc = centre - ray.origin;
    let along = oc.dot(ray.dir);
    let dist2 = oc.length_squared() - along * along;
    if dist2 > radius * radius {
        return false;
    }
    // The sphere's extent along the ray overlaps (0, t_max).
    along + radius > 0.0 && along - radius < t_max
}

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub min: Vec3,
    /// Maximum corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box.
    pub const EMPTY: Self = Self {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// Grows the box to include a sphere.
    pub fn include_sphere(&mut self, c: Vec3, r: f32) {
        self.min = self.min.min(c - Vec3::splat(r));
        self.max = self.max.max(c + Vec3::splat(r));
    }

    /// Whether the ray meets the box within `(0, t_max)` (slab test).
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f32) -> bool {
        let inv = ray.dir.recip();
        let t0 = (self.min - ray.origin) * inv;
        let t1 = (self.max - ray.origin) * inv;
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element().min(t_max);
        near <= far
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: Vec3, d: Vec3) -> Ray {
        Ray {
            origin: o,
            dir: d.normalize(),
        }
    }

    #[test]
    fn capsule_side_and_cap_hits() {
        let s = Shape::Capsule {
            a: Vec3::ZERO,
            b: Vec3::new(0.0, -1.0, 0.0),
            radius: 0.1,
        };
        let (t, n) = s
            .intersect(&ray(Vec3::new(-2.0, -0.5, 0.0), Vec3::X), 0.0, 10.0)
            .unwrap();
        assert!((t - 1.9).abs() < 1e-5 && (n - Vec3::NEG_X).length() < 1e-5);
        let (t, n) = s
            .intersect(&ray(Vec3::new(0.0, 2.0, 0.0), Vec3::NEG_Y), 0.0, 10.0)
            .unwrap();
        assert!((t - 1.9).abs() < 1e-5 && (n - Vec3::Y).length() < 1e-5);
        assert!(
            s.intersect(&ray(Vec3::new(-2.0, -0.5, 0.2), Vec3::X), 0.0, 10.0)
                .is_none()
        );
        // t_max is honoured.
        assert!(
            s.intersect(&ray(Vec3::new(-2.0, -0.5, 0.0), Vec3::X), 0.0, 1.0)
                .is_none()
        );
    }

    #[test]
    fn ellipsoid_hit_and_normal() {
        let s = Shape::Ellipsoid {
            centre: Vec3::new(0.0, 1.0, 0.0),
            radii: Vec3::new(0.5, 0.25, 0.1),
        };
        let (t, n) = s
            .intersect(&ray(Vec3::new(0.0, 3.0, 0.0), Vec3::NEG_Y), 0.0, 10.0)
            .unwrap();
        assert!((t - 1.75).abs() < 1e-5 && (n - Vec3::Y).length() < 1e-5);
        let (t, _) = s
            .intersect(&ray(Vec3::new(0.0, 1.0, 5.0), Vec3::NEG_Z), 0.0, 10.0)
            .unwrap();
        assert!((t - 4.9).abs() < 1e-5);
    }

    #[test]
    fn bounds_are_conservative() {
        let mut b = Aabb::EMPTY;
        b.include_sphere(Vec3::ZERO, 1.0);
        assert!(b.hit(&ray(Vec3::new(-5.0, 0.99, 0.0), Vec3::X), 100.0));
        assert!(!b.hit(&ray(Vec3::new(-5.0, 1.01, 0.0), Vec3::X), 100.0));
        assert!(!b.hit(&ray(Vec3::new(-5.0, 0.0, 0.0), Vec3::X), 3.0));
        assert!(hits_sphere(
            &ray(Vec3::new(-5.0, 0.99, 0.0), Vec3::X),
            Vec3::ZERO,
            1.0,
            100.0
        ));
        assert!(!hits_sphere(
            &ray(Vec3::new(-5.0, 0.0, 0.0), Vec3::NEG_X),
            Vec3::ZERO,
            1.0,
            100.0
        ));
    }
}
