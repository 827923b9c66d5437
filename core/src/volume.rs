//! Regular grids in the subject frame: the voxels of a visual hull, and the texels of the
//! ground under the subject (the plane `y = 0`, [`crate::conventions`]). Both the product
//! (hull carving, shadow maps) and the virtual stage's truth (true occupancy, true ground
//! shadow) sample the same grids through these types, so that their values compare texel
//! for texel.

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};

/// Most voxels a grid may hold (1024³ bits is 128 MiB: far beyond any use here).
pub const MAX_VOXELS: u64 = 1 << 30;
/// Most texels per side of a ground grid.
pub const MAX_GROUND_TEXELS: u32 = 8192;

/// A box of cubic voxels: voxel `(i, j, k)` is centred at
/// `origin + (i + ½, j + ½, k + ½) · voxel_m`, `i` along `+x`, `j` along `+y`, `k` along
/// `+z`; index `(k · ny + j) · nx + i`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VoxelGrid {
    /// The box's lowest corner, metres (subject frame).
    pub origin: [f32; 3],
    /// Voxel side, metres.
    pub voxel_m: f32,
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
}

impl VoxelGrid {
    /// The grid of voxels of side `voxel_m` covering the box `min`–`max` (rounded up to
    /// whole voxels), refused when empty, non-finite or larger than [`MAX_VOXELS`].
    pub fn covering(min: Vec3, max: Vec3, voxel_m: f32) -> Result<Self> {
        let bad = |p: String| CoreError::invalid("voxel grid", p);
        if !(voxel_m.is_finite() && voxel_m > 0.0) {
            return Err(bad(format!("voxel side {voxel_m} m must be positive")));
        }
        let size = max - min;
        if !(min.is_finite() && max.is_finite()) || size.min_element() <= 0.0 {
            return Err(bad(format!("box {min} – {max} is empty or not finite")));
        }
        let dims = (size / voxel_m).ceil();
        let count = dims.x as f64 * dims.y as f64 * dims.z as f64;
        if count > MAX_VOXELS as f64 {
            return Err(bad(format!(
                "{} x {} x {} voxels of {voxel_m} m exceed {MAX_VOXELS}",
                dims.x, dims.y, dims.z
            )));
        }
        Ok(Self {
            origin: min.to_array(),
            voxel_m,
            dims: [dims.x as u32, dims.y as u32, dims.z as u32],
        })
    }

    /// Checks a grid read from a file.
    pub fn validate(&self) -> std::result::Result<(), String> {
        let count = self.dims.iter().map(|&d| d as u64).product::<u64>();
        if !(self.voxel_m.is_finite() && self.voxel_m > 0.0) {
            return Err(format!("voxel side {} is not positive", self.voxel_m));
        }
        if self.origin.iter().any(|c| !c.is_finite()) {
            return Err("grid origin is not finite".into());
        }
        if count == 0 || count > MAX_VOXELS {
            return Err(format!("{:?} voxels: 1 to {MAX_VOXELS}", self.dims));
        }
        Ok(())
    }

    /// Voxels in the grid.
    pub fn len(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }

    /// Whether the grid holds no voxel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Index of voxel `(i, j, k)`.
    pub fn index(&self, i: u32, j: u32, k: u32) -> usize {
        (k as usize * self.dims[1] as usize + j as usize) * self.dims[0] as usize + i as usize
    }

    /// `(i, j, k)` of an index.
    pub fn cell(&self, index: usize) -> [u32; 3] {
        let nx = self.dims[0] as usize;
        let ny = self.dims[1] as usize;
        [
            (index % nx) as u32,
            ((index / nx) % ny) as u32,
            (index / (nx * ny)) as u32,
        ]
    }

    /// Centre of voxel `(i, j, k)`.
    pub fn centre(&self, i: u32, j: u32, k: u32) -> Vec3 {
        Vec3::from(self.origin) + (Vec3::new(i as f32, j as f32, k as f32) + 0.5) * self.voxel_m
    }

    /// The box's highest corner.
    pub fn max_corner(&self) -> Vec3 {
        Vec3::from(self.origin)
            + Vec3::new(
                self.dims[0] as f32,
                self.dims[1] as f32,
                self.dims[2] as f32,
            ) * self.voxel_m
    }
}

