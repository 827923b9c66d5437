// Pre-lit views as `Rgba8UnormSrgb`, the same bytes as the integer codes: the sampler
// decodes sRGB before it filters, in hardware (with the hardware's filter precision).
// The views' scales and layers lie in the shared pages as for the codes.

@group(1) @binding(10) var prelit_texels: texture_2d_array<f32>;

// Bilinear sample of a pre-lit view at full-image coordinates s (edge repeated).
fn sample_prelit(view: u32, s: vec2<f32>) -> vec4<f32> {
    let layer = prelit_layer(view);
    if (layer < 0) {
        return vec4<f32>(0.0);
    }
    let t = textureSampleLevel(prelit_texels, bilinear, crop_uv(s), layer, 0.0);
    let scale = view_scale(view);
    return vec4<f32>(t.rgb * scale, t.a);
}
