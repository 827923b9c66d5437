//! `#[repr(C)]` Pod structs mirroring the WGSL structs of the passes, padded explicitly;
//! a test (`tests/validate.rs`) checks each size and member offset against naga's layout
//! of the shader.

use bytemuck::{Pod, Zeroable};

/// `View` of `common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuView {
    /// Quaternion `(x, y, z, w)` of `world_from_camera`.
    pub rotation: [f32; 4],
    /// Camera centre.
    pub centre: [f32; 3],
    /// Padding to 16 bytes.
    pub pad: f32,
    /// fx, fy, cx, cy.
    pub intrinsics: [f32; 4],
}

/// `Quad` of `common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuQuad {
    /// Corner.
    pub p00: [f32; 3],
    /// Column.
    pub u: u32,
    /// Edge toward the next column.
    pub e1: [f32; 3],
    /// Row.
    pub v: u32,
    /// Edge toward the next row.
    pub e2: [f32; 3],
    /// 0 inside, 1 wall above, 2 wall below.
    pub wall: u32,
    /// Twist.
    pub e3: [f32; 3],
    /// Clamped γ of a wall.
    pub wall_gamma: f32,
    /// Normal.
    pub normal: [f32; 3],
    /// Padding to 16 bytes.
    pub pad: f32,
}

/// `QuadFrame` of `morph/solved.wgsl`: a quad's rectified frame
/// (`frf_render::rectified::QuadFrame`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuQuadFrame {
    /// `world_from_rectified` x column (image right; w unused).
    pub axis_x: [f32; 4],
    /// y column (image down).
    pub axis_y: [f32; 4],
    /// The plane's inward normal.
    pub axis_n: [f32; 4],
    /// fx, fy, cx, cy.
    pub intrinsics: [f32; 4],
    /// Per vertex: view pixel to rectified pixel, columns padded to 16 bytes.
    pub to_rectified: [[[f32; 4]; 3]; 4],
    /// Per vertex: rectified pixel to view pixel.
    pub from_rectified: [[[f32; 4]; 3]; 4],
    /// In-plane centres: `[A.x, A.y, B.x, B.y]`, `[C.x, C.y, D.x, D.y]`.
    pub centres: [[f32; 4]; 2],
    /// Depth of the fixation point along the normal.
    pub fixation_depth: f32,
    /// 1 where the quad has a frame.
    pub valid: u32,
    /// Padding to 16 bytes.
    pub pad: [f32; 2],
}

/// `Frame` of `common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuFrame {
    /// Virtual camera's `world_from_camera` x column (w unused).
    pub axis_x: [f32; 4],
    /// y column.
    pub axis_y: [f32; 4],
    /// z column.
    pub axis_z: [f32; 4],
    /// Centre (w unused).
    pub centre: [f32; 4],
    /// fx, fy, cx, cy.
    pub intrinsics: [f32; 4],
    /// Output size.
    pub size: [u32; 2],
    /// `frf_render::morph::Variant::index`: what the frame was drawn with, for inspection
    /// (the frame pass's pipeline is specialized to it, its override `KIND`).
    pub variant: u32,
    /// Number of quads.
    pub quad_count: u32,
    /// Grid columns.
    pub columns: u32,
    /// Grid rows.
    pub rows: u32,
    /// Crop origin in the full image.
    pub crop_origin: [u32; 2],
    /// Crop size.
    pub crop_size: [u32; 2],
    /// `frf_render::morph::Variant::flags`: as `variant` (the override `FLAGS`).
    pub flags: u32,
    /// 1: the compute frame pass also writes the walker's depth at each pixel
    /// (`frf_render::proxy::Proxy::depth`), which orders walkers that overlap.
    pub depth: u32,
    /// The pixels shaded, `[x0, y0, x1, y1]` (ends exclusive; `frf_render::footprint`):
    /// the walker is transparent outside them.
    pub bounds: [u32; 4],
    /// Where the frame pass writes: pixel `p` of the frame at texel `p + place.xy` of
    /// layer `place.z` of its target (`frf_render::atlas`; w unused).
    pub place: [i32; 4],
    /// Where the pose's copy lies in the shared pages bound beside it, in words from
    /// the page's start: `[heads, codes, flows, 0]`, its views' heads (scale, pre-lit
    /// layer, flow layers), its first pre-lit layer's codes and its flows' codes
    /// (`frf_render::gpu::prelit`).
    pub prelit: [u32; 4],
    /// The compute frame pass's 8x8 tiles of `bounds`, numbered across its dispatch:
    /// `[first, across, tiles, renders]`, the render's first, its tiles across, its
    /// tiles, and (the dispatch's first record only) the renders of the dispatch.
    pub tiles: [u32; 4],
}

