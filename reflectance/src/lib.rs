//! The flowed reflectance field as data (docs/design.md sections 3 and 4.1): per pose and view
//! `(u, v)`, the basis images (premultiplied, linear), alpha and the flows to each grid
//! neighbour, plus per-pose shadow attenuation maps; how it is stored compactly with
//! random access, and how it is relit.
//!
//! - [`field`]: the data model: header (grid, per-view cameras and turntable angles,
//!   lighting basis, codec parameters) and per-view data.
//! - [`flowcodec`]: signed-logarithmic 8-bit flow quantization and canonical Huffman
//!   coding, optionally left-predicted.
//! - [`imagecodec`]: the basis images of a view as one gamma-2.2 JPEG mosaic; alpha and
//!   shadow maps lossless to 16 bits with zstd.
//! - [`project`], [`relight`]: HDR environments projected onto the basis (spherical
//!   Voronoi regions of the lights, turntable rotation, two floor models) and CPU
//!   relighting.
//! - [`gait_speed`]: the treadmill's speed, recorded or measured from the hulls.
//! - [`container`], [`store`]: the field file, an indexed and checksummed container that
//!   reads one view without the rest; [`decoded`]: views' basis images kept decoded
//!   between reads; [`stats`]: its contents and compression ratios.
//!
//! Conventions: [`frf_core::conventions`].

pub mod chunk;
pub mod container;
pub mod decoded;
pub mod error;
pub mod field;
pub mod floor_light;
pub mod flowcodec;
pub mod gait_speed;
pub mod gloss;
pub mod hull;
pub mod imagecodec;
pub mod light_fit;
pub mod merge;
pub mod normalcodec;
pub mod project;
pub mod relight;
pub mod sh_transfer;
pub mod shadow;
pub mod stats;
pub mod store;
pub mod sun_depth;
pub mod sun_light;
pub mod unzstd;
pub mod verify;
pub mod yaw_light;
pub mod yaw_table;

pub use container::{FieldFile, FieldWriter};
pub use field::{FieldHeader, ViewData};

pub use error::{ReflectanceError, Result};
