// The frame pass: for every pixel of the virtual camera, re-bin its ray through the
// cylinder of camera centres and morph the quad's pre-lit images there. A full-screen
// triangle; the fragment shader is the twin of `render/src/cpu.rs` (`render_pixel`).
// Compiled after `common.wgsl`.
//
// Bind group 0 holds per-frame data, bind group 1 the resident pose.

@group(0) @binding(0) var<uniform> frame: Frame;
// Pixels inside the grid, clamped above, clamped below, missed.
@group(0) @binding(1) var<storage, read_write> stats: array<atomic<u32>, 4>;

// Pre-lit views: RGB sRGB codes of colour / scale, alpha code; one layer per view.
@group(1) @binding(0) var prelit: texture_2d_array<u32>;
// Flow codes (u, v); one layer per stored flow.
@group(1) @binding(1) var flows: texture_2d_array<i32>;
@group(1) @binding(2) var<storage, read> views: array<View>;
@group(1) @binding(3) var<storage, read> quads: array<Quad>;
@group(1) @binding(4) var<storage, read> tables: Tables;

fn srgb_value(code: u32) -> f32 {
    return tables.srgb[code / 4u][code % 4u];
}

fn flow_value(code: i32) -> f32 {
    let i = u32(code + 128);
    return tables.flow[i / 4u][i % 4u];
}

// Where the ray `origin + t dir` enters the cylinder: the smallest parameter of all
// intersections, unless all lie behind the camera.
fn intersect(origin: vec3<f32>, dir: vec3<f32>) -> Hit {
    var best = Hit(0u, 0u, 0.0, 0.0, vec3<f32>(0.0), 3.4e38, 3u);
    var any_ahead = false;
    for (var i = 0u; i < frame.quad_count; i++) {
        let q = quads[i];
        let denom = dot(q.normal, dir);
        if (abs(denom) < 1e-9) {
            continue;
        }
        let t = dot(q.normal, q.p00 - origin) / denom;
        let p = origin + dir * t;
        let r = inverse_bilinear(p, q.p00, q.e1, q.e2, q.e3, q.normal);
        if (!r.ok || outside(r.bg) > 1e-4) {
            continue;
        }
        if (t >= 0.0) {
            any_ahead = true;
        }
        if (t < best.t) {
            var gamma = clamp(r.bg.y, 0.0, 1.0);
            var clamped = 0u;
            if (q.wall != 0u) {
                gamma = q.wall_gamma;
                clamped = q.wall;
            }
            best = Hit(q.u, q.v, clamp(r.bg.x, 0.0, 1.0), gamma, p, t, clamped);
        }
    }
    if (!any_ahead) {
        best.clamped = 3u;
    }
    return best;
}

// Bilinear sample of a pre-lit view at full-image coordinates s (edge repeated).
fn sample_prelit(view: u32, s: vec2<f32>) -> vec4<f32> {
    let size = vec2<f32>(frame.crop_size);
    let x = clamp(s.x - f32(frame.crop_origin.x), -1.0, size.x);
    let y = clamp(s.y - f32(frame.crop_origin.y), -1.0, size.y);
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let scale = views[view].scale;
    let last = vec2<i32>(frame.crop_size) - vec2<i32>(1);
    var out = vec4<f32>(0.0);
    for (var dy = 0; dy < 2; dy++) {
        let wy = select(fy, 1.0 - fy, dy == 0);
        for (var dx = 0; dx < 2; dx++) {
            let wx = select(fx, 1.0 - fx, dx == 0);
            let xi = clamp(i32(x0) + dx, 0, last.x);
            let yi = clamp(i32(y0) + dy, 0, last.y);
            let t = textureLoad(prelit, vec2<i32>(xi, yi), i32(view), 0);
            let wt = wx * wy;
            out.x += wt * (scale * srgb_value(t.x));
            out.y += wt * (scale * srgb_value(t.y));
            out.z += wt * (scale * srgb_value(t.z));
            out.w += wt * f32(t.w) / 255.0;
        }
    }
    return out;
}