/// `Proxy` of `common.wgsl`: the pose's geometric proxy (`frf_render::proxy`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuProxy {
    /// The hull grid's lowest corner.
    pub origin: [f32; 3],
    /// Voxel side, metres.
    pub voxel: f32,
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// 1 when the pose has a hull.
    pub present: u32,
    /// `(x, z)` of the fallback's vertical axis.
    pub axis: [f32; 2],
    /// Where the hull's blocks' bits start in its words (`VoxelHull::words`).
    pub block_words_at: u32,
    /// Voxels along a block's side.
    pub block: u32,
}

/// `SunDepthJob` of `sun_depth.wgsl`: one sun's map of the hull, its frame and where its
/// values go.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuSunDepthJob {
    /// Unit, toward the sun (subject frame); w: `far`, `toward · p` where rays start.
    pub toward: [f32; 4],
    /// The map's x axis (xyz) and its corner's x (w).
    pub axis_x: [f32; 4],
    /// Its y axis and its corner's y.
    pub axis_y: [f32; 4],
    /// Texels along x and y, where its values start, 1 when the slot is in use.
    pub size: [u32; 4],
    /// Texel side, metres (x; the rest unused).
    pub texel: [f32; 4],
}

/// `SunMap` of `sun_depth.wgsl`: a map to make, its walker's hull and its occluders.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuSunMap {
    /// The map's frame and where its values go.
    pub map: GpuSunDepthJob,
    /// The walker's own hull (its entry in the table of hulls), the first of its
    /// occluders (in the occluders' table) and how many; the fourth unused.
    pub hulls: [u32; 4],
}

/// `HullAt` of `sun_depth.wgsl`: a hull of the table of hulls, and where its words start.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuHullAt {
    /// Its grid.
    pub proxy: GpuProxy,
    /// The first of its words in the array of every hull's words (the rest unused).
    pub at: [u32; 4],
}

/// `SunOccluder` of `sun_depth.wgsl`: another walker's hull walked along one sun's map of
/// a walker (`frf_reflectance::sun_depth::Occluder`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuSunOccluder {
    /// Its hull's entry in the table of hulls (the rest unused).
    pub hull: [u32; 4],
    /// `there_from_here` (the walker's frame into the occluder's): its rotation's columns
    /// and its translation (w unused).
    pub there_x: [f32; 4],
    /// (See `there_x`.)
    pub there_y: [f32; 4],
    /// (See `there_x`.)
    pub there_z: [f32; 4],
    /// (See `there_x`.)
    pub there_t: [f32; 4],
}

/// `LightFitParams` of `light_fit.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuLightFitParams {
    /// Texels per photograph.
    pub texels: u32,
    /// Photographs (lights).
    pub lights: u32,
    /// Nearest lights used (at most 4).
    pub nearest: u32,
    /// Padding.
    pub pad0: u32,
    /// The new light (xyz, unit) and the ratio's floor (w).
    pub light: [f32; 4],
    /// The nearest lights' indices.
    pub indices: [u32; 4],
    /// Their weights.
    pub weights: [f32; 4],
    /// The view (xyz, unit, toward the camera) and the glossy lobe's roughness (w; 0:
    /// no lobe).
    pub view: [f32; 4],
}

