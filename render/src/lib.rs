//! Render: the four-way flowed light-field renderer (docs/design.md section 4), in wgpu with WGSL
//! shaders (`shaders/`) and as a CPU reference of the same mathematics.
//!
//! - [`geometry`]: a pose's grid, crop, cameras and cylinder, shared by both renderers;
//! - [`resident`]: a pose made ready to render: pre-lit views, alpha, flow codes, cropped.
//! - [`cylinder`]: light-field re-binning through the squashed cylinder of camera centres;
//!   [`proxy`]: where rays beyond the grid's rows meet the subject (the visual hull).
//! - [`morph`]: the solved four-way morph (its derivation is in the module docs), and the
//!   interpolations it is measured against (E06's flowed morphs, linear blend, nearest
//!   view); [`rectified`]: the quads' rectified frames it solves in.
//! - [`cpu`]: the CPU reference renderer; [`gpu`]: the wgpu renderer, its twin;
//!   [`renderer`]: one front for both.
//! - [`shadow`]: the subject's relit shadow on the ground; [`composite`]: backdrops and
//!   Porter–Duff compositing of the subject over them.
//! - [`pose_plan`]: what a pose must provide to the frames drawn (views, flows,
//!   conditions, maps), as the scene's planner (crate `frf-scene`) decides it.
//! - [`synthetic`]: a procedural pose of the original's shape, for benchmarks without a
//!   field.
//!
//! Conventions: [`frf_core::conventions`].

pub mod atlas;
pub mod composite;
pub mod cpu;
pub mod cylinder;
pub mod detail;
pub mod error;
pub mod extend;
pub mod footprint;
pub mod geometry;
pub mod gpu;
pub mod morph;
pub mod motion;
pub mod pose_plan;
pub mod proxy;
pub mod rectified;
pub mod reduced_views;
pub mod renderer;
pub mod resident;
pub mod shadow;
pub mod shadow_reach;
pub mod synthetic;

pub use error::{RenderError, Result};
