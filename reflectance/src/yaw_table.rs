//! One environment map's relighting coefficients as a function of yaw (docs/design.md
//! section 4.1, *The yaw table*). The turntable and a walker's heading turn the subject
//! about the vertical only, and so does turning a light: the coefficients of a view under a
//! map depend on the sum of those angles alone, the turn `C` of [`turn_of`]. A table holds
//! them at [`SAMPLES_PER_TURN`] evenly spaced turns, each made the first time a view needs
//! it (from the map's prefix sums, [`PreparedMap`], made once), and a view between two
//! samples reads their linear interpolation. A light that turns, and every walker of a
//! crowd, read the same table: once its samples are made, a new light costs the host a
//! lookup per view, whatever the number of walkers.
//!
//! The map's suns, relit by the views' normals rather than by the basis
//! ([`crate::sun_light`]), are found once with the coefficients of what they leave
//! ([`YawTable::suns`], [`Part::LessSuns`]); turning the light turns them.
//!
//! At a sample's turn a table gives the direct projection of the map turned there
//! ([`Projector::project`]) to within float rounding. Between samples the table moves
//! linearly, where the direct projection, which takes each texel into the cell its centre
//! falls in, jumps as texels cross cells: on a smooth sky by up to 3.7 % of the largest
//! coefficient within a quarter of a degree, and the two differ by as much (3.0e-2
//! measured; 2.5e-4 on the built-in sky; `reflectance/tests/yaw_table.rs`).

use std::sync::{Arc, OnceLock};

use frf_core::env::EnvMap;
use frf_core::image::Rgb;
use frf_core::sun::Sun;
use rayon::prelude::*;

use crate::error::Result;
use crate::project::{FloorModel, PreparedMap, Projector, turn_of};
use crate::sun_light::MAX_SUNS;

/// Samples a table holds per turn: one every quarter of a degree. A sample of the stage's
/// 26 conditions is 312 bytes, so a whole table of both parts is under 1 MB; the views of
/// a field lie on whole degrees (10° apart on the stage), which are samples.
pub const SAMPLES_PER_TURN: usize = 1440;

/// Which light a table's coefficients are of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// The whole map.
    Whole,
    /// The map less its suns ([`YawTable::suns`]), on the conditions of the upper
    /// hemisphere; the floor conditions keep the whole map's (the ground the suns light).
    LessSuns,
}

/// Coefficients at the samples of one map, made when first needed.
#[derive(Debug)]
struct Samples {
    map: PreparedMap,
    values: Vec<OnceLock<Vec<Rgb>>>,
}

