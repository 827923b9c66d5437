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
    /// Per elevation row of the grid: its runs of one condition along the azimuth,
    /// `(first cell, end cell, condition)`, covering the row once.
    runs: Vec<Vec<(u32, u32, u16)>>,
    /// `Σ_l E_l` per condition and channel.
    delivered: Vec<Rgb>,
    floor: Vec<bool>,
}

fn cell_direction(ia: usize, ie: usize) -> Vec3 {
    let az = (ia as f32 + 0.5) / AZ_CELLS as f32 * 2.0 * PI - PI;
    let el = (ie as f32 + 0.5) / EL_CELLS as f32 * PI - PI / 2.0;
    frf_core::light::direction_from_azimuth_elevation(az, el)
}

/// The radiance of a map row's texels (`prefix`: its prefix sums, `w` texels) whose
/// grid cell, at `C = c` ([`Projector::region_light_many`]), is in `a..b`: those with
/// `frac(C − (x + ½)/w) ∈ [a, b) / AZ_CELLS`, one contiguous span of `x` for each whole
/// turn `n` that `C − (x + ½)/w` can lie in.
fn span_sum(prefix: &[[f64; 3]], w: usize, c: f64, (a, b): (u32, u32)) -> [f64; 3] {
    let (lo_cell, hi_cell) = (a as f64 / AZ_CELLS as f64, b as f64 / AZ_CELLS as f64);
    let wf = w as f64;
    let mut out = [0.0f64; 3];
    // Over x in 0..w, C − (x + ½)/w lies in (C − 1, C).
    let first = (c - 1.0).floor() as i64;
    for n in first..=c.floor() as i64 {
        let n = n as f64;
        // C − (x + ½)/w ∈ [lo + n, hi + n)  ⟺  x ∈ (w(C − hi − n) − ½, w(C − lo − n) − ½].
        let from = ((wf * (c - hi_cell - n) - 0.5).floor() + 1.0).max(0.0);
        let to = (wf * (c - lo_cell - n) - 0.5).floor().min(wf - 1.0);
        if from <= to {
            let (from, to) = (from as usize, to as usize);
            for ch in 0..3 {
                out[ch] += prefix[to + 1][ch] - prefix[from][ch];
            }
        }
    }
    out
}

/// The turn `C = (3π + ψ + t) / 2π` at which a map turned by `ψ` (radians) is seen by a
/// subject at turntable angle `t` (radians); a whole turn later is the same light.
pub fn turn_of(yaw: f32, turntable: f32) -> f64 {
    (3.0 * std::f64::consts::PI + yaw as f64 + turntable as f64) / std::f64::consts::TAU
}

/// A map made ready to project at any turn: per texel row, its solid angle, its row of the
/// lookup grid and the prefix sums of its radiance (below the horizon, the ground's under
/// [`FloorModel::LambertianGround`]). Made once per map (`rows × width` additions); each
/// turn then costs `rows × runs` ([`Projector::region_light_at`]).
#[derive(Debug, Clone)]
pub struct PreparedMap {
    width: usize,
    rows: Vec<(f64, usize, Vec<[f64; 3]>)>,
}

impl PreparedMap {
    /// `env`'s rows (its yaw plays no part: turns are given to
    /// [`Projector::region_light_at`]), with the floor conditions lit by `floor`.
    pub fn new(env: &EnvMap, floor: FloorModel) -> Self {
        let img = env.image();
        let (w, h) = img.size();
        let ground = match floor {
            FloorModel::Environment => None,
            FloorModel::LambertianGround { albedo } => Some(env.lambertian_ground(albedo)),
        };
        let rows = (0..h)
            .into_par_iter()
            .map(|y| {
                let d = env.direction_of(0.0, y as f32);
                let el = azimuth_elevation(d).1;
                let ie = (((el + PI / 2.0) / PI * EL_CELLS as f32) as usize).min(EL_CELLS - 1);
                let mut prefix = Vec::with_capacity(w + 1);
                let mut sum = [0.0f64; 3];
                prefix.push(sum);
                for x in 0..w {
                    let l = match ground {
                        Some(g) if d.y < 0.0 => g,
                        _ => img.get(x, y),
                    };
                    for c in 0..3 {
                        sum[c] += l[c] as f64;
                    }
                    prefix.push(sum);
                }
                (env.texel_solid_angle(y) as f64, ie, prefix)
            })
            .collect();
        Self { width: w, rows }
    }
}

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
        let grid: Vec<u16> = (0..EL_CELLS * AZ_CELLS)
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
        let runs: Vec<Vec<(u32, u32, u16)>> = (0..EL_CELLS)
            .map(|ie| {
                let row = &grid[ie * AZ_CELLS..(ie + 1) * AZ_CELLS];
                let mut runs: Vec<(u32, u32, u16)> = Vec::new();
                for (ia, &k) in row.iter().enumerate() {
                    match runs.last_mut() {
                        Some(r) if r.2 == k => r.1 = ia as u32 + 1,
                        _ => runs.push((ia as u32, ia as u32 + 1, k)),
                    }
                }
                runs
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
            runs,
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

    /// [`Projector::region_light`] at each of `turntables`.
    ///
    /// An environment map is equirectangular: a texel row has one elevation (a turn about
    /// `+y` keeps it), hence one row of the lookup grid, and its texels' azimuths step
    /// evenly. Texel `x` of a map `w` wide turned by `ψ`, seen at turntable `t`, falls in
    /// grid cell `⌊frac(C − (x + ½)/w) · AZ_CELLS⌋` with `C = (3π + ψ + t) / 2π`
    /// ([`turn_of`]). So each run of one condition along the grid row takes a contiguous
    /// span of texels (two where it wraps), summed from the row's prefix sums
    /// ([`PreparedMap`]): a turntable angle costs rows × runs, not rows × texels, which is
    /// what makes relighting a crowd under a moving light cheap for the host. Texels whose
    /// centre lies on a cell boundary (to within rounding) may fall on its other side than
    /// a direct lookup would put them.
    pub fn region_light_many(
        &self,
        env: &EnvMap,
        turntables: &[f32],
        floor: FloorModel,
    ) -> Vec<Vec<Rgb>> {
        let prepared = PreparedMap::new(env, floor);
        turntables
            .par_iter()
            .map(|&t| self.region_light_at(&prepared, turn_of(env.yaw(), t)))
            .collect()
    }

    /// `∫ L dω` of a prepared map over each condition's region at turn `c` (see
    /// [`Projector::region_light_many`]; `c` and `c + 1` are one turn).
    pub fn region_light_at(&self, map: &PreparedMap, c: f64) -> Vec<Rgb> {
        let mut total = vec![[0.0f64; 3]; self.conditions()];
        for (omega, ie, prefix) in &map.rows {
            for &(a, b, k) in &self.runs[*ie] {
                let sum = span_sum(prefix, map.width, c, (a, b));
                for ch in 0..3 {
                    total[k as usize][ch] += sum[ch] * omega;
                }
            }
        }
        total.into_iter().map(|t| t.map(|v| v as f32)).collect()
    }

    /// The relighting coefficients of the light `light` (per condition, as
    /// [`Projector::region_light`] gives it): divided by the light each condition
    /// delivers.
    pub fn coefficients_of(&self, light: &[Rgb]) -> Vec<Rgb> {
        light
            .iter()
            .zip(&self.delivered)
            .map(|(light, d)| [0, 1, 2].map(|c| if d[c] > 0.0 { light[c] / d[c] } else { 0.0 }))
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
        let coefficients: Vec<Vec<Rgb>> = lights.iter().map(|l| self.coefficients_of(l)).collect();
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
