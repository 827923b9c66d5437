// The frame pass: for every pixel of the virtual camera, re-bin its ray through the
// cylinder of camera centres and morph the quad's pre-lit images there; the twin of
// `render/src/cpu.rs` (`render_pixel`). Compiled after `common.wgsl` and two sampling
// snippets of `sample/` (how the pre-lit views and the flows are stored and filtered:
// `sample_prelit` and `sample_flow_layer`), chosen by `frf_render::gpu::formats`.
//
// The solved morph (variant 4) is in `morph/solved.wgsl`, composed after this file.
// Entry points: `fs_main` (a full-screen triangle into a colour target), `cs_main` (the
// same pixels from a compute pass into a storage texture, and what happened to each
// pixel's ray counted per workgroup, then once per workgroup into `stats`), `cs_classes`
// (those counts alone, for frames drawn by `fs_main`).
// Bind group 0 holds per-frame data, bind group 1 the resident pose.

@group(0) @binding(0) var<uniform> frame: Frame;
// Pixels inside the grid, clamped above, clamped below, missed (compute entry points).
@group(0) @binding(1) var<storage, read_write> stats: array<atomic<u32>, 4>;
// The compute pass's target (`cs_main` only).
@group(0) @binding(2) var target_image: texture_storage_2d<rgba32float, write>;

@group(1) @binding(2) var<storage, read> views: array<View>;
@group(1) @binding(3) var<storage, read> quads: array<Quad>;
@group(1) @binding(4) var<storage, read> tables: Tables;
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

const TAU: f32 = 6.2831855;

// What the search over quads keeps: the hit of smallest t (of equal ones, the first
// quad's, whatever the order), and whether any lies ahead. Twin of `Nearest`.
struct Nearest {
    hit: Hit,
    index: u32,
    any_ahead: bool,
}

// Offers the hit of the ray on quad i, if any (twin of `Quad::hit` and `Nearest::offer`).
fn offer(i: u32, origin: vec3<f32>, dir: vec3<f32>, n: ptr<function, Nearest>) {
    let q = quads[i];
    let denom = dot(q.normal, dir);
    if (abs(denom) < 1e-9) {
        return;
    }
    let t = dot(q.normal, q.p00 - origin) / denom;
    let p = origin + dir * t;
    let r = inverse_bilinear(p, q.p00, q.e1, q.e2, q.e3, q.normal);
    if (!r.ok || outside(r.bg) > 1e-4) {
        return;
    }
    if (t >= 0.0) {
        (*n).any_ahead = true;
    }
    if (t < (*n).hit.t || (t == (*n).hit.t && i < (*n).index)) {
        var gamma = clamp(r.bg.y, 0.0, 1.0);
        var clamped = 0u;
        if (q.wall != 0u) {
            gamma = q.wall_gamma;
            clamped = q.wall;
        }
        (*n).hit = Hit(q.u, q.v, clamp(r.bg.x, 0.0, 1.0), gamma, p, t, clamped);
        (*n).index = i;
    }
}

// The signed angle turning `start` into `end`, in (-pi, pi].
fn turn(start: vec2<f32>, end: vec2<f32>) -> f32 {
    return atan2(cross2(start, end), dot(start, end));
}

// Azimuth of v (relative to the axis point) in [0, 2 pi) (twin of `ColumnIndex::azimuth`).
fn column_azimuth(v: vec2<f32>) -> f32 {
    let s = column_index.header.orientation * turn(column_index.header.reference, v);
    return select(s, s + TAU, s < 0.0);
}

// Offers the quads of every span whose range meets the azimuths swept from `start` to
// `end` (twin of `ColumnIndex::walk`).
fn walk_spans(start: vec2<f32>, end: vec2<f32>, origin: vec3<f32>, dir: vec3<f32>, n: ptr<function, Nearest>) {
    let c = column_index.header;
    let sweep = c.orientation * turn(start, end);
    var a = column_azimuth(start);
    var len = sweep;
    if (sweep < 0.0) {
        a = column_azimuth(end);
        len = -sweep;
    }
    // Into (hi_last - 2 pi, hi_last].
    let last = column_index.ranges[c.spans - 1u].y;
    a -= TAU * ceil((a - last) / TAU);
    if (a > last) {
        a -= TAU;
    }
    if (a <= last - TAU) {
        a += TAU;
    }
    let b = a + len;
    // The first span whose range ends at or after a.
    var lo = 0u;
    var hi = c.spans;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (column_index.ranges[mid].y < a) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    for (var u = lo; u < c.spans && column_index.ranges[u].x <= b; u++) {
        for (var k = 0u; k < c.quads_per_span; k++) {
            offer(u * c.quads_per_span + k, origin, dir, n);
        }
    }
    // The same spans a turn later.
    for (var u = 0u; u < c.spans && column_index.ranges[u].x + TAU <= b; u++) {
        for (var k = 0u; k < c.quads_per_span; k++) {
            offer(u * c.quads_per_span + k, origin, dir, n);
        }
    }
}

