//! Rectification of vertical view pairs (docs/design.md section 2.3): vertical neighbours come
//! from different cameras, so before flow is computed the neighbour is warped onto the
//! plane fronto-parallel to the reference camera through the turntable axis (the plane
//! through the point where the camera's optical axis passes closest to the axis, facing
//! the camera). Points on that plane then line up exactly, and flow only has to explain
//! the subject's depth relief around it. The flow found between the reference and the
//! rectified neighbour is mapped back through the homography, so that the stored flow is
//! in true pixel coordinates of both images.
//!
//! The plane-induced homography (Hartley & Zisserman, "Multiple View Geometry", 13.1):
//! with `M = R_ref K_ref⁻¹` mapping a reference pixel to its ray direction, the plane
//! `n·X = n·P`, `c = n·(P − C_ref)`, it is
//! `H = K_o R_oᵀ (I + (C_ref − C_o) nᵀ / c) M`, taking reference pixels to the other view.

use frf_core::camera::Camera;
use frf_core::image::{Border, FlowImage, Image, Pixel};
use glam::{Mat3, Vec2, Vec3};

use crate::error::{IngestError, Result};

/// A homography between two images' pixel coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Homography(pub Mat3);

impl Homography {
    /// Applies it to a pixel.
    #[inline]
    pub fn apply(&self, p: Vec2) -> Vec2 {
        let q = self.0 * Vec3::new(p.x, p.y, 1.0);
        Vec2::new(q.x / q.z, q.y / q.z)
    }
}

fn intrinsics(c: &Camera) -> Mat3 {
    let k = &c.intrinsics;
    Mat3::from_cols(
        Vec3::new(k.fx, 0.0, 0.0),
        Vec3::new(0.0, k.fy, 0.0),
        Vec3::new(k.cx, k.cy, 1.0),
    )
}

/// The homography from `reference`'s pixels to `other`'s induced by the plane through
/// `point` with normal `normal`.
pub fn plane_homography(
    reference: &Camera,
    other: &Camera,
    point: Vec3,
    normal: Vec3,
) -> Result<Homography> {
    let n = normal.normalize_or_zero();
    let c = n.dot(point - reference.centre());
    if n == Vec3::ZERO || c.abs() < 1e-6 {
        return Err(IngestError::Degenerate(
            "rectification plane passes through the reference camera".into(),
        ));
    }
    let m = reference.world_from_camera.rotation * intrinsics(reference).inverse();
    let outer = Mat3::from_cols(
        (reference.centre() - other.centre()) * n.x,
        (reference.centre() - other.centre()) * n.y,
        (reference.centre() - other.centre()) * n.z,
    ) * (1.0 / c);
    let h = intrinsics(other)
        * other.world_from_camera.rotation.transpose()
        * (Mat3::IDENTITY + outer)
        * m;
    if !h.is_finite() {
        return Err(IngestError::Degenerate("degenerate rectification".into()));
    }
    Ok(Homography(h))
}

/// The rectifying homography of a vertical pair: the plane fronto-parallel to
/// `reference` through its [`Camera::axis_point`].
pub fn rectifying_homography(reference: &Camera, other: &Camera) -> Result<Homography> {
    plane_homography(
        reference,
        other,
        reference.axis_point(),
        reference.forward(),
    )
}

/// `other` resampled on the reference grid through `h`: `out(s) = other(H s)`.
pub fn rectify<P: Pixel>(
    other: &Image<P>,
    h: &Homography,
    width: usize,
    height: usize,
) -> Image<P> {
    Image::from_fn(width, height, |x, y| {
        let q = h.apply(Vec2::new(x as f32, y as f32));
        other.sample_bilinear(q.x, q.y, Border::Zero)
    })
}

