// Shared by the renderer's passes (prepended to them when they are compiled): the
// structures mirrored by `src/types.rs` (a test checks their sizes against
// this file), and the pure functions of light-field re-binning, twins of
// `render/src/cylinder.rs` and `render/src/morph/` operation for operation.

// One view of the pose: its camera (what a copy of the pose read of it, its scale and
// layers, lies with the copy's pre-lit views: `render/src/gpu/prelit.rs`).
struct View {
    // Orientation of `world_from_camera`, a quaternion (x, y, z, w).
    rotation: vec4<f32>,
    // Camera centre (subject frame).
    centre: vec3<f32>,
    pad: f32,
    // fx, fy, cx, cy.
    intrinsics: vec4<f32>,
}

// A quad of the cylinder of camera centres (or a wall above / below the grid).
struct Quad {
    p00: vec3<f32>,
    u: u32,
    e1: vec3<f32>,
    v: u32,
    e2: vec3<f32>,
    // 0: inside the grid, 1: wall above the top row, 2: wall below the bottom row.
    wall: u32,
    e3: vec3<f32>,
    wall_gamma: f32,
    normal: vec3<f32>,
    pad: f32,
}

// The header of a cylinder's column index (`render/src/cylinder/column_index.rs`): which
// column spans a ray's line can reach, seen from above.
struct ColumnIndex {
    // (x, z) of the axis point A, and the unit direction from it of azimuth 0.
    axis: vec2<f32>,
    reference: vec2<f32>,
    // 1 when the columns run counterclockwise in (x, z), -1 otherwise.
    orientation: f32,
    // The annulus about A holding every quad's footprint.
    r_min: f32,
    r_max: f32,
    spans: u32,
    quads_per_span: u32,
    // 0: every quad is solved.
    enabled: u32,
}

// What a frame renders.
struct Frame {
    // The virtual camera: `world_from_camera` columns, centre, intrinsics.
    axis_x: vec4<f32>,
    axis_y: vec4<f32>,
    axis_z: vec4<f32>,
    centre: vec4<f32>,
    intrinsics: vec4<f32>,
    size: vec2<u32>,
    // The morph the frame is drawn with (the frame pass reads its pipeline's overrides
    // `KIND` and `FLAGS` instead; these say what it was given).
    variant: u32,
    quad_count: u32,
    columns: u32,
    rows: u32,
    crop_origin: vec2<u32>,
    crop_size: vec2<u32>,
    // Its refinements: 1 rays beyond the rows through the proxy, 2 occlusion-aware morphs.
    flags: u32,
    // 1: the compute frame pass also writes the walker's depth (`subject_depth`).
    depth: u32,
    // The pixels shaded, [x0, y0, x1, y1] (ends exclusive): the walker is transparent
    // outside them (`render/src/footprint.rs`).
    bounds: vec4<u32>,
    // Where the frame pass writes: pixel p of the frame at texel p + place.xy of layer
    // place.z of its target (`render/src/atlas.rs`; w unused).
    place: vec4<i32>,
    // Where the pose's copy lies in the shared pages bound beside it (words; x its views'
    // heads: scale, pre-lit layer and flow layers, y its first pre-lit layer's codes,
    // z its flows' codes; `render/src/gpu/prelit.rs`).
    prelit: vec4<u32>,
    // The compute frame pass's 8x8 tiles of `bounds`, numbered across its dispatch: x the
    // render's first, y its tiles across, z its tiles; w (the dispatch's first record
    // only) the renders of the dispatch.
    tiles: vec4<u32>,
}

// The pose's geometric proxy: the visual hull's grid (its bits are bound beside it) and
// the vertical axis of the fallback (`render/src/proxy.rs`).
struct Proxy {
    origin: vec3<f32>,
    voxel: f32,
    dims: vec3<u32>,
    // 1 when the pose has a hull.
    present: u32,
    axis: vec2<f32>,
    // Where the hull's blocks' bits start in its words, and voxels along a block's side.
    block_words_at: u32,
    block: u32,
}

// sRGB code -> linear, and flow code + 128 -> displacement (unknown -> 0).
struct Tables {
    srgb: array<vec4<f32>, 64>,
    flow: array<vec4<f32>, 64>,
}

// One triangle covering the viewport: the vertex stage of every full-screen pass.
@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

// The unit direction (subject frame) of the ray through the pixel of a fragment at
// `position`; pixel (x, y) has its centre at integer coordinates (docs/conventions.md).
fn pixel_ray(f: Frame, position: vec4<f32>) -> vec3<f32> {
    let pixel = floor(position.xy);
    let k = f.intrinsics;
    let dc = vec3<f32>((pixel.x - k.z) / k.x, (pixel.y - k.w) / k.y, 1.0);
    return normalize(f.axis_x.xyz * dc.x + f.axis_y.xyz * dc.y + f.axis_z.xyz * dc.z);
}

fn normalize_or_zero(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if (l > 0.0) {
        return v / l;
    }
    return vec3<f32>(0.0);
}

