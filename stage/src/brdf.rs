//! Reflectance model of the walker: Lambertian diffuse plus a Torrance–Sparrow specular
//! lobe (Torrance & Sparrow, JOSA 1967; in the form of Cook & Torrance, TOG 1982):
//! Beckmann microfacet distribution, V-cavity shadowing–masking, Schlick's Fresnel term.

use frf_core::image::Rgb;
use glam::Vec3;

use crate::material::Surface;

/// The two terms of the reflectance for one light, per unit irradiance at normal
/// incidence: the diffuse weight `max(n·l, 0) / π` (to be multiplied by the albedo) and
/// the specular term `f_s(l, v) · max(n·l, 0)` (colourless). Splitting them lets the
/// renderer shade once and apply a pixel-averaged albedo ([`crate::render`]).
#[inline]
pub fn terms(s: &Surface, n: Vec3, l: Vec3, v: Vec3) -> (f32, f32) {
    let nl = n.dot(l);
    let nv = n.dot(v);
    if nl <= 0.0 || nv <= 0.0 {
        return (0.0, 0.0);
    }
    let h = (l + v).normalize();
    let nh = n.dot(h).max(1e-4);
    let vh = v.dot(h).max(1e-4);
    let m2 = s.roughness * s.roughness;
    let nh2 = nh * nh;
    // Beckmann: exp(-tan²θh / m²) / (π m² cos⁴θh).
    let d = (-(1.0 - nh2) / (nh2 * m2)).exp() / (std::f32::consts::PI * m2 * nh2 * nh2);
    let g = (2.0 * nh * nv / vh).min(2.0 * nh * nl / vh).min(1.0);
    let f = s.f0 + (1.0 - s.f0) * (1.0 - vh).powi(5);
    (nl * std::f32::consts::FRAC_1_PI, f * d * g / (4.0 * nv))
}

/// Reflected radiance per unit irradiance at normal incidence: `f(l, v) · max(n·l, 0)`,
/// per channel, for unit normal `n`, light direction `l` and view direction `v` (both
/// pointing away from the surface).
#[inline]
pub fn reflect(s: &Surface, n: Vec3, l: Vec3, v: Vec3) -> Rgb {
    let (diffuse, specular) = terms(s, n, l, v);
    s.albedo.map(|a| a * diffuse + specular)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn surface() -> Surface {
        Surface {
            albedo: [0.5, 0.4, 0.3],
            f0: 0.04,
            roughness: 0.3,
        }
    }

    #[test]
    fn energy_is_conserved_for_a_white_furnace() {
        // Integrate f·cos over the hemisphere of view directions (reciprocity lets us
        // swap l and v): the albedo must not exceed 1.
        let s = Surface {
            albedo: [0.8; 3],
            ..surface()
        };
        let n = Vec3::Y;
        let l = Vec3::new(0.3, 0.9, 0.1).normalize();
        let steps = 200;
        let mut total = 0.0;
        for i in 0..steps {
            for j in 0..2 * steps {
                let theta = (i as f32 + 0.5) / steps as f32 * std::f32::consts::FRAC_PI_2;
                let phi = (j as f32 + 0.5) / (2 * steps) as f32 * std::f32::consts::TAU;
                let v = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                let dw = theta.sin()
                    * (std::f32::consts::FRAC_PI_2 / steps as f32)
                    * (std::f32::consts::TAU / (2 * steps) as f32);
                // By reciprocity reflect(n, v, l) = f(l, v) (n·v): the integrand of
                // the directional albedo for light from l.
                total += reflect(&s, n, v, l)[0] * dw;
            }
        }
        // Lambert 0.8 plus a few percent of specular; never more than 1.
        assert!(total > 0.8 && total < 1.0, "directional albedo {total}");
    }

    #[test]
    fn back_facing_gives_zero() {
        let s = surface();
        assert_eq!(reflect(&s, Vec3::Y, Vec3::NEG_Y, Vec3::Y), [0.0; 3]);
        assert_eq!(reflect(&s, Vec3::Y, Vec3::Y, Vec3::NEG_Y), [0.0; 3]);
    }

    #[test]
    fn highlight_peaks_in_the_mirror_direction() {
        let s = Surface {
            albedo: [0.0; 3],
            ..surface()
        };
        let l = Vec3::new(0.5, 0.8, 0.0).normalize();
        let mirror = Vec3::new(-0.5, 0.8, 0.0).normalize();
        let off = Vec3::new(-0.2, 0.8, 0.5).normalize();
        assert!(reflect(&s, Vec3::Y, l, mirror)[0] > 3.0 * reflect(&s, Vec3::Y, l, off)[0]);
    }
}
