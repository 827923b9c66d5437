//! The virtual light stage: a CPU ray tracer that films an articulated, textured walker
//! on a treadmill atop a turntable inside a lighting dome, as the original rig did
//! (Einarsson et al., EGSR 2006; docs/design.md sections 1 and 5), and that knows the exact
//! ground truth of everything it films.
//!
//! - [`rig`]: the dome's 26 basis conditions, track and matte lighting, the 3 cameras,
//!   the turntable and the 33-slot schedule of a lighting set.
//! - [`actor`], [`gait`], [`leg`], [`body`], [`material`], [`brdf`]: the walker (16
//!   capsules and ellipsoids), its treadmill gait (planted feet moving with the belt, legs
//!   by inverse kinematics) with seeded cycle-to-cycle perturbations, procedural
//!   textures, and Lambert + Torrance–Sparrow reflectance.
//! - [`render`], [`studio`], [`sensor`]: the ray tracer (supersampled, shadowed), the
//!   retro-reflective floor and backdrop, and the sensor's noise and 12-bit quantization.
//! - [`crowd`]: the true image of several walkers in one world, each at its own instant
//!   and under its own lights, occluding and shadowing one another.
//! - [`truth`]: true alpha, true optical flow between any two views or instants, and the
//!   true image of any virtual camera under any basis combination or HDR environment.
//! - [`writer`]: writes a capture directory described by a manifest
//!   ([`frf_core::manifest`]), resumably, with the ground truth beside it.
//!
//! Frames, axes and units: [`frf_core::conventions`].

pub mod actor;
pub mod body;
pub mod brdf;
pub mod config;
pub mod contact;
pub mod crowd;
pub mod error;
pub mod gait;
pub mod geometry;
pub mod ground;
pub mod leg;
pub mod material;
pub mod olat_sphere;
pub mod optics;
pub mod render;
pub mod rig;
pub mod rng;
pub mod sensor;
pub mod stage;
pub mod studio;
pub mod truth;
pub mod truth_shot;
pub mod writer;

pub use config::{Preset, SetFlowTruth, StageConfig};
pub use error::{Result, StageError};
pub use gait::Gait;
pub use rig::Exposure;
pub use stage::{Stage, ViewSetup};
pub use truth::{Neighbour, TrueFlow, TruthImage};
pub use writer::{WriteReport, open_stage, write_capture};
