// Flows decoded at upload as `Rg16Float` (unknown texels as zero), filtered by the
// sampler in hardware: the codes' values rounded to half precision.

@group(1) @binding(1) var flows: texture_2d_array<f32>;

// Bilinear sample of stored flow `layer` at full-image coordinates s.
fn sample_flow_layer(layer: i32, s: vec2<f32>) -> vec2<f32> {
    return textureSampleLevel(flows, bilinear, crop_uv(s), layer, 0.0).xy;
}
