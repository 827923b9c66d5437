//! What the plan of a shot asks of one pose of a field, as plain data: the views, flows,
//! conditions, maps and level of detail to read and relight. The scene's planner
//! (`frf_scene::plan`) decides it; [`crate::resident`] reads a pose through it.

use serde::Serialize;

use crate::footprint::SubjectBounds;

/// What one pose of the field must provide.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PosePlan {
    /// The pose.
    pub pose: u32,
    /// Per view (`u`-major): needed.
    pub views: Vec<bool>,
    /// Per view and neighbour ([`frf_core::grid::Neighbour::ALL`] order): the flow is needed.
    pub flows: Vec<[bool; 4]>,
    /// Per basis condition: relit.
    pub conditions: Vec<bool>,
    /// The shadow maps are read.
    pub shadow_maps: bool,
    /// The visual hull is read.
    pub hull: bool,
    /// The pose's motion toward the next and the previous pose
    /// ([`frf_core::grid::PoseStep`] order) is read, for the views read.
    pub pose_flows: [bool; 2],
    /// The level of detail it is drawn at ([`frf_render::detail`]): the finest any frame
    /// needs (0, full detail, for a shot morphed between poses).
    pub level: u8,
    /// The level its shadow maps are relit at: the coarsest whose texel spans at most
    /// a frame's pixel at the walker, over every frame (0 without maps).
    pub shadow_level: u8,
    /// Where its subject can show ([`SubjectBounds::of_pose`]): the views read are those
    /// of the rays through these bounds.
    pub bounds: SubjectBounds,
}
