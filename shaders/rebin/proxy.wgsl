// The geometric proxy of rays clamped to a row, and of the solved morph's starting
// depth: the ray's first occupied voxel of the visual hull (3D DDA), else its point
// nearest the hull's vertical axis. Twin of `render/src/proxy.rs` and
// `VoxelHull::first_hit`; part of the frame pass (composed after `rebin.wgsl`).

// Where the ray `origin + t dir` (t >= 0) enters the pose's first occupied hull voxel, or
// -1 (`hull.wgsl`).
fn hull_first_hit(origin: vec3<f32>, dir: vec3<f32>) -> f32 {
    return hull_first_hit_of(proxy, 0u, origin, dir);
}

// The first hull hit of the ray an invocation shades, along its unit direction, walked
// once: every entry point of the frame pass shades one pixel an invocation, and the
// solved morph's starting point, a clamped ray's point and the walker's depth all ask it
// of that pixel's ray (from the frame's centre), which walked the hull twice before.
var<private> ray_hit: f32;
var<private> ray_walked: bool;

// `hull_first_hit` of the invocation's ray (`origin`, `unit`: its unit direction), walked
// the first time it is asked.
fn ray_first_hit(origin: vec3<f32>, unit: vec3<f32>) -> f32 {
    if (!ray_walked) {
        ray_hit = hull_first_hit(origin, unit);
        ray_walked = true;
    }
    return ray_hit;
}

// What a ray that misses the hull adds to the depth: twin of `proxy::MISS_DEPTH_M`.
const MISS_DEPTH_M: f32 = 1e4;

// The depth of the subject along the ray, metres: to the hull's first voxel, else
// MISS_DEPTH_M plus the distance to the ray's point nearest the subject's vertical axis (a
// vertical ray: its horizontal distance to the axis). Twin of `Proxy::depth`.
fn subject_depth(origin: vec3<f32>, dir_in: vec3<f32>) -> f32 {
    let dir = normalize_or_zero(dir_in);
    let t = ray_first_hit(origin, dir);
    if (t >= 0.0) {
        return t;
    }
    let o = origin.xz - proxy.axis;
    let d = dir.xz;
    let dd = dot(d, d);
    if (dd < 1e-8) {
        return MISS_DEPTH_M + length(o);
    }
    return MISS_DEPTH_M + max(-dot(o, d) / dd, 0.0);
}

// Where the ray meets the subject as far as the proxy knows (w = 1), or w = 0 without a
// hull and for a vertical ray beside it: twin of `Proxy::point` (walked along the unit
// direction, as the depth is).
fn proxy_point(origin: vec3<f32>, dir_in: vec3<f32>) -> vec4<f32> {
    if (proxy.present == 0u) {
        return vec4<f32>(0.0);
    }
    let dir = normalize_or_zero(dir_in);
    let t = ray_first_hit(origin, dir);
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
