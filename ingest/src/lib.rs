//! Ingest: turns a capture (see [`frf_core::capture`]) into a flowed reflectance field:
//! mattes from track and matte frames, lighting-basis registration by optical flow,
//! inter-view flow for every grid neighbour, and the write-out through the reflectance
//! container, with a report of time per step and, when the caller can judge it against a
//! ground truth ([`evidence::Evaluator`]), each step's error (docs/design.md section 2).
//!
//! - [`pipeline`]: the ingest, pose by pose, parallel, resumable, with a report;
//! - [`views`], [`matte`], [`registration`]: one view's mattes and registered basis images;
//! - [`edges`]: keeping backdrop light out of the subject's edge pixels;
//! - [`interview`], [`guided`], [`rectify`]: flow between grid neighbours, guided by the
//!   pose's visual hull or matched through rectification;
//! - [`shadows`]: the pose's visual hull and its shadow attenuation maps;
//! - [`evidence`]: what ingest hands to an evaluator, and the errors it records;
//! - [`ring`]: a calibrated ring of real photographs (Middlebury multi-view) as a field.
//!
//! Conventions: [`frf_core::conventions`].

pub mod edges;
pub mod error;
pub mod evidence;
pub mod guided;
pub mod interview;
pub mod matte;
pub mod olat;
pub mod olat_field;
pub mod pipeline;
pub mod poseflow;
pub mod rectify;
pub mod registration;
pub mod report_text;
pub mod ring;
pub mod shadows;
pub mod views;

pub use error::{IngestError, Result};
