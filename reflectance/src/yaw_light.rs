//! A light as its renderer relights it: a sum of environment maps, each turned by a yaw
//! and weighted (a map turned by a scene's lighting keys, two maps cross-fading, a scene's
//! sun in a map of its own), read through each map's [`YawTable`] (docs/design.md section
//! 4.1, *The yaw table*). Coefficients are linear in the light, so the sum's are the sum of
//! the tables' at each map's own turn; a walker's heading turns every map alike
//! ([`YawLight::turned`]), and a light that turns changes only the yaws: no map is
//! projected again and no sun found again.

use std::sync::Arc;

use frf_core::env::EnvMap;
use frf_core::image::{Rgb, luminance};
use frf_core::sun::Sun;
use glam::{Mat3, Vec3};

use crate::error::Result;
use crate::project::{FloorModel, Projector};
use crate::sun_depth::Occluder;
use crate::sun_light::MAX_SUNS;
use crate::yaw_table::{Part, YawTable};

/// One map of a light: its table, its weight and its turn (radians about `+y`).
#[derive(Debug, Clone)]
pub struct YawTerm {
    /// The map's table.
    pub table: Arc<YawTable>,
    /// Its weight (a cross-fade's share times the light's intensity).
    pub weight: f32,
    /// Its turn, radians.
    pub yaw: f32,
}

/// A light as a sum of turned, weighted maps (see the module text), and the other
/// walkers that stand in the way of its suns ([`YawLight::with_occluders`]).
#[derive(Debug, Clone)]
pub struct YawLight {
    terms: Vec<YawTerm>,
    occluders: Vec<Occluder>,
}

/// What relights a pose under a light: per view its coefficients (with the suns taken out
/// where they are relit by the normals), the suns, and the ground's coefficients.
#[derive(Debug, Clone)]
pub struct ViewLighting {
    /// Per turntable angle asked: the coefficients of every condition.
    pub coefficients: Vec<Vec<Rgb>>,
    /// The suns relit by the normals (scene frame of the light, brightest first).
    pub suns: Vec<Sun>,
    /// Per turntable angle asked: what the suns add to the coefficients when the basis
    /// relights them (the whole light's less `coefficients`; empty without suns), where
    /// the normals' sun is not trusted ([`crate::sun_light::SunLight::trust`]).
    pub sun_coefficients: Vec<Vec<Rgb>>,
    /// The coefficients at turntable angle 0 of the whole light (the ground's frame).
    pub ground: Vec<Rgb>,
}

impl YawLight {
    /// A light of `terms`.
    pub fn new(terms: Vec<YawTerm>) -> Self {
        Self {
            terms,
            occluders: Vec::new(),
        }
    }

    /// The same light with `occluders` (in the frame of the walker it lights) in the way of
    /// its suns: they shade the walker where they stand between it and a sun
    /// ([`crate::sun_depth::Occluder`]).
    pub fn with_occluders(mut self, occluders: Vec<Occluder>) -> Self {
        self.occluders = occluders;
        self
    }

    /// The other walkers in the way of its suns.
    pub fn occluders(&self) -> &[Occluder] {
        &self.occluders
    }

    /// `env` (turned by its own yaw) as a light of one map, through a table of its own.
    pub fn of_env(projector: Arc<Projector>, env: &EnvMap, floor: FloorModel) -> Self {
        Self::new(vec![YawTerm {
            table: Arc::new(YawTable::new(projector, env, floor)),
            weight: 1.0,
            yaw: env.yaw(),
        }])
    }

