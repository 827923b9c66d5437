// Pre-lit views as integer codes in the shared pages bound as `prelit`
// (`render/src/gpu/prelit.rs`): from word `frame.prelit.y` per layer its texels, each RGB
// the sRGB codes of colour / the view's scale and A the alpha code (packed RGBA8);
// decoded texel by texel through the table, then filtered in the shader. The exact twin
// of `ResidentPose::sample_prelit`.

fn srgb_value(code: u32) -> f32 {
    return tables.srgb[code / 4u][code % 4u];
}

// Bilinear sample of a pre-lit view at full-image coordinates s (edge repeated).
fn sample_prelit(view: u32, s: vec2<f32>) -> vec4<f32> {
    let layer = prelit_layer(view);
    if (layer < 0) {
        return vec4<f32>(0.0);
    }
    let c = crop_position(s);
    let scale = view_scale(view);
    let first = frame.prelit.y + u32(layer) * frame.crop_size.x * frame.crop_size.y;
    var out = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        let p = vec2<u32>(c.texel[k]);
        let code = prelit[first + p.y * frame.crop_size.x + p.x];
        let t = vec4<u32>(code & 255u, (code >> 8u) & 255u, (code >> 16u) & 255u, code >> 24u);
        let wt = c.weight[k];
        out.x += wt * (scale * srgb_value(t.x));
        out.y += wt * (scale * srgb_value(t.y));
        out.z += wt * (scale * srgb_value(t.z));
        out.w += wt * f32(t.w) / 255.0;
    }
    return out;
}
