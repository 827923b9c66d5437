//! Projection of an HDR environment onto the lighting basis (docs/design.md section 4.1): the
//! coefficient of condition `k` is the environment's light over the condition's region
//! of the sphere, `∫_{Ω_k} L dω`, divided by the light the condition itself delivers,
//! `Σ_{l ∈ k} E_l`. Relighting with these coefficients then reproduces the environment's
//! light region by region.
//!
//! **Regions.** A condition's region is the union of the spherical Voronoi cells of its
//! lights among all lights of the basis: each direction belongs to the condition of its
//! nearest light. This needs nothing but the lights' directions (which every capture
//! manifest declares), covers the sphere exactly once, and for the stage's equal-area
//! grids of lights reproduces its cells up to their boundaries. Directions are looked up
//! in a 0.5° azimuth–elevation grid of nearest conditions, built once per basis.
//!
//! **Turntable.** For a view whose subject stood at turntable angle `θ`, the dome had to
//! show the environment rotated by `+θ` ([`frf_core::conventions`]): texel direction `d`
//! (subject frame) falls in the dome region containing `R_y(θ) d`.
//!
//! **Floor.** The floor conditions simulate light coming up from the ground. Two models
//! ([`FloorModel`]): the environment's own lower hemisphere (what a light probe
//! photographed on location sees below the horizon: the real ground, lit as it was),
//! which is also what the virtual stage's ground truth integrates; or, for maps without a
//! usable lower hemisphere (skies, studio maps), a Lambertian ground of given albedo lit
//! by the upper hemisphere, `L_ground = ρ/π · ∫_{upper} L cos θ dω`, unshadowed.

use std::f32::consts::PI;

use frf_core::env::EnvMap;
use frf_core::image::Rgb;
use frf_core::light::azimuth_elevation;
use glam::Vec3;
use rayon::prelude::*;

use crate::error::{ReflectanceError, Result};
use crate::field::ConditionRecord;

/// Where the light of the floor conditions comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FloorModel {
    /// The environment's lower hemisphere, as captured.
    Environment,
    /// A Lambertian ground of this RGB albedo lit by the environment's upper hemisphere.
    LambertianGround {
        /// Ground albedo.
        albedo: Rgb,
    },
}

/// Azimuth and elevation cells of the lookup grid per degree.
const CELLS_PER_DEGREE: usize = 2;
const AZ_CELLS: usize = 360 * CELLS_PER_DEGREE;
const EL_CELLS: usize = 180 * CELLS_PER_DEGREE;

/// Projects environments onto one lighting basis.
#[derive(Debug, Clone)]
pub struct Projector {
    /// Nearest condition per (elevation, azimuth) cell of the dome frame.
    grid: Vec<u16>,
    /// `Σ_l E_l` per condition and channel.
    delivered: Vec<Rgb>,
    floor: Vec<bool>,
}

fn cell_direction(ia: usize, ie: usize) -> Vec3 {
    let az = (ia as f32 + 0.5) / AZ_CELLS as f32 * 2.0 * PI - PI;
    let el = (ie as f32 + 0.5) / EL_CELLS as f32 * PI - PI / 2.0;
    frf_core::light::direction_from_azimuth_elevation(az, el)
}

/// One texel of an environment map: its azimuth and elevation (radians) and radiance.
type Texel = (f32, f32, Rgb);

impl Projector {
    /// A projector for `conditions` (dome frame).
    pub fn new(conditions: &[ConditionRecord]) -> Result<Self> {
        let lights: Vec<(Vec3, u16)> = conditions
            .iter()
            .enumerate()
            .flat_map(|(k, c)| {
                c.lights
                    .iter()
                    .map(move |l| (Vec3::from(l.direction).normalize(), k as u16))
            })
            .collect();
        if lights.is_empty() || conditions.len() > u16::MAX as usize {
            return Err(ReflectanceError::Misuse(
                "a basis needs 1..65535 conditions with lights".into(),
            ));
        }
        let grid = (0..EL_CELLS * AZ_CELLS)
            .into_par_iter()
            .map(|i| {
                let d = cell_direction(i % AZ_CELLS, i / AZ_CELLS);
                lights
                    .iter()
                    .max_by(|a, b| a.0.dot(d).total_cmp(&b.0.dot(d)))
                    .map(|l| l.1)
                    .unwrap_or(0)
            })
            .collect();
        let delivered = conditions
            .iter()
            .map(|c| {
                c.lights.iter().fold([0.0f32; 3], |acc, l| {
                    [0, 1, 2].map(|i| acc[i] + l.intensity[i])
                })
            })
            .collect();
        Ok(Self {
            grid,
            delivered,
            floor: conditions.iter().map(|c| c.floor).collect(),
        })
    }

    /// Number of conditions.
    pub fn conditions(&self) -> usize {
        self.delivered.len()
    }

    /// The condition whose region holds `direction` (dome frame).
    pub fn condition_of(&self, direction: Vec3) -> usize {
        let (az, el) = azimuth_elevation(direction.normalize_or_zero());
        self.lookup(az, el)
    }

