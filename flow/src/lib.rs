//! Optical flow for the pipeline: a robust estimator after Black & Anandan (CVIU 1996) in
//! the measured form of Sun, Roth & Black ("Secrets of optical flow", CVPR 2010), with
//! Middlebury `.flo` I/O (re-exported from [`frf_core::flo`]), end-point and angular error
//! metrics, colour-wheel visualization, a backward-warp helper and the benchmark runner
//! behind `frf flow-bench`.
//!
//! Flow direction and pixel coordinates follow [`frf_core::conventions`]: pixel `s` of
//! the first image corresponds to `s + F(s)` of the second.
//!
//! How the estimator is built, and where each choice comes from (each module's own
//! documentation gives the details and sources):
//! - input normalisation, structure–texture decomposition, gradient constancy: `texture.rs`;
//! - image pyramid and its anti-aliasing: `pyramid.rs`;
//! - robust penalties (Lorentzian, generalized Charbonnier) and GNC: [`penalty`];
//! - warping, linearisation and IRLS: `solver.rs` (bicubic sampling: `interp.rs`,
//!   derivative filter: `gradient.rs`); red-black SOR in a vectorisable layout: `sor.rs`;
//! - median filtering between warps and Classic+NL's weighted median: `median.rs`,
//!   `weighted_median.rs`;
//! - coarse-to-fine and GNC stages: [`estimate`];
//! - presets: [`presets`].
//!
//! The estimator holds no global state and parallelises inside with rayon, so it can be
//! called from many threads, or from an outer rayon `par_iter` over image pairs, without
//! oversubscribing the machine.

pub mod bench;
pub mod error;
pub mod estimate;
pub mod files;
mod gradient;
mod interp;
mod median;
pub mod metrics;
pub mod params;
pub mod penalty;
pub mod presets;
mod pyramid;
mod solver;
mod sor;
mod texture;
pub mod viz;
pub mod warp;
mod weighted_median;

pub use error::{FlowError, Result};
pub use estimate::{estimate_flow, estimate_flow_from};
pub use frf_core::flo::{UNKNOWN, is_known, read_flo, write_flo};
pub use metrics::{FlowErrors, flow_errors};
pub use params::{ColorMode, FlowParams, Interpolation, TextureFilter};
pub use penalty::Penalty;
pub use presets::Preset;
pub use warp::{backward_warp, backward_warp_masked};
