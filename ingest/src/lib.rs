//! Ingest: turns a capture (see [`frf_core::capture`]) into a flowed reflectance field:
//! mattes from track and matte frames, lighting-basis registration by optical flow,
//! inter-view flow for every grid neighbour, and the write-out through the reflectance
//! container, with a report of each step's error against the virtual light stage's
//! ground truth (BRIEF section 3). The estimating ingest arrives with the ingest issue;
//! this crate holds so far:
//!
//! - [`oracle`]: the field a perfect ingest would produce, built from the stage's ground
//!   truth (used to measure storage and, later, rendering apart from ingest errors);
//! - [`eval`], [`metrics`]: basis-projection error and codec curves against the truth.
//!
//! Conventions: [`frf_core::conventions`].

pub mod error;
pub mod eval;
pub mod matte;
pub mod metrics;
pub mod oracle;
pub mod rectify;
pub mod registration;

pub use error::{IngestError, Result};
