//! The subject's shadow on the ground (docs/design.md section 4.4): a pose's attenuation
//! maps (one per upper basis condition, [`frf_reflectance::shadow`]) relit with the same
//! environment as the subject give the **relative irradiance** of the ground patch under
//! it, per channel:
//!
//! `S(x) = Σ_k c_k E_k A_k(x) / Σ_k c_k E_k`
//!
//! with `c_k` the environment's coefficient of condition `k` (projected for the ground's
//! frame, turntable angle 0: the maps are traced with the dome's lights as the subject
//! frame sees them at angle 0), `E_k` the irradiance condition `k` delivers to the
//! unshadowed ground and `A_k` its map. `S = 1` is unshadowed; where nothing lights the
//! ground from above (the sum is 0) `S = 1`, and off the patch `S = 1`. Toward the edge
//! of the patch the maps fade to 1 ([`edge_fade`]): a shadow longer than the patch (a low
//! sun's) thins out instead of ending on a straight line, and the patch leaves no square
//! behind. This is the CPU reference; `shaders/shadow.wgsl` relights the maps and
//! `shaders/composite.wgsl` samples them with the same fade on the GPU.

use frf_core::image::{Border, GrayImage, Image, Rgb, RgbImage};
use frf_core::light::DirLight;
use frf_core::volume::GroundGrid;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_reflectance::field::ShadowSpec;
use frf_reflectance::hull::VoxelHull;
use frf_reflectance::shadow::ground_irradiance;
use glam::Vec3;
use rayon::prelude::*;

use crate::error::Result;

/// A pose's attenuation maps and what relighting them needs.
#[derive(Debug, Clone)]
pub struct ShadowMaps {
    /// The ground grid and the conditions of the maps.
    pub spec: ShadowSpec,
    /// One map per condition of the spec.
    pub maps: Vec<GrayImage>,
    /// Per map: the irradiance its condition delivers to the unshadowed ground.
    pub irradiance: Vec<Rgb>,
}

impl ShadowMaps {
    /// The maps of pose `pose`, or `None` when the field holds none.
    pub fn load<R: ReadAt>(field: &FieldFile<R>, pose: u32) -> Result<Option<Self>> {
        let h = field.header();
        let (Some(spec), Some(maps)) = (&h.shadows, field.shadows(pose)?) else {
            return Ok(None);
        };
        let irradiance = spec
            .conditions
            .iter()
            .map(|&k| ground_irradiance(&h.conditions[k]))
            .collect();
        Ok(Some(Self {
            spec: spec.clone(),
            maps,
            irradiance,
        }))
    }

    /// The maps box-filtered by `level` (blocks of `2^level` texels a side, averaged), or
    /// by the coarsest level below it that divides their side: the same patch of ground
    /// in fewer texels, for a walker too small in the frame to tell them apart.
    pub fn reduced(self, level: u8) -> Self {
        let n = self.spec.ground.texels;
        let level = (0..=level.min(15))
            .rev()
            .find(|&l| n.is_multiple_of(1 << l) && n >> l > 0)
            .unwrap_or(0);
        if level == 0 {
            return self;
        }
        let b = 1usize << level;
        let m = (n >> level) as usize;
        let mut spec = self.spec.clone();
        spec.ground.texels = m as u32;
        let maps = self
            .maps
            .iter()
            .map(|map| {
                Image::from_fn(m, m, |x, y| {
                    let mut sum = 0.0;
                    for dy in 0..b {
                        for dx in 0..b {
                            sum += map.get(x * b + dx, y * b + dy);
                        }
                    }
                    sum / (b * b) as f32
                })
            })
            .collect();
        Self {
            spec,
            maps,
            irradiance: self.irradiance,
        }
    }

    /// Per map: `c_k E_k` (RGB), the weights of [`ShadowMaps::relight`] from the
    /// coefficients of every condition of the field.
    pub fn weights(&self, coefficients: &[Rgb]) -> Vec<Rgb> {
        self.spec
            .conditions
            .iter()
            .zip(&self.irradiance)
            .map(|(&k, e)| [0, 1, 2].map(|c| coefficients[k][c] * e[c]))
            .collect()
    }

    /// The relative irradiance of the ground under the coefficients of every condition
    /// of the field (see the module docs).
    pub fn relight(&self, coefficients: &[Rgb]) -> RelitShadow {
        let weights = self.weights(coefficients);
        let total = weights
            .iter()
            .fold([0.0f32; 3], |a, w| [0, 1, 2].map(|c| a[c] + w[c]));
        let n = self.spec.ground.texels as usize;
        let image = Image::from_fn(n, n, |x, y| {
            let mut lit = [0.0f32; 3];
            for (map, w) in self.maps.iter().zip(&weights) {
                let a = map.get(x, y);
                for c in 0..3 {
                    lit[c] += w[c] * a;
                }
            }
            [0, 1, 2].map(|c| {
                if total[c] > 0.0 {
                    (lit[c] / total[c]).clamp(0.0, 1.0)
                } else {
                    1.0
                }
            })
        });
        RelitShadow {
            ground: self.spec.ground,
            image,
        }
    }
}