fn cross2(m: vec2<f32>, n: vec2<f32>) -> f32 {
    return m.x * n.y - m.y * n.x;
}

// How far (beta, gamma) lies outside the unit square.
fn outside(bg: vec2<f32>) -> f32 {
    let dx = max(max(-bg.x, bg.x - 1.0), 0.0);
    let dy = max(max(-bg.y, bg.y - 1.0), 0.0);
    return dx + dy;
}

struct Bilinear {
    bg: vec2<f32>,
    ok: bool,
}

fn beta_for(g: f32, q: vec2<f32>, a: vec2<f32>, b: vec2<f32>, c: vec2<f32>) -> f32 {
    let d = a + c * g;
    if (abs(d.x) >= abs(d.y)) {
        return (q.x - g * b.x) / d.x;
    }
    return (q.y - g * b.y) / d.y;
}

fn finite(x: f32) -> bool {
    // NaN fails both comparisons; infinities exceed the largest finite f32.
    return abs(x) <= 3.4e38;
}

// The inverse bilinear map on a quad, in its plane.
fn inverse_bilinear(p: vec3<f32>, p00: vec3<f32>, e1: vec3<f32>, e2: vec3<f32>, e3: vec3<f32>, normal: vec3<f32>) -> Bilinear {
    let x_axis = normalize_or_zero(e1);
    let y_axis = cross(normal, x_axis);
    let q = vec2<f32>(dot(p - p00, x_axis), dot(p - p00, y_axis));
    let a = vec2<f32>(dot(e1, x_axis), dot(e1, y_axis));
    let b = vec2<f32>(dot(e2, x_axis), dot(e2, y_axis));
    let c = vec2<f32>(dot(e3, x_axis), dot(e3, y_axis));
    let k2 = cross2(c, b);
    let k1 = cross2(a, b) - cross2(c, q);
    let k0 = -cross2(a, q);
    let scale = max(max(abs(k1), abs(k0)), 1e-30);
    var best = Bilinear(vec2<f32>(0.0), false);
    var best_out = 3.4e38;
    var roots = array<f32, 2>(0.0, 0.0);
    var count = 0;
    if (abs(k2) <= 1e-6 * scale) {
        if (abs(k1) < 1e-30) {
            return best;
        }
        roots[0] = -k0 / k1;
        count = 1;
    } else {
        let disc = k1 * k1 - 4.0 * k2 * k0;
        if (disc < 0.0) {
            return best;
        }
        let s = sqrt(disc);
        let qq = -0.5 * (k1 + select(-1.0, 1.0, k1 >= 0.0) * s);
        roots[0] = qq / k2;
        count = 1;
        if (abs(qq) > 1e-30) {
            roots[1] = k0 / qq;
            count = 2;
        }
    }
    for (var i = 0; i < count; i++) {
        let g = roots[i];
        let beta = beta_for(g, q, a, b, c);
        if (!finite(beta)) {
            continue;
        }
        let bg = vec2<f32>(beta, g);
        let o = outside(bg);
        if (o < best_out) {
            best_out = o;
            best = Bilinear(bg, true);
        }
    }
    return best;
}

struct Hit {
    u: u32,
    v: u32,
    beta: f32,
    gamma: f32,
    point: vec3<f32>,
    t: f32,
    // 0: inside, 1: above, 2: below; 3: no hit.
    clamped: u32,
}

fn quat_to_axes(q: vec4<f32>) -> mat3x3<f32> {
    let x2 = q.x + q.x;
    let y2 = q.y + q.y;
    let z2 = q.z + q.z;
    let xx = q.x * x2;
    let xy = q.x * y2;
    let xz = q.x * z2;
    let yy = q.y * y2;
    let yz = q.y * z2;
    let zz = q.z * z2;
    let wx = q.w * x2;
    let wy = q.w * y2;
    let wz = q.w * z2;
    return mat3x3<f32>(
        vec3<f32>(1.0 - (yy + zz), xy + wz, xz - wy),
        vec3<f32>(xy - wz, 1.0 - (xx + zz), yz + wx),
        vec3<f32>(xz + wy, yz - wx, 1.0 - (xx + yy)),
    );
}

fn bilinear_weights(beta: f32, gamma: f32) -> vec4<f32> {
    let b = 1.0 - beta;
    let g = 1.0 - gamma;
    return vec4<f32>(b * g, beta * g, b * gamma, beta * gamma);
}

// Views A, B, C, D of the quad of a hit.
fn quad_views(hit: Hit, columns: u32, rows: u32) -> vec4<u32> {
    var top = hit.v;
    if (rows > 1u) {
        top = hit.v + 1u;
    }
    let bottom = min(hit.v, rows - 1u);
    let upper = min(top, rows - 1u);
    let a = (hit.u % columns) * rows + bottom;
    let b = ((hit.u + 1u) % columns) * rows + bottom;
    let c = (hit.u % columns) * rows + upper;
    let d = ((hit.u + 1u) % columns) * rows + upper;
    return vec4<u32>(a, b, c, d);
}