    /// The luminance of its radiance arriving from `direction` (subject frame) below the
    /// horizon as its maps hold it, or `None` when a map's floor conditions are lit by a
    /// modelled ground rather than the map's own lower hemisphere (a uniform ground,
    /// which a floor condition already is).
    pub fn ground_radiance(&self) -> Option<impl Fn(Vec3) -> f32 + '_> {
        (self.terms.iter())
            .all(|t| t.table.floor() == FloorModel::Environment)
            .then_some(move |d: Vec3| {
                (self.terms.iter())
                    .map(|t| {
                        let turned = Mat3::from_rotation_y(-t.yaw) * d;
                        t.weight * luminance(t.table.coarse_map().radiance(turned))
                    })
                    .sum()
            })
    }

    /// The share of its luminance that arrives from below the horizon.
    pub fn ground_share(&self) -> f32 {
        let (mut below, mut total) = (0.0f64, 0.0f64);
        for t in &self.terms {
            let (b, all) = t.table.ground_parts();
            below += b * t.weight as f64;
            total += all * t.weight as f64;
        }
        if total > 0.0 {
            (below / total) as f32
        } else {
            0.0
        }
    }

    /// Its maps.
    pub fn terms(&self) -> &[YawTerm] {
        &self.terms
    }

    /// The same light turned by a further `angle` radians (a walker's heading turns its
    /// light by minus the heading).
    pub fn turned(&self, angle: f32) -> Self {
        Self::new(
            self.terms
                .iter()
                .map(|t| YawTerm {
                    yaw: t.yaw + angle,
                    ..t.clone()
                })
                .collect(),
        )
        .with_occluders(self.occluders.clone())
    }

    /// Its coefficients at each of `turntables` (radians). With `suns`, the maps' suns
    /// (up to [`MAX_SUNS`] in all: a map's suns are taken whole or not at all, the maps of
    /// brightest suns first) are returned apart and taken out of the coefficients of the
    /// upper conditions ([`Part::LessSuns`]).
    pub fn lighting(&self, turntables: &[f32], suns: bool) -> Result<ViewLighting> {
        // Views of one turntable angle (a column's cameras, the views not read) are lit
        // alike: each angle is read from the tables once.
        let (angles, at) = crate::sun_light::distinct(turntables);
        if angles.len() < turntables.len() {
            let lit = self.lighting(&angles, suns)?;
            let spread = |per: Vec<Vec<Rgb>>| -> Vec<Vec<Rgb>> {
                if per.is_empty() {
                    return per;
                }
                at.iter().map(|&k| per[k].clone()).collect()
            };
            return Ok(ViewLighting {
                coefficients: spread(lit.coefficients),
                sun_coefficients: spread(lit.sun_coefficients),
                ..lit
            });
        }
        let conditions = self
            .terms
            .first()
            .map_or(0, |t| t.table.projector().conditions());
        let (parts, taken) = self.suns_taken(suns)?;
        let taken: Vec<Sun> = taken.into_iter().map(|(_, _, s)| s).collect();
        let mut coefficients = vec![vec![[0.0f32; 3]; conditions]; turntables.len()];
        let mut sun_coefficients = if taken.is_empty() {
            Vec::new()
        } else {
            vec![vec![[0.0f32; 3]; conditions]; turntables.len()]
        };
        for (t, part) in self.terms.iter().zip(&parts) {
            let c = t.table.coefficients(*part, t.yaw, turntables)?;
            for (sum, c) in coefficients.iter_mut().zip(&c) {
                add_weighted(sum, c, t.weight);
            }
            if *part == Part::LessSuns {
                let whole = t.table.coefficients(Part::Whole, t.yaw, turntables)?;
                for ((sum, whole), less) in sun_coefficients.iter_mut().zip(&whole).zip(&c) {
                    add_weighted(sum, whole, t.weight);
                    add_weighted(sum, less, -t.weight);
                }
            }
        }
        let ground = self.ground(conditions)?;
        Ok(ViewLighting {
            coefficients,
            suns: taken,
            sun_coefficients,
            ground,
        })
    }
}

impl YawLight {
    /// The coefficients at turntable angle 0 of the whole light (the ground's frame), of
    /// `conditions` conditions.
    pub fn ground(&self, conditions: usize) -> Result<Vec<Rgb>> {
        let mut ground = vec![[0.0f32; 3]; conditions];
        for t in &self.terms {
            let own = t.table.coefficients(Part::Whole, t.yaw, &[0.0])?;
            add_weighted(&mut ground, &own[0], t.weight);
        }
        Ok(ground)
    }

    /// Which part of each term's map its coefficients are of, and the suns relit by the
    /// normals apart (with `suns`; none without): up to [`MAX_SUNS`] in all, a map's suns
    /// taken whole or not at all, the maps of brightest suns first. Each sun taken with
    /// its term and its place among the map's suns, turned and weighted as the term is.
    pub fn suns_taken(&self, suns: bool) -> Result<(Vec<Part>, Vec<TakenSun>)> {
        let mut parts = vec![Part::Whole; self.terms.len()];
        let mut taken = Vec::new();
        if !suns {
            return Ok((parts, taken));
        }
        let mut by_sun: Vec<(usize, f32)> = Vec::new();
        for (i, t) in self.terms.iter().enumerate() {
            if let Some(first) = t.table.suns()?.first() {
                by_sun.push((i, t.weight * luminance(first.illuminance())));
            }
        }
        // Brightest first; of equals, the first map's.
        by_sun.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        for (i, _) in by_sun {
            let t = &self.terms[i];
            let found = t.table.suns()?;
            if t.weight > 0.0 && taken.len() + found.len() <= MAX_SUNS {
                parts[i] = Part::LessSuns;
                taken.extend((found.iter().enumerate()).map(|(j, s)| (i, j, turned_sun(s, t))));
            }
        }
        Ok((parts, taken))
    }
}

/// A sun taken from a light's maps ([`YawLight::suns_taken`]): its term, its place among
/// the map's suns, and the sun as the term turns and weighs it.
pub type TakenSun = (usize, usize, Sun);

/// A map's sun as its term turns and weighs it (itself for a term of weight 1, unturned).
fn turned_sun(sun: &Sun, t: &YawTerm) -> Sun {
    let s = if t.yaw == 0.0 {
        *sun
    } else {
        sun.rotated(t.yaw)
    };
    if t.weight == 1.0 {
        s
    } else {
        s.scaled(t.weight)
    }
}

/// `sum += w · c`, per condition and channel (`c` itself when `sum` is zero and `w` 1).
fn add_weighted(sum: &mut [Rgb], c: &[Rgb], w: f32) {
    for (s, c) in sum.iter_mut().zip(c) {
        for ch in 0..3 {
            s[ch] += w * c[ch];
        }
    }
}
