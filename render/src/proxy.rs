//! The geometric proxy of a pose (docs/design.md section 4.3): where a ray that leaves the
//! grid's rows meets the subject, so that it can be looked up in the row it is clamped to.
//!
//! Inside the grid the camera interpolated at the ray's hit on the cylinder lies on the
//! ray, and the ray's direction alone says where it passes through that camera's image.
//! Above the top row or below the bottom one, the ray is clamped to the row: the row's
//! camera no longer lies on the ray, and reading its image along the ray's direction (as
//! if the camera had been carried up the wall to the ray) tears the image at the row's
//! edge (the head shifted against the body, for a camera inside the cylinder looking
//! up). Instead the point where the ray meets the subject is found on the proxy and
//! projected into the row's camera. At the row's edge the camera is on the ray again and
//! both readings agree, so the image continues without a seam; beyond it, the lookup is
//! right to the accuracy of the proxy.
//!
//! - **The visual hull**: the ray's first occupied voxel in front of the virtual camera
//!   ([`VoxelHull::first_hit`]; the hull contains the subject, so its surface is at most
//!   a voxel or two in front of it).
//! - **Beside the hull**: the point of the ray nearest the vertical axis through the
//!   hull's box, in front of the camera; such rays see little of the subject, and the
//!   point keeps their lookup near the subject's depth (read along their direction, the
//!   row's image would show a displaced copy of the subject there).
//! - **Without a hull** (a ring of photographs, a field ingested without shadows) there
//!   is no proxy, and clamped rays are read along their direction as before: a guessed
//!   depth does worse than none (measured on dinoRing, one row: 20.2 against 23.9 dB).
//!
//! `proxy_point` in `shaders/rebin.wgsl` is the GPU twin.
//!
//! **Depth.** Where walkers overlap in a frame, each pixel puts them over each other by
//! their depth there ([`Proxy::depth`]): the distance along the pixel's ray to the hull's
//! first voxel; where the ray misses the hull (or there is none), [`MISS_DEPTH_M`] plus
//! the distance to the ray's point nearest the subject's vertical axis, so that a walker
//! whose hull the ray meets goes in front of one whose hull it misses (that one shows
//! little there: an edge, a limb the hull of its pose does not hold). Distances are kept
//! by the rigid move from the world into a walker's subject frame, so every walker's are
//! comparable. A walker between two poses takes the nearer of its two poses' depths
//! (the union of their hulls holds a limb on its way from one to the other). Measured on
//! `scenes/crossing.toml` (the small oracle field of every third pose, every frame, the
//! pixels whose ray meets two true bodies): the truly nearest body put in front at 95.3 %
//! by position, 95.2 % by the depth of the first pose's hull with its misses at their
//! fallback distance, 91.3 % with misses put behind, 97.1 % with misses behind and the
//! two poses' depths. `subject_depth` in `shaders/rebin/proxy.wgsl` is its twin.

use std::sync::Arc;

use bytemuck::Zeroable;
use frf_reflectance::hull::{BLOCK, VoxelHull};
use glam::{Vec2, Vec3};

use frf_shaders::types::GpuProxy;

/// Below this squared horizontal length a ray is treated as vertical: it has no nearest
/// point to a vertical axis.
const VERTICAL_EPS: f32 = 1e-8;

/// What a ray that misses a walker's hull adds to its depth there, metres: farther than
/// any walker of a frame, so that walkers whose hull the ray meets go in front (see the
/// module docs).
pub const MISS_DEPTH_M: f32 = 1e4;

/// A pose's geometric proxy (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct Proxy {
    hull: Option<Arc<VoxelHull>>,
    /// `(x, z)` of the vertical axis of the fallback.
    axis: Vec2,
}

impl Proxy {
    /// The proxy of a pose with `hull` (none: no proxy).
    pub fn new(hull: Option<VoxelHull>) -> Self {
        Self::shared(hull.map(Arc::new))
    }

    /// [`Proxy::new`] of a hull held elsewhere too.
    pub fn shared(hull: Option<Arc<VoxelHull>>) -> Self {
        let axis = hull
            .as_ref()
            .and_then(|h| h.bounds())
            .map_or(Vec2::ZERO, |(lo, hi)| {
                let c = 0.5 * (lo + hi);
                Vec2::new(c.x, c.z)
            });
        Self { hull, axis }
    }

    /// The visual hull, if there is one.
    pub fn hull(&self) -> Option<&VoxelHull> {
        self.hull.as_deref()
    }

    /// The hull, to keep (a sun's map of it, [`frf_reflectance::sun_depth::SunDepth`]).
    pub fn hull_shared(&self) -> Option<&Arc<VoxelHull>> {
        self.hull.as_ref()
    }

    /// `(x, z)` of the fallback's vertical axis.
    pub fn axis(&self) -> Vec2 {
        self.axis
    }

    /// The proxy as the GPU reads it: its description and the hull's occupancy words
    /// (one empty word without a hull: a binding is never empty).
    pub fn gpu(&self) -> (GpuProxy, Vec<u32>) {
        let words = self.hull.as_deref().map_or_else(|| vec![0], |h| h.words());
        (self.gpu_info(), words)
    }

    /// [`Proxy::gpu`]'s description alone (the hull's words are not copied).
    pub fn gpu_info(&self) -> GpuProxy {
        let info = match self.hull.as_deref() {
            Some(h) => {
                let g = h.grid();
                GpuProxy {
                    origin: g.origin,
                    voxel: g.voxel_m,
                    dims: g.dims,
                    present: 1,
                    block_words_at: h.block_words_at() as u32,
                    block: BLOCK as u32,
                    ..Zeroable::zeroed()
                }
            }
            None => GpuProxy::zeroed(),
        };
        GpuProxy {
            axis: self.axis.to_array(),
            ..info
        }
    }

