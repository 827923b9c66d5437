// The solved four-way morph: each of the quad's views sampled where it shows the point
// the output pixel shows, found by a fixed-point solve through the view's own outgoing
// flows in the quad's rectified frame. Twin of `render/src/morph/solved.rs` (whose
// documentation derives it) and of `render/src/rectified.rs`; composed into the frame
// pass after `rebin.wgsl` (`frf_render::gpu::formats`).

// The rectified frame of a quad (`QuadFrame` of `render/src/rectified.rs`).
struct QuadFrame {
    // `world_from_rectified`: image right, image down, the plane's inward normal (w unused).
    axis_x: vec4<f32>,
    axis_y: vec4<f32>,
    axis_n: vec4<f32>,
    // fx, fy, cx, cy.
    intrinsics: vec4<f32>,
    // Per vertex A, B, C, D: the view's pixel to the rectified pixel, and back.
    to_rectified: array<mat3x3<f32>, 4>,
    from_rectified: array<mat3x3<f32>, 4>,
    // In-plane centres: A in .xy and B in .zw of the first, C and D of the second.
    centres: array<vec4<f32>, 2>,
    fixation_depth: f32,
    // 1 where the quad has a frame.
    valid: u32,
    pad: vec2<f32>,
}

// Per quad (u, v) of the grid, u-major, max(rows - 1, 1) per column.
@group(1) @binding(9) var<storage, read> quad_frames: array<QuadFrame>;

// Fixed-point steps per source at most (`solved::ITERATIONS`), and from the proxy's depth
// (`solved::PROXY_ITERATIONS`).
const SOLVE_ITERATIONS: i32 = 2;
const PROXY_ITERATIONS: i32 = 1;
// A step this short ends the iteration (`solved::SETTLED_PX`); last-step length at which
// a source weighs 1/e, and the least factor (`solved::SETTLE_PX`, `solved::SETTLE_FLOOR`).
const SETTLED_PX: f32 = 0.01;
const SETTLE_PX: f32 = 2.0;
const SETTLE_FLOOR: f32 = 1e-3;

// Twin of `rectified::apply`.
fn homography(h: mat3x3<f32>, p: vec2<f32>) -> vec2<f32> {
    let q = h * vec3<f32>(p, 1.0);
    var z = q.z;
    if (abs(z) < 1e-6) {
        z = 1e-6;
    }
    return vec2<f32>(q.x / z, q.y / z);
}

// The quad frame a hit lies in (twin of `PoseGeometry::quad_frame`).
fn frame_index(hit: Hit) -> u32 {
    let frame_rows = max(frame.rows, 2u) - 1u;
    return (hit.u % frame.columns) * frame_rows + min(hit.v, frame_rows - 1u);
}

fn frame_centre(f: u32, k: u32) -> vec2<f32> {
    let pair = quad_frames[f].centres[k / 2u];
    if (k % 2u == 0u) {
        return pair.xy;
    }
    return pair.zw;
}

fn to_plane(f: u32, p: vec3<f32>) -> vec3<f32> {
    let q = quad_frames[f];
    return vec3<f32>(dot(q.axis_x.xyz, p), dot(q.axis_y.xyz, p), dot(q.axis_n.xyz, p));
}

// The rectified pixel of a direction in .xy, and 1 in .z when it points into the plane's
// inner side (twin of `QuadFrame::project_direction`).
fn project_rectified(f: u32, dir: vec3<f32>) -> vec3<f32> {
    let d = to_plane(f, dir);
    if (d.z <= 1e-6 * length(dir)) {
        return vec3<f32>(0.0);
    }
    let k = quad_frames[f].intrinsics;
    return vec3<f32>(k.x * d.x / d.z + k.z, k.y * d.y / d.z + k.w, 1.0);
}

// The output camera of a ray (twin of `solved::Output`).
struct SolvedOutput {
    centre: vec2<f32>,
    s: vec2<f32>,
    inverse_depth: f32,
    // Fixed-point steps at most.
    steps: i32,
    ok: bool,
}

