// The suns' maps of every walker relit between two frames, in one dispatch (docs/design.md
// section 4.1): per texel of a grid across a sun, how far toward the sun a walker's hull,
// and the hulls of the other walkers in the way of its sun, reach along the texel's line:
// the largest `toward . p` of their occupied points there (`f32::MIN` where the line
// misses them all). One invocation a texel (x) of a map (y) walks its walker's hull and
// then each occluder's from a texel beyond their boxes on the sun's side
// (`hull_first_hit_of`, `rebin/hull.wgsl`, composed after this file); the relight pass
// then reads the maps. Every hull walked sits in one table of hulls over one array of
// words, so that a crowd's maps are one dispatch, not one per walker and occluder. Twin of
// `SunDepth::reach` (`reflectance/src/sun_depth.rs`). Compiled after `common.wgsl`.

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

// A map to make: its frame, the walker's own hull (x: its entry in `hulls`), and the
// occluders walked after it (y: the first in `occluders`, z: how many).
struct SunMap {
    map: SunDepthJob,
    hulls: vec4<u32>,
}

// A hull of the table: its grid, and (x) where its words start in `hull_bits`.
struct HullAt {
    proxy: Proxy,
    at: vec4<u32>,
}

// Another walker's hull walked along a walker's map (`SunDepth::with_occluders`): its
// entry in `hulls` (x), and `there_from_here`, the walker's frame into the occluder's
// (rotation columns, translation).
struct SunOccluder {
    hull: vec4<u32>,
    there_x: vec4<f32>,
    there_y: vec4<f32>,
    there_z: vec4<f32>,
    there_t: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> hulls: array<HullAt>;
@group(0) @binding(1) var<storage, read> hull_bits: array<u32>;
@group(0) @binding(2) var<storage, read> maps: array<SunMap>;
// Every map's values, each from its `size.z` (x fastest).
@group(0) @binding(3) var<storage, read_write> reach: array<f32>;
@group(0) @binding(4) var<storage, read> occluders: array<SunOccluder>;

// f32's lowest finite value: a line that misses the hull.
const MISSES: f32 = -3.4028235e38;

// One texel (x) of map y.
@compute @workgroup_size(64)
fn sun_depth(@builtin(global_invocation_id) id: vec3<u32>) {
    let m = maps[id.y];
    let job = m.map;
    let i = id.x;
    if (job.size.w == 0u || i >= job.size.x * job.size.y) {
        return;
    }
    let q = vec2<f32>(job.axis_x.w, job.axis_y.w)
        + (vec2<f32>(f32(i % job.size.x), f32(i / job.size.x)) + 0.5) * job.texel.x;
    let d = job.toward.xyz;
    let far = job.toward.w;
    let origin = job.axis_x.xyz * q.x + job.axis_y.xyz * q.y + d * far;
    let own = hulls[m.hulls.x];
    let t = hull_first_hit_of(own.proxy, own.at.x, origin, -d);
    var r = select(MISSES, far - t, t >= 0.0);
    for (var k = m.hulls.y; k < m.hulls.y + m.hulls.z; k++) {
        let o = occluders[k];
        let h = hulls[o.hull.x];
        let there = mat3x3<f32>(o.there_x.xyz, o.there_y.xyz, o.there_z.xyz);
        let s = hull_first_hit_of(h.proxy, h.at.x, there * origin + o.there_t.xyz, there * -d);
        if (s >= 0.0) {
            r = max(r, far - s);
        }
    }
    reach[job.size.z + i] = r;
}
