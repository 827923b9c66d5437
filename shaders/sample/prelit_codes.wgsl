// Pre-lit views as integer codes (`Rgba8Uint`): RGB the sRGB codes of colour / the
// view's scale, A the alpha code; decoded texel by texel through the table, then
// filtered in the shader. The exact twin of `ResidentPose::sample_prelit`.

@group(1) @binding(0) var prelit: texture_2d_array<u32>;

fn srgb_value(code: u32) -> f32 {
    return tables.srgb[code / 4u][code % 4u];
}

// Bilinear sample of a pre-lit view at full-image coordinates s (edge repeated).
fn sample_prelit(view: u32, s: vec2<f32>) -> vec4<f32> {
    let layer = views[view].prelit_layer;
    if (layer < 0) {
        return vec4<f32>(0.0);
    }
    let c = crop_position(s);
    let scale = views[view].scale;
    var out = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        let t = textureLoad(prelit, c.texel[k], layer, 0);
        let wt = c.weight[k];
        out.x += wt * (scale * srgb_value(t.x));
        out.y += wt * (scale * srgb_value(t.y));
        out.z += wt * (scale * srgb_value(t.z));
        out.w += wt * f32(t.w) / 255.0;
    }
    return out;
}
