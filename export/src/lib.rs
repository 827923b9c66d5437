//! Walkers leaving frf (docs/export.md): a flowed reflectance field as one binary glTF
//! 2.0 file that any glTF viewer opens and a player relights.
//!
//! - Every pose's visual hull is an ordinary mesh, one node per pose, switched by a
//!   plain animation (scale 1 at its pose's time, 0 otherwise, step interpolation) at the
//!   cycle's rate: any viewer shows a walking silhouette.
//! - The extension [`format::EXTENSION`] holds, per pose and view: the camera, alpha,
//!   the view's SH transfer (nine RGB coefficients per texel, [`frf_reflectance::sh_transfer`]:
//!   a player relights it by an L2 light probe's coefficients, exactly as frf relights
//!   the band-limited light), the fitted normals and albedo a sun is relit by, and the
//!   flows to the grid neighbours the four-way morph draws between views with; and the
//!   SH convention the transfer is for ([`frf_core::sh::Convention`]).
//!
//! A relit sprite sheet (the walk cycle from a ring of headings, for engines that play
//! flipbooks) is rendered by the scene system: `frf_scene::sprites`.
//!
//! What the SH tier cannot do: a sharp sun is not L2 (band 2 is a 60° lobe); a player
//! adds it from the normals and albedo, as frf's sun relighting does from the normals.

pub mod error;
pub mod format;
pub mod glb;
pub mod hull_mesh;
pub mod ktx2;
pub mod model;
pub mod read;
pub mod view_maps;
mod write;

pub use error::{ExportError, Result};
pub use write::{AtlasError, ExportOptions, ExportReport, Textures, Tier, ViewSelection, export};
