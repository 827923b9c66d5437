//! Shadow attenuation maps (docs/design.md section 2.4): for each basis condition lighting
//! the ground from above, the fraction of its light that reaches each texel of the ground
//! patch under the subject past the pose's visual hull. Relit with an environment's
//! coefficients (`frf_render::shadow`), they give the relative irradiance under the
//! subject.
//!
//! For condition `k` with lights `l` (direction `d_l`, irradiance at normal incidence
//! `E_l`), at ground point `x`:
//! `A_k(x) = Σ_l w_l V_l(x) / Σ_l w_l`, `w_l = lum(E_l) · max(0, d_l·y)`, where `V_l(x)`
//! is 1 when the ray from `x` toward `d_l` misses the hull. A condition whose lights all
//! lie at or below the horizon sends no light to the ground: its map is 1 (no light, no
//! shadow). The floor conditions light the subject from below and cast nothing on the
//! ground: they have no map.
//!
//! **Light samples.** Traced toward each light's direction only (`samples = 1`, as the
//! original's dome did physically), a condition of a few lights casts a few separate hard
//! shadows where the environment it stands for would cast one. With `samples = n > 1`,
//! each light is traced toward `n` directions spread evenly over the cone of the solid
//! angle it stands for (the region of the sphere the projection gives it), each weighted
//! by its own cosine: the light of the region, as the projection treats it.

use frf_core::image::{Image, Rgb, luminance};
use frf_core::volume::GroundGrid;
use glam::Vec3;
use rayon::prelude::*;

use crate::field::{ConditionRecord, ShadowSpec};
use crate::hull::VoxelHull;

/// Rays toward the lights start this far above the ground (metres): voxels resting on the
/// ground still shadow the texel under them, the ground never shadows itself.
const GROUND_OFFSET_M: f32 = 1e-4;

/// The shadow spec of a basis: the conditions that light the ground from above (every
/// condition that is not a floor one), on `ground`, each light traced toward
/// `light_samples` directions.
pub fn shadow_spec(
    conditions: &[ConditionRecord],
    ground: GroundGrid,
    light_samples: usize,
) -> ShadowSpec {
    ShadowSpec {
        ground,
        light_samples,
        conditions: conditions
            .iter()
            .enumerate()
            .filter(|(_, c)| !c.floor)
            .map(|(k, _)| k)
            .collect(),
    }
}

/// Where a relit shadow starts fading to 1 (unshadowed) toward its patch's edge, as a
/// fraction of the half side: a shadow longer than the patch thins out instead of ending
/// on a straight line (`frf_render::shadow::edge_fade`; the export states it for players).
pub const EDGE_FADE_FROM: f32 = 0.8;

/// Irradiance (RGB) condition `c` delivers to the unshadowed ground: `Σ_l E_l max(0, d_l·y)`.
pub fn ground_irradiance(c: &ConditionRecord) -> Rgb {
    c.lights.iter().fold([0.0; 3], |acc, l| {
        let cos = l.direction[1].max(0.0);
        [0, 1, 2].map(|k| acc[k] + l.intensity[k] * cos)
    })
}

/// `n` unit directions spread evenly over the cone of solid angle `omega` about `d`
/// (a Fibonacci spiral in the cone's cap; `d` itself for `n = 1` or an empty cone).
pub fn cone_directions(d: Vec3, omega: f32, n: usize) -> Vec<Vec3> {
    let d = d.normalize_or_zero();
    if n <= 1 || omega.is_nan() || omega <= 0.0 {
        return vec![d];
    }
    // Cap of solid angle Ω: 1 − cos θ = Ω / 2π.
    let depth = (omega / std::f32::consts::TAU).min(2.0);
    let (t1, t2) = d.any_orthonormal_pair();
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let cos = 1.0 - depth * (i as f32 + 0.5) / n as f32;
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            let phi = golden * i as f32;
            (d * cos + (t1 * phi.cos() + t2 * phi.sin()) * sin).normalize()
        })
        .collect()
}