// Where the ray `origin + t dir` enters the cylinder: the smallest parameter of all
// intersections, unless all lie behind the camera. Only the quads of the spans its line
// can reach are solved (twin of `ColumnIndex::spans_along`); all of them without an index.
fn intersect(origin: vec3<f32>, dir: vec3<f32>) -> Hit {
    var n = Nearest(Hit(0u, 0u, 0.0, 0.0, vec3<f32>(0.0), 3.4e38, 3u), 0xffffffffu, false);
    let c = column_index.header;
    let big = vec3<f32>(3.4e38);
    let finite_ray = all(abs(origin) <= big) && all(abs(dir) <= big);
    if (c.enabled == 0u || !finite_ray) {
        for (var i = 0u; i < frame.quad_count; i++) {
            offer(i, origin, dir, &n);
        }
    } else {
        let o = origin.xz - c.axis;
        let m = max(abs(dir.x), abs(dir.z));
        if (m == 0.0) {
            // Vertical: a point.
            let r = length(o);
            if (r >= c.r_min && r <= c.r_max) {
                walk_spans(o, o, origin, dir, &n);
            }
        } else {
            let d = normalize(dir.xz / m);
            let across = vec2<f32>(-d.y, d.x);
            let h = dot(o, across);
            if (abs(h) <= c.r_max) {
                let foot = across * h;
                let outer = sqrt(c.r_max * c.r_max - h * h);
                if (abs(h) >= c.r_min) {
                    walk_spans(foot - d * outer, foot + d * outer, origin, dir, &n);
                } else {
                    let inner = sqrt(c.r_min * c.r_min - h * h);
                    walk_spans(foot - d * outer, foot - d * inner, origin, dir, &n);
                    walk_spans(foot + d * inner, foot + d * outer, origin, dir, &n);
                }
            }
        }
    }
    var best = n.hit;
    if (!n.any_ahead) {
        best.clamped = 3u;
    }
    return best;
}

// Whether hull voxel `c` is occupied; outside the grid is empty.
fn hull_at(c: vec3<i32>) -> bool {
    let d = vec3<i32>(proxy.dims);
    if (any(c < vec3<i32>(0)) || any(c >= d)) {
        return false;
    }
    let index = u32((c.z * d.y + c.y) * d.x + c.x);
    return ((hull_bits[index / 32u] >> (index % 32u)) & 1u) == 1u;
}

// Where the ray `origin + t dir` (t >= 0) enters its first occupied hull voxel, or -1:
// twin of `VoxelHull::first_hit` (3D DDA).
fn hull_first_hit(origin: vec3<f32>, dir: vec3<f32>) -> f32 {
    if (proxy.present == 0u) {
        return -1.0;
    }
    let lo = proxy.origin;
    let hi = lo + vec3<f32>(proxy.dims) * proxy.voxel;
    var enter = 0.0;
    var exit = 3.4e38;
    for (var a = 0; a < 3; a++) {
        if (dir[a] == 0.0) {
            if (origin[a] < lo[a] || origin[a] > hi[a]) {
                return -1.0;
            }
            continue;
        }
        let t0 = (lo[a] - origin[a]) / dir[a];
        let t1 = (hi[a] - origin[a]) / dir[a];
        enter = max(enter, min(t0, t1));
        exit = min(exit, max(t0, t1));
    }
    if (enter > exit) {
        return -1.0;
    }
    let s = proxy.voxel;
    let dims = vec3<i32>(proxy.dims);
    let p = origin + dir * enter;
    var cell = vec3<i32>(0);
    var t_next = vec3<f32>(3.4e38);
    var t_delta = vec3<f32>(3.4e38);
    var step = vec3<i32>(0);
    for (var a = 0; a < 3; a++) {
        cell[a] = clamp(i32(floor((p[a] - lo[a]) / s)), 0, dims[a] - 1);
        if (dir[a] != 0.0) {
            step[a] = select(-1, 1, dir[a] > 0.0);
            let boundary = lo[a] + f32(cell[a] + select(0, 1, step[a] > 0)) * s;
            t_next[a] = (boundary - origin[a]) / dir[a];
            t_delta[a] = s / abs(dir[a]);
        }
    }
    var t_cell = enter;
    let steps = dims.x + dims.y + dims.z + 3;
    for (var i = 0; i < steps; i++) {
        if (hull_at(cell)) {
            return t_cell;
        }
        var a = 2;
        if (t_next.x <= t_next.y && t_next.x <= t_next.z) {
            a = 0;
        } else if (t_next.y <= t_next.z) {
            a = 1;
        }
        if (t_next[a] > exit) {
            return -1.0;
        }
        t_cell = t_next[a];
        cell[a] += step[a];
        t_next[a] += t_delta[a];
        if (cell[a] < 0 || cell[a] >= dims[a]) {
            return -1.0;
        }
    }
    return -1.0;
}