// Bilinear sample of the flow from a view toward `dir` (0 right, 1 left, 2 up, 3 down),
// each texel decoded first; unknown texels and absent flows displace by zero.
fn sample_flow(view: u32, dir: u32, s: vec2<f32>) -> vec2<f32> {
    let layer = views[view].flow_layers[dir];
    if (layer < 0) {
        return vec2<f32>(0.0);
    }
    let size = vec2<f32>(frame.crop_size);
    let x = clamp(s.x - f32(frame.crop_origin.x), -1.0, size.x);
    let y = clamp(s.y - f32(frame.crop_origin.y), -1.0, size.y);
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let last = vec2<i32>(frame.crop_size) - vec2<i32>(1);
    var out = vec2<f32>(0.0);
    for (var dy = 0; dy < 2; dy++) {
        let wy = select(fy, 1.0 - fy, dy == 0);
        for (var dx = 0; dx < 2; dx++) {
            let wx = select(fx, 1.0 - fx, dx == 0);
            let xi = clamp(i32(x0) + dx, 0, last.x);
            let yi = clamp(i32(y0) + dy, 0, last.y);
            let c = textureLoad(flows, vec2<i32>(xi, yi), layer, 0);
            if (c.x != -128 && c.y != -128) {
                out += vec2<f32>(flow_value(c.x), flow_value(c.y)) * (wx * wy);
            }
        }
    }
    return out;
}

const RIGHT: u32 = 0u;
const LEFT: u32 = 1u;
const UP: u32 = 2u;
const DOWN: u32 = 3u;

// The morph of the quad's views at s (see `render/src/morph.rs` for the derivation).
fn morph(hit: Hit, s: vec2<f32>) -> vec4<f32> {
    let q = quad_views(hit, frame.columns, frame.rows);
    let beta = hit.beta;
    let gamma = hit.gamma;
    let b = 1.0 - beta;
    let g = 1.0 - gamma;
    let w = bilinear_weights(beta, gamma);
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
        case 2u: {
            var p = q.x;
            var r = q.y;
            if (gamma >= 0.5) {
                p = q.z;
                r = q.w;
            }
            let fp = sample_flow(r, LEFT, s);
            let fr = sample_flow(p, RIGHT, s);
            out += sample_prelit(p, s + beta * fp) * b;
            out += sample_prelit(r, s + b * fr) * beta;
        }
        default: {
            let disp = array<vec2<f32>, 4>(
                beta * sample_flow(q.y, LEFT, s) + gamma * sample_flow(q.z, DOWN, s),
                b * sample_flow(q.x, RIGHT, s) + gamma * sample_flow(q.w, DOWN, s),
                beta * sample_flow(q.w, LEFT, s) + g * sample_flow(q.x, UP, s),
                b * sample_flow(q.z, RIGHT, s) + g * sample_flow(q.y, UP, s),
            );
            for (var i = 0u; i < 4u; i++) {
                if (w[i] > 0.0) {
                    out += sample_prelit(q[i], s + disp[i]) * w[i];
                }
            }
        }
    }
    return out;
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let dir = pixel_ray(frame, position);
    let hit = intersect(frame.centre.xyz, dir);
    if (hit.clamped == 3u) {
        atomicAdd(&stats[3], 1u);
        return vec4<f32>(0.0);
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
    let axes = quat_to_axes(quat * (1.0 / length(quat)));
    let dcam = vec3<f32>(dot(axes[0], dir), dot(axes[1], dir), dot(axes[2], dir));
    if (dcam.z <= 1e-6) {
        atomicAdd(&stats[3], 1u);
        return vec4<f32>(0.0);
    }
    let s = vec2<f32>(intr.x * dcam.x / dcam.z + intr.z, intr.y * dcam.y / dcam.z + intr.w);
    atomicAdd(&stats[hit.clamped], 1u);
    return morph(hit, s);
}
