//! A sun relit by a field's fitted normals instead of its basis (docs/design.md section
//! 4.1): the basis integrates a sun over its condition's cell, which blurs and moves its
//! terminator; the sun is taken out of the environment ([`Sun::extract`]), the rest
//! relit by the basis as before, and the sun added per texel by the light fit
//! ([`relight_texel`]): the nearest conditions' images, per unit of their light, times
//! the ratio of the normal's shading under the sun to its shading under them.
//!
//! Each view sees the dome turned by its turntable angle `θ`, so the sun's direction in
//! its dome frame (where its normals were fitted) is `R_y(θ) d`, as the projection turns
//! an environment's texel ([`crate::project`]). The nearest images carry their own
//! directions' cast shadows, not the sun's: a texel the pose's visual hull hides from the
//! sun gets none of it ([`SunLight::sunlit`], by the hull's map seen from the sun,
//! [`SunDepth`]). The CPU reference of the GPU's sun term (`shaders/relight.wgsl`).

use frf_core::image::Rgb;
use frf_core::sun::Sun;
use std::sync::Arc;

use glam::{Mat3, Vec3};

use crate::field::ConditionRecord;
use crate::hull::VoxelHull;
use crate::light_fit::{
    condition_light_shares, condition_lights, group_shading, nearest_weights_by, per_unit,
    relight_texel,
};
use crate::sun_depth::SunDepth;

/// Conditions whose images a texel's sun is carried by, weighted by the inverse of their
/// angle to the sun to the power [`WEIGHT_POWER`]. Measured at the captured views of the
/// stage's small oracle field (subject PSNR; a sun alone at 40° / the built-in sky):
/// 3 conditions by inverse angle 30.50 / 32.30 dB, 3 by its square 31.08 / 32.97, 2 by
/// inverse angle 31.25 / 33.02, 2 by its square 31.41 / 33.23. Fewer images blur the
/// cast shadows and texture they carry less.
pub const NEAREST: usize = 2;
/// See [`NEAREST`].
pub const WEIGHT_POWER: f32 = 2.0;
/// Suns a relighting takes out of an environment and relights by the normals, brightest
/// first ([`Sun::extract`] again on what the last left): a map may hold several sharp
/// lights (a cathedral's windows). Measured at the captured views of the small oracle
/// field (subject PSNR; `grace`, whose two brightest windows carry 29 % and 20 % of its
/// light / `studio_small_03`): 1 sun 31.16 / 31.46 dB, 2 31.76 / -, 3 31.96 / -,
/// 4 32.73 / 32.34, 6 32.85 / -; the basis 29.27 / 25.93. Maps with one sun (the
/// built-in sky) or a soft one (`forest_slope`, `st_fagans_interior`) score the same
/// with 1 or 4. Each sun costs a shadow ray where it would light a texel.
pub const MAX_SUNS: usize = 4;
/// How far from the visual hull's surface a shadow ray toward the sun starts, as a
/// fraction of the height of the hull's grid (the subject's height and a margin; 1.88 m
/// for the stage's walker), so that it scales with the subject.
/// The hull is wider than the body and its surface point lies ahead of the true one, so
/// occluders near the texel are the hull's own error; far ones (a leg over the other, an
/// arm over the torso) are cast shadows. Chosen at the captured views of the small
/// oracle field of pose 0, as metres (2 cm voxels; subject PSNR, a sun alone at 20°,
/// 40°, 70° / the built-in sky): no shadow 31.97, 31.41, 29.00 / 33.23 dB; 0.04 m 31.09,
/// 30.24, - / 31.64; 0.16 m 32.00, -, - / 32.80; 0.32 m 32.40, 31.93, 30.58 / 33.64;
/// 0.48 m 31.97, 31.80, - / 33.51. With the hull at 5 mm voxels (a sun at 20°, 70° / the
/// sky): 0.16 m 32.65, 31.92 / 34.01; 0.24 m 32.74, 31.79 / 34.14; 0.32 m 32.45, 30.86 /
/// 34.35; 0.40 m 32.02, 30.47 / 34.40. Reported on pose 1 and checked at the tiny and
/// paper sizes in docs/results/hard_light.md.
/// Leaving the hull's voxels around the point before looking for an occluder, instead
/// of a fixed offset, scored 0.5-1.2 dB under no shadow.
pub const SHADOW_OFFSET_PER_HEIGHT: f32 = 0.17;