/// `Job` of `relight.wgsl`: one view of a relit pose copy, of every copy relit in a
/// submission (one dispatch reads them all: every offset counts from its binding's start,
/// a shared page).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuRelightJob {
    /// Its first basis code, words from the start of the basis page.
    pub basis_offset: u32,
    /// Where its copy's batch's coefficients start in their page (`vec4`s): every index
    /// the coefficients hold counts from there.
    pub coefficients_at: u32,
    /// Its first coefficient, from `coefficients_at`.
    pub coefficient_offset: u32,
    /// Its basis images.
    pub tiles: u32,
    /// Its view index (of its head in the copy's pre-lit range).
    pub view: u32,
    /// Its layer of the copy's pre-lit views.
    pub layer: u32,
    /// Its first texel in the relit scratch.
    pub relit_offset: u32,
    /// 1 when its codes are followed by its texels' points on the hull (`t` along their
    /// camera rays, the bits of an f32), 0 without.
    pub surface: u32,
    /// Its peak's slot.
    pub peak: u32,
    /// Where its copy's heads start in the pre-lit page, words.
    pub heads_at: u32,
    /// Where its copy's first layer's codes start in the pre-lit page, words.
    pub codes_at: u32,
    /// Texels of its view (its pose's crop) and the crop's row length.
    pub texels: u32,
    /// See `texels`.
    pub width: u32,
    /// The crop's corner in the image, pixels: a texel's pixel is this plus its place
    /// in the crop.
    pub x0: u32,
    /// See `x0`.
    pub y0: u32,
    /// Sun slots its coefficients hold, those unused last and marked empty.
    pub sun_slots: u32,
    /// Its camera.
    pub camera: GpuView,
}

/// `ShadowJob` of `shadow.wgsl`: one walker's shadow relit into a layer.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuShadowJob {
    /// Where its maps start in the maps' buffer (floats).
    pub maps_at: u32,
    /// Maps.
    pub maps: u32,
    /// Texels per side of the maps.
    pub texels: u32,
    /// Where its weights start in the weights' buffer (`vec4`s).
    pub weights_at: u32,
    /// The layer of the output it writes.
    pub layer: u32,
    /// Padding to 32 bytes.
    pub pad: [u32; 3],
}

/// `Composite` of `composite.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuComposite {
    /// 0 none, 1 environment, 2 plate.
    pub backdrop: u32,
    /// 0 the environment's lower hemisphere, 1 a Lambertian ground.
    pub ground_look: u32,
    /// 1 when the pose has a relit shadow.
    pub has_shadow: u32,
    /// Texels per side of the relit shadow.
    pub shadow_texels: u32,
    /// Radiance of the Lambertian ground (w unused).
    pub ground_radiance: [f32; 4],
    /// Size of the environment map.
    pub env_size: [u32; 2],
    /// Yaw of the environment, radians.
    pub env_yaw: f32,
    /// Side of the shadow's ground patch, metres.
    pub shadow_extent: f32,
    /// Walkers drawn.
    pub instances: u32,
    /// Tiles in a row of the frame's tile lists (`frf_render::footprint::TileLists`).
    pub tile_columns: u32,
    /// Their side, pixels (`frf_render::footprint::TILE`).
    pub tile_side: u32,
    /// 1: walkers that overlap at a pixel are put over each other by their depths
    /// there (`frf_render::composite::stack_by_depth`); 0: in the listed order.
    pub by_depth: u32,
}

/// `Instance` of `composite.wgsl`: `subject_from_world` of a walker.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuInstance {
    /// Rotation column x (w unused).
    pub col_x: [f32; 4],
    /// Rotation column y.
    pub col_y: [f32; 4],
    /// Rotation column z.
    pub col_z: [f32; 4],
    /// Translation; w: texels a side of its relit shadow (its level of detail; 0
    /// without one).
    pub translation: [f32; 4],
    /// The pixels its frame pass shaded, `[x0, y0, x1, y1]` (ends exclusive): elsewhere
    /// it is transparent and its render not read.
    pub bounds: [u32; 4],
    /// Where its render lies: pixel `p` at texel `p + place.xy` of layer `place.z` of the
    /// subjects (`frf_render::atlas`; w unused).
    pub place: [i32; 4],
}

/// `ColumnIndex` of `common.wgsl`: the header of a cylinder's column index
/// (`frf_render::cylinder::column_index`); per span its range of azimuths follows it in the
/// same buffer.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuColumnIndex {
    /// `(x, z)` of the axis point.
    pub axis: [f32; 2],
    /// Unit direction `(x, z)` of azimuth 0.
    pub reference: [f32; 2],
    /// 1 when the columns run counterclockwise in `(x, z)`, −1 otherwise.
    pub orientation: f32,
    /// Inner radius of the annulus holding every footprint.
    pub r_min: f32,
    /// Outer radius.
    pub r_max: f32,
    /// Column spans.
    pub spans: u32,
    /// Quads per span (`rows + 1`).
    pub quads_per_span: u32,
    /// 1 when the index is used; 0: every quad is solved.
    pub enabled: u32,
}

