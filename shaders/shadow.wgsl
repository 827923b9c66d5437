// The relit shadows (docs/design.md section 4.4) of every walker of a frame, in one
// dispatch (one workgroup layer a walker): the relative irradiance of every texel of its
// ground patch, S = Σ_k w_k A_k / Σ_k w_k per channel, with w_k = c_k E_k the light
// condition k brings to the unshadowed ground under the walker's light and A_k its
// pose's attenuation map; 1 where nothing lights the ground from above. Written into the
// walker's layer of the frame's shadows, the corner of its texels. Twin of
// `ShadowMaps::relight` in `render/src/shadow.rs`. Compiled after `common.wgsl`.

struct ShadowJob {
    // Where its maps start in `maps` (floats), and how many.
    maps_at: u32,
    maps: u32,
    // Texels per side of its maps.
    texels: u32,
    // Where its weights start in `weights`.
    weights_at: u32,
    // Its layer of `relit`.
    layer: u32,
    pad: array<u32, 3>,
}

// Every pose's maps, map after map, each row-major (rows along +z).
@group(0) @binding(0) var<storage, read> maps: array<f32>;
// Per job and map: w_k (rgb).
@group(0) @binding(1) var<storage, read> weights: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> jobs: array<ShadowJob>;
@group(0) @binding(3) var relit: texture_storage_2d_array<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn relight_shadows(@builtin(global_invocation_id) id: vec3<u32>) {
    let job = jobs[id.z];
    let n = job.texels;
    if (id.x >= n || id.y >= n) {
        return;
    }
    let i = id.y * n + id.x;
    var lit = vec3<f32>(0.0);
    var total = vec3<f32>(0.0);
    for (var k = 0u; k < job.maps; k++) {
        let w = weights[job.weights_at + k].xyz;
        lit += w * maps[job.maps_at + k * n * n + i];
        total += w;
    }
    var s = vec3<f32>(1.0);
    for (var c = 0; c < 3; c++) {
        if (total[c] > 0.0) {
            s[c] = clamp(lit[c] / total[c], 0.0, 1.0);
        }
    }
    textureStore(relit, vec2<i32>(id.xy), i32(job.layer), vec4<f32>(s, 1.0));
}
