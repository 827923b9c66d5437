//! Optical flow for the pipeline: a robust estimator after Black & Anandan (CVIU 1996) in
//! the measured form of Sun, Roth & Black ("Secrets of optical flow", CVPR 2010), with
//! Middlebury `.flo` I/O (re-exported from [`frf_core::flo`]), end-point and angular error
//! metrics, colour-wheel visualization and a backward-warp helper.
//!
//! Flow direction and pixel coordinates follow [`frf_core::conventions`].
//! The estimator itself arrives with the optical-flow issue; this crate currently
//! holds the file format and the warp that the virtual light stage's tests use.

pub use frf_core::flo::{UNKNOWN, is_known, read_flo, write_flo};
