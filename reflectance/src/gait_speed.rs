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

use glam::Vec3;

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
    let grid = hull.grid();
    let band = BELT_BAND_M.max(grid.voxel_m);
    let [nx, ny, nz] = grid.dims;
    let mut sums = [(0.0f64, 0usize); 2];
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
                    sums[side].1 += 1;
                }
            }
        }
    }
    sums.map(|(sum, count)| (count >= MIN_FOOT_VOXELS).then(|| sum / count as f64))
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
        // Too few poses, or no foot ever down: no guess.
        assert_eq!(from_hulls(&poses[..2], 1.0), None);
        let up = feet(None, None);
        assert_eq!(from_hulls(&[(0.0, &up), (0.1, &up), (0.2, &up)], 1.0), None);
    }
}
