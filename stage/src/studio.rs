//! The stage around the actor, fixed in the world frame: a floor of retro-reflective
//! cloth (treadmill belt, turntable top and the floor around them, all at `y = 0`), and
//! a gray paper backdrop behind the subject as seen from the cameras. And how each is
//! lit: by the dome's lights in basis and track frames, and by the cameras' ring lights
//! (retro-reflection) and the backdrop's back-lighting in matte frames.

use frf_core::image::Rgb;
use frf_core::light::DirLight;
use glam::Vec3;

use crate::geometry::Ray;

/// Distance of the backdrop plane behind the turntable axis, metres (on the `-z` side).
pub const BACKDROP_DISTANCE_M: f32 = 2.5;
/// Half-width and height of the backdrop, metres (the original's was 3 m x 4 m; ours is
/// wide enough to fill every camera's view behind the subject).
const BACKDROP_HALF_WIDTH_M: f32 = 2.5;
const BACKDROP_HEIGHT_M: f32 = 4.0;
/// Diffuse albedo of the backdrop: 18 % gray paper, as in the original.
const BACKDROP_ALBEDO: f32 = 0.18;
/// Radiance of the back-lit backdrop in matte frames.
pub const BACKDROP_MATTE_RADIANCE: f32 = 0.6;
/// Diffuse albedo of the retro-reflective cloth away from the retro direction.
const FLOOR_ALBEDO: f32 = 0.12;
/// Peak retro-reflection (radiance per unit irradiance, 1/sr) and its angular width:
/// glass-bead cloth returns light within ~1–2 degrees of the source.
const RETRO_GAIN: f32 = 7.0;
const RETRO_WIDTH_RAD: f32 = 1.5 * std::f32::consts::PI / 180.0;

/// How a frame is lit.
#[derive(Debug, Clone, PartialEq)]
pub enum Illumination {
    /// Dome lights (world frame): basis and track frames.
    Lights(Vec<DirLight>),
    /// A matte frame: the camera's ring light (coaxial with the camera, toward `ring`'s
    /// direction from the subject) lights the retro-reflective floor, and the backdrop is
    /// lit from behind; the subject receives only the weak ring light.
    Matte {
        /// The ring light: direction toward the camera, and its irradiance.
        ring: DirLight,
    },
    /// Everything off.
    Dark,
}

/// What a ray hits in the studio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StudioHit {
    /// The floor, at this point.
    Floor(Vec3),
    /// The backdrop, at this point.
    Backdrop(Vec3),
}

impl StudioHit {
    /// The point hit.
    pub fn point(&self) -> Vec3 {
        match *self {
            StudioHit::Floor(p) | StudioHit::Backdrop(p) => p,
        }
    }

    fn normal(&self) -> Vec3 {
        match self {
            StudioHit::Floor(_) => Vec3::Y,
            StudioHit::Backdrop(_) => Vec3::Z,
        }
    }
}

/// The nearest studio surface along a ray and its distance.
pub fn intersect(ray: &Ray) -> Option<(f32, StudioHit)> {
    let mut best = None;
    if ray.dir.y < -1e-6 {
        let t = -ray.origin.y / ray.dir.y;
        let p = ray.origin + ray.dir * t;
        if t > 0.0 && p.z >= -BACKDROP_DISTANCE_M {
            best = Some((t, StudioHit::Floor(p)));
        }
    }
    if ray.dir.z < -1e-6 {
        let t = (-BACKDROP_DISTANCE_M - ray.origin.z) / ray.dir.z;
        let p = ray.origin + ray.dir * t;
        let inside = p.x.abs() <= BACKDROP_HALF_WIDTH_M && (0.0..=BACKDROP_HEIGHT_M).contains(&p.y);
        if t > 0.0 && inside && best.is_none_or(|(tb, _)| t < tb) {
            best = Some((t, StudioHit::Backdrop(p)));
        }
    }
    best
}

/// Radiance toward `view` (unit, from the surface toward the eye) of a studio surface
/// under one dome light, without shadowing.
pub fn reflect(hit: &StudioHit, light: &DirLight, view: Vec3) -> Rgb {
    let n = hit.normal();
    let cos = n.dot(light.direction);
    if cos <= 0.0 {
        return [0.0; 3];
    }
    let k = match hit {
        StudioHit::Backdrop(_) => BACKDROP_ALBEDO * std::f32::consts::FRAC_1_PI * cos,
        StudioHit::Floor(_) => {
            let diffuse = FLOOR_ALBEDO * std::f32::consts::FRAC_1_PI * cos;
            // Beyond 5 widths the lobe is below 1e-10 of its peak: skip acos and exp.
            let cos_to_source = light.direction.dot(view);
            if cos_to_source < (5.0 * RETRO_WIDTH_RAD).cos() {
                diffuse
            } else {
                let angle = cos_to_source.clamp(-1.0, 1.0).acos();
                diffuse + RETRO_GAIN * (-(angle / RETRO_WIDTH_RAD).powi(2)).exp()
            }
        }
    };
    light.irradiance.map(|e| e * k)
}

/// Radiance of a studio surface in a matte frame.
pub fn matte_radiance(hit: &StudioHit, ring: &DirLight) -> Rgb {
    match hit {
        StudioHit::Backdrop(_) => [BACKDROP_MATTE_RADIANCE; 3],
        StudioHit::Floor(_) => ring.irradiance.map(|e| e * RETRO_GAIN),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cameras_see_floor_then_backdrop() {
        let eye = Vec3::new(0.0, 0.9, 4.5);
        let down = Ray {
            origin: eye,
            dir: Vec3::new(0.0, -0.3, -1.0).normalize(),
        };
        assert!(matches!(intersect(&down), Some((_, StudioHit::Floor(_)))));
        let level = Ray {
            origin: eye,
            dir: Vec3::NEG_Z,
        };
        let (t, hit) = intersect(&level).unwrap();
        assert!(matches!(hit, StudioHit::Backdrop(_)) && (t - 7.0).abs() < 1e-4);
        let up = Ray {
            origin: eye,
            dir: Vec3::Y,
        };
        assert!(intersect(&up).is_none());
    }

    #[test]
    fn retro_reflection_is_bright_only_toward_the_source() {
        let floor = StudioHit::Floor(Vec3::ZERO);
        let light = DirLight {
            direction: Vec3::new(0.0, 0.4, 1.0).normalize(),
            irradiance: [0.1; 3],
        };
        let back = reflect(&floor, &light, light.direction)[0];
        let side = reflect(&floor, &light, Vec3::new(0.3, 0.4, 1.0).normalize())[0];
        assert!(back > 0.5 && side < 0.01, "{back} {side}");
    }
}
