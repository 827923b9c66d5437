//! The treadmill belt's speed, as the field records it
//! ([`crate::FieldHeader::gait_speed_mps`])
//! or, for a field that lacks it (older fields, real captures), as measured from the
//! visual hulls of its poses ([`measure`]).
//!
//! **The measure.** A foot on the belt is carried backward (`-x` of the subject frame) at
//! the belt's speed, so the hull's voxels touching the belt (centres within
//! [`BELT_BAND_M`] of `y = 0`, or the lowest layer of voxels larger than that) are the
//! planted feet, one on each side of the walker's centre line (`z < 0` the left, `z ≥ 0`
//! the right). Between two consecutive poses in which the same side has a foot down, that
//! foot's mean `x` moves back by `v Δt`; the last pose pairs with the first of the next
//! cycle. Lift-off and touch-down between two poses, a swing foot still close to the belt
//! and the hull's coarseness spoil some pairs, so the answer is the median over all
//! pairs. It refuses to guess (`None`) with fewer than [`MIN_POSES`] poses with hulls, or
//! no pair with a foot down in both, or a median that is not a positive speed.

use glam::{Vec2, Vec3};

use crate::container::{FieldFile, ReadAt};
use crate::error::Result;
use crate::hull::VoxelHull;

/// Voxels whose centres lie at most this high touch the belt, metres: a level sole rests
/// on `y = 0`, and the hull's lowest layer of 5 mm to 1.2 cm voxels is centred below it.
pub const BELT_BAND_M: f32 = 0.02;

/// The fewest poses (with hulls) a measure is made from: two give one pair, which a
/// foot landing between them spoils.
pub const MIN_POSES: usize = 3;

/// Voxels a side needs on the belt to count as a foot down (a stray voxel is not one).
const MIN_FOOT_VOXELS: usize = 3;

/// The belt's speed of `field`: the header's when recorded, else [`measure`]d from its
/// hulls; `None` when neither tells.
pub fn gait_speed_mps<R: ReadAt>(field: &FieldFile<R>) -> Result<Option<f64>> {
    match field.header().gait_speed_mps {
        Some(v) => Ok(Some(v)),
        None => measure(field),
    }
}

/// The belt's speed measured from the hulls of `field`'s poses (see the module docs).
pub fn measure<R: ReadAt>(field: &FieldFile<R>) -> Result<Option<f64>> {
    let mut hulls = Vec::new();
    for p in &field.header().poses {
        if let Some(hull) = field.hull(p.pose)? {
            hulls.push((p.time_s, hull));
        }
    }
    let poses: Vec<(f64, &VoxelHull)> = hulls.iter().map(|(t, h)| (*t, h)).collect();
    Ok(from_hulls(&poses, field.header().cycle_seconds))
}

/// The belt's speed from hulls at the instants `(time_s, hull)` (seconds into the cycle,
/// any order) of a walk repeating every `cycle_seconds` (see the module docs).
pub fn from_hulls(poses: &[(f64, &VoxelHull)], cycle_seconds: f64) -> Option<f64> {
    if poses.len() < MIN_POSES || !cycle_seconds.is_finite() || cycle_seconds <= 0.0 {
        return None;
    }
    let mut feet: Vec<(f64, [Option<f64>; 2])> =
        poses.iter().map(|&(t, h)| (t, planted_feet(h))).collect();
    feet.sort_by(|a, b| a.0.total_cmp(&b.0));
    let next_cycle = (feet[0].0 + cycle_seconds, feet[0].1);
    let mut speeds: Vec<f64> = feet
        .iter()
        .zip(feet.iter().skip(1).chain(std::iter::once(&next_cycle)))
        .filter(|(a, b)| b.0 > a.0)
        .flat_map(|(a, b)| {
            (0..2).filter_map(move |side| match (a.1[side], b.1[side]) {
                (Some(x0), Some(x1)) => Some(-(x1 - x0) / (b.0 - a.0)),
                _ => None,
            })
        })
        .collect();
    if speeds.is_empty() {
        return None;
    }
    speeds.sort_by(f64::total_cmp);
    let n = speeds.len();
    let median = if n % 2 == 1 {
        speeds[n / 2]
    } else {
        0.5 * (speeds[n / 2 - 1] + speeds[n / 2])
    };
    (median.is_finite() && median > 0.0).then_some(median)
}

/// The mean `x` of the hull's voxels on the belt on each side (left `z < 0`, right
/// `z ≥ 0`), where that side has a foot down.
fn planted_feet(hull: &VoxelHull) -> [Option<f64>; 2] {
    feet_on_belt(hull).map(|f| f.map(|p| f64::from(p.x)))
}