impl Samples {
    fn new(map: PreparedMap) -> Self {
        Self {
            map,
            values: (0..SAMPLES_PER_TURN).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Makes the samples `wanted` that are not made yet, in parallel.
    fn make(&self, projector: &Projector, wanted: &[usize]) {
        let mut missing: Vec<usize> = wanted
            .iter()
            .copied()
            .filter(|&i| self.values[i].get().is_none())
            .collect();
        missing.sort_unstable();
        missing.dedup();
        let made: Vec<(usize, Vec<Rgb>)> = missing
            .into_par_iter()
            .map(|i| {
                let c = i as f64 / SAMPLES_PER_TURN as f64;
                let light = projector.region_light_at(&self.map, c);
                (i, projector.coefficients_of(&light))
            })
            .collect();
        for (i, v) in made {
            // Another thread may have made it meanwhile: the same values.
            let _ = self.values[i].set(v);
        }
    }

    fn get(&self, i: usize) -> &[Rgb] {
        self.values[i]
            .get()
            .expect("samples are made before they are read")
    }
}

/// Where turn `c` falls among the samples: the two around it and the weight of the second
/// (0 on a sample, to within rounding).
fn bracket(c: f64) -> (usize, usize, f32) {
    let n = SAMPLES_PER_TURN as f64;
    let f = c.rem_euclid(1.0) * n;
    let nearest = f.round();
    // A turn within 1e-6 of a sample (about 2e-7 degrees) is that sample.
    if (f - nearest).abs() < 1e-6 {
        let i = (nearest as usize) % SAMPLES_PER_TURN;
        return (i, i, 0.0);
    }
    let i0 = (f.floor() as usize) % SAMPLES_PER_TURN;
    (i0, (i0 + 1) % SAMPLES_PER_TURN, (f - f.floor()) as f32)
}

/// One map's coefficients by turn, and its suns (see the module text).
#[derive(Debug)]
pub struct YawTable {
    projector: Arc<Projector>,
    map: EnvMap,
    floor: FloorModel,
    whole: Samples,
    /// The suns (map frame, unturned) and the samples of what they leave; `None` inside
    /// when the map has no sun.
    less_suns: OnceLock<Option<(Vec<Sun>, Samples)>>,
    /// [`YawTable::coarse_map`], made when first needed.
    coarse: OnceLock<EnvMap>,
    /// [`YawTable::ground_parts`], found when first needed.
    ground: OnceLock<(f64, f64)>,
}

impl YawTable {
    /// The table of `env` (its own yaw is left out: turns are given when reading) over
    /// `projector`'s basis, the floor conditions lit by `floor`.
    pub fn new(projector: Arc<Projector>, env: &EnvMap, floor: FloorModel) -> Self {
        let map = env.rotated(-env.yaw());
        Self {
            whole: Samples::new(PreparedMap::new(&map, floor)),
            projector,
            map,
            floor,
            less_suns: OnceLock::new(),
            coarse: OnceLock::new(),
            ground: OnceLock::new(),
        }
    }

    /// The projector of its basis.
    pub fn projector(&self) -> &Projector {
        &self.projector
    }

    /// The map, unturned.
    pub fn map(&self) -> &EnvMap {
        &self.map
    }

    /// The map averaged over 10° texels ([`EnvMap::coarse`]), unturned: the ground's shape
    /// as the floor conditions' lights sample it ([`crate::floor_light`]).
    pub fn coarse_map(&self) -> &EnvMap {
        self.coarse.get_or_init(|| self.map.coarse(36, 18))
    }

    /// Its coarse map's luminance arriving from below the horizon and in all (each
    /// `∫ L dω`), found once: what [`crate::yaw_light::YawLight::ground_share`] weighs.
    pub fn ground_parts(&self) -> (f64, f64) {
        *self.ground.get_or_init(|| {
            let map = self.coarse_map();
            let (w, h) = map.image().size();
            let (mut below, mut total) = (0.0f64, 0.0f64);
            for y in 0..h {
                let omega = map.texel_solid_angle(y) as f64;
                let row: f64 = (0..w)
                    .map(|x| frf_core::image::luminance(map.image().get(x, y)) as f64)
                    .sum();
                total += row * omega;
                if map.direction_of(0.0, y as f32).y < 0.0 {
                    below += row * omega;
                }
            }
            (below, total)
        })
    }

    /// What lights its floor conditions.
    pub fn floor(&self) -> FloorModel {
        self.floor
    }

    /// The map's suns (map frame, unturned, brightest first, at most [`MAX_SUNS`]), each
    /// found in what the last left ([`Sun::extract`]); found once.
    pub fn suns(&self) -> Result<&[Sun]> {
        Ok(self.less_suns()?.map_or(&[], |(s, _)| s.as_slice()))
    }

    fn less_suns(&self) -> Result<Option<&(Vec<Sun>, Samples)>> {
        if let Some(made) = self.less_suns.get() {
            return Ok(made.as_ref());
        }
        let (suns, rest) = Sun::extract_all(&self.map, MAX_SUNS)?;
        let made = rest.map(|r| (suns, Samples::new(PreparedMap::new(&r, self.floor))));
        // (Another thread may have found the same suns meanwhile.)
        Ok(self.less_suns.get_or_init(|| made).as_ref())
    }

    /// The coefficients (per condition, RGB) of `part` of the map turned by `yaw`, at each
    /// of `turntables` (radians): the samples they need made first, in one batch.
    pub fn coefficients(&self, part: Part, yaw: f32, turntables: &[f32]) -> Result<Vec<Vec<Rgb>>> {
        let brackets: Vec<(usize, usize, f32)> = turntables
            .iter()
            .map(|&t| bracket(turn_of(yaw, t)))
            .collect();
        let wanted: Vec<usize> = brackets.iter().flat_map(|&(a, b, _)| [a, b]).collect();
        self.whole.make(&self.projector, &wanted);
        let rest = match part {
            Part::Whole => None,
            Part::LessSuns => self.less_suns()?.map(|(_, s)| s),
        };
        if let Some(rest) = rest {
            rest.make(&self.projector, &wanted);
        }
        Ok(brackets
            .iter()
            .map(|&(a, b, w)| {
                let whole = lerp(self.whole.get(a), self.whole.get(b), w);
                match rest {
                    None => whole,
                    Some(rest) => {
                        let less = lerp(rest.get(a), rest.get(b), w);
                        (0..whole.len())
                            .map(|k| {
                                if self.projector.is_floor(k) {
                                    whole[k]
                                } else {
                                    less[k]
                                }
                            })
                            .collect()
                    }
                }
            })
            .collect())
    }

    /// Every sample of `part` (made first, in parallel), sample after sample, each a
    /// value per condition: what the device holds to look a view's coefficients up by its
    /// turn (`frf-render`'s light on the device). `None` for [`Part::LessSuns`] of a map
    /// without suns. Unlike [`YawTable::coefficients`], the floor conditions of
    /// [`Part::LessSuns`] are what the suns leave: the reader takes the whole map's there.
    pub fn samples(&self, part: Part) -> Result<Option<Vec<Rgb>>> {
        let samples = match part {
            Part::Whole => &self.whole,
            Part::LessSuns => match self.less_suns()? {
                Some((_, s)) => s,
                None => return Ok(None),
            },
        };
        let all: Vec<usize> = (0..SAMPLES_PER_TURN).collect();
        samples.make(&self.projector, &all);
        Ok(Some(
            all.iter().flat_map(|&i| samples.get(i).to_vec()).collect(),
        ))
    }

    /// Samples made so far (of the whole map), of [`SAMPLES_PER_TURN`].
    pub fn samples_made(&self) -> usize {
        self.whole
            .values
            .iter()
            .filter(|v| v.get().is_some())
            .count()
    }
}

/// `a + w (b − a)` per condition and channel (`a` itself at `w = 0`).
fn lerp(a: &[Rgb], b: &[Rgb], w: f32) -> Vec<Rgb> {
    if w == 0.0 {
        return a.to_vec();
    }
    a.iter()
        .zip(b)
        .map(|(a, b)| [0, 1, 2].map(|c| a[c] + w * (b[c] - a[c])))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_turn_on_a_sample_reads_it_alone_and_between_two_reads_both() {
        let n = SAMPLES_PER_TURN as f64;
        assert_eq!(bracket(0.0), (0, 0, 0.0));
        assert_eq!(bracket(1.0 + 3.0 / n), (3, 3, 0.0));
        assert_eq!(
            bracket(-1.0 / n),
            (SAMPLES_PER_TURN - 1, SAMPLES_PER_TURN - 1, 0.0)
        );
        let (a, b, w) = bracket(2.5 / n);
        assert_eq!((a, b), (2, 3));
        assert!((w - 0.5).abs() < 1e-4);
        let (a, b, _) = bracket(1.0 - 0.5 / n);
        assert_eq!((a, b), (SAMPLES_PER_TURN - 1, 0));
    }
}
