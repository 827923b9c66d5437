// The geometric proxy of rays clamped to a row, and of the solved morph's starting
// depth: the ray's first occupied voxel of the visual hull (3D DDA), else its point
// nearest the hull's vertical axis. Twin of `render/src/proxy.rs` and
// `VoxelHull::first_hit`; part of the frame pass (composed after `rebin.wgsl`).

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
