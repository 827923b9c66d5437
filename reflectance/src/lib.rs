//! The flowed reflectance field as data (BRIEF sections 4 and 5.1): per pose and view
//! `(u, v)`, the basis images (premultiplied, linear), alpha and the flows to each grid
//! neighbour, plus per-pose shadow attenuation maps; how it is stored compactly with
//! random access, and how it is relit.
//!
//! - [`flowcodec`]: signed-logarithmic 8-bit flow quantization and canonical Huffman
//!   coding, optionally left-predicted.
//!
//! Conventions: [`frf_core::conventions`].

pub mod error;
pub mod flowcodec;
pub mod imagecodec;

pub use error::{ReflectanceError, Result};