/// A square patch of the ground `y = 0` centred under the subject, `texels x texels`
/// over `extent_m x extent_m` metres: texel `(i, j)` is centred at
/// `x = (i + ½) · s − extent/2`, `z = (j + ½) · s − extent/2` with `s = extent / texels`
/// (rows of the map run along `+z`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GroundGrid {
    /// Side of the patch, metres (3 in the original).
    pub extent_m: f32,
    /// Texels per side (128 in the original).
    pub texels: u32,
}

impl GroundGrid {
    /// The original's grid: 128 x 128 texels over 3 m x 3 m.
    pub const ORIGINAL: GroundGrid = GroundGrid {
        extent_m: 3.0,
        texels: 128,
    };

    /// Checks the grid: a positive finite extent and 1 to [`MAX_GROUND_TEXELS`] texels.
    pub fn validate(&self) -> std::result::Result<(), String> {
        if !(self.extent_m.is_finite() && self.extent_m > 0.0) {
            return Err(format!(
                "ground extent {} m must be positive",
                self.extent_m
            ));
        }
        if !(1..=MAX_GROUND_TEXELS).contains(&self.texels) {
            return Err(format!(
                "{} ground texels per side: 1 to {MAX_GROUND_TEXELS}",
                self.texels
            ));
        }
        Ok(())
    }

    /// Texel side, metres.
    pub fn texel_m(&self) -> f32 {
        self.extent_m / self.texels as f32
    }

    /// The ground point (y = 0) at the centre of texel `(i, j)`.
    pub fn centre(&self, i: u32, j: u32) -> Vec3 {
        let s = self.texel_m();
        let half = 0.5 * self.extent_m;
        Vec3::new(
            (i as f32 + 0.5) * s - half,
            0.0,
            (j as f32 + 0.5) * s - half,
        )
    }

    /// Continuous texel coordinates of a ground point `(x, z)`: texel centres at
    /// integers, as image pixels ([`crate::conventions`]).
    pub fn texel_of(&self, x: f32, z: f32) -> Vec2 {
        let s = self.texel_m();
        let half = 0.5 * self.extent_m;
        Vec2::new((x + half) / s - 0.5, (z + half) / s - 0.5)
    }

    /// Whether the ground point `(x, z)` lies on the patch.
    pub fn contains(&self, x: f32, z: f32) -> bool {
        let half = 0.5 * self.extent_m;
        x.abs() <= half && z.abs() <= half
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voxel_indices_and_centres_agree() {
        let g = VoxelGrid::covering(Vec3::new(-1.0, 0.0, -0.5), Vec3::new(1.0, 2.0, 0.5), 0.25)
            .unwrap();
        assert_eq!(g.dims, [8, 8, 4]);
        assert_eq!(g.len(), 256);
        for index in [0, 7, 8, 63, 64, 255] {
            let [i, j, k] = g.cell(index);
            assert_eq!(g.index(i, j, k), index);
        }
        assert_eq!(g.centre(0, 0, 0), Vec3::new(-0.875, 0.125, -0.375));
        assert_eq!(g.max_corner(), Vec3::new(1.0, 2.0, 0.5));
        let e = VoxelGrid::covering(Vec3::ZERO, Vec3::ONE, 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("voxel side 0 m"), "{e}");
        let e = VoxelGrid::covering(Vec3::ZERO, Vec3::ONE, 1e-4)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("10000 x 10000 x 10000 voxels") && e.contains("exceed"),
            "{e}"
        );
        let e = VoxelGrid::covering(Vec3::ONE, Vec3::ZERO, 0.1)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("box [1, 1, 1] – [0, 0, 0]") && e.contains("empty"),
            "{e}"
        );
    }

    #[test]
    fn ground_texels_map_to_points_and_back() {
        let g = GroundGrid::ORIGINAL;
        let p = g.centre(0, 127);
        assert!((p.x + 1.5 - 3.0 / 256.0).abs() < 1e-6 && p.y == 0.0);
        let t = g.texel_of(p.x, p.z);
        assert!((t - Vec2::new(0.0, 127.0)).length() < 1e-4);
        assert!(g.contains(1.5, -1.5) && !g.contains(1.51, 0.0));
        let e = GroundGrid {
            extent_m: 0.0,
            texels: 4,
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("ground extent 0 m"), "{e}");
        let e = GroundGrid {
            extent_m: 3.0,
            texels: 0,
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("0 ground texels"), "{e}");
    }
}
