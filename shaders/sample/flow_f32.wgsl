// Flows decoded at upload as `Rg32Float` (unknown texels as zero): unfilterable, so
// filtered in the shader; the codes' twin up to nothing (the same decoded values).

@group(1) @binding(1) var flows: texture_2d_array<f32>;

// Bilinear sample of stored flow `layer` at full-image coordinates s.
fn sample_flow_layer(layer: i32, s: vec2<f32>) -> vec2<f32> {
    let c = crop_position(s);
    var out = vec2<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        out += textureLoad(flows, c.texel[k], layer, 0).xy * c.weight[k];
    }
    return out;
}