    #[inline]
    fn lookup(&self, az: f32, el: f32) -> usize {
        let ia = (((az + PI) / (2.0 * PI)).rem_euclid(1.0) * AZ_CELLS as f32) as usize;
        let ie = ((el + PI / 2.0) / PI * EL_CELLS as f32) as usize;
        self.grid[ie.min(EL_CELLS - 1) * AZ_CELLS + ia.min(AZ_CELLS - 1)] as usize
    }

    /// `∫ L dω` of `env` over each condition's region, for a subject at turntable angle
    /// `turntable` (radians), with the floor conditions lit by `floor`.
    pub fn region_light(&self, env: &EnvMap, turntable: f32, floor: FloorModel) -> Vec<Rgb> {
        self.region_light_many(env, &[turntable], floor).remove(0)
    }

    /// [`Projector::region_light`] at each of `turntables`: the direction, radiance and
    /// solid angle of each texel are found once for all of them (the same arithmetic,
    /// so the same sums).
    pub fn region_light_many(
        &self,
        env: &EnvMap,
        turntables: &[f32],
        floor: FloorModel,
    ) -> Vec<Vec<Rgb>> {
        let img = env.image();
        let (w, h) = img.size();
        let ground = match floor {
            FloorModel::Environment => None,
            FloorModel::LambertianGround { albedo } => Some(env.lambertian_ground(albedo)),
        };
        // Per row: its texels' (azimuth, elevation, radiance); and its solid angle.
        let texels: Vec<(f64, Vec<Texel>)> = (0..h)
            .into_par_iter()
            .map(|y| {
                let row = (0..w)
                    .map(|x| {
                        let d = env.direction_of(x as f32, y as f32);
                        let (az, el) = azimuth_elevation(d);
                        let l = match ground {
                            Some(g) if d.y < 0.0 => g,
                            _ => img.get(x, y),
                        };
                        (az, el, l)
                    })
                    .collect();
                (env.texel_solid_angle(y) as f64, row)
            })
            .collect();
        turntables
            .iter()
            .map(|&turntable| {
                let per_row: Vec<Vec<[f64; 3]>> = texels
                    .par_iter()
                    .map(|(omega, row)| {
                        let mut acc = vec![[0.0f64; 3]; self.conditions()];
                        for &(az, el, l) in row {
                            let k = self.lookup(az + turntable, el);
                            for c in 0..3 {
                                acc[k][c] += l[c] as f64 * omega;
                            }
                        }
                        acc
                    })
                    .collect();
                let mut total = vec![[0.0f64; 3]; self.conditions()];
                for row in per_row {
                    for (t, r) in total.iter_mut().zip(row) {
                        for c in 0..3 {
                            t[c] += r[c];
                        }
                    }
                }
                total.into_iter().map(|t| t.map(|v| v as f32)).collect()
            })
            .collect()
    }

    /// The relighting coefficients (per condition, per channel) of `env` for a subject at
    /// turntable angle `turntable` (radians).
    pub fn project(&self, env: &EnvMap, turntable: f32, floor: FloorModel) -> Vec<Rgb> {
        self.project_many(env, &[turntable], floor).remove(0)
    }

    /// [`Projector::project`] at each of `turntables` (each distinct angle once).
    pub fn project_many(
        &self,
        env: &EnvMap,
        turntables: &[f32],
        floor: FloorModel,
    ) -> Vec<Vec<Rgb>> {
        let mut distinct: Vec<f32> = Vec::new();
        for &t in turntables {
            if !distinct.iter().any(|d| d.to_bits() == t.to_bits()) {
                distinct.push(t);
            }
        }
        let lights = self.region_light_many(env, &distinct, floor);
        let coefficients: Vec<Vec<Rgb>> = lights
            .iter()
            .map(|light| {
                light
                    .iter()
                    .zip(&self.delivered)
                    .map(|(light, d)| {
                        [0, 1, 2].map(|c| if d[c] > 0.0 { light[c] / d[c] } else { 0.0 })
                    })
                    .collect()
            })
            .collect();
        turntables
            .iter()
            .map(|t| {
                let k = distinct
                    .iter()
                    .position(|d| d.to_bits() == t.to_bits())
                    .expect("every angle is among the distinct ones");
                coefficients[k].clone()
            })
            .collect()
    }

    /// Per condition: the elevations (radians, lowest and highest) its region reaches,
    /// from the lookup grid's cell edges. Turned about the vertical axis, the region
    /// never leaves this band.
    pub fn elevation_bands(&self) -> Vec<(f32, f32)> {
        let mut bands = vec![(f32::INFINITY, f32::NEG_INFINITY); self.conditions()];
        for ie in 0..EL_CELLS {
            let lo = ie as f32 / EL_CELLS as f32 * PI - PI / 2.0;
            let hi = (ie + 1) as f32 / EL_CELLS as f32 * PI - PI / 2.0;
            for ia in 0..AZ_CELLS {
                let b = &mut bands[self.grid[ie * AZ_CELLS + ia] as usize];
                b.0 = b.0.min(lo);
                b.1 = b.1.max(hi);
            }
        }
        bands
    }

    /// Whether condition `k` is a floor condition.
    pub fn is_floor(&self, k: usize) -> bool {
        self.floor[k]
    }
}
