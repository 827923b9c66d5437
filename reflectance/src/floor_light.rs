//! Light from below relit by the fitted normals (docs/design.md section 4.1): a floor
//! condition lights the subject from a 120° sector of the lower hemisphere at one
//! radiance, while a bright ground sends up light of its own shape (brighter toward the
//! sun's side, a sunlit patch). The basis scales the condition's image by the sector's
//! whole light, so the shape within the sector is lost.
//!
//! Each of the condition's lights stands for its sub-cell; the environment's radiance
//! there ([`floor_shares`], per view, as the view's turntable turned the dome) reweights
//! them, and a texel of normal `n` takes the condition's image times the ratio of its
//! shading under the reweighted lights to its shading under the condition's own
//! ([`floor_ratio`]): exact for a Lambertian texel that sees the same lights, and the
//! image keeps what the ratio does not model (the body's own occlusion of the ground's
//! light, texture). Where the condition's own shading is under [`RATIO_FLOOR`] of the
//! reweighted one (light from where the condition barely reaches the texel), and for a
//! texel with no normal, the ratio is 1: the basis.

use glam::{Mat3, Vec3};

use crate::light_fit::{RATIO_FLOOR, group_shading};

/// Below this share of a light's luminance from below the horizon, its ground is left to
/// the basis, and from it to [`GROUND_SHARE`]'s second relit by the normals in full,
/// smoothly between ([`ground_weight`]). Chosen on `forest_slope_1k` (14 % from below)
/// and `ground_patch` (45 %) at the small oracle field's captured views (subject PSNR,
/// the basis 37.49 / 29.89 dB): relit in full 37.13 / 35.77, by half the ratio's change
/// 37.34 / 32.92; the other maps are reported in docs/results/hard_light.md. Where the
/// ground sends up little light its shape matters little and the model's own errors
/// (a normal the fit got wrong, the body's occlusion of the reweighted lights) dominate.
pub const GROUND_SHARE: [f32; 2] = [0.2, 0.35];

/// How far a light whose ground sends up `share` of its luminance relights the floor
/// conditions by the normals ([`GROUND_SHARE`]), 0 to 1.
pub fn ground_weight(share: f32) -> f32 {
    crate::sun_light::smoothstep(GROUND_SHARE[0], GROUND_SHARE[1], share)
}

/// Per turntable angle asked (radians) and per condition of `lights` (each its lights'
/// unit directions and shares, dome frame, [`crate::light_fit::condition_light_shares`]):
/// for the floor conditions (`floor[k]`), the shares of their lights reweighted by
/// `radiance` (arriving from a direction of the subject's frame), summing to 1, and
/// moved from their own only by `weight` of the way ([`ground_weight`]); empty for the
/// others, where the light sends up nothing, and at weight 0.
pub fn floor_shares(
    lights: &[Vec<(Vec3, f32)>],
    floor: &[bool],
    (turntables, weight): (&[f32], f32),
    radiance: impl Fn(Vec3) -> f32,
) -> Vec<Vec<Vec<f32>>> {
    if weight <= 0.0 {
        return Vec::new();
    }
    turntables
        .iter()
        .map(|&theta| {
            // A dome direction `l` is the subject's `R_y(−θ) l` (`crate::project`).
            let to_subject = Mat3::from_rotation_y(-theta);
            (lights.iter().zip(floor))
                .map(|(group, &is_floor)| {
                    if !is_floor {
                        return Vec::new();
                    }
                    let weighted: Vec<f32> = group
                        .iter()
                        .map(|&(l, share)| share * radiance(to_subject * l).max(0.0))
                        .collect();
                    let total: f32 = weighted.iter().sum();
                    if total > 0.0 && total.is_finite() {
                        (weighted.iter().zip(group))
                            .map(|(w, &(_, own))| own + weight * (w / total - own))
                            .collect()
                    } else {
                        Vec::new()
                    }
                })
                .collect()
        })
        .collect()
}

