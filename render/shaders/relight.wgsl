// The relighting pass (docs/design.md section 4.1), one view at a time: the weighted sum of the
// view's basis images (JPEG-decoded 8-bit gamma-2.2 codes, linearized through the table
// the CPU uses), then its encoding into the pre-lit texture layer as sRGB codes of
// colour / scale, the scale being the view's brightest value. Twin of
// `ResidentPose::relight_cpu` in `render/src/resident.rs`. Compiled after `common.wgsl`.

struct RelightParams {
    texels: u32,
    tiles: u32,
    width: u32,
    view: u32,
}

@group(0) @binding(0) var<uniform> params: RelightParams;
// Tiles x texels, packed RGBA8: the basis codes; tile 0's alpha byte holds the view's
// alpha code.
@group(0) @binding(1) var<storage, read> basis: array<u32>;
// Per tile: rgb = coefficient x tile scale; w = 0 when the condition is not used.
@group(0) @binding(2) var<storage, read> coefficients: array<vec4<f32>>;
// Code -> (code / 255)^2.2.
@group(0) @binding(3) var<storage, read> gamma: array<vec4<f32>, 64>;
// The relit colour (and alpha code) of every texel, between the two passes.
@group(0) @binding(4) var<storage, read_write> relit: array<vec4<f32>>;
// Per view: the largest relit value, as the bits of a non-negative f32 (whose order
// `atomicMax` on u32 preserves).
@group(0) @binding(5) var<storage, read_write> peaks: array<atomic<u32>>;
// The view's layer of the pre-lit texture.
@group(0) @binding(6) var output: texture_storage_2d<rgba8uint, write>;

fn gamma_value(code: u32) -> f32 {
    return gamma[code / 4u][code % 4u];
}

@compute @workgroup_size(64)
fn relight(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= params.texels) {
        return;
    }
    var out = vec3<f32>(0.0);
    for (var k = 0u; k < params.tiles; k++) {
        let c = coefficients[k];
        if (c.w == 0.0) {
            continue;
        }
        let code = basis[k * params.texels + i];
        out.x += c.x * gamma_value(code & 255u);
        out.y += c.y * gamma_value((code >> 8u) & 255u);
        out.z += c.z * gamma_value((code >> 16u) & 255u);
    }
    let alpha = f32(basis[i] >> 24u);
    relit[i] = vec4<f32>(out, alpha);
    atomicMax(&peaks[params.view], bitcast<u32>(max(out.x, max(out.y, out.z))));
}

fn srgb_encode(v: f32) -> f32 {
    let x = clamp(v, 0.0, 1.0);
    if (x <= 0.0031308) {
        return 12.92 * x;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

@compute @workgroup_size(64)
fn encode(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= params.texels) {
        return;
    }
    var scale = bitcast<f32>(atomicLoad(&peaks[params.view]));
    if (scale <= 0.0) {
        scale = 1.0;
    }
    let r = relit[i];
    let code = vec4<u32>(
        u32(round(srgb_encode(r.x / scale) * 255.0)),
        u32(round(srgb_encode(r.y / scale) * 255.0)),
        u32(round(srgb_encode(r.z / scale) * 255.0)),
        u32(r.w),
    );
    textureStore(output, vec2<i32>(i32(i % params.width), i32(i / params.width)), code);
}
