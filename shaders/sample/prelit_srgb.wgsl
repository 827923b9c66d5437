// Pre-lit views as `Rgba8UnormSrgb`, the same bytes as the integer codes: the sampler
// decodes sRGB before it filters, in hardware (with the hardware's filter precision).

@group(1) @binding(0) var prelit: texture_2d_array<f32>;

// Bilinear sample of a pre-lit view at full-image coordinates s (edge repeated).
fn sample_prelit(view: u32, s: vec2<f32>) -> vec4<f32> {
    let layer = views[view].prelit_layer;
    if (layer < 0) {
        return vec4<f32>(0.0);
    }
    let t = textureSampleLevel(prelit, bilinear, crop_uv(s), layer, 0.0);
    let scale = views[view].scale;
    return vec4<f32>(t.rgb * scale, t.a);
}