// Where the ray meets the subject as far as the proxy knows (w = 1), or w = 0 without a
// hull and for a vertical ray beside it: twin of `Proxy::point`.
fn proxy_point(origin: vec3<f32>, dir: vec3<f32>) -> vec4<f32> {
    if (proxy.present == 0u) {
        return vec4<f32>(0.0);
    }
    let t = hull_first_hit(origin, dir);
    if (t >= 0.0) {
        return vec4<f32>(origin + dir * t, 1.0);
    }
    let o = origin.xz - proxy.axis;
    let d = dir.xz;
    let dd = dot(d, d);
    if (dd < 1e-8) {
        return vec4<f32>(0.0);
    }
    let tn = max(-dot(o, d) / dd, 0.0);
    return vec4<f32>(origin + dir * tn, 1.0);
}

// Bilinear sample of the flow from a view toward `dir` (0 right, 1 left, 2 up, 3 down);
// absent flows displace by zero.
fn sample_flow(view: u32, dir: u32, s: vec2<f32>) -> vec2<f32> {
    let layer = views[view].flow_layers[dir];
    if (layer < 0) {
        return vec2<f32>(0.0);
    }
    return sample_flow_layer(layer, s);
}

const RIGHT: u32 = 0u;
const LEFT: u32 = 1u;
const UP: u32 = 2u;
const DOWN: u32 = 3u;

fn opposite(dir: u32) -> u32 {
    return dir ^ 1u;
}

// The occlusion cue's factor for a squared, fraction-weighted flow inconsistency
// (twin of `morph::e06::confidence`; sigma 2 px, floor 1e-3).
fn confidence(err2: f32) -> f32 {
    return max(exp(-err2 / 4.0), 1e-3);
}

// The displacement of a source by the flow stored on `view` toward `dir`, a fraction
// `frac` of it, and (when occlusion-aware) the squared inconsistency of that flow with
// the flow back from the source `src` (x, y: displacement; z: inconsistency).
fn displaced(src: u32, view: u32, dir: u32, back: u32, frac: f32, s: vec2<f32>, occlusion: bool) -> vec3<f32> {
    if (frac == 0.0) {
        return vec3<f32>(0.0);
    }
    let f = sample_flow(view, dir, s);
    var err2 = 0.0;
    if (occlusion) {
        let e = frac * (f + sample_flow(src, back, s + f));
        err2 = dot(e, e);
    }
    return vec3<f32>(frac * f, err2);
}

