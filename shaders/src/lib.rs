//! Shaders: the WGSL of the renderer's GPU passes (the `.wgsl` files beside this crate's
//! `src/`, see their README), included at compile time, and the `#[repr(C)]` Pod mirrors
//! of the structs they share with the CPU ([`types`]). The renderer (`frf-render`)
//! compiles them on its device; this crate's tests validate every pass with naga as
//! compiled and check every mirror's size and member offsets against naga's layout, with
//! no GPU.
//!
//! A pass is compiled as [`COMMON`] followed by the pass ([`composed`]); the frame pass is
//! [`REBIN`] with its pieces: one sampling snippet of each kind ([`PRELIT`], [`FLOW`]),
//! the ray's entry into the cylinder, the proxy and the morphs ([`frame_pass`]).

pub mod types;

/// `common.wgsl`: the structures and pure functions every pass shares.
pub const COMMON: &str = include_str!("../common.wgsl");
/// `relight.wgsl`: the relighting pass.
pub const RELIGHT: &str = include_str!("../relight.wgsl");
/// `rebin.wgsl`, standalone: the frame pass, before its pieces.
pub const REBIN: &str = include_str!("../rebin.wgsl");
/// `shadow.wgsl`, standalone.
pub const SHADOW: &str = include_str!("../shadow.wgsl");
/// `composite.wgsl`, standalone.
pub const COMPOSITE: &str = include_str!("../composite.wgsl");
/// `present.wgsl`: a frame shown in a window.
pub const PRESENT: &str = include_str!("../present.wgsl");
/// `time_morph.wgsl`: the morph in time of a frame between two poses.
pub const TIME_MORPH: &str = include_str!("../time_morph.wgsl");
/// `turn_light.wgsl`: a light's coefficients looked up on the device by each view's turn.
pub const TURN_LIGHT: &str = include_str!("../turn_light.wgsl");
/// `light_fit.wgsl`: photographs under single lights relit by a per-texel light fit.
pub const LIGHT_FIT: &str = include_str!("../light_fit.wgsl");
/// `floor.wgsl`, standalone.
pub const FLOOR: &str = include_str!("../floor.wgsl");
/// `rebin/cylinder.wgsl`: a ray's entry into the cylinder of camera centres, composed
/// after the frame pass.
pub const CYLINDER: &str = include_str!("../rebin/cylinder.wgsl");
/// `rebin/proxy.wgsl`: the geometric proxy, composed after the frame pass.
pub const PROXY: &str = include_str!("../rebin/proxy.wgsl");
/// `rebin/hull.wgsl`: a ray's walk through a visual hull's voxels, composed after the
/// frame pass and after the suns' maps.
pub const HULL: &str = include_str!("../rebin/hull.wgsl");
/// `morph/e06.wgsl`: E06's morphs, composed after the frame pass.
pub const E06: &str = include_str!("../morph/e06.wgsl");
/// `morph/solved.wgsl`: the solved four-way morph, composed after the frame pass.
pub const SOLVED: &str = include_str!("../morph/solved.wgsl");
/// `sample/prelit_codes.wgsl`: pre-lit views as integer codes.
pub const PRELIT_CODES: &str = include_str!("../sample/prelit_codes.wgsl");
/// `sample/prelit_srgb.wgsl`: pre-lit views as sRGB8, filtered in hardware.
pub const PRELIT_SRGB: &str = include_str!("../sample/prelit_srgb.wgsl");
/// `sample/flow_codes.wgsl`: flows as 8-bit log codes.
pub const FLOW_CODES: &str = include_str!("../sample/flow_codes.wgsl");
/// `sample/flow_f16.wgsl`: flows as half floats, filtered in hardware.
pub const FLOW_F16: &str = include_str!("../sample/flow_f16.wgsl");
/// `sample/flow_f32.wgsl`: flows as floats.
pub const FLOW_F32: &str = include_str!("../sample/flow_f32.wgsl");

/// `sun_depth.wgsl`: a sun's map of a pose's hull, composed with the hull's walk
/// ([`sun_depth_pass`]).
pub const SUN_DEPTH: &str = include_str!("../sun_depth.wgsl");

/// Every pass but the frame pass ([`frame_pass`]) and the sun's map ([`sun_depth_pass`]),
/// named.
pub const PASSES: [(&str, &str); 8] = [
    ("relight", RELIGHT),
    ("turn_light", TURN_LIGHT),
    ("shadow", SHADOW),
    ("composite", COMPOSITE),
    ("floor", FLOOR),
    ("present", PRESENT),
    ("time_morph", TIME_MORPH),
    ("light_fit", LIGHT_FIT),
];

/// The snippets that read the pre-lit views (one is compiled into a frame pass), named as
/// the renderer's image formats.
pub const PRELIT: [(&str, &str); 2] = [("codes", PRELIT_CODES), ("srgb8", PRELIT_SRGB)];

/// The snippets that read the flows, named as the renderer's flow formats.
pub const FLOW: [(&str, &str); 3] = [("codes8", FLOW_CODES), ("f16", FLOW_F16), ("f32", FLOW_F32)];

/// A pass's full source: the shared definitions, then the pass.
pub fn composed(pass: &str) -> String {
    format!("{COMMON}\n{pass}")
}

/// The frame pass's full source with one snippet reading the pre-lit views (of
/// [`PRELIT`]) and one reading the flows (of [`FLOW`]), for one morph: `(kind, flags)`,
/// the interpolation and its refinements (`frf_render::morph::Variant::index` and
/// `flags`), written into the source as the constants `KIND` and `FLAGS`, so that the
/// module compiled holds that morph alone (docs/design.md section 4.5).
pub fn frame_pass(prelit: &str, flow: &str, (kind, flags): (u32, u32)) -> String {
    let morph = format!("const KIND: u32 = {kind}u;\nconst FLAGS: u32 = {flags}u;");
    [
        COMMON, &morph, prelit, flow, REBIN, CYLINDER, PROXY, HULL, E06, SOLVED,
    ]
    .join("\n")
}

/// The sun-depth pass's full source: the shared definitions, the pass, and the walk
/// through a hull it shares with the frame pass ([`HULL`]).
pub fn sun_depth_pass() -> String {
    [COMMON, SUN_DEPTH, HULL].join("\n")
}