    /// Bytes the proxy holds where it is rendered.
    pub fn resident_bytes(&self) -> u64 {
        let words = self.hull.as_deref().map_or(1, |h| h.word_count().max(1));
        (4 * words + std::mem::size_of::<GpuProxy>()) as u64
    }

    /// Where the ray `origin + t dir` (`t ≥ 0`) meets the subject, as far as the proxy
    /// knows: its first hull voxel, else its point nearest the hull's axis; `None`
    /// without a hull, and for a vertical ray that misses it.
    pub fn point(&self, origin: Vec3, dir: Vec3) -> Option<Vec3> {
        let hull = self.hull.as_ref()?;
        // Walked along the unit direction, as the depth is (the GPU walks the ray once
        // for both).
        let dir = dir.normalize_or_zero();
        if let Some(t) = hull.first_hit(origin, dir) {
            return Some(origin + dir * t);
        }
        let o = Vec2::new(origin.x, origin.z) - self.axis;
        let d = Vec2::new(dir.x, dir.z);
        let dd = d.length_squared();
        if dd < VERTICAL_EPS {
            return None;
        }
        let t = (-o.dot(d) / dd).max(0.0);
        Some(origin + dir * t)
    }
}

impl Proxy {
    /// The depth of the subject along the ray from `origin` in direction `dir` (any
    /// length), metres: see the module docs.
    pub fn depth(&self, origin: Vec3, dir: Vec3) -> f32 {
        let dir = dir.normalize_or_zero();
        if let Some(t) = self.hull.as_ref().and_then(|h| h.first_hit(origin, dir)) {
            return t;
        }
        let o = Vec2::new(origin.x, origin.z) - self.axis;
        let d = Vec2::new(dir.x, dir.z);
        let dd = d.length_squared();
        if dd < VERTICAL_EPS {
            return MISS_DEPTH_M + o.length();
        }
        MISS_DEPTH_M + (-o.dot(d) / dd).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use frf_core::volume::VoxelGrid;

    #[test]
    fn depth_is_the_distance_to_the_proxy_or_to_the_axis() {
        let grid =
            VoxelGrid::covering(Vec3::new(-0.2, 0.0, -0.2), Vec3::new(0.2, 2.0, 0.2), 0.1).unwrap();
        let p = Proxy::new(Some(VoxelHull::full(grid)));
        // Straight at the box from 3 m: its face at 0.2 m from the axis.
        let d = p.depth(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 0.0, -2.0));
        assert!((d - 2.8).abs() < 1e-4, "{d}");
        // Beside the box: behind every walker whose hull a ray meets, in order of the
        // nearest point to the axis.
        let d = p.depth(Vec3::new(0.0, 2.5, 3.0), Vec3::new(0.0, 0.0, -1.0));
        assert!((d - (MISS_DEPTH_M + 3.0)).abs() < 1e-2, "{d}");
        // No hull: the nearest point to the axis, along a unit ray.
        let none = Proxy::new(None);
        let d = none.depth(Vec3::new(0.0, 1.0, 3.0), Vec3::new(1.0, 0.0, -1.0));
        assert!((d - MISS_DEPTH_M - 3.0 / 2f32.sqrt()).abs() < 1e-2, "{d}");
        // A vertical ray: its horizontal distance to the axis.
        let d = none.depth(Vec3::new(3.0, 5.0, 4.0), Vec3::NEG_Y);
        assert!((d - MISS_DEPTH_M - 5.0).abs() < 1e-2);
    }

    #[test]
    fn without_a_hull_there_is_no_point() {
        let p = Proxy::new(None);
        assert!(p.point(Vec3::new(0.0, 1.0, 3.0), Vec3::NEG_Z).is_none());
    }

    #[test]
    fn beside_a_hull_the_point_is_nearest_its_axis_and_in_front() {
        let grid =
            VoxelGrid::covering(Vec3::new(-0.1, 0.0, -0.1), Vec3::new(0.1, 0.2, 0.1), 0.1).unwrap();
        let p = Proxy::new(Some(VoxelHull::full(grid)));
        let q = p
            .point(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 0.6, -0.8))
            .unwrap();
        assert!((q - Vec3::new(0.0, 3.25, 0.0)).length() < 1e-5, "{q}");
        // Looking away from the axis: the camera's own position.
        let q = p
            .point(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 0.0, 1.0))
            .unwrap();
        assert_eq!(q, Vec3::new(0.0, 1.0, 3.0));
        assert!(p.point(Vec3::new(0.0, 1.0, 3.0), Vec3::Y).is_none());
    }

    #[test]
    fn with_a_hull_the_point_is_on_its_surface_and_the_axis_through_its_box() {
        let grid =
            VoxelGrid::covering(Vec3::new(0.5, 0.0, 0.5), Vec3::new(1.5, 2.0, 1.5), 0.1).unwrap();
        let hull = VoxelHull::full(grid);
        let p = Proxy::new(Some(hull));
        assert!((p.axis() - Vec2::new(1.0, 1.0)).length() < 1e-5);
        let q = p.point(Vec3::new(1.0, 1.0, 4.0), Vec3::NEG_Z).unwrap();
        assert!((q - Vec3::new(1.0, 1.0, 1.5)).length() < 1e-4, "{q}");
        // Beside the box: nearest the box's axis.
        let q = p.point(Vec3::new(1.0, 3.0, 4.0), Vec3::NEG_Z).unwrap();
        assert!((q - Vec3::new(1.0, 3.0, 1.0)).length() < 1e-4, "{q}");
    }
}