/// One view's sun: its direction in the view's dome frame, and the nearest conditions'
/// inverse-angle weights.
#[derive(Debug, Clone, PartialEq)]
pub struct SunView {
    /// Unit, toward the sun, dome frame of the view.
    pub direction: Vec3,
    /// `(condition, weight)`, [`NEAREST`] of them, weights summing to 1.
    pub nearest: Vec<(usize, f32)>,
}

/// A sun relit by a pose's normals (see the module text).
#[derive(Debug, Clone)]
pub struct SunLight {
    /// Per condition: the direction of the light standing for it ([`condition_lights`]).
    pub directions: Vec<Vec3>,
    /// Per condition: its lights' directions and shares of its light (luminance).
    pub lights: Vec<Vec<(Vec3, f32)>>,
    /// Per condition: the sun's illuminance per unit of the condition's, per channel
    /// (0 where the condition delivers none).
    pub unit: Vec<Rgb>,
    /// Per view.
    pub views: Vec<SunView>,
    /// Unit, toward the sun, subject frame (where the visual hull is).
    pub subject: Vec3,
    /// The pose's visual hull seen from the sun, which casts its shadows (`None`: no
    /// hull, no cast shadows).
    pub depth: Option<SunDepth>,
    /// How far from a texel's point its shadow ray starts, metres ([`shadow_offset_m`]).
    pub shadow_offset_m: f32,
}

/// [`SHADOW_OFFSET_PER_HEIGHT`] of the height of `hull`'s grid, metres.
pub fn shadow_offset_m(hull: &VoxelHull) -> f32 {
    let g = hull.grid();
    SHADOW_OFFSET_PER_HEIGHT * g.dims[1] as f32 * g.voxel_m
}

impl SunLight {
    /// `sun` (subject frame) over a basis of `conditions`, for views at turntable angles
    /// `turntables` (radians), its shadows cast by `hull` where there is one.
    pub fn new(
        sun: &Sun,
        conditions: &[ConditionRecord],
        turntables: &[f32],
        hull: Option<&Arc<VoxelHull>>,
    ) -> Self {
        let lights = condition_lights(conditions);
        let directions: Vec<Vec3> = lights.iter().map(|l| l.0).collect();
        let e = sun.illuminance();
        let unit = lights
            .iter()
            .map(|(_, delivered)| per_unit(e, *delivered))
            .collect();
        let lights = condition_light_shares(conditions);
        let views = turntables
            .iter()
            .map(|&theta| {
                let direction = (Mat3::from_rotation_y(theta) * sun.direction()).normalize();
                SunView {
                    direction,
                    nearest: nearest_weights_by(&directions, direction, NEAREST, WEIGHT_POWER),
                }
            })
            .collect();
        Self {
            directions,
            lights,
            unit,
            views,
            subject: sun.direction(),
            depth: hull.map(|h| SunDepth::new(h, sun.direction())),
            shadow_offset_m: hull.map_or(0.0, |h| shadow_offset_m(h)),
        }
    }

    /// Condition `k`'s shading of a normal `n`, per unit of its light: its lights'
    /// `max(n · l, 0)` weighted by their shares.
    pub fn shading(&self, k: usize, n: Vec3) -> f32 {
        group_shading(&self.lights[k], n)
    }

