// A sun's map of a pose's visual hull (docs/design.md section 4.1), made on the GPU: per
// texel of a grid across the sun, how far toward the sun the hull reaches along the
// texel's line, the largest `toward . p` of its occupied points there (`f32::MIN` where
// the line misses it). One invocation a texel walks the hull from a texel beyond its box
// on the sun's side (`hull_first_hit` of `rebin/proxy.wgsl`, composed after this file);
// the relight pass then reads the map. Twin of `SunDepth::reach`
// (`reflectance/src/sun_depth.rs`). Compiled after `common.wgsl`, with the proxy after it.

// One sun's map: its frame (set on the host, `SunDepth::new`) and where its values go.
struct SunDepthJob {
    // Unit, toward the sun (subject frame); w: `far`, `toward . p` where rays start.
    toward: vec4<f32>,
    // The map's x and y axes (xyz) and its corner's x and y (w).
    axis_x: vec4<f32>,
    axis_y: vec4<f32>,
    // Texels along x and y, where its values start in `reach`, 1 when in use.
    size: vec4<u32>,
    // Texel side, metres (x).
    texel: vec4<f32>,
}

// The pose's hull, as the frame pass binds it.
@group(0) @binding(0) var<storage, read> proxy: Proxy;
@group(0) @binding(1) var<storage, read> hull_bits: array<u32>;
@group(0) @binding(2) var<storage, read> jobs: array<SunDepthJob>;
// Every sun's map, one after the other (x fastest).
@group(0) @binding(3) var<storage, read_write> reach: array<f32>;

// f32's lowest finite value: a line that misses the hull.
const MISSES: f32 = -3.4028235e38;

// Another walker's hull walked along a walker's map (`SunDepth::with_occluders`): the
// map's job (its `far` beyond both hulls) and `there_from_here`, the walker's frame into
// the occluder's (rotation columns, translation). The occluder's hull is bound as
// `proxy` and `hull_bits`.
struct SunOccluderJob {
    map: SunDepthJob,
    there_x: vec4<f32>,
    there_y: vec4<f32>,
    there_z: vec4<f32>,
    there_t: vec4<f32>,
}

@group(0) @binding(4) var<storage, read> occluder_jobs: array<SunOccluderJob>;

// One texel (x) of the map of sun slot y.
@compute @workgroup_size(64)
fn sun_depth(@builtin(global_invocation_id) id: vec3<u32>) {
    let job = jobs[id.y];
    let i = id.x;
    if (job.size.w == 0u || i >= job.size.x * job.size.y) {
        return;
    }
    let q = vec2<f32>(job.axis_x.w, job.axis_y.w)
        + (vec2<f32>(f32(i % job.size.x), f32(i / job.size.x)) + 0.5) * job.texel.x;
    let d = job.toward.xyz;
    let far = job.toward.w;
    let origin = job.axis_x.xyz * q.x + job.axis_y.xyz * q.y + d * far;
    let t = hull_first_hit(origin, -d);
    reach[job.size.z + i] = select(MISSES, far - t, t >= 0.0);
}

// One texel (x) of the map of occluder job y: the reach there raised to the occluder's
// where it lies farther toward the sun. Runs after `sun_depth` made the map.
@compute @workgroup_size(64)
fn sun_occluder(@builtin(global_invocation_id) id: vec3<u32>) {
    let o = occluder_jobs[id.y];
    let job = o.map;
    let i = id.x;
    if (job.size.w == 0u || i >= job.size.x * job.size.y) {
        return;
    }
    let q = vec2<f32>(job.axis_x.w, job.axis_y.w)
        + (vec2<f32>(f32(i % job.size.x), f32(i / job.size.x)) + 0.5) * job.texel.x;
    let d = job.toward.xyz;
    let far = job.toward.w;
    let origin = job.axis_x.xyz * q.x + job.axis_y.xyz * q.y + d * far;
    let there = mat3x3<f32>(o.there_x.xyz, o.there_y.xyz, o.there_z.xyz);
    let t = hull_first_hit(there * origin + o.there_t.xyz, there * -d);
    if (t >= 0.0) {
        reach[job.size.z + i] = max(reach[job.size.z + i], far - t);
    }
}
