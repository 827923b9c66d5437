//! Pinhole cameras in the project's conventions ([`crate::conventions`]): OpenCV camera
//! axes (`+x` right, `+y` down, `+z` forward), intrinsics in pixels with pixel centres
//! at integer coordinates, and a rigid `world_from_camera` transform in metres.

use glam::{Mat3, Vec2, Vec3};
use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};

/// Focal lengths and principal point, in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Intrinsics {
    /// Focal length along `x`, pixels.
    pub fx: f32,
    /// Focal length along `y`, pixels.
    pub fy: f32,
    /// Principal point `x`, pixels (pixel centres at integers).
    pub cx: f32,
    /// Principal point `y`, pixels.
    pub cy: f32,
}

/// A rigid transform: `p_to = rotation * p_from + translation`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rigid {
    /// Orthonormal rotation with determinant +1.
    pub rotation: Mat3,
    /// Translation, metres.
    pub translation: Vec3,
}

impl Rigid {
    /// The identity transform.
    pub const IDENTITY: Self = Self {
        rotation: Mat3::IDENTITY,
        translation: Vec3::ZERO,
    };

    /// Applies the transform to a point.
    #[inline]
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.rotation * p + self.translation
    }

    /// Applies the rotation to a direction.
    #[inline]
    pub fn transform_vector(&self, v: Vec3) -> Vec3 {
        self.rotation * v
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Self {
        let rt = self.rotation.transpose();
        Self {
            rotation: rt,
            translation: -(rt * self.translation),
        }
    }

    /// `self ∘ other`: first `other`, then `self`.
    pub fn compose(&self, other: &Rigid) -> Self {
        Self {
            rotation: self.rotation * other.rotation,
            translation: self.rotation * other.translation + self.translation,
        }
    }

    /// A rotation about `+y` by `angle` radians (right-handed: azimuth grows).
    pub fn rotation_y(angle: f32) -> Self {
        Self {
            rotation: Mat3::from_rotation_y(angle),
            translation: Vec3::ZERO,
        }
    }

    /// Checks that the rotation is orthonormal with determinant +1 (within `tolerance`)
    /// and that everything is finite.
    pub fn validate(&self, tolerance: f32) -> std::result::Result<(), String> {
        let cols = self.rotation.to_cols_array();
        if !cols
            .iter()
            .chain(self.translation.as_ref())
            .all(|v| v.is_finite())
        {
            return Err("contains NaN or infinity".into());
        }
        let should_be_identity = self.rotation.transpose() * self.rotation;
        let err = (should_be_identity - Mat3::IDENTITY)
            .to_cols_array()
            .iter()
            .fold(0.0f32, |m, v| m.max(v.abs()));
        if err > tolerance {
            return Err(format!(
                "rotation is not orthonormal (|RᵀR - I| = {err:.2e})"
            ));
        }
        if self.rotation.determinant() < 0.0 {
            return Err("rotation is a reflection (determinant < 0)".into());
        }
        Ok(())
    }
}

/// A pinhole camera: image size, intrinsics and pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Intrinsics.
    pub intrinsics: Intrinsics,
    /// Pose: camera coordinates to world coordinates.
    pub world_from_camera: Rigid,
}