/// The ratio a floor condition's image is relit by at a texel of normal `normal` (see
/// the module text): its shading under `lights` reweighted to `shares` over its shading
/// under their own; 1 with no normal, no shares, or too little of its own.
pub fn floor_ratio(normal: Option<Vec3>, lights: &[(Vec3, f32)], shares: &[f32]) -> f32 {
    let Some(n) = normal else {
        return 1.0;
    };
    if shares.len() != lights.len() || shares.is_empty() {
        return 1.0;
    }
    let own = group_shading(lights, n);
    let env: f32 = (lights.iter().zip(shares))
        .map(|(&(l, _), &e)| e * n.dot(l).max(0.0))
        .sum();
    if own > 0.0 && own >= RATIO_FLOOR * env {
        env / own
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A floor sector's lights: 4 azimuths x 3 elevations below the horizon, equal shares.
    fn sector() -> Vec<(Vec3, f32)> {
        let mut out = Vec::new();
        for a in 0..4 {
            for e in 0..3 {
                let az = (15.0 + 30.0 * a as f32).to_radians();
                let el = -(15.0 + 25.0 * e as f32).to_radians();
                out.push((
                    Vec3::new(az.sin() * el.cos(), el.sin(), az.cos() * el.cos()),
                    1.0 / 12.0,
                ));
            }
        }
        out
    }

    #[test]
    fn a_uniform_ground_leaves_the_basis_and_a_bright_side_relights_the_texels_facing_it() {
        let lights = vec![sector()];
        let uniform = floor_shares(&lights, &[true], (&[0.0, 1.0], 1.0), |_| 2.0);
        for n in [Vec3::NEG_Y, Vec3::new(0.3, -0.5, 0.8).normalize()] {
            let r = floor_ratio(Some(n), &lights[0], &uniform[0][0]);
            assert!((r - 1.0).abs() < 1e-5, "{r}");
        }
        // The ground bright toward +x: a texel facing +x down gains, one facing +z
        // (away from it within the sector) loses.
        let bright_x = floor_shares(&lights, &[true], (&[0.0], 1.0), |d| {
            1.0 + 4.0 * d.x.max(0.0)
        });
        let toward = floor_ratio(
            Some(Vec3::new(1.0, -0.5, 0.0).normalize()),
            &lights[0],
            &bright_x[0][0],
        );
        let away = floor_ratio(
            Some(Vec3::new(-0.4, -0.5, 1.0).normalize()),
            &lights[0],
            &bright_x[0][0],
        );
        assert!(toward > 1.05 && away < 0.95, "{toward} {away}");
        // Turning the turntable by 90° turns which dome lights the bright side is behind.
        let turned = floor_shares(
            &lights,
            &[true],
            (&[std::f32::consts::FRAC_PI_2], 1.0),
            |d| 1.0 + 4.0 * d.x.max(0.0),
        );
        assert_ne!(turned[0][0], bright_x[0][0]);
        // No normal, or a condition not on the floor: the basis.
        assert_eq!(floor_ratio(None, &lights[0], &bright_x[0][0]), 1.0);
        assert!(floor_shares(&lights, &[false], (&[0.0], 1.0), |_| 1.0)[0][0].is_empty());
        // Half the weight: half the ratio's change; none, nothing to relight.
        let half = floor_shares(&lights, &[true], (&[0.0], 0.5), |d| {
            1.0 + 4.0 * d.x.max(0.0)
        });
        let n = Some(Vec3::new(1.0, -0.5, 0.0).normalize());
        let r = floor_ratio(n, &lights[0], &half[0][0]);
        assert!(
            (r - (1.0 + 0.5 * (toward - 1.0))).abs() < 1e-4,
            "{r} {toward}"
        );
        assert!(floor_shares(&lights, &[true], (&[0.0], 0.0), |_| 1.0).is_empty());
        assert_eq!(ground_weight(0.14), 0.0);
        assert_eq!(ground_weight(0.45), 1.0);
        // A texel the condition barely reaches: its ratio would be noise, so 1.
        let up = floor_ratio(Some(Vec3::Y), &lights[0], &bright_x[0][0]);
        assert_eq!(up, 1.0);
    }
}