/// The mean `(x, z)` of the hull's voxels on the belt on each side (left `z < 0`, right
/// `z ≥ 0`), where that side has a foot down (at least [`MIN_FOOT_VOXELS`] of them).
pub fn feet_on_belt(hull: &VoxelHull) -> [Option<Vec2>; 2] {
    let grid = hull.grid();
    let band = BELT_BAND_M.max(grid.voxel_m);
    let [nx, ny, nz] = grid.dims;
    let mut sums = [(0.0f64, 0.0f64, 0usize); 2];
    for j in 0..ny {
        if grid.centre(0, j, 0).y > band {
            break;
        }
        for k in 0..nz {
            for i in 0..nx {
                if hull.at(i64::from(i), i64::from(j), i64::from(k)) {
                    let c: Vec3 = grid.centre(i, j, k);
                    let side = usize::from(c.z >= 0.0);
                    sums[side].0 += f64::from(c.x);
                    sums[side].1 += f64::from(c.z);
                    sums[side].2 += 1;
                }
            }
        }
    }
    sums.map(|(x, z, count)| {
        (count >= MIN_FOOT_VOXELS)
            .then(|| Vec2::new((x / count as f64) as f32, (z / count as f64) as f32))
    })
}

/// Where a field's walker has its feet on the belt through its cycle, as its visual
/// hulls tell it ([`feet_on_belt`] of every pose's hull): what keeps a walker's planted
/// foot in place when it turns on a path.
#[derive(Debug, Clone, PartialEq)]
pub struct FootTrack {
    /// Seconds a cycle.
    pub cycle_seconds: f64,
    /// The belt's speed, metres per second ([`gait_speed_mps`]).
    pub speed_mps: f64,
    /// `(seconds into the cycle, per side the foot's point on the belt when down)`,
    /// in time order.
    pub samples: Vec<(f64, [Option<Vec2>; 2])>,
    /// Per side, when each of its feet lands and lifts (seconds into the cycle; a step
    /// may wrap round the cycle's end): half way between the poses that see it change.
    contacts: [Vec<(f64, f64)>; 2],
}

impl FootTrack {
    /// The track of `field`'s hulls; `None` with fewer than [`MIN_POSES`] poses with
    /// hulls, or without the belt's speed.
    pub fn of<R: ReadAt>(field: &FieldFile<R>) -> Result<Option<Self>> {
        let h = field.header();
        let mut hulls = Vec::new();
        for p in &h.poses {
            if let Some(hull) = field.hull(p.pose)? {
                hulls.push((p.time_s, hull));
            }
        }
        // The belt's speed as [`gait_speed_mps`] gives it, from the hulls read once.
        let poses: Vec<(f64, &VoxelHull)> = hulls.iter().map(|(t, h)| (*t, h)).collect();
        let Some(speed_mps) = h
            .gait_speed_mps
            .or_else(|| from_hulls(&poses, h.cycle_seconds))
        else {
            return Ok(None);
        };
        let samples = poses.iter().map(|&(t, h)| (t, feet_on_belt(h))).collect();
        Ok(Self::new(samples, h.cycle_seconds, speed_mps))
    }

    /// The track of `samples` (any order) of a cycle of `cycle_seconds` on a belt of
    /// `speed_mps`; `None` with fewer than [`MIN_POSES`].
    pub fn new(
        mut samples: Vec<(f64, [Option<Vec2>; 2])>,
        cycle_seconds: f64,
        speed_mps: f64,
    ) -> Option<Self> {
        if samples.len() < MIN_POSES
            || cycle_seconds.is_nan()
            || cycle_seconds <= 0.0
            || !speed_mps.is_finite()
        {
            return None;
        }
        samples.sort_by(|a, b| a.0.total_cmp(&b.0));
        let n = samples.len();
        let contacts = [0, 1].map(|side| {
            let down = |k: usize| samples[k % n].1[side].is_some();
            let between = |k: usize| {
                let (a, b) = (samples[k % n].0, samples[(k + 1) % n].0);
                (a + 0.5 * (b - a).rem_euclid(cycle_seconds)).rem_euclid(cycle_seconds)
            };
            if (0..n).all(down) {
                return vec![(0.0, cycle_seconds)];
            }
            let mut steps = Vec::new();
            for k in 0..n {
                // A step lands between sample k (up) and k + 1 (down).
                if !down(k) && down(k + 1) {
                    let mut j = k + 1;
                    while down(j + 1) {
                        j += 1;
                    }
                    steps.push((between(k), between(j)));
                }
            }
            steps
        });
        Some(Self {
            cycle_seconds,
            speed_mps,
            samples,
            contacts,
        })
    }

    /// Seconds from `a` forward to `b` round the cycle.
    fn ahead(&self, a: f64, b: f64) -> f64 {
        (b - a).rem_euclid(self.cycle_seconds)
    }

