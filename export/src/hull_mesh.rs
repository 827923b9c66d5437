//! A pose's visual hull as a triangle mesh for any glTF viewer: the hull resampled at
//! a coarser voxel (a voxel occupied where the fine hull holds its centre), its surface
//! quads split in two.

use frf_core::volume::VoxelGrid;
use frf_reflectance::hull::VoxelHull;
use glam::Vec3;

use crate::error::{ExportError, Result};

/// A triangle mesh: positions (metres, subject frame) and triangle indices.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    /// Vertices.
    pub positions: Vec<[f32; 3]>,
    /// Three per triangle, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
}

/// The surface of `hull` resampled at `voxel_m` (never finer than its own voxel).
pub fn hull_mesh(hull: &VoxelHull, voxel_m: f32) -> Result<Mesh> {
    let g = hull.grid();
    let voxel_m = voxel_m.max(g.voxel_m);
    let lo = Vec3::from(g.origin);
    let grid = VoxelGrid::covering(lo, g.max_corner(), voxel_m)
        .map_err(|e| ExportError::Field(format!("the hull's grid: {e}")))?;
    let coarse = VoxelHull::from_fn(grid, |p| {
        let c = ((p - lo) / g.voxel_m).floor();
        hull.at(c.x as i64, c.y as i64, c.z as i64)
    });
    let (vertices, quads) = coarse.surface();
    let indices = quads
        .iter()
        .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
        .collect();
    Ok(Mesh {
        positions: vertices.iter().map(|v| v.to_array()).collect(),
        indices,
    })
}
