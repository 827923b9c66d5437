// The relit shadow (docs/design.md section 4.4), once per pose and lighting: the relative
// irradiance of every texel of the ground patch, S = Σ_k w_k A_k / Σ_k w_k per channel,
// with w_k = c_k E_k the light condition k brings to the unshadowed ground and A_k its
// attenuation map; 1 where nothing lights the ground from above. Twin of
// `ShadowMaps::relight` in `render/src/shadow.rs`. Compiled after `common.wgsl`.

struct ShadowParams {
    // Texels per side of the maps.
    texels: u32,
    // Maps.
    maps: u32,
    pad: vec2<u32>,
}

@group(0) @binding(0) var<uniform> params: ShadowParams;
// The maps, map after map, each row-major (rows along +z).
@group(0) @binding(1) var<storage, read> maps: array<f32>;
// Per map: w_k (rgb).
@group(0) @binding(2) var<storage, read> weights: array<vec4<f32>>;
@group(0) @binding(3) var relit: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn relight_shadow(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = params.texels;
    if (id.x >= n || id.y >= n) {
        return;
    }
    let i = id.y * n + id.x;
    var lit = vec3<f32>(0.0);
    var total = vec3<f32>(0.0);
    for (var k = 0u; k < params.maps; k++) {
        let w = weights[k].xyz;
        lit += w * maps[k * n * n + i];
        total += w;
    }
    var s = vec3<f32>(1.0);
    for (var c = 0; c < 3; c++) {
        if (total[c] > 0.0) {
            s[c] = clamp(lit[c] / total[c], 0.0, 1.0);
        }
    }
    textureStore(relit, vec2<i32>(id.xy), vec4<f32>(s, 1.0));
}
