//! Shared conventions and data types of the flowed-reflectance-field pipeline.
//!
//! Every other crate of the workspace builds on these: [`image::Image`] buffers with
//! bilinear sampling, linear 16-bit PNG / EXR / Middlebury `.flo` input and output that
//! writes atomically, pinhole [`camera::Camera`]s, the capture [`manifest`] that
//! declares a lighting-dome capture, and HDR [`env::EnvMap`] environments. The
//! axes, units and coordinate conventions they all share are written once, in
//! [`conventions`].

pub mod argument;
pub mod atomic;
pub mod bars;
pub mod camera;
pub mod capture;
pub mod claim;
pub mod contact;
pub mod conventions;
pub mod env;
pub mod error;
pub mod filter;
pub mod flo;
pub mod grid;
pub mod image;
pub mod io;
pub mod light;
pub mod lru;
pub mod manifest;
pub mod preview;
pub mod progress;
pub mod sh;
pub mod shared_data;
pub mod subject_motion;
pub mod sun;
pub mod thread_clock;
pub mod volume;

pub use argument::BadArgument;
pub use error::{CoreError, Fault, Result};
