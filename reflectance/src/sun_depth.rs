//! A sun's view of a pose's visual hull (docs/design.md section 4.1): over a grid across
//! the sun's direction `d`, how far toward the sun the hull reaches along each line
//! parallel to `d` (the largest `d · p` of its occupied points there). A point `p` has
//! hull between it and the sun exactly when the hull reaches past it along its line,
//! `reach(p) > d · p`: one lookup, where tracing a ray from every texel of every view
//! toward the sun took one walk through the hull each (the shadow map of real-time
//! rendering, made by one ray per texel of the map from the sun's side).
//!
//! The map's texel is [`TEXEL_PER_VOXEL`] of the hull's voxel (1 cm at 5 mm voxels), so a
//! point's line is within half a texel of the one traced for it; for views read at a level
//! of detail it is as much wider as their texels are (twice a level), which leaves a map
//! texel about a view's texel and takes a quarter of the walks a level. The map's frame is set
//! on the host; its values are traced on the host when the CPU reference first reads them
//! ([`SunDepth::reach`]), and on the GPU by `shaders/sun_depth.wgsl`, the same walk through
//! the hull (`shaders/rebin/proxy.wgsl`), where the relight pass reads them: a turning
//! sun costs the host no walk.
//!
//! **Other walkers in the way** ([`Occluder`]): a walker near another may stand between it
//! and the sun. Its hull, placed where it stands in this walker's frame, is walked along
//! the same lines and raises their reach where it lies farther toward the sun
//! ([`SunDepth::with_occluders`]): the map's texels stay this walker's (only its own points
//! are looked up), and their lines start beyond both hulls.

use std::sync::{Arc, OnceLock};

use frf_core::camera::Rigid;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::hull::VoxelHull;

/// Another walker's hull in the way of a walker's suns: the hull, and where it stands in
/// the walker's frame.
#[derive(Debug, Clone)]
pub struct Occluder {
    /// Its visual hull (in its own subject frame).
    pub hull: Arc<VoxelHull>,
    /// Its subject frame into the walker's.
    pub here_from_there: Rigid,
}

/// The map's texel side in voxels of the hull. Measured at the captured views of the
/// small oracle field (5 mm voxels; subject PSNR under the built-in sky / `grace`, and the
/// host's time to find `grace`'s four suns and make their maps): 1 voxel 34.48 / 32.71 dB,
/// 44 ms; 2 voxels 34.59 / 32.67 dB, 13 ms; 4 voxels 34.07 / 32.71 dB. A ray from every
/// texel of every view gave 34.35 / 32.73 dB.
pub const TEXEL_PER_VOXEL: f32 = 2.0;

/// How far the hull reaches toward a sun (see the module text): the map's frame, and its
/// values made when first read on the host ([`SunDepth::reach`]; the GPU makes its own
/// from the frame, `shaders/sun_depth.wgsl`).
#[derive(Debug, Clone)]
pub struct SunDepth {
    /// Unit, toward the sun (subject frame).
    pub toward: Vec3,
    /// Unit vectors across the sun: the map's x and y axes.
    pub axes: [Vec3; 2],
    /// `(axes[0] · p, axes[1] · p)` of texel (0, 0)'s lowest corner.
    pub corner: Vec2,
    /// Texel side, metres.
    pub texel: f32,
    /// Texels along x and y.
    pub size: [u32; 2],
    /// `toward · p` where each texel's ray starts, a texel beyond the hull's box (and its
    /// occluders') on the sun's side.
    pub far: f32,
    hull: Arc<VoxelHull>,
    /// Other walkers' hulls in the way ([`SunDepth::with_occluders`]).
    pub occluders: Vec<Occluder>,
    reach: OnceLock<Vec<f32>>,
}

