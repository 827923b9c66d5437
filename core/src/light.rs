//! Distant (directional) lights, the common currency of the dome's basis conditions, of
//! environments reduced to lights, and of the renderers. A light's strength is its
//! irradiance at normal incidence ([`crate::conventions`]).

use glam::Vec3;

use crate::image::Rgb;

/// The largest total light (`∫ L dω`, any channel) a loaded map or light may carry: far
/// above any real scene (the sun's is about 1e5 in units of sky radiance), far below
/// f32's 3.4e38, so that relit sums and exposures stay finite.
pub const MAX_TOTAL_LIGHT: f64 = 1e30;

/// A distant light: the unit direction from the subject toward it, and its RGB
/// irradiance at normal incidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirLight {
    /// Unit vector pointing from the subject toward the light.
    pub direction: Vec3,
    /// RGB irradiance at normal incidence.
    pub irradiance: Rgb,
}

impl DirLight {
    /// The same light after rotating the world by `rotation`.
    pub fn rotated(&self, rotation: glam::Mat3) -> Self {
        Self {
            direction: rotation * self.direction,
            ..*self
        }
    }

    /// The light with its irradiance multiplied by `k`.
    pub fn scaled(&self, k: f32) -> Self {
        Self {
            irradiance: self.irradiance.map(|c| c * k),
            ..*self
        }
    }
}

/// The unit direction with azimuth `azimuth` and elevation `elevation` (radians):
/// `(sin φ cos e, sin e, cos φ cos e)`.
#[inline]
pub fn direction_from_azimuth_elevation(azimuth: f32, elevation: f32) -> Vec3 {
    Vec3::new(
        azimuth.sin() * elevation.cos(),
        elevation.sin(),
        azimuth.cos() * elevation.cos(),
    )
}

/// Azimuth and elevation (radians) of a unit direction.
#[inline]
pub fn azimuth_elevation(d: Vec3) -> (f32, f32) {
    (d.x.atan2(d.z), d.y.clamp(-1.0, 1.0).asin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn azimuth_elevation_round_trip() {
        for (a, e) in [(0.3f32, 0.2f32), (-2.0, -1.0), (3.0, 1.4)] {
            let d = direction_from_azimuth_elevation(a, e);
            let (a2, e2) = azimuth_elevation(d);
            assert!((a - a2).abs() < 1e-5 && (e - e2).abs() < 1e-5);
        }
        assert!((direction_from_azimuth_elevation(0.0, 0.0) - Vec3::Z).length() < 1e-6);
    }
}
