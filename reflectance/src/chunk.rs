//! The key of a chunk of a field file: which pose and view, and what it holds
//! ([`crate::container`] indexes chunks by it; the decoded-image cache keys on it too).

use frf_core::grid::{Neighbour, PoseStep};
use serde::{Deserialize, Serialize};

/// What a chunk holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ChunkKind {
    /// The basis images of a view (JPEG mosaic).
    Basis,
    /// The alpha of a view.
    Alpha,
    /// The flow from a view to a neighbour.
    Flow(Neighbour),
    /// The flow from a view to the same camera's view of the next or previous captured
    /// pose ([`PoseStep::of`]).
    PoseFlow(PoseStep),
    /// The shadow attenuation maps of a pose (`u = v = 0`).
    Shadows,
    /// The visual hull of a pose (`u = v = 0`).
    Hull,
    /// The normals fitted to a view's basis images ([`crate::light_fit`]), which relight
    /// it under a sun; fields written before them hold none.
    Normals,
}

/// Which chunk: kind, pose and view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct ChunkKey {
    /// Pose.
    pub pose: u32,
    /// Horizontal view index.
    pub u: u32,
    /// Vertical view index.
    pub v: u32,
    /// What it holds.
    pub kind: ChunkKind,
}

impl std::fmt::Display for ChunkKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.kind {
            ChunkKind::Basis => write!(
                f,
                "basis images of pose {} view ({}, {})",
                self.pose, self.u, self.v
            ),
            ChunkKind::Alpha => write!(
                f,
                "alpha of pose {} view ({}, {})",
                self.pose, self.u, self.v
            ),
            ChunkKind::Flow(n) => write!(
                f,
                "flow {} of pose {} view ({}, {})",
                n.name(),
                self.pose,
                self.u,
                self.v
            ),
            ChunkKind::PoseFlow(s) => write!(
                f,
                "flow {} of pose {} view ({}, {})",
                s.name(),
                self.pose,
                self.u,
                self.v
            ),
            ChunkKind::Shadows => write!(f, "shadow maps of pose {}", self.pose),
            ChunkKind::Hull => write!(f, "visual hull of pose {}", self.pose),
            ChunkKind::Normals => write!(
                f,
                "normals of pose {} view ({}, {})",
                self.pose, self.u, self.v
            ),
        }
    }
}