impl Camera {
    /// A camera at `eye` looking at `target`, with `up` the world direction that should
    /// appear upward in the image, a vertical field of view in radians, and the principal
    /// point at the image centre.
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        vertical_fov: f32,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(CoreError::invalid("size", format!("{width}x{height}")));
        }
        if !(vertical_fov > 1e-4 && vertical_fov < std::f32::consts::PI - 1e-3) {
            return Err(CoreError::invalid(
                "field of view",
                format!(
                    "{:.3} degrees is outside (0, 180)",
                    vertical_fov.to_degrees()
                ),
            ));
        }
        if !(eye.is_finite() && target.is_finite() && up.is_finite()) {
            return Err(CoreError::invalid(
                "camera",
                format!("eye {eye}, target {target} and up {up} must be finite"),
            ));
        }
        if !(target - eye).length().is_finite() {
            // Each finite, but their distance overflows: a position in light years.
            return Err(CoreError::invalid(
                "camera",
                format!("eye {eye} and target {target} are too far apart to compute with"),
            ));
        }
        let forward = (target - eye).normalize_or_zero();
        if forward == Vec3::ZERO {
            return Err(CoreError::invalid(
                "camera",
                format!("eye {eye} equals target {target}"),
            ));
        }
        let right = forward.cross(up).normalize_or_zero();
        if right == Vec3::ZERO {
            return Err(CoreError::invalid(
                "camera",
                format!("view direction {forward} is parallel to up {up}"),
            ));
        }
        let down = forward.cross(right);
        let f = (height as f32 / 2.0) / (vertical_fov / 2.0).tan();
        Ok(Self {
            width,
            height,
            intrinsics: Intrinsics {
                fx: f,
                fy: f,
                cx: (width as f32 - 1.0) / 2.0,
                cy: (height as f32 - 1.0) / 2.0,
            },
            world_from_camera: Rigid {
                rotation: Mat3::from_cols(right, down, forward),
                translation: eye,
            },
        })
    }

    /// Camera centre in world coordinates.
    pub fn centre(&self) -> Vec3 {
        self.world_from_camera.translation
    }

    /// Viewing direction (camera `+z`) in world coordinates.
    pub fn forward(&self) -> Vec3 {
        self.world_from_camera.rotation.z_axis
    }

    /// Projects a world point to pixel coordinates; `None` if it is not in front of the
    /// camera (depth below 1 mm).
    #[inline]
    pub fn project(&self, p_world: Vec3) -> Option<Vec2> {
        let pc = self.world_from_camera.rotation.transpose() * (p_world - self.centre());
        if pc.z < 1e-3 {
            return None;
        }
        let k = &self.intrinsics;
        Some(Vec2::new(
            k.fx * pc.x / pc.z + k.cx,
            k.fy * pc.y / pc.z + k.cy,
        ))
    }

    /// The point on the subject's axis (the world `y` axis: the turntable's) nearest to
    /// the camera's optical axis: where the camera looks at the subject.
    pub fn axis_point(&self) -> Vec3 {
        // Closest points of the lines C + s f and (0, y, 0).
        let (c, f) = (self.centre(), self.forward());
        let horizontal = Vec3::new(f.x, 0.0, f.z);
        let s = if horizontal.length_squared() > 1e-12 {
            -(Vec3::new(c.x, 0.0, c.z).dot(horizontal)) / horizontal.length_squared()
        } else {
            0.0
        };
        Vec3::new(0.0, c.y + s * f.y, 0.0)
    }

    /// Depth (camera `z`) of a world point.
    #[inline]
    pub fn depth(&self, p_world: Vec3) -> f32 {
        self.forward().dot(p_world - self.centre())
    }

    /// Unit world direction of the ray through pixel coordinates `pixel`.
    #[inline]
    pub fn ray_direction(&self, pixel: Vec2) -> Vec3 {
        let k = &self.intrinsics;
        let dc = Vec3::new((pixel.x - k.cx) / k.fx, (pixel.y - k.cy) / k.fy, 1.0);
        (self.world_from_camera.rotation * dc).normalize()
    }

    /// The same camera after a rigid motion of the world: `new_world_from_old * camera`.
    pub fn transformed(&self, new_world_from_old: &Rigid) -> Self {
        Self {
            world_from_camera: new_world_from_old.compose(&self.world_from_camera),
            ..*self
        }
    }

    /// Vertical field of view in radians.
    pub fn vertical_fov(&self) -> f32 {
        2.0 * ((self.height as f32 / 2.0) / self.intrinsics.fy).atan()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_camera_too_far_away_is_said_so_not_called_coincident() {
        let far = Camera::look_at(
            Vec3::splat(1e30),
            Vec3::new(0.0, 0.9, 0.0),
            Vec3::Y,
            0.6,
            64,
            48,
        );
        let said = far.expect_err("refused").to_string();
        assert!(said.contains("too far apart"), "{said}");
        let same = Camera::look_at(Vec3::ONE, Vec3::ONE, Vec3::Y, 0.6, 64, 48);
        assert!(same.expect_err("refused").to_string().contains("equals"));
    }

    fn cam() -> Camera {
        Camera::look_at(
            Vec3::new(0.3, 1.2, 4.5),
            Vec3::new(0.0, 0.9, 0.0),
            Vec3::Y,
            0.5,
            64,
            90,
        )
        .unwrap()
    }

    #[test]
    fn look_at_centre_projects_to_principal_point() {
        let c = cam();
        let p = c.project(Vec3::new(0.0, 0.9, 0.0)).unwrap();
        assert!((p - Vec2::new(31.5, 44.5)).length() < 1e-3);
        assert!(c.world_from_camera.validate(1e-5).is_ok());
        // World up appears upward in the image (smaller y).
        let above = c.project(Vec3::new(0.0, 1.4, 0.0)).unwrap();
        assert!(above.y < p.y);
        // Point behind the camera.
        assert!(c.project(Vec3::new(0.6, 1.5, 9.0)).is_none());
    }

    #[test]
    fn ray_and_projection_are_inverse() {
        let c = cam();
        for (x, y) in [(0.0, 0.0), (63.0, 89.0), (10.25, 70.5)] {
            let px = Vec2::new(x, y);
            let p = c.centre() + c.ray_direction(px) * 3.7;
            assert!((c.project(p).unwrap() - px).length() < 1e-3);
        }
    }

    #[test]
    fn rotation_about_y_moves_azimuth() {
        let r = Rigid::rotation_y(0.5);
        let d = r.transform_vector(Vec3::Z);
        assert!((d.x.atan2(d.z) - 0.5).abs() < 1e-6);
        let inv = r.inverse().compose(&r);
        assert!((inv.rotation - Mat3::IDENTITY).abs_diff_eq(Mat3::ZERO, 1e-6));
    }

    #[test]
    fn degenerate_look_at_is_refused() {
        let e = Camera::look_at(Vec3::ZERO, Vec3::ZERO, Vec3::Y, 0.5, 8, 8)
            .unwrap_err()
            .to_string();
        assert!(e.contains("eye [0, 0, 0] equals target [0, 0, 0]"), "{e}");
        let e = Camera::look_at(Vec3::ZERO, Vec3::Y, Vec3::Y, 0.5, 8, 8)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("view direction [0, 1, 0] is parallel to up [0, 1, 0]"),
            "{e}"
        );
        let e = Camera::look_at(Vec3::ZERO, Vec3::X, Vec3::Y, 0.0, 8, 8)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("field of view") && e.contains("0.000 degrees"),
            "{e}"
        );
        let e = Camera::look_at(Vec3::NAN, Vec3::X, Vec3::Y, 0.5, 8, 8)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("eye [NaN, NaN, NaN]") && e.contains("finite"),
            "{e}"
        );
    }
}