    /// Whether the sun reaches `surface`, a texel's point on the visual hull (subject
    /// frame), as far as the hull can tell: from [`SunLight::shadow_offset_m`] toward the sun on,
    /// the hull does not lie between it and the sun ([`SunDepth::shades`]). Without a
    /// hull, always. (`shaders/relight.wgsl` is its twin.)
    pub fn sunlit(&self, surface: Vec3) -> bool {
        (self.depth.as_ref())
            .is_none_or(|m| !m.shades(surface + self.subject * self.shadow_offset_m))
    }

    /// The sun's light at a texel of view `view` whose normal is `normal` (`None`: none
    /// fitted), its basis images' linear values being `photo(k)`.
    pub fn texel(&self, view: usize, normal: Option<Vec3>, photo: impl Fn(usize) -> Rgb) -> Rgb {
        let v = &self.views[view];
        relight_texel(
            normal,
            |k| {
                let (p, u) = (photo(k), self.unit[k]);
                [p[0] * u[0], p[1] * u[1], p[2] * u[2]]
            },
            (|k: usize, n: Vec3| self.shading(k, n), self.lights.len()),
            v.direction,
            &v.nearest,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::LightRecord;

    fn condition(direction: Vec3, e: f32) -> ConditionRecord {
        ConditionRecord {
            name: String::new(),
            floor: false,
            lights: vec![LightRecord {
                direction: direction.normalize().to_array(),
                intensity: [e; 3],
                solid_angle_sr: 0.5,
            }],
        }
    }

    #[test]
    fn the_shadow_offset_scales_with_the_subject() {
        let hull = |height: f32| {
            let grid = frf_core::volume::VoxelGrid::covering(
                Vec3::new(-0.3, 0.0, -0.3),
                Vec3::new(0.3, height, 0.3),
                0.05,
            );
            Arc::new(VoxelHull::from_fn(grid.unwrap(), |p| p.y < 0.9 * height))
        };
        let sun = Sun::new(Vec3::Y, 0.53, [1.0; 3]).unwrap();
        let conditions = vec![condition(Vec3::Y, 1.0)];
        let offset =
            |h: f32| SunLight::new(&sun, &conditions, &[0.0], Some(&hull(h))).shadow_offset_m;
        let (walker, child) = (offset(1.9), offset(0.95));
        assert!(
            (walker - SHADOW_OFFSET_PER_HEIGHT * 1.9).abs() < 0.03,
            "{walker}"
        );
        assert!((child / walker - 0.5).abs() < 0.03, "{child} {walker}");
        // Without a hull nothing is cast, and nothing is offset.
        assert_eq!(
            SunLight::new(&sun, &conditions, &[0.0], None).shadow_offset_m,
            0.0
        );
    }

    #[test]
    fn a_sun_on_a_condition_light_relights_as_its_image_scaled() {
        let conditions: Vec<ConditionRecord> = [Vec3::Y, Vec3::X, Vec3::Z, -Vec3::X]
            .into_iter()
            .map(|d| condition(d, 2.0))
            .collect();
        // The sun at +X of the subject frame: +X in the dome at θ = 0, −Z at θ = 90°.
        let sun = Sun::new(Vec3::X, 0.53, [4.0, 4.0, 4.0]).unwrap();
        let light = SunLight::new(&sun, &conditions, &[0.0, std::f32::consts::FRAC_PI_2], None);
        assert_eq!(light.views[0].nearest, vec![(1, 1.0)]);
        assert!(light.views[1].direction.distance(-Vec3::Z) < 1e-5);
        let photo = |k: usize| [k as f32 + 1.0, 0.5, 0.0];
        // A texel facing the sun: the condition's image, times 4 / 2.
        let lit = light.texel(0, Some(Vec3::X), photo);
        assert!(
            (lit[0] - 4.0).abs() < 1e-5 && (lit[1] - 1.0).abs() < 1e-5,
            "{lit:?}"
        );
        // A texel facing away is dark; one without a normal takes the interpolation.
        assert_eq!(light.texel(0, Some(-Vec3::X), photo), [0.0; 3]);
        assert_eq!(light.texel(0, None, photo), [4.0, 1.0, 0.0]);
    }
}
