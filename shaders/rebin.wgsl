// The frame pass: for every pixel of the virtual camera, re-bin its ray through the
// cylinder of camera centres and morph the quad's pre-lit images there; the twin of
// `render/src/cpu.rs` (`render_pixel`). Compiled after `common.wgsl` and two sampling
// snippets of `sample/` (how the pre-lit views and the flows are stored and filtered:
// `sample_prelit` and `sample_flow_layer`), chosen by `frf_render::gpu::formats`.
//
// Composed after it: the re-binning through the cylinder (`rebin/cylinder.wgsl`), the
// geometric proxy (`rebin/proxy.wgsl`), E06's morphs (`morph/e06.wgsl`) and the solved
// morph (`morph/solved.wgsl`, variant 4).
// Entry points: `fs_main` (a full-screen triangle into a colour target, scissored to the
// frame's bounds), `cs_main` (the pixels of the frame's bounds from a compute pass into a
// storage texture, and the pixels whose rays were clamped or missed counted into
// `stats`), `cs_classes` (those counts alone, for frames drawn by `fs_main`).
// Bind group 0 holds per-frame data, bind group 1 the resident pose.
//
// A module is compiled per morph (`frf_render::morph::Variant`): its interpolation `KIND`
// (`Variant::index`: 0 nearest, 1 linear, 2 two-way, 3 E06's four-way, 4 the solved
// four-way) and its refinements `FLAGS` (`Variant::flags`: 1 rays beyond the rows through
// the proxy, 2 occlusion-aware morphs) are constants written before the pass
// (`frf_shaders::frame_pass`), so the shader compiled holds that morph alone.

// The frames' records, 256 bytes apart (`FRAME_STRIDE` in render/src/gpu/rebin.rs): a
// render's own first. A compute dispatch of several renders of one pose reads render z's
// at z (`FRAMES_BOUND` at most); every entry point copies its record into `frame`.
struct FrameRecord {
    f: Frame,
    pad: array<vec4<u32>, 4>,
}
@group(0) @binding(0) var<uniform> frames: array<FrameRecord, 256>;
var<private> frame: Frame;
// Pixels clamped above, clamped below and missed, at 1 to 3 (compute entry points; those
// inside the grid, the rest of the shaded pixels, are not counted: a count of every pixel
// would be an atomic per pixel on one word).
@group(0) @binding(1) var<storage, read_write> stats: array<atomic<u32>, 4>;
// The compute pass's target (`cs_main` only): pixel p of the frame goes to texel
// p + frame.place.xy of layer frame.place.z.
@group(0) @binding(2) var target_image: texture_storage_2d_array<rgba32float, write>;
// Beside it when `frame.depth` is 1 (`cs_main` only): the walker's depth at the pixel
// (`subject_depth`), which orders walkers that overlap in the composite.
@group(0) @binding(3) var depth_image: texture_storage_2d_array<r32float, write>;

// The shared pages of pose copies (`render/src/gpu/prelit.rs`): a render's views'
// heads from word `frame.prelit.x`, 8 words a view: its pre-lit scale (f32 bits), its
// pre-lit layer (-1: not held, transparent), two unused, its flow layers toward right,
// left, up, down (-1: none stored); its pre-lit codes from `frame.prelit.y`.
@group(1) @binding(0) var<storage, read> prelit: array<u32>;
@group(1) @binding(2) var<storage, read> views: array<View>;
@group(1) @binding(3) var<storage, read> quads: array<Quad>;
@group(1) @binding(4) var<uniform> tables: Tables;
@group(1) @binding(5) var<storage, read> proxy: Proxy;
// The hull's occupancy: voxel i at bit i % 32 of word i / 32.
@group(1) @binding(6) var<storage, read> hull_bits: array<u32>;
@group(1) @binding(7) var<storage, read> column_index: ColumnLookup;

// The column index, and per span its range of azimuths [lo, hi].
struct ColumnLookup {
    header: ColumnIndex,
    ranges: array<vec2<f32>>,
}

