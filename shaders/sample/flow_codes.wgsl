// Flows as their stored 8-bit log codes (`Rg8Sint`), each texel decoded through the
// table, then filtered in the shader; unknown texels displace by zero. The exact twin of
// `ResidentPose::sample_flow`.

@group(1) @binding(1) var flows: texture_2d_array<i32>;

fn flow_value(code: i32) -> f32 {
    let i = u32(code + 128);
    return tables.flow[i / 4u][i % 4u];
}

// Bilinear sample of stored flow `layer` at full-image coordinates s.
fn sample_flow_layer(layer: i32, s: vec2<f32>) -> vec2<f32> {
    let c = crop_position(s);
    var out = vec2<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        let code = textureLoad(flows, c.texel[k], layer, 0);
        if (code.x != -128 && code.y != -128) {
            out += vec2<f32>(flow_value(code.x), flow_value(code.y)) * c.weight[k];
        }
    }
    return out;
}