/// The relative irradiance of the ground patch under the subject.
#[derive(Debug, Clone, PartialEq)]
pub struct RelitShadow {
    /// The patch.
    pub ground: GroundGrid,
    /// Relative irradiance per texel (rows along `+z`).
    pub image: RgbImage,
}

pub use frf_reflectance::shadow::EDGE_FADE_FROM;

/// The weight of 1 (unshadowed) at ground point `(x, z)` of a patch of side `extent_m`
/// centred on the subject: 0 inside [`EDGE_FADE_FROM`] of the half side (the maps as
/// they are), rising smoothly (smoothstep of the larger of `|x|` and `|z|`) to 1 at the
/// edge. `shaders/composite.wgsl`'s `edge_fade` is its twin.
pub fn edge_fade(x: f32, z: f32, extent_m: f32) -> f32 {
    let half = 0.5 * extent_m;
    let t =
        ((x.abs().max(z.abs()) / half - EDGE_FADE_FROM) / (1.0 - EDGE_FADE_FROM)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl RelitShadow {
    /// The relative irradiance at ground point `(x, z)`: bilinear between texel centres,
    /// the edge texels held out to the patch's border, faded to 1 toward the edge
    /// ([`edge_fade`]), 1 off the patch.
    pub fn at(&self, x: f32, z: f32) -> Rgb {
        if !self.ground.contains(x, z) {
            return [1.0; 3];
        }
        let t = self.ground.texel_of(x, z);
        let s = self.image.sample_bilinear(t.x, t.y, Border::Clamp);
        let w = edge_fade(x, z, self.ground.extent_m);
        s.map(|c| c + (1.0 - c) * w)
    }
}

/// Rays toward the lights start this far above the ground (metres), as in the maps.
const GROUND_OFFSET_M: f32 = 1e-4;

/// The relative irradiance of the ground traced directly against a pose's visual hull
/// under distant `lights` (e.g. an environment's median-cut lights, subject frame):
/// `S(x) = Σ_l E_l max(0, d_l·y) V_l(x) / Σ_l E_l max(0, d_l·y)` per channel, `V_l` 1
/// when the ray toward `d_l` misses the hull. Not the original's method (the maps are):
/// it keeps a small sun's shadow in one piece, which no 23-condition basis can, and is
/// measured against the maps as an ablation.
pub fn traced_shadow(hull: &VoxelHull, lights: &[DirLight], ground: GroundGrid) -> RelitShadow {
    let n = ground.texels as usize;
    let lights: Vec<(Vec3, Rgb)> = lights
        .iter()
        .filter(|l| l.direction.y > 0.0)
        .map(|l| {
            let d = l.direction.normalize();
            (d, l.irradiance.map(|e| e * d.y))
        })
        .collect();
    let total = lights.iter().fold([0.0f64; 3], |a, (_, e)| {
        [0, 1, 2].map(|c| a[c] + e[c] as f64)
    });
    let pixels: Vec<Rgb> = (0..n * n)
        .into_par_iter()
        .map(|t| {
            let p = ground.centre((t % n) as u32, (t / n) as u32);
            let origin = Vec3::new(p.x, GROUND_OFFSET_M, p.z);
            let mut lit = [0.0f64; 3];
            for (d, e) in &lights {
                if !hull.blocks(origin, *d) {
                    for c in 0..3 {
                        lit[c] += e[c] as f64;
                    }
                }
            }
            [0, 1, 2].map(|c| {
                if total[c] > 0.0 {
                    (lit[c] / total[c]) as f32
                } else {
                    1.0
                }
            })
        })
        .collect();
    RelitShadow {
        ground,
        image: Image::from_vec(n, n, pixels).expect("n * n texels"),
    }
}

/// Where the ray `origin + t dir` (`t > 0`) meets the ground plane `y = 0` from above, if
/// it does.
pub fn ground_hit(origin: Vec3, dir: Vec3) -> Option<Vec3> {
    if !(origin.y > 0.0 && dir.y < 0.0) {
        return None;
    }
    let t = -origin.y / dir.y;
    let p = origin + dir * t;
    p.is_finite().then_some(Vec3::new(p.x, 0.0, p.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn maps() -> ShadowMaps {
        let ground = GroundGrid {
            extent_m: 2.0,
            texels: 4,
        };
        ShadowMaps {
            spec: ShadowSpec {
                ground,
                conditions: vec![0, 2],
                light_samples: 1,
            },
            // Condition 0 blocked at texel (1, 1); condition 2 half blocked everywhere.
            maps: vec![
                Image::from_fn(4, 4, |x, y| if (x, y) == (1, 1) { 0.0 } else { 1.0 }),
                Image::new(4, 4, 0.5),
            ],
            irradiance: vec![[1.0, 1.0, 1.0], [2.0, 2.0, 0.0]],
        }
    }

    #[test]
    fn relighting_weights_the_maps_by_the_light_they_carry() {
        let m = maps();
        // Condition 1 (a floor one, no map) must not matter.
        let relit = m.relight(&[[1.0; 3], [50.0; 3], [1.0; 3]]);
        // Texel (0, 0): lit = 1·1 + 2·0.5 = 2 of 3 in red and green; blue: only the first.
        let p = relit.image.get(0, 0);
        assert!((p[0] - 2.0 / 3.0).abs() < 1e-6 && p[2] == 1.0, "{p:?}");
        let q = relit.image.get(1, 1);
        assert!((q[0] - 1.0 / 3.0).abs() < 1e-6 && q[2] == 0.0, "{q:?}");
        // No light from above at all: unshadowed by definition.
        let dark = m.relight(&[[0.0; 3]; 3]);
        assert!(dark.image.pixels().iter().all(|p| *p == [1.0; 3]));
        // Off the patch: 1.
        assert_eq!(relit.at(1.5, 0.0), [1.0; 3]);
        // At texel (1, 1)'s centre, (-0.25, -0.25).
        assert_eq!(relit.at(-0.25, -0.25), q);
    }

    #[test]
    fn reduced_maps_average_blocks_over_the_same_patch() {
        let m = maps();
        let r = m.clone().reduced(1);
        assert_eq!(r.spec.ground.texels, 2);
        assert_eq!(r.spec.ground.extent_m, m.spec.ground.extent_m);
        // Block (0, 0) holds the one blocked texel of the first map: 3/4 lit.
        assert_eq!(r.maps[0].get(0, 0), 0.75);
        assert_eq!(r.maps[0].get(1, 1), 1.0);
        assert_eq!(r.maps[1].get(1, 0), 0.5);
        // Relit, the patch is the same: a reduced texel's centre relights as its block.
        let c = [[1.0; 3], [50.0; 3], [1.0; 3]];
        let (full, half) = (m.relight(&c), r.relight(&c));
        assert_eq!(half.at(1.5, 0.0), [1.0; 3]);
        let block = [(0, 0), (1, 0), (0, 1), (1, 1)]
            .iter()
            .map(|&(x, y)| full.image.get(x, y)[0])
            .sum::<f32>()
            / 4.0;
        assert!((half.at(-0.5, -0.5)[0] - block).abs() < 1e-6);
        // A level past what divides the side stops at the coarsest that does; 0 is as is.
        assert_eq!(m.clone().reduced(5).spec.ground.texels, 1);
        assert_eq!(m.clone().reduced(0).maps, m.maps);
    }

    #[test]
    fn the_maps_fade_to_one_toward_the_patch_edge() {
        // Red is 2/3 everywhere but texel (1, 1); the patch's half side is 1 m.
        let relit = maps().relight(&[[1.0; 3], [50.0; 3], [1.0; 3]]);
        let red = |x: f32| relit.at(x, 0.3)[0];
        assert!((red(0.79) - 2.0 / 3.0).abs() < 1e-6, "{}", red(0.79));
        // Half way through the fade band: smoothstep(1/2) = 1/2 of the way to 1.
        assert!((red(0.9) - 5.0 / 6.0).abs() < 1e-5, "{}", red(0.9));
        assert!(red(0.999) > 0.999 && red(0.85) < red(0.9) && red(0.9) < red(0.95));
        // The same along z and on the other side.
        assert!((relit.at(0.3, -0.9)[0] - 5.0 / 6.0).abs() < 1e-5);
    }

    #[test]
    fn rays_meet_the_ground_from_above_only() {
        let p = ground_hit(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0).normalize(),
        );
        assert!((p.unwrap() - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-5);
        assert!(ground_hit(Vec3::new(0.0, 2.0, 0.0), Vec3::Y).is_none());
        assert!(ground_hit(Vec3::new(0.0, -1.0, 0.0), Vec3::NEG_Y).is_none());
        // A grazing ray far away is still finite.
        let far = ground_hit(Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, -1e-7, 0.0));
        assert!(far.is_none_or(|p| p.is_finite()));
    }
}
