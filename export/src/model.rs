//! The extension's object ([`crate::format::EXTENSION`]) as types: the writer builds one
//! and serialises it, the reader parses into it, and a test holds the JSON schema
//! (`export/schema/`) to what they serialise (every object closed to other keys), so the
//! writer, the reader and the schema cannot drift apart. docs/export.md says what each
//! field means.

use std::collections::BTreeMap;

use frf_core::image::Rgb;
use frf_core::sh::{Convention, SH_COUNT};
use frf_reflectance::field::{CameraRecord, ConditionRecord};
use serde::{Deserialize, Serialize};

/// The extension's object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Extension {
    /// The format's version ([`crate::format::VERSION`]).
    pub version: u32,
    /// How the transfer is stored.
    pub tier: TierName,
    /// The convention of the transfer's nine coefficients.
    pub sh: Convention,
    /// The capture's grid of cameras.
    pub grid: Grid,
    /// Seconds a walk cycle takes.
    pub cycle_seconds: f64,
    /// Poses a cycle holds.
    pub poses_per_cycle: u32,
    /// The walk's speed, where the field records it or its hulls tell it (root motion).
    pub walk: Option<Walk>,
    /// The field's file name.
    pub source: Option<String>,
    /// The ground-shadow basis' patch and weights, where the field holds shadow maps.
    pub ground_shadow: Option<GroundShadow>,
    /// The lighting basis' conditions, where the export holds the views' basis images
    /// (`frf export --basis`): what a sun is relit by as frf relights it.
    pub basis: Option<Basis>,
    /// The poses exported.
    pub poses: Vec<PoseRecord>,
}

/// How the transfer is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TierName {
    /// Three atlases, one a channel.
    Full,
    /// One grey atlas and a colour per texel.
    Compact,
}

/// The capture's grid of cameras.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Grid {
    /// Views round the turntable (walk cycles).
    pub columns: usize,
    /// Camera heights.
    pub rows: usize,
    /// Whether the columns close into a ring.
    pub wraps: bool,
    /// Captured image width, pixels.
    pub width: u32,
    /// Captured image height, pixels.
    pub height: u32,
}

/// The walk's speed (root motion).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Walk {
    /// Metres a second.
    pub speed_mps: f64,
    /// Metres a cycle.
    pub stride_m: f64,
    /// The direction walked, in the subject frame.
    pub forward: [f64; 3],
    /// Whether the speed was measured from the hulls (the field records none).
    pub measured: bool,
}

/// The lighting basis whose images the views hold (`frf export --basis`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Basis {
    /// Tiles a row of a view's basis atlas ([`crate::format::BASIS_COLUMNS`]).
    pub columns: usize,
    /// The conditions, in the order of the atlases' tiles: each its lights (dome frame:
    /// a view's dome is the subject frame turned by its turntable angle), as the field
    /// records them.
    pub conditions: Vec<ConditionRecord>,
}

/// The ground-shadow basis (frf's attenuation maps, one per upper lighting condition) and
/// how an L2 light relights it: the ground's relative irradiance under light `c_i` is
/// `S(x) = Σ_m w_m A_m(x) / Σ_m w_m` per channel, `w_m = Σ_i c_i weights[m][i]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroundShadow {
    /// Side of the square patch under the subject, metres (centred on its axis).
    pub extent_m: f32,
    /// Texels a side of each map (rows along `+z`, columns along `+x`).
    pub texels: u32,
    /// Where the maps start fading to 1 toward the patch's edge, a fraction of the half
    /// side.
    pub edge_fade_from: f32,
    /// Per map: the SH weights of its condition times the irradiance it delivers to the
    /// unshadowed ground (nine RGB).
    pub weights: Vec<[Rgb; SH_COUNT]>,
}

/// One pose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseRecord {
    /// The pose's index in the field.
    pub pose: u32,
    /// Its time in the cycle, seconds.
    pub time_s: f64,
    /// Its node (the hull mesh).
    pub node: usize,
    /// Every camera of the grid, `u`-major (a player re-bins rays through them all).
    pub cameras: Vec<CameraRecord>,
    /// How far from the hull's surface a sun's shadow ray starts, metres.
    pub sun_shadow_offset_m: f32,
    /// Its ground-shadow maps (an image's index: a grey PNG of the maps one above the
    /// other), where the field holds them.
    pub ground_shadow: Option<usize>,
    /// The field's poses its views' motion leads to, by the step's name (`next`,
    /// `prev`): only where the field holds pose-to-pose flows.
    pub motion_to: BTreeMap<String, u32>,
    /// The largest component of its views' flows as a reader decodes them, pixels: how
    /// far a flow may carry colour beyond the hull, known before any flow is decoded
    /// (`None` in exports written before it).
    #[serde(default)]
    pub max_flow_px: Option<f32>,
    /// The views exported.
    pub views: Vec<ViewRecord>,
}

/// One view of a pose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ViewRecord {
    /// Its column.
    pub u: usize,
    /// Its row.
    pub v: usize,
    /// The turntable's angle when it was captured, degrees.
    pub turntable_deg: f32,
    /// Its camera.
    pub camera: CameraRecord,
    /// Its alpha (an image's index).
    pub alpha: usize,
    /// Its SH transfer.
    pub transfer: Transfer,
    /// Its fitted normals (an image's index), where the field holds them.
    pub normals: Option<usize>,
    /// Its albedo.
    pub albedo: ScaledImage,
    /// Its flows toward its grid neighbours, by the neighbour's name (an image's index).
    pub flows: BTreeMap<String, usize>,
    /// The subject's motion toward the next and the previous pose, by the step's name
    /// (`next`, `prev`), where the field holds pose-to-pose flows.
    pub motion: BTreeMap<String, MotionImage>,
    /// Its basis images (`frf export --basis`; else null).
    pub basis: Option<BasisImages>,
}

/// A view's basis images, one tile per condition: radiance under the condition,
/// `offset + scale × code` per condition and channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BasisImages {
    /// The atlases (images' indices): red, green, blue; or one KTX2 image of the three.
    pub images: Vec<usize>,
    /// Per condition and channel: a code's step.
    pub scale: Vec<Rgb>,
    /// Per condition and channel: the value of code 0.
    pub offset: Vec<Rgb>,
}

/// A view's motion toward another pose: metres across the subject's axis (tangential to
/// the circle of cameras) and up it, per texel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MotionImage {
    /// A 16-bit grey-alpha PNG (across in grey, up in alpha): `(q − 32768) · step_m`.
    pub image: usize,
    /// Metres a code.
    pub step_m: f32,
}

/// A view's SH transfer: per coefficient and channel, `offset + scale × code`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Transfer {
    /// The atlases (images' indices): three (red, green, blue) or one (grey, compact)
    /// JPEGs, or one KTX2 image of them (R, G, B; compact R).
    pub images: Vec<usize>,
    /// Per coefficient and channel: a code's step.
    pub scale: [Rgb; SH_COUNT],
    /// Per coefficient and channel: the value of code 0.
    pub offset: [Rgb; SH_COUNT],
    /// The compact tier's colour per texel.
    pub colour: Option<ScaledImage>,
}

/// An image and the scale of its codes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScaledImage {
    /// The image's index.
    pub image: usize,
    /// Per channel: the value of code 255.
    pub scale: Rgb,
}
