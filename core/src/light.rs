//! Distant (directional) lights, the common currency of the dome's basis conditions, of
//! environments reduced to lights, and of the renderers. A light's strength is its
//! irradiance at normal incidence ([`crate::conventions`]).

use glam::Vec3;

use crate::image::Rgb;

/// The widest sun taken, degrees: wider is an area light, not a sun.
pub const MAX_SUN_DIAMETER_DEG: f32 = 20.0;

/// What is wrong with a sun's values, if anything (`sun_fault`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SunFault {
    /// The direction is not finite, or zero.
    Direction,
    /// The angular diameter is not within (0, [`MAX_SUN_DIAMETER_DEG`]] degrees.
    Diameter,
    /// The illuminance is not finite, is negative, or beyond [`MAX_TOTAL_LIGHT`].
    Illuminance,
}

/// The first of a sun's values that a sun cannot have (`None`: it can be one), as
/// `frf_core::sun::Sun::new` and a light file's suns (`frf_core::sh`) check them.
pub fn sun_fault(direction: Vec3, diameter_deg: f32, illuminance: Rgb) -> Option<SunFault> {
    if !direction.is_finite() || direction.abs().max_element() <= 0.0 {
        return Some(SunFault::Direction);
    }
    if !(diameter_deg > 0.0 && diameter_deg <= MAX_SUN_DIAMETER_DEG) {
        return Some(SunFault::Diameter);
    }
    // (In f32, as the light is held: a sun of 1e30 is at the bound, not beyond it.)
    let light = |c: &f32| c.is_finite() && *c >= 0.0 && *c <= MAX_TOTAL_LIGHT as f32;
    (!illuminance.iter().all(light)).then_some(SunFault::Illuminance)
}

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

/// The largest turn (a yaw, an azimuth) taken, degrees either way: beyond it a double no
/// longer holds the angle to a whole degree (doubles hold every whole number to 2^53, about
/// 9e15), so the turn it names is not known.
pub const MOST_TURN_DEG: f64 = 1e15;

/// `degrees` as the same turn within ±180°, reduced in double precision (as it is when
/// already within): 1e9° is -80°, the turn 1e9 mod 360 names, where f32 radians of 1e9°
/// miss it by degrees.
pub fn within_half_turn(degrees: f64) -> f64 {
    if degrees.abs() <= 180.0 {
        degrees
    } else {
        (degrees + 180.0).rem_euclid(360.0) - 180.0
    }
}

/// The radians of a turn of `degrees` ([`within_half_turn`] first; an angle within ±180°
/// converts as `f32::to_radians` converts it). A turn is given in degrees, held in double
/// precision (the command line's `--yaw`, a scene's `yaw_deg`) and made radians here, the
/// one place, where it turns a map (`EnvMap::rotated`).
pub fn turn_radians(degrees: f64) -> f32 {
    (within_half_turn(degrees) as f32).to_radians()
}

/// `degrees` as a turn, refused where it is not finite or beyond [`MOST_TURN_DEG`] (the
/// problem in words).
pub fn checked_turn(degrees: f64) -> std::result::Result<f64, String> {
    if !degrees.is_finite() {
        return Err(format!("{degrees}° is not a finite angle"));
    }
    if degrees.abs() > MOST_TURN_DEG {
        return Err(format!(
            "{degrees:e}° is beyond ±{MOST_TURN_DEG:e}°, where a double no longer holds the turn \
             to a whole degree"
        ));
    }
    Ok(degrees)
}

/// Azimuth and elevation (radians) of a unit direction.
#[inline]
pub fn azimuth_elevation(d: Vec3) -> (f32, f32) {
    (d.x.atan2(d.z), d.y.clamp(-1.0, 1.0).asin())
}

#[cfg(test)]
mod tests {
    /// Turns of any size name the turn they are mod 360, reduced in double precision: the
    /// same radians as the angle within ±180° (exactly), where f32 radians of the angle
    /// itself are off by degrees; beyond the stated range and not finite are refused.
    #[test]
    fn a_turn_is_reduced_in_double_precision() {
        use super::*;
        for (deg, same) in [
            (1e9, -80.0),
            (1e15, -80.0),
            (-1e9, 80.0),
            (540.0, -180.0),
            (-190.0, 170.0),
            (359.5, -0.5),
        ] {
            assert_eq!(turn_radians(deg), (same as f32).to_radians(), "{deg}");
        }
        // Within ±180°: as before, bit for bit.
        for deg in [0.0f32, 0.7, -179.9, 180.0, 42.123] {
            assert_eq!(turn_radians(f64::from(deg)), deg.to_radians());
        }
        // Control: f32 radians of 1e9° are not -80°'s turn.
        let naive = (1e9f32).to_radians();
        let off = (naive.sin() - (-80f32).to_radians().sin()).abs();
        assert!(off > 0.01, "{off}");
        assert!(checked_turn(1e15).is_ok());
        assert!(checked_turn(2e15).unwrap_err().contains("beyond"));
        assert!(checked_turn(f64::NAN).is_err());
    }

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