/// `Present` of `present.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuPresent {
    /// Top-left corner of the frame in the window, pixels.
    pub origin: [f32; 2],
    /// Size of the frame in the window, pixels.
    pub extent: [f32; 2],
    /// The layer shown (`frf_render::gpu::present::ShownLayer`).
    pub layer: u32,
    /// 1 when the shader encodes sRGB (the target format does not).
    pub encode: u32,
    /// `2^stops`.
    pub exposure: f32,
    /// Padding.
    pub pad: u32,
}

/// `TimeMorph` of `time_morph.wgsl`: a walker's morph in time between two poses.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuTimeMorph {
    /// Columns of the 2x2 map from metres to pixels.
    pub to_image: [f32; 4],
    /// The walker's pixel box: first column and row, one past the last.
    pub bounds: [u32; 4],
    /// Offsets in their pages of the renders of pose `k` (xy) and `k'` (zw).
    pub at_poses: [i32; 4],
    /// Offsets of the two poses' motion renders.
    pub at_motions: [i32; 4],
    /// Offset of the morph (xy; zw the same).
    pub at_morph: [i32; 4],
    /// The fraction of the way from `k` to `k'`.
    pub s: f32,
    /// 1: the walker's depth is the nearer of its two poses' (the morph's depth written
    /// beside it); 0: no depth is read or written.
    pub by_depth: u32,
    /// The morph's page among the morphs' pages.
    pub morph_page: u32,
    /// Padding.
    pub pad: u32,
    /// The pages of pose `k`'s render (among the subjects'), of pose `k'`'s and of the
    /// two poses' motion renders (among the scratch renders').
    pub pages: [u32; 4],
}

/// `TurnParams` of `turn_light.wgsl`: what every relight of one dispatch shares.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuTurnParams {
    /// Relights in the dispatch (a row of workgroups each).
    pub relights: u32,
    /// Samples of a yaw table per turn.
    pub samples: u32,
    /// Sun slots per job.
    pub sun_slots: u32,
    /// A table's coarse map, texels across.
    pub coarse_w: u32,
    /// Its texels down.
    pub coarse_h: u32,
    /// The least share of a condition's shading a ratio is taken over.
    pub ratio_floor: f32,
    /// The leave-one-out error at which a sun's trust starts to fall.
    pub trust_low: f32,
    /// The error at which it has fallen to 0.
    pub trust_high: f32,
}

/// `TurnRelight` of `turn_light.wgsl`: one batch of a pose's views relit under one light,
/// where its parts lie in the buffers the dispatch binds.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuTurnRelight {
    /// Where its jobs start in the data page (`vec4`s; two a job).
    pub jobs_at: u32,
    /// Its jobs (views).
    pub jobs: u32,
    /// Threads per job: the most conditions of a job, then the sun slots.
    pub items: u32,
    /// Where the field's conditions start in the data page (`vec4`s; four a condition).
    pub conditions_at: u32,
    /// Conditions of the field.
    pub conditions: u32,
    /// Where its words (the jobs' images' scales, then the plan's mask) start in the
    /// data page (`vec4`s; four words each).
    pub words_at: u32,
    /// Where the plan's mask of conditions starts among its words.
    pub mask: u32,
    /// Where its light's record starts among the lights (`vec4`s).
    pub light_at: u32,
    /// Where its coefficients start in the coefficients' page (`vec4`s).
    pub coefficients_at: u32,
    /// Padding to 48 bytes.
    pub pad1: u32,
    /// Padding.
    pub pad2: u32,
    /// Padding.
    pub pad3: u32,
}

/// `TurnJob` of `turn_light.wgsl`: one view of a batch whose light the device looks up.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuTurnJob {
    /// Its first coefficient in the batch's coefficients.
    pub coefficient_offset: u32,
    /// Its basis images.
    pub tiles: u32,
    /// Its turntable angle, a fraction of a turn.
    pub turn: f32,
    /// 1 when it holds normals (room for the floor conditions' shares), else 0.
    pub normals: u32,
    /// Where its images' scales start among its relight's words.
    pub scales: u32,
    /// Padding to 32 bytes.
    pub pad1: u32,
    /// Padding.
    pub pad2: u32,
    /// Padding.
    pub pad3: u32,
}