// Twin of `solved::output`.
fn solved_output(hit: Hit, origin: vec3<f32>, dir: vec3<f32>) -> SolvedOutput {
    var out: SolvedOutput;
    out.ok = false;
    let f = frame_index(hit);
    if (quad_frames[f].valid == 0u) {
        return out;
    }
    var point = vec4<f32>(0.0);
    if ((FLAGS & 1u) != 0u) {
        point = proxy_point(origin, dir);
    }
    var centre = hit.point;
    var r = vec3<f32>(0.0);
    if (hit.clamped == 0u || frame.rows == 1u) {
        // On the ray: inside the grid, and anywhere on a grid of one row.
        r = project_rectified(f, dir);
    } else {
        let q = quad_views(hit, frame.columns, frame.rows);
        let w = bilinear_weights(hit.beta, hit.gamma);
        centre = vec3<f32>(0.0);
        for (var i = 0u; i < 4u; i++) {
            centre += views[q[i]].centre * w[i];
        }
        if (point.w > 0.0) {
            r = project_rectified(f, point.xyz - centre);
        } else {
            r = project_rectified(f, dir);
        }
    }
    if (r.z == 0.0) {
        return out;
    }
    let plane = to_plane(f, centre);
    var inverse_depth = 1.0 / quad_frames[f].fixation_depth;
    out.steps = SOLVE_ITERATIONS;
    if (point.w > 0.0) {
        let v = 1.0 / (to_plane(f, point.xyz).z - plane.z);
        if (finite(v) && v > 0.0) {
            inverse_depth = v;
            out.steps = PROXY_ITERATIONS;
        }
    }
    out.centre = plane.xy;
    out.s = r.xy;
    out.inverse_depth = inverse_depth;
    out.ok = true;
    return out;
}

// Twin of `solved::fractions`.
fn solve_fractions(f: u32, k: u32, vertical: bool, to: vec2<f32>) -> vec2<f32> {
    let c = frame_centre(f, k);
    let o = to - c;
    let b1 = frame_centre(f, k ^ 1u) - c;
    let b2 = frame_centre(f, k ^ 2u) - c;
    let det = cross2(b1, b2);
    if (vertical && abs(det) > 1e-9) {
        return vec2<f32>(cross2(o, b2) / det, cross2(b1, o) / det);
    }
    return vec2<f32>(dot(o, b1) / max(dot(b1, b1), 1e-12), 0.0);
}

// Twin of `solved::solve`: the pixel of vertex k that shows the output's point (.xy) and
// the length of the last fixed-point step (.z).
fn solve_source(f: u32, q: vec4<u32>, k: u32, out: SolvedOutput) -> vec3<f32> {
    let h = k ^ 1u;
    let v = k ^ 2u;
    let vertical = q[v] != q[k];
    let ac = solve_fractions(f, k, vertical, out.centre);
    let toward_h = select(LEFT, RIGHT, k % 2u == 0u);
    let toward_v = select(DOWN, UP, k < 2u);
    let view = q[k];
    let k_f = quad_frames[f].intrinsics;
    let focal = vec2<f32>(k_f.x, k_f.y);
    // Without a vertical partner: the output's offset across the row, moved by the
    // inverse depth the row's flow measures.
    var across = vec2<f32>(0.0);
    var along = vec2<f32>(0.0);
    if (!vertical) {
        let c = frame_centre(f, k);
        let b = frame_centre(f, h) - c;
        across = (out.centre - c - b * ac.x) * focal;
        let p = b * focal;
        along = p / max(dot(p, p), 1e-12);
    }
    // `here` is H_X(x); after a step it is s - D by construction.
    var here = out.s + (out.centre - frame_centre(f, k)) * vec2<f32>(k_f.x, k_f.y) * out.inverse_depth;
    var x = homography(quad_frames[f].from_rectified[k], here);
    var step = 0.0;
    for (var i = 0; i < out.steps; i++) {
        var d = vec2<f32>(0.0);
        if (ac.x != 0.0 || any(across != vec2<f32>(0.0))) {
            let fh = sample_flow(view, toward_h, x);
            let d_h = homography(quad_frames[f].to_rectified[h], x + fh) - here;
            d += ac.x * d_h + across * dot(d_h, along);
        }
        if (ac.y != 0.0) {
            let fv = sample_flow(view, toward_v, x);
            d += ac.y * (homography(quad_frames[f].to_rectified[v], x + fv) - here);
        }
        here = out.s - d;
        let next = homography(quad_frames[f].from_rectified[k], here);
        step = length(next - x);
        x = next;
        if (step < SETTLED_PX) {
            break;
        }
    }
    return vec3<f32>(x, step);
}

// Twin of `solved::shade` (after its output).
fn solved_morph(hit: Hit, out: SolvedOutput) -> vec4<f32> {
    let f = frame_index(hit);
    let q = quad_views(hit, frame.columns, frame.rows);
    let w = bilinear_weights(hit.beta, hit.gamma);
    var acc = vec4<f32>(0.0);
    var total = 0.0;
    for (var k = 0u; k < 4u; k++) {
        if (w[k] <= 0.0) {
            continue;
        }
        let r = solve_source(f, q, k, out);
        let settle = r.z / SETTLE_PX;
        let wk = w[k] * max(exp(-(settle * settle)), SETTLE_FLOOR);
        acc += sample_prelit(q[k], r.xy) * wk;
        total += wk;
    }
    if (total > 0.0) {
        acc /= total;
    }
    return acc;
}