// Bilinear, clamped to the edge: for the formats the hardware filters.
@group(1) @binding(8) var bilinear: sampler;

// The four texels (in the crop) and weights of a bilinear sample at full-image
// coordinates s, texel centres at integers, the edge repeated.
struct CropSample {
    texel: array<vec2<i32>, 4>,
    weight: vec4<f32>,
}

fn crop_position(s: vec2<f32>) -> CropSample {
    let size = vec2<f32>(frame.crop_size);
    let p = clamp(s - vec2<f32>(frame.crop_origin), vec2<f32>(-1.0), size);
    let p0 = floor(p);
    let f = p - p0;
    let last = vec2<i32>(frame.crop_size) - vec2<i32>(1);
    let a = clamp(vec2<i32>(p0), vec2<i32>(0), last);
    let b = clamp(vec2<i32>(p0) + vec2<i32>(1), vec2<i32>(0), last);
    var out: CropSample;
    out.texel = array<vec2<i32>, 4>(a, vec2<i32>(b.x, a.y), vec2<i32>(a.x, b.y), b);
    out.weight = vec4<f32>((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
    return out;
}

// The sampler's coordinates of full-image position s (texel centres at integers).
fn crop_uv(s: vec2<f32>) -> vec2<f32> {
    return (s - vec2<f32>(frame.crop_origin) + 0.5) / vec2<f32>(frame.crop_size);
}

// Where view `view`'s head starts in `prelit`.
fn view_head(view: u32) -> u32 {
    return frame.prelit.x + view * 8u;
}

// The view's pre-lit colour scale.
fn view_scale(view: u32) -> f32 {
    return bitcast<f32>(prelit[view_head(view)]);
}

// The view's pre-lit layer; -1 for a view not held.
fn prelit_layer(view: u32) -> i32 {
    return bitcast<i32>(prelit[view_head(view) + 1u]);
}

// Bilinear sample of the flow from a view toward `dir` (0 right, 1 left, 2 up, 3 down);
// absent flows displace by zero.
fn sample_flow(view: u32, dir: u32, s: vec2<f32>) -> vec2<f32> {
    let layer = bitcast<i32>(prelit[view_head(view) + 4u + dir]);
    if (layer < 0) {
        return vec2<f32>(0.0);
    }
    return sample_flow_layer(layer, s);
}

// The neighbour directions, as `Neighbour::index` numbers them.
const RIGHT: u32 = 0u;
const LEFT: u32 = 1u;
const UP: u32 = 2u;
const DOWN: u32 = 3u;

// Where a pixel's ray samples the views: its hit on the cylinder, the position s in the
// interpolated camera (the solved morph: its output camera instead), and its class (0
// inside, 1 clamped above, 2 below, 3 missed).
struct Classified {
    hit: Hit,
    s: vec2<f32>,
    solved: SolvedOutput,
    kind: u32,
}

fn classify(position: vec2<f32>) -> Classified {
    var out: Classified;
    let dir = pixel_ray(frame, vec4<f32>(position, 0.0, 1.0));
    let hit = intersect(frame.centre.xyz, dir);
    out.hit = hit;
    out.kind = 3u;
    if (hit.clamped == 3u) {
        return out;
    }
    if (KIND == 4u) {
        // The solved morph looks the ray up in the quad's rectified frame.
        out.solved = solved_output(hit, frame.centre.xyz, dir);
        if (out.solved.ok) {
            out.kind = hit.clamped;
        }
        return out;
    }
    let q = quad_views(hit, frame.columns, frame.rows);
    // The camera at (beta, gamma), centred at the hit.
    let w = bilinear_weights(hit.beta, hit.gamma);
    let q0 = views[q.x].rotation;
    var quat = vec4<f32>(0.0);
    var intr = vec4<f32>(0.0);
    for (var i = 0u; i < 4u; i++) {
        var qi = views[q[i]].rotation;
        if (dot(qi, q0) < 0.0) {
            qi = -qi;
        }
        quat += qi * w[i];
        intr += views[q[i]].intrinsics * w[i];
    }
    // Clamped to a row: the ray's point on the proxy, seen from the camera on the row.
    var ray = dir;
    if ((FLAGS & 1u) != 0u && hit.clamped != 0u) {
        let point = proxy_point(frame.centre.xyz, dir);
        if (point.w > 0.0) {
            var centre = vec3<f32>(0.0);
            for (var i = 0u; i < 4u; i++) {
                centre += views[q[i]].centre * w[i];
            }
            ray = point.xyz - centre;
        }
    }
    let axes = quat_to_axes(quat * (1.0 / length(quat)));
    let dcam = vec3<f32>(dot(axes[0], ray), dot(axes[1], ray), dot(axes[2], ray));
    if (dcam.z <= 1e-6 * length(ray)) {
        return out;
    }
    out.s = vec2<f32>(intr.x * dcam.x / dcam.z + intr.z, intr.y * dcam.y / dcam.z + intr.w);
    out.kind = hit.clamped;
    return out;
}

// The premultiplied linear RGBA of a classified pixel.
fn shade_classified(c: Classified) -> vec4<f32> {
    if (c.kind == 3u) {
        return vec4<f32>(0.0);
    }
    if (KIND == 4u) {
        return solved_morph(c.hit, c.solved);
    }
    return morph(c.hit, c.s);
}

// The premultiplied linear RGBA of the pixel at `position` (its centre).
fn shade(position: vec2<f32>) -> vec4<f32> {
    return shade_classified(classify(position));
}

// Drawn into the layer `frame.place.z`, where frame pixel p lies at p + frame.place.xy.
@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    frame = frames[0].f;
    return shade(position.xy - vec2<f32>(frame.place.xy));
}

// Counts a pixel of class `kind` (those inside are not counted, see `stats`).
fn count_class(kind: u32) {
    if (kind != 0u) {
        atomicAdd(&stats[kind], 1u);
    }
}

// The record of the dispatch whose tiles hold tile `w` (the last whose first tile is at
// or before it), by bisection over the dispatch's records.
fn record_of_tile(w: u32) -> u32 {
    var lo = 0u;
    var hi = frames[0].f.tiles.w;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (frames[mid].f.tiles.x <= w) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// The frame pass as a compute dispatch: shades and counts the pixel classes. Its
// workgroups are the 8x8 tiles of every render's bounds one after another (`tiles` of
// the records), rows of them when they outnumber a dimension's workgroups.
@compute @workgroup_size(8, 8)
fn cs_main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
) {
    let w = group.y * groups.x + group.x;
    frame = frames[record_of_tile(w)].f;
    let t = w - frame.tiles.x;
    if (t >= frame.tiles.z) {
        return;
    }
    let p = vec2<u32>(t % frame.tiles.y, t / frame.tiles.y) * 8u + local.xy + frame.bounds.xy;
    if (all(p < frame.bounds.zw)) {
        let c = classify(vec2<f32>(p) + 0.5);
        let at = vec2<i32>(p) + frame.place.xy;
        textureStore(target_image, at, frame.place.z, shade_classified(c));
        if (frame.depth == 1u) {
            let dir = pixel_ray(frame, vec4<f32>(vec2<f32>(p) + 0.5, 0.0, 1.0));
            textureStore(depth_image, at, frame.place.z, vec4<f32>(subject_depth(frame.centre.xyz, dir)));
        }
        count_class(c.kind);
    }
}

// The pixel classes alone, for frames drawn by the fragment pass.
@compute @workgroup_size(8, 8)
fn cs_classes(@builtin(global_invocation_id) id: vec3<u32>) {
    frame = frames[id.z].f;
    let p = id.xy + frame.bounds.xy;
    if (all(p < frame.bounds.zw)) {
        count_class(classify(vec2<f32>(p) + 0.5).kind);
    }
}