    /// Side `side`'s foot on the belt `t` seconds into the cycle, when it is down: its
    /// step (when it landed and when it lifts) and its point, from the pose nearest in
    /// time that sees it down, carried by the belt from there.
    fn foot(&self, side: usize, t: f64) -> Option<((f64, f64), Vec2)> {
        let &(land, lift) = self.contacts[side]
            .iter()
            .find(|&&(land, lift)| self.ahead(land, t) <= self.ahead(land, lift))?;
        let nearest = (self.samples.iter())
            .filter(|s| s.1[side].is_some())
            .min_by(|a, b| {
                let d = |s: f64| self.ahead(s, t).min(self.ahead(t, s));
                d(a.0).total_cmp(&d(b.0))
            })?;
        let p = nearest.1[side]?;
        // Seconds from the sample to t, the short way round the cycle.
        let mut dt = self.ahead(nearest.0, t);
        if dt > 0.5 * self.cycle_seconds {
            dt -= self.cycle_seconds;
        }
        Some((
            (land, lift),
            p - Vec2::new((self.speed_mps * dt) as f32, 0.0),
        ))
    }

    /// The point on the belt the walker stands on `t` seconds into its cycle (subject
    /// frame, `(x, z)`), and whether both feet are down: its foot that is down; while both
    /// are, the mean of the two; `None` in the air.
    pub fn stance(&self, t: f64) -> Option<(Vec2, bool)> {
        let t = t.rem_euclid(self.cycle_seconds);
        match [self.foot(0, t), self.foot(1, t)] {
            [Some((_, p)), None] | [None, Some((_, p))] => Some((p, false)),
            [Some(a), Some(b)] => Some((0.5 * (a.1 + b.1), true)),
            [None, None] => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use frf_core::volume::VoxelGrid;

    /// A hull holding two boxes on the belt (feet) at `x_left` and `x_right` (`None`: that
    /// foot lifted 10 cm).
    fn feet(x_left: Option<f32>, x_right: Option<f32>) -> VoxelHull {
        let grid = VoxelGrid::covering(Vec3::new(-1.0, 0.0, -0.3), Vec3::new(1.0, 0.3, 0.3), 0.01)
            .expect("a valid grid");
        VoxelHull::from_fn(grid, |p| {
            let foot = |x: Option<f32>, z: f32| {
                let (x, lift) = x.map_or((0.0, 0.1), |x| (x, 0.0));
                (p.x - x).abs() < 0.12 && (p.z - z).abs() < 0.05 && p.y > lift && p.y < lift + 0.09
            };
            foot(x_left, -0.1) || foot(x_right, 0.1)
        })
    }

    #[test]
    fn a_foot_carried_by_the_belt_tells_its_speed() {
        let v = 1.2;
        // Left down from 0 to 0.5 s, right from 0.4 s to 0.9 s (it lands 0.3 m ahead).
        let x = |t: f64, t0: f64| Some((0.3 - v * (t - t0)) as f32);
        let hulls: Vec<(f64, VoxelHull)> = (0..10)
            .map(|k| {
                let t = k as f64 / 10.0;
                let left = (t <= 0.5).then(|| x(t, 0.0)).flatten();
                let right = (0.4..=0.9).contains(&t).then(|| x(t, 0.4)).flatten();
                (t, feet(left, right))
            })
            .collect();
        let poses: Vec<(f64, &VoxelHull)> = hulls.iter().map(|(t, h)| (*t, h)).collect();
        let measured = from_hulls(&poses, 1.0).expect("a measure");
        assert!((measured - v).abs() < 0.05 * v, "{measured}");
        // The track: the foot down at each instant, carried by the belt between poses;
        // both down where the steps overlap (0.4 to 0.5 s, seen at 0.4 and 0.5).
        let samples = hulls.iter().map(|(t, h)| (*t, feet_on_belt(h))).collect();
        let track = FootTrack::new(samples, 1.0, v).expect("a track");
        let (p, both) = track.stance(0.12).expect("the left foot is down");
        assert!(
            !both && (p.x - (0.3 - v * 0.12) as f32).abs() < 0.02 && p.y < 0.0,
            "{p}"
        );
        let (p, both) = track.stance(0.72).expect("the right foot is down");
        assert!(
            !both && (p.x - (0.3 - v * 0.32) as f32).abs() < 0.02 && p.y > 0.0,
            "{p}"
        );
        assert!(track.stance(0.47).expect("both").1);
        // Too few poses, or no foot ever down: no guess.
        assert_eq!(from_hulls(&poses[..2], 1.0), None);
        let up = feet(None, None);
        assert_eq!(from_hulls(&[(0.0, &up), (0.1, &up), (0.2, &up)], 1.0), None);
    }
}
