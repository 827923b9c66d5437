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

/// The surface of `hull` (pose `pose`'s) resampled at `voxel_m` (never finer than its
/// own voxel); refused where the hull fills no voxel of that side: an empty mesh is no
/// valid glTF (its accessors would count nothing).
pub fn hull_mesh(hull: &VoxelHull, voxel_m: f32, pose: u32) -> Result<Mesh> {
    let mesh = resampled_surface(hull, voxel_m)?;
    if mesh.indices.is_empty() {
        return Err(ExportError::Option(format!(
            "--mesh-voxel {voxel_m}: pose {pose}'s hull fills no voxel of that side, so \
             its mesh would be empty: a smaller side (the default is 0.02)"
        )));
    }
    Ok(mesh)
}

/// The surface of `hull` resampled at `voxel_m`, empty where no coarse voxel's centre
/// lies in the hull.
fn resampled_surface(hull: &VoxelHull, voxel_m: f32) -> Result<Mesh> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A hull of a 10 cm block in the middle of a metre's grid: at 2 cm a closed mesh;
    /// at 50 cm no coarse voxel's centre lies in it, and the mesh is refused by name
    /// (it was written as an invalid .glb with no note).
    #[test]
    fn a_voxel_the_hull_fills_none_of_is_refused() {
        let grid = VoxelGrid::covering(Vec3::ZERO, Vec3::ONE, 0.02).unwrap();
        let hull = VoxelHull::from_fn(grid, |p| (p - Vec3::splat(0.5)).abs().max_element() < 0.05);
        let fine = hull_mesh(&hull, 0.02, 3).unwrap();
        assert!(fine.indices.len() >= 36, "{} indices", fine.indices.len());
        let e = hull_mesh(&hull, 0.5, 3).unwrap_err().to_string();
        assert!(
            e.contains("--mesh-voxel 0.5") && e.contains("pose 3"),
            "{e}"
        );
    }
}
