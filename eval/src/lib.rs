//! Evaluation against the virtual light stage's ground truth: everything that scores the
//! product's results (ingest, storage, relighting, rendering) against what the stage
//! knows exactly, kept out of the product's crates so that ingesting a real capture or
//! rendering a field builds none of the ray tracer.
//!
//! - [`metrics`]: PSNR, SSIM, alpha error and IoU, with their mask rules, in one place;
//! - [`oracle`]: the field a perfect ingest would produce, from the stage's truth;
//! - [`ingest`]: each ingest step's error ([`ingest::StageEvaluator`], handed to
//!   [`frf_ingest::pipeline::ingest`]);
//! - [`storage`]: the error of the lighting basis and of the image codec;
//! - [`views`]: rendered frames between the grid's views against the true frames;
//!   [`quads`]: `frf eval` at quad centres, with the scene's scores;
//! - [`ingest_budget`]: the error budget of ingest: fields with one ingest component at
//!   a time taken from the truth, scored at the captured views and at quad centres;
//! - [`budget`]: the error budget of view interpolation: every variant at offsets along
//!   rows, columns and toward quad centres, beside the captured views, the floor of any
//!   flow-based morph and geometry baselines (unstructured lumigraph rendering);
//! - [`paths`]: the suite of camera paths people render (inside, near, outside, above and
//!   below the grid of cameras);
//! - [`scene`]: the relit shadow, composites and matte edges against the truth;
//! - [`shot`]: the frames of a scene's shot against their true composites;
//! - [`report`]: error against run time of every stage's settings: rows, Pareto fronts,
//!   plots and the page that shows them;
//! - [`ring`]: views held out of a ring of real photographs, rendered from their
//!   neighbours, against the photographs.
//!
//! Conventions: [`frf_core::conventions`].

pub mod budget;
pub mod error;
pub mod ingest;
pub mod ingest_budget;
pub mod metrics;
pub mod olat;
pub mod oracle;
pub mod paths;
pub mod quads;
pub mod report;
pub mod ring;
pub mod scene;
pub mod shot;
pub mod storage;
pub mod sun_fit;
pub mod sweep;
pub mod views;

pub use error::{EvalError, Result};