/// The attenuation map of every condition of `spec` (see the module docs), each light
/// traced toward `spec.light_samples` directions: texel `(i, j)` at
/// [`GroundGrid::centre`], rows along `+z`.
pub fn attenuation_maps(
    hull: &VoxelHull,
    conditions: &[ConditionRecord],
    spec: &ShadowSpec,
) -> Vec<Image<f32>> {
    let samples = spec.light_samples;
    let n = spec.ground.texels as usize;
    spec.conditions
        .par_iter()
        .map(|&k| {
            let lights: Vec<(Vec3, f32)> = conditions[k]
                .lights
                .iter()
                .flat_map(|l| {
                    let lum = luminance(l.intensity);
                    let dirs = cone_directions(Vec3::from(l.direction), l.solid_angle_sr, samples);
                    let count = dirs.len() as f32;
                    dirs.into_iter()
                        .map(move |d| (d, lum * d.y.max(0.0) / count))
                })
                .filter(|(_, w)| *w > 0.0)
                .collect();
            let total: f32 = lights.iter().map(|l| l.1).sum();
            let pixels = (0..n * n)
                .map(|t| {
                    if total <= 0.0 {
                        return 1.0;
                    }
                    let p = spec.ground.centre((t % n) as u32, (t / n) as u32);
                    let origin = Vec3::new(p.x, GROUND_OFFSET_M, p.z);
                    let lit: f32 = lights
                        .iter()
                        .filter(|(d, _)| !hull.blocks(origin, *d))
                        .map(|l| l.1)
                        .sum();
                    (lit / total).clamp(0.0, 1.0)
                })
                .collect();
            Image::from_vec(n, n, pixels).expect("n * n texels")
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::LightRecord;
    use frf_core::volume::VoxelGrid;

    fn condition(name: &str, floor: bool, dirs: &[[f32; 3]]) -> ConditionRecord {
        ConditionRecord {
            name: name.into(),
            floor,
            lights: dirs
                .iter()
                .map(|d| LightRecord {
                    direction: *d,
                    intensity: [1.0; 3],
                    solid_angle_sr: 0.1,
                })
                .collect(),
        }
    }

    /// A 0.4 m cube standing on the ground at the origin.
    fn cube() -> VoxelHull {
        let grid = VoxelGrid::covering(Vec3::new(-0.2, 0.0, -0.2), Vec3::new(0.2, 0.4, 0.2), 0.05)
            .unwrap();
        VoxelHull::full(grid)
    }

    #[test]
    fn a_light_overhead_shadows_the_cube_footprint_and_the_horizon_shadows_nothing() {
        let conditions = vec![
            condition("zenith", false, &[[0.0, 1.0, 0.0]]),
            condition("horizon", false, &[[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
            condition("floor", true, &[[0.0, -1.0, 0.0]]),
            condition("half", false, &[[0.0, 1.0, 0.0], [0.6, 0.8, 0.0]]),
        ];
        let spec = shadow_spec(
            &conditions,
            GroundGrid {
                extent_m: 2.0,
                texels: 20,
            },
            1,
        );
        assert_eq!(spec.conditions, vec![0, 1, 3]);
        let maps = attenuation_maps(&cube(), &conditions, &spec);
        // Texel (10, 10) is centred at (0.05, 0, 0.05): under the cube.
        assert_eq!(maps[0].get(10, 10), 0.0);
        assert_eq!(maps[0].get(0, 0), 1.0);
        assert!(maps[1].pixels().iter().all(|&a| a == 1.0));
        // Under the cube both lights of "half" are blocked. At x = -0.25 m, beside the
        // cube, the overhead light arrives and the slanted one (toward +x, rising 0.8 per
        // 0.6) enters the cube's side: weights 1 and 0.8 (their cosines), 1 / 1.8 arrives.
        assert_eq!(maps[2].get(10, 10), 0.0);
        let beside = maps[2].get(7, 10);
        assert!((beside - 1.0 / 1.8).abs() < 1e-6, "{beside}");
        assert_eq!(ground_irradiance(&conditions[3]), [1.8; 3]);
        assert_eq!(ground_irradiance(&conditions[1]), [0.0; 3]);
    }

    #[test]
    fn cone_directions_fill_the_cone_and_keep_its_axis_on_average() {
        let d = Vec3::new(0.3, 0.8, 0.2).normalize();
        assert_eq!(cone_directions(d, 0.5, 1), vec![d]);
        let omega = 0.2;
        let dirs = cone_directions(d, omega, 32);
        let max_angle = (1.0 - omega / std::f32::consts::TAU).acos();
        assert!(dirs.iter().all(|v| (v.length() - 1.0).abs() < 1e-5));
        assert!(dirs.iter().all(|v| v.dot(d).acos() <= max_angle + 1e-4));
        let mean = dirs.iter().copied().sum::<Vec3>().normalize();
        assert!(mean.dot(d) > 0.9999, "{mean} vs {d}");
        // Spread: the widest sample is near the cone's edge.
        let widest = dirs.iter().map(|v| v.dot(d).acos()).fold(0.0f32, f32::max);
        assert!(widest > 0.9 * max_angle);
    }
}
