//! The names and numbers of the export's file format, shared by the writer and the
//! reader (docs/export.md, export/schema/).

/// The glTF extension holding the field (listed in `extensionsUsed`, not required: any
/// viewer shows the hulls without it).
pub const EXTENSION: &str = "FRF_flowed_reflectance_field";
/// Its version; a reader refuses another.
pub const VERSION: u32 = 1;
/// A transfer atlas is 3 x 3 tiles of a view's size, coefficient `i` at column `i % 3`,
/// row `i / 3`.
pub const ATLAS_COLUMNS: usize = 3;
/// A basis atlas (`frf export --basis`) is tiles of a view's size, 6 a row: condition
/// `k` at column `k % 6`, row `k / 6` (26 conditions: 6 x 5, the atlas near square).
pub const BASIS_COLUMNS: usize = 6;
/// Flows are 16-bit: a stored value `q` is `q / FLOW_SCALE - FLOW_OFFSET_PX` pixels.
pub const FLOW_SCALE: f32 = 256.0;
/// See [`FLOW_SCALE`]: flows from −128 to +128 px at 1/256 px.
pub const FLOW_OFFSET_PX: f32 = 128.0;
/// Motion is 16-bit: a stored value `q` is `(q − MOTION_ZERO) · step_m` metres.
pub const MOTION_ZERO: u16 = 32768;