// E06's morphs of the quad's views at s (see `render/src/morph/e06.rs` for the derivation and
// the occlusion cue).
fn morph(hit: Hit, s: vec2<f32>) -> vec4<f32> {
    let q = quad_views(hit, frame.columns, frame.rows);
    let beta = hit.beta;
    let gamma = hit.gamma;
    let b = 1.0 - beta;
    let g = 1.0 - gamma;
    let w = bilinear_weights(beta, gamma);
    let occlusion = (frame.flags & 2u) != 0u;
    var out = vec4<f32>(0.0);
    switch frame.variant {
        case 0u: {
            // Nearest: the last vertex of largest weight.
            var k = 0u;
            for (var i = 1u; i < 4u; i++) {
                if (w[i] >= w[k]) {
                    k = i;
                }
            }
            out = sample_prelit(q[k], s);
        }
        case 1u: {
            for (var i = 0u; i < 4u; i++) {
                if (w[i] > 0.0) {
                    out += sample_prelit(q[i], s) * w[i];
                }
            }
        }
        default: {
            // Per source: its view, weight, and its two flows (stored on, toward, back
            // toward, fraction); the two-way morph uses the nearer row's two sources.
            var src = q;
            var weight = w;
            var flow_view = array<vec2<u32>, 4>(
                vec2<u32>(q.y, q.z), vec2<u32>(q.x, q.w), vec2<u32>(q.w, q.x), vec2<u32>(q.z, q.y),
            );
            let toward = array<vec2<u32>, 4>(
                vec2<u32>(LEFT, DOWN), vec2<u32>(RIGHT, DOWN), vec2<u32>(LEFT, UP), vec2<u32>(RIGHT, UP),
            );
            var frac = array<vec2<f32>, 4>(
                vec2<f32>(beta, gamma), vec2<f32>(b, gamma), vec2<f32>(beta, g), vec2<f32>(b, g),
            );
            if (frame.variant == 2u) {
                var p = q.x;
                var r = q.y;
                if (gamma >= 0.5) {
                    p = q.z;
                    r = q.w;
                }
                src = vec4<u32>(p, r, p, r);
                weight = vec4<f32>(b, beta, 0.0, 0.0);
                flow_view[0] = vec2<u32>(r, p);
                flow_view[1] = vec2<u32>(p, p);
                frac[0] = vec2<f32>(beta, 0.0);
                frac[1] = vec2<f32>(b, 0.0);
            }
            var total = 0.0;
            for (var i = 0u; i < 4u; i++) {
                if (weight[i] > 0.0) {
                    let d0 = displaced(src[i], flow_view[i].x, toward[i].x, opposite(toward[i].x), frac[i].x, s, occlusion);
                    let d1 = displaced(src[i], flow_view[i].y, toward[i].y, opposite(toward[i].y), frac[i].y, s, occlusion);
                    var wi = weight[i];
                    if (occlusion) {
                        wi *= confidence(d0.z + d1.z);
                    }
                    out += sample_prelit(src[i], s + (d0.xy + d1.xy)) * wi;
                    total += wi;
                }
            }
            if (occlusion && total > 0.0) {
                out /= total;
            }
        }
    }
    return out;
}

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
    if (frame.variant == 4u) {
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
    if ((frame.flags & 1u) != 0u && hit.clamped != 0u) {
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
    if (frame.variant == 4u) {
        return solved_morph(c.hit, c.solved);
    }
    return morph(c.hit, c.s);
}

// The premultiplied linear RGBA of the pixel at `position` (its centre).
fn shade(position: vec2<f32>) -> vec4<f32> {
    return shade_classified(classify(position));
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    return shade(position.xy);
}

// Per workgroup, how many of its pixels fell in each class; added to `stats` once.
var<workgroup> class_counts: array<atomic<u32>, 4>;

fn clear_counts(local: u32) {
    if (local < 4u) {
        atomicStore(&class_counts[local], 0u);
    }
    workgroupBarrier();
}

fn flush_counts(local: u32) {
    workgroupBarrier();
    if (local < 4u) {
        let n = atomicLoad(&class_counts[local]);
        if (n > 0u) {
            atomicAdd(&stats[local], n);
        }
    }
}

// The frame pass as a compute dispatch: shades and counts the pixel classes.
@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    clear_counts(local);
    if (id.x < frame.size.x && id.y < frame.size.y) {
        let c = classify(vec2<f32>(id.xy) + 0.5);
        textureStore(target_image, id.xy, shade_classified(c));
        atomicAdd(&class_counts[c.kind], 1u);
    }
    flush_counts(local);
}

// The pixel classes alone, for frames drawn by the fragment pass.
@compute @workgroup_size(8, 8)
fn cs_classes(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    clear_counts(local);
    if (id.x < frame.size.x && id.y < frame.size.y) {
        atomicAdd(&class_counts[classify(vec2<f32>(id.xy) + 0.5).kind], 1u);
    }
    flush_counts(local);
}
