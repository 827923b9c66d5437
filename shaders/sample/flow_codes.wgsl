// Flows as their stored 8-bit log codes in the shared pages (`render/src/gpu/prelit.rs`):
// from word `frame.prelit.z`, layer after layer, two texels a word (the first in its low
// half), each texel's x code in the low byte and y in the high; each decoded through the
// table, then filtered in the shader; unknown texels displace by zero. The exact twin of
// `ResidentPose::sample_flow`.

@group(1) @binding(1) var<storage, read> flow_codes: array<u32>;

// The codes of texel p of stored flow `layer`, sign-extended.
fn flow_code(layer: i32, p: vec2<i32>) -> vec2<i32> {
    let size = frame.crop_size;
    let t = (u32(layer) * size.y + u32(p.y)) * size.x + u32(p.x);
    let half = (flow_codes[frame.prelit.z + t / 2u] >> ((t % 2u) * 16u)) & 0xffffu;
    return vec2<i32>(i32(half << 24u) >> 24u, i32(half << 16u) >> 24u);
}

fn flow_value(code: i32) -> f32 {
    let i = u32(code + 128);
    return tables.flow[i / 4u][i % 4u];
}

// Bilinear sample of stored flow `layer` at full-image coordinates s.
fn sample_flow_layer(layer: i32, s: vec2<f32>) -> vec2<f32> {
    let c = crop_position(s);
    var out = vec2<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        let code = flow_code(layer, c.texel[k]);
        if (code.x != -128 && code.y != -128) {
            out += vec2<f32>(flow_value(code.x), flow_value(code.y)) * c.weight[k];
        }
    }
    return out;
}
