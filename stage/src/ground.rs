//! The truth behind the visual hull and the shadows: which points of space the walker
//! fills, and how much of the light reaching the ground `y = 0` it blocks. Both are of
//! the unperturbed walker at a pose's reference instant, in the subject frame, as
//! [`crate::Stage::truth_image`] shows it; [`relative_irradiance_among`] takes several
//! actors (a crowd, [`crate::crowd`]).
//!
//! **Relative irradiance** at a ground point `x` under distant lights `l` (direction
//! `d_l`, irradiance at normal incidence `E_l`, RGB): the irradiance with the walker over
//! that without it, per channel,
//! `S(x) = Σ_l E_l max(0, d_l·y) V_l(x) / Σ_l E_l max(0, d_l·y)`, with `V_l(x)` 1 when the
//! ray from `x` toward `d_l` misses the walker. 1 means unshadowed; where no light comes
//! from above (the sum is 0) it is 1 by definition (no light, no shadow).

use frf_core::image::{Image, Rgb, RgbImage};
use frf_core::light::DirLight;
use frf_core::volume::{GroundGrid, VoxelGrid};
use glam::Vec3;
use rayon::prelude::*;

use crate::actor::Actor;
use crate::geometry::Ray;
use crate::stage::Stage;

/// Rays toward the lights start this far above the ground (metres), so that a foot
/// resting on it still shadows the point under it but the ground never shadows itself.
const GROUND_OFFSET_M: f32 = 1e-4;

/// The relative irradiance at ground point `point` under `lights`, with `actor` in the
/// way (see the module docs).
pub fn relative_irradiance(actor: &Actor, lights: &[DirLight], point: Vec3) -> Rgb {
    relative_irradiance_among(std::slice::from_ref(actor), lights, point)
}

/// The relative irradiance at ground point `point` under `lights`, with every actor of
/// `actors` in the way: a light counts only where no actor blocks it (see the module
/// docs; `V_l(x)` is 1 when the ray misses them all).
pub fn relative_irradiance_among(actors: &[Actor], lights: &[DirLight], point: Vec3) -> Rgb {
    let origin = Vec3::new(point.x, point.y + GROUND_OFFSET_M, point.z);
    let (mut lit, mut all) = ([0.0f64; 3], [0.0f64; 3]);
    for l in lights {
        let cos = l.direction.y;
        if cos <= 0.0 {
            continue;
        }
        let ray = Ray {
            origin,
            dir: l.direction,
        };
        let visible = !actors.iter().any(|a| a.occludes(&ray, 0.0, f32::INFINITY));
        for c in 0..3 {
            let e = (l.irradiance[c] * cos) as f64;
            all[c] += e;
            if visible {
                lit[c] += e;
            }
        }
    }
    [0, 1, 2].map(|c| {
        if all[c] > 0.0 {
            (lit[c] / all[c]) as f32
        } else {
            1.0
        }
    })
}

impl Stage {
    /// The unperturbed walker at pose `pose`'s reference instant, subject frame.
    pub fn true_actor(&self, pose: u32) -> Actor {
        self.actor(None, self.pose_time_s(pose))
    }

    /// The unperturbed walker `time_s` seconds into its cycle, subject frame.
    pub fn true_actor_at(&self, time_s: f64) -> Actor {
        self.actor(None, time_s)
    }

    /// Which voxels of `grid` the walker of pose `pose` fills (voxel centre inside).
    pub fn true_occupancy(&self, pose: u32, grid: &VoxelGrid) -> Vec<bool> {
        let actor = self.true_actor(pose);
        (0..grid.len())
            .into_par_iter()
            .map(|index| {
                let [i, j, k] = grid.cell(index);
                actor.contains(grid.centre(i, j, k))
            })
            .collect()
    }

    /// The relative irradiance at the centre of every texel of `ground` under `lights`
    /// (subject frame) with the walker of pose `pose` in the way; rows run along `+z`.
    pub fn true_ground_shadow(
        &self,
        pose: u32,
        lights: &[DirLight],
        ground: &GroundGrid,
    ) -> RgbImage {
        let actor = self.true_actor(pose);
        let n = ground.texels as usize;
        let pixels: Vec<Rgb> = (0..n * n)
            .into_par_iter()
            .map(|t| {
                let (i, j) = ((t % n) as u32, (t / n) as u32);
                relative_irradiance(&actor, lights, ground.centre(i, j))
            })
            .collect();
        Image::from_vec(n, n, pixels).expect("n * n texels")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Preset, StageConfig};

    #[test]
    fn the_walker_fills_its_torso_and_stands_on_the_ground() {
        let stage = Stage::new(StageConfig::preset(Preset::Tiny)).unwrap();
        let actor = stage.true_actor(0);
        let b = actor.bounds();
        // The bounding box holds the whole body: a point well above it is empty.
        assert!(!actor.contains(Vec3::new(0.0, 2.5, 0.0)));
        // Somewhere at chest height on the axis the body is solid.
        assert!((0..20).any(|k| actor.contains(Vec3::new(0.02 * k as f32 - 0.2, 1.3, 0.0))));
        // The lower foot touches the ground: occupied voxels reach y < 2 cm.
        let grid = VoxelGrid::covering(b.min, b.max, 0.02).unwrap();
        let occ = stage.true_occupancy(0, &grid);
        let lowest = occ
            .iter()
            .enumerate()
            .filter(|(_, o)| **o)
            .map(|(i, _)| {
                grid.centre(grid.cell(i)[0], grid.cell(i)[1], grid.cell(i)[2])
                    .y
            })
            .fold(f32::INFINITY, f32::min);
        assert!(lowest < 0.02, "lowest occupied voxel centre at {lowest} m");
    }

    #[test]
    fn a_sun_overhead_shadows_the_ground_under_the_walker_only() {
        let stage = Stage::new(StageConfig::preset(Preset::Tiny)).unwrap();
        let sun = [DirLight {
            direction: Vec3::Y,
            irradiance: [3.0, 2.0, 1.0],
        }];
        let ground = GroundGrid {
            extent_m: 3.0,
            texels: 32,
        };
        let s = stage.true_ground_shadow(0, &sun, &ground);
        // The corner is far from the walker: lit. Some texel near the feet is dark.
        assert_eq!(s.get(0, 0), [1.0; 3]);
        assert!(s.pixels().iter().any(|p| p[0] == 0.0));
        // A light at the horizon or below adds nothing: all ones.
        let horizon = [DirLight {
            direction: Vec3::X,
            irradiance: [1.0; 3],
        }];
        let s = stage.true_ground_shadow(0, &horizon, &ground);
        assert!(s.pixels().iter().all(|p| *p == [1.0; 3]));
    }
}
