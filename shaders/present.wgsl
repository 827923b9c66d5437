// The present pass: a composited frame (its kept RGBA32F targets, never read back) shown
// in a window. One layer is chosen: the composite, the walkers alone or the backdrop
// (premultiplied linear RGBA, times 2^exposure, over a grey checkerboard where
// transparent), the composite's alpha, or the relative irradiance of the ground (the
// shadow layer, 1 unshadowed). The frame is letterboxed into the viewport (nearest texel)
// and sRGB-encoded here when the window's format does not do it. Compiled after
// `common.wgsl` (its full-screen vertex stage).

struct Present {
    // Top-left corner and size of the frame in the window, pixels.
    origin: vec2<f32>,
    extent: vec2<f32>,
    // 0 composite, 1 walkers alone, 2 backdrop, 3 alpha, 4 shadow.
    layer: u32,
    // 1 when the target is not an sRGB format: encode here.
    encode: u32,
    // 2^stops.
    exposure: f32,
    pad: u32,
}

@group(0) @binding(0) var<uniform> params: Present;
@group(0) @binding(1) var composite: texture_2d<f32>;
@group(0) @binding(2) var shadow: texture_2d<f32>;
@group(0) @binding(3) var backdrop: texture_2d<f32>;
@group(0) @binding(4) var subjects: texture_2d<f32>;

fn encode_srgb(v: vec3<f32>) -> vec3<f32> {
    let c = clamp(v, vec3<f32>(0.0), vec3<f32>(1.0));
    let low = c * 12.92;
    let high = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(high, low, c <= vec3<f32>(0.0031308));
}

fn decode_srgb(v: vec3<f32>) -> vec3<f32> {
    let c = clamp(v, vec3<f32>(0.0), vec3<f32>(1.0));
    let low = c / 12.92;
    let high = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(high, low, c <= vec3<f32>(0.04045));
}

// Premultiplied `p` over a checkerboard of 8-pixel squares (linear greys).
fn over_checker(p: vec4<f32>, pixel: vec2<f32>) -> vec3<f32> {
    let square = (u32(pixel.x / 8.0) + u32(pixel.y / 8.0)) & 1u;
    let grey = select(0.18, 0.35, square == 1u);
    return p.rgb + (1.0 - p.a) * vec3<f32>(grey);
}

@fragment
fn fs_present(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<f32>(textureDimensions(composite));
    let rel = (position.xy - params.origin) / params.extent;
    if (any(rel < vec2<f32>(0.0)) || any(rel >= vec2<f32>(1.0))) {
        return vec4<f32>(0.05, 0.05, 0.05, 1.0);
    }
    let texel = vec2<i32>(min(floor(rel * size), size - 1.0));
    let pixel = vec2<f32>(texel);
    var rgb: vec3<f32>;
    switch params.layer {
        case 1u: {
            rgb = over_checker(textureLoad(subjects, texel, 0) * vec4<f32>(vec3<f32>(params.exposure), 1.0), pixel);
        }
        case 2u: {
            rgb = over_checker(textureLoad(backdrop, texel, 0) * vec4<f32>(vec3<f32>(params.exposure), 1.0), pixel);
        }
        case 3u: {
            rgb = vec3<f32>(textureLoad(composite, texel, 0).a);
        }
        case 4u: {
            rgb = textureLoad(shadow, texel, 0).rgb;
        }
        default: {
            rgb = over_checker(textureLoad(composite, texel, 0) * vec4<f32>(vec3<f32>(params.exposure), 1.0), pixel);
        }
    }
    let data = params.layer == 3u || params.layer == 4u;
    if (params.encode == 1u && !data) {
        rgb = encode_srgb(rgb);
    }
    if (params.encode == 0u && data) {
        // Alpha and irradiance ratios are shown as values, not as light: undo the
        // encoding the target applies.
        rgb = decode_srgb(rgb);
    }
    return vec4<f32>(rgb, 1.0);
}