/// Maps flow from the reference to the rectified neighbour back to true coordinates:
/// `F(s) = H(s + F'(s)) − s`.
pub fn unrectify_flow(rectified_flow: &FlowImage, h: &Homography) -> FlowImage {
    let w = rectified_flow.width();
    let pixels = rectified_flow
        .pixels()
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let s = Vec2::new((i % w) as f32, (i / w) as f32);
            let t = h.apply(s + Vec2::new(f[0], f[1])) - s;
            [t.x, t.y]
        })
        .collect();
    Image::from_vec(w, rectified_flow.height(), pixels).expect("same size as the input")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cameras() -> (Camera, Camera) {
        let target = Vec3::new(0.0, 0.9, 0.0);
        let eye = |deg: f32| {
            target + frf_core::light::direction_from_azimuth_elevation(0.1, deg.to_radians()) * 4.5
        };
        (
            Camera::look_at(eye(17.0), target, Vec3::Y, 0.48, 64, 90).unwrap(),
            Camera::look_at(eye(34.0), target, Vec3::Y, 0.48, 64, 90).unwrap(),
        )
    }

    #[test]
    fn points_on_the_plane_map_exactly() {
        let (a, b) = cameras();
        let h = rectifying_homography(&a, &b).unwrap();
        let p0 = a.axis_point();
        assert!((p0 - Vec3::new(0.0, 0.9, 0.0)).length() < 1e-4, "{p0}");
        let n = a.forward();
        // Two directions in the plane.
        let (e1, e2) = (
            n.cross(Vec3::Y).normalize(),
            n.cross(n.cross(Vec3::Y)).normalize(),
        );
        for (s, t) in [(0.0, 0.0), (0.3, -0.2), (-0.25, 0.6)] {
            let x = p0 + e1 * s + e2 * t;
            let (pa, pb) = (a.project(x).unwrap(), b.project(x).unwrap());
            assert!(
                (h.apply(pa) - pb).length() < 1e-2,
                "{} vs {pb}",
                h.apply(pa)
            );
        }
    }

    /// Checked against geometry, not the homography's formula: a pixel's ray from the
    /// reference camera meets the rectification plane at a point whose projection into
    /// the other camera is where zero rectified flow must land, and where the rectified
    /// image must have sampled the other image.
    #[test]
    fn zero_rectified_flow_lands_where_the_plane_point_projects() {
        let (a, b) = cameras();
        let h = rectifying_homography(&a, &b).unwrap();
        let f = unrectify_flow(&Image::new(64, 90, [0.0; 2]), &h);
        // The other image: a smooth function of its pixel position.
        let g = |p: Vec2| [0.01 * p.x + 0.002 * p.y * p.y / 90.0, 0.3];
        let other = Image::from_fn(64, 90, |x, y| g(Vec2::new(x as f32, y as f32)));
        let rectified = rectify(&other, &h, 64, 90);
        let (p0, n) = (a.axis_point(), a.forward());
        for (x, y) in [(10, 70), (32, 45), (5, 5), (60, 20)] {
            let s = Vec2::new(x as f32, y as f32);
            let d = a.ray_direction(s);
            let t = (p0 - a.centre()).dot(n) / d.dot(n);
            let pb = b.project(a.centre() + d * t).unwrap();
            let got = f.get(x, y);
            assert!(
                (Vec2::new(got[0], got[1]) - (pb - s)).length() < 1e-2,
                "flow at ({x}, {y}) {got:?}, the plane point moves by {}",
                pb - s
            );
            if (1.0..62.0).contains(&pb.x) && (1.0..88.0).contains(&pb.y) {
                let (r, expected) = (rectified.get(x, y)[0], g(pb)[0]);
                assert!(
                    (r - expected).abs() < 1e-3,
                    "rectified ({x}, {y}) {r} vs {expected}"
                );
            }
        }
        // A degenerate plane is refused.
        let e = plane_homography(&a, &b, a.centre(), Vec3::Z)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("rectification plane") && e.contains("reference camera"),
            "{e}"
        );
    }
}
