//! Ingest: turns a capture (see [`frf_core::capture`]) into a flowed reflectance field:
//! mattes from track and matte frames, lighting-basis registration by optical flow,
//! inter-view flow for every grid neighbour, and the write-out through the reflectance
//! container, with a report of each step's error against the virtual light stage's
//! ground truth (BRIEF section 3).
//!
//! - [`pipeline`]: the ingest, pose by pose, parallel, resumable, with a report;
//! - [`views`], [`matte`], [`registration`]: one view's mattes and registered basis images;
//! - [`interview`], [`rectify`]: flow between grid neighbours, vertical pairs rectified;
//! - [`evaluate`]: each step's error against the virtual stage's truth;
//! - [`ring`]: a calibrated ring of real photographs (Middlebury multi-view) as a field;
//! - [`oracle`]: the field a perfect ingest would produce, built from the stage's ground
//!   truth (to measure storage and rendering apart from ingest errors);
//! - [`eval`], [`metrics`]: basis-projection error and codec curves against the truth.
//!
//! Conventions: [`frf_core::conventions`].

pub mod error;
pub mod eval;
pub mod evaluate;
pub mod interview;
pub mod matte;
pub mod metrics;
pub mod oracle;
pub mod pipeline;
pub mod rectify;
pub mod registration;
pub mod ring;
pub mod views;

pub use error::{IngestError, Result};