impl SunDepth {
    /// The map of `hull` seen from the direction `toward` (any length but zero), for
    /// views read at level of detail `level`: its texel [`TEXEL_PER_VOXEL`] voxels at
    /// full detail, twice as wide a level (a texel of the map about a texel of the views,
    /// whose points it is looked up for: a quarter of the walks a level).
    pub fn new(hull: &Arc<VoxelHull>, toward: Vec3, level: u8) -> Self {
        let d = toward.normalize_or(Vec3::Y);
        let (x, y) = d.any_orthonormal_pair();
        let g = hull.grid();
        let texel = g.voxel_m * TEXEL_PER_VOXEL * (1u32 << level.min(8)) as f32;
        let (min, max, far, _) = projected_box(hull, [x, y, d], &Rigid::IDENTITY);
        // Rays start a texel beyond the box on the sun's side.
        let far = far + texel;
        let size = ((max - min) / texel).ceil().max(Vec2::ONE);
        Self {
            toward: d,
            axes: [x, y],
            corner: min,
            texel,
            size: [size.x as u32, size.y as u32],
            far,
            hull: hull.clone(),
            occluders: Vec::new(),
            reach: OnceLock::new(),
        }
    }

    /// The same map with `occluders` in the way too: those whose hull's box, seen along
    /// the sun, overlaps the map and reaches farther toward the sun than this hull's
    /// lowest point (the others cannot shade it) are kept, and the lines start beyond
    /// them.
    pub fn with_occluders(mut self, occluders: &[Occluder]) -> Self {
        let [x, y] = self.axes;
        let d = self.toward;
        let (map_lo, map_hi) = (
            self.corner,
            self.corner + Vec2::new(self.size[0] as f32, self.size[1] as f32) * self.texel,
        );
        let own_low = projected_box(&self.hull, [x, y, d], &Rigid::IDENTITY).3;
        for o in occluders {
            let (lo, hi, far, _) = projected_box(&o.hull, [x, y, d], &o.here_from_there);
            let overlaps = lo.x < map_hi.x && hi.x > map_lo.x && lo.y < map_hi.y && hi.y > map_lo.y;
            if overlaps && far > own_low {
                self.far = self.far.max(far + self.texel);
                self.occluders.push(o.clone());
            }
        }
        self
    }

    /// The most texels a map of `hull` can have, whatever the sun's direction: the box's
    /// diagonal across, a texel more, on each axis.
    pub fn most_texels(hull: &VoxelHull) -> usize {
        let g = hull.grid();
        let diagonal = (g.max_corner() - Vec3::from(g.origin)).length();
        let side = (diagonal / (g.voxel_m * TEXEL_PER_VOXEL)).ceil() as usize + 1;
        side * side
    }

    /// Its texels.
    pub fn texels(&self) -> usize {
        self.size[0] as usize * self.size[1] as usize
    }

    /// Per texel (x fastest): the largest `toward · p` of the hull along its centre's
    /// line, `f32::MIN` where the line misses the hull; made on the first call.
    pub fn reach(&self) -> &[f32] {
        if let Some(made) = self.reach.get() {
            return made;
        }
        // Made outside the lock's initialisation: a parallel loop inside `get_or_init` can
        // deadlock, when a thread waiting in it steals work that asks for the same map.
        // Two threads that both make it make the same values.
        let made = {
            let [x, y] = self.axes;
            let w = self.size[0] as usize;
            (0..self.texels())
                .into_par_iter()
                .map(|i| {
                    let q = self.corner
                        + (Vec2::new((i % w) as f32, (i / w) as f32) + 0.5) * self.texel;
                    let origin = x * q.x + y * q.y + self.toward * self.far;
                    let own = self
                        .hull
                        .first_hit(origin, -self.toward)
                        .map_or(f32::MIN, |t| self.far - t);
                    self.occluders.iter().fold(own, |reach, o| {
                        let there = o.here_from_there.inverse();
                        let dir = there.rotation * -self.toward;
                        match o.hull.first_hit(there.transform_point(origin), dir) {
                            Some(t) => reach.max(self.far - t),
                            None => reach,
                        }
                    })
                })
                .collect()
        };
        self.reach.get_or_init(|| made)
    }

    /// Whether the hull lies between `p` and the sun: it reaches past `p` along the line
    /// of `p`'s texel (a point beside the map has none).
    pub fn shades(&self, p: Vec3) -> bool {
        let q = (Vec2::new(self.axes[0].dot(p), self.axes[1].dot(p)) - self.corner) / self.texel;
        let (i, j) = (q.x.floor(), q.y.floor());
        if !(i >= 0.0 && j >= 0.0 && i < self.size[0] as f32 && j < self.size[1] as f32) {
            return false;
        }
        self.reach()[j as usize * self.size[0] as usize + i as usize] > self.toward.dot(p)
    }
}

/// The hull's box, moved by `place`, seen along `axes` (`[x, y, toward]`): the least and
/// most of its corners' `(x · p, y · p)`, and the most and least of their `toward · p`.
fn projected_box(hull: &VoxelHull, [x, y, d]: [Vec3; 3], place: &Rigid) -> (Vec2, Vec2, f32, f32) {
    let g = hull.grid();
    let (lo, hi) = (Vec3::from(g.origin), g.max_corner());
    let (mut min, mut max) = (Vec2::INFINITY, Vec2::NEG_INFINITY);
    let (mut far, mut near) = (f32::NEG_INFINITY, f32::INFINITY);
    for c in 0..8 {
        let p = place.transform_point(Vec3::new(
            if c & 1 == 0 { lo.x } else { hi.x },
            if c & 2 == 0 { lo.y } else { hi.y },
            if c & 4 == 0 { lo.z } else { hi.z },
        ));
        let q = Vec2::new(x.dot(p), y.dot(p));
        min = min.min(q);
        max = max.max(q);
        far = far.max(d.dot(p));
        near = near.min(d.dot(p));
    }
    (min, max, far, near)
}

#[cfg(test)]
mod tests {
    use super::*;
    use frf_core::volume::VoxelGrid;

    #[test]
    fn another_hull_toward_the_sun_shades_and_one_away_does_not() {
        let own = ball(Vec3::new(0.0, 1.0, 0.0), 0.3, 0.02);
        let other = ball(Vec3::new(0.0, 1.0, 0.0), 0.3, 0.02);
        // A sun low in +x; the other walker 1.5 m toward it, and another 1.5 m away.
        let toward = Vec3::new(1.0, 0.1, 0.0);
        let at = |x: f32| Occluder {
            hull: other.clone(),
            here_from_there: Rigid {
                rotation: glam::Mat3::from_rotation_y(0.7),
                translation: Vec3::new(x, 0.0, 0.0),
            },
        };
        let map = SunDepth::new(&own, toward, 0).with_occluders(&[at(1.5), at(-1.5)]);
        assert_eq!(map.occluders.len(), 1, "the one behind cannot shade");
        // The ball's side facing the sun is now in the other's shadow; without it, lit.
        let facing = Vec3::new(0.0, 1.0, 0.0) + toward.normalize() * 0.32;
        assert!(map.shades(facing));
        assert!(!SunDepth::new(&own, toward, 0).shades(facing));
        // Its top sees over the other: still lit.
        assert!(!map.shades(Vec3::new(0.0, 1.31, 0.0)));
    }

    /// A ball of radius `r` about `c`, voxels of side `s`.
    fn ball(c: Vec3, r: f32, s: f32) -> Arc<VoxelHull> {
        let grid = VoxelGrid::covering(c - Vec3::splat(r + s), c + Vec3::splat(r + s), s).unwrap();
        Arc::new(VoxelHull::from_fn(grid, |p| p.distance(c) <= r))
    }

    #[test]
    fn the_map_shades_as_the_hull_blocks_a_ray_toward_the_sun() {
        let hull = ball(Vec3::new(0.0, 1.0, 0.0), 0.3, 0.02);
        for toward in [
            Vec3::Y,
            Vec3::new(1.0, 1.0, 0.3),
            Vec3::new(-0.2, 0.4, -1.0),
        ] {
            let map = SunDepth::new(&hull, toward, 0);
            let d = toward.normalize();
            let (mut agree, mut total) = (0, 0);
            // Points on a grid through and around the ball.
            for i in -12..=12 {
                for j in -12..=12 {
                    for k in -12..=12 {
                        let p = Vec3::new(i as f32, j as f32 + 20.0, k as f32) * 0.05 + 0.013;
                        total += 1;
                        agree += usize::from(map.shades(p) == hull.blocks(p, d));
                    }
                }
            }
            // Lines within half a texel (a voxel) of the point's disagree only at the rim.
            assert!(
                agree as f32 >= 0.985 * total as f32,
                "{toward}: {agree} of {total}"
            );
            // Under the ball, shaded; beside it and above it, not.
            let c = Vec3::new(0.0, 1.0, 0.0);
            assert!(map.shades(c - d * 0.5));
            assert!(!map.shades(c + d * 0.5));
            assert!(!map.shades(c + d.any_orthonormal_vector() * 0.5));
        }
    }
}
