// The GPU twin of `LightFit::relight` (reflectance/src/light_fit.rs): photographs under
// single lights relit under a light between them, per texel
//
//   I(l) = Σ w_k I_k · M(l) / Σ w_k M(l_k),   M(l) = ρ max(n · l, 0)
//
// over the nearest kept lights (`weights`), or, where their fitted shading is under
// `ratio_floor` of the new light's, the fit's shading scaled by the texel's
// least-squares ratio of photographs to fit over every light. Texels without a fit
// (`fit.w == 0`) take the interpolation alone. With a glossy lobe (`view.w`, its
// roughness, > 0; per texel its strength in the albedo's w), each photograph's highlight
// is taken out first and the new light's added (`reflectance/src/gloss.rs`).

struct LightFitParams {
    texels: u32,
    lights: u32,
    // Nearest lights used (at most 4).
    nearest: u32,
    pad0: u32,
    // The new light, unit (xyz), and the ratio's floor (w).
    light: vec4<f32>,
    // The nearest lights' indices and weights.
    indices: vec4<u32>,
    weights: vec4<f32>,
    // Toward the camera (xyz) and the lobe's roughness (w; 0: none).
    view: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: LightFitParams;
// Per light, its photograph: texels RGB(A), light-major.
@group(0) @binding(1) var<storage, read> photos: array<vec4<f32>>;
// Per light, its direction (xyz).
@group(0) @binding(2) var<storage, read> directions: array<vec4<f32>>;
// Per texel: normal (xyz) and whether fitted (w), then albedo (rgb).
@group(0) @binding(3) var<storage, read> normals: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> albedo: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> relit: array<vec4<f32>>;

fn shade(i: u32, l: vec3<f32>) -> vec3<f32> {
    return albedo[i].rgb * max(dot(normals[i].xyz, l), 0.0);
}

// Texel i's highlight under a unit light from l: its strength times Torrance-Sparrow's
// lobe (twin of `lobe` and `Gloss::highlight`, reflectance/src/gloss.rs).
fn highlight(i: u32, l: vec3<f32>) -> f32 {
    let k = albedo[i].w;
    let m = params.view.w;
    let n = normals[i].xyz;
    let v = params.view.xyz;
    let nl = dot(n, l);
    let nv = dot(n, v);
    if (k <= 0.0 || m <= 0.0 || normals[i].w == 0.0 || nl <= 0.0 || nv <= 0.0) {
        return 0.0;
    }
    let h = normalize(l + v);
    let nh = max(dot(n, h), 1e-4);
    let vh = max(dot(v, h), 1e-4);
    let m2 = m * m;
    let nh2 = nh * nh;
    let d = exp(-(1.0 - nh2) / (nh2 * m2)) / (3.14159265 * m2 * nh2 * nh2);
    let g = min(min(2.0 * nh * nv / vh, 2.0 * nh * nl / vh), 1.0);
    return k * d * g / (4.0 * nv);
}

// Photograph k at texel i, its highlight taken out (no channel below zero).
fn matte(k: u32, i: u32) -> vec3<f32> {
    let p = photos[k * params.texels + i].rgb;
    return max(p - vec3<f32>(highlight(i, directions[k].xyz)), vec3<f32>(0.0));
}

@compute @workgroup_size(64)
fn relight_fit(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.texels {
        return;
    }
    var interpolated = vec3<f32>(0.0);
    var shaded = vec3<f32>(0.0);
    for (var j = 0u; j < params.nearest; j++) {
        let k = params.indices[j];
        let w = params.weights[j];
        interpolated += w * matte(k, i);
        shaded += w * shade(i, directions[k].xyz);
    }
    if normals[i].w == 0.0 {
        relit[i] = vec4<f32>(interpolated, 1.0);
        return;
    }
    let wanted = shade(i, params.light.xyz);
    let glint = vec3<f32>(highlight(i, params.light.xyz));
    let t = wanted.r + wanted.g + wanted.b;
    let s = shaded.r + shaded.g + shaded.b;
    if t <= 0.0 {
        relit[i] = vec4<f32>(glint, 1.0);
        return;
    }
    if s >= params.light.w * t {
        let ratio = select(vec3<f32>(0.0), wanted / max(shaded, vec3<f32>(1e-30)), shaded > vec3<f32>(0.0));
        relit[i] = vec4<f32>(interpolated * ratio + glint, 1.0);
        return;
    }
    var num = vec3<f32>(0.0);
    var den = vec3<f32>(0.0);
    for (var k = 0u; k < params.lights; k++) {
        let m = shade(i, directions[k].xyz);
        num += matte(k, i) * m;
        den += m * m;
    }
    let scale = select(vec3<f32>(1.0), num / max(den, vec3<f32>(1e-30)), den > vec3<f32>(0.0));
    relit[i] = vec4<f32>(wanted * scale + glint, 1.0);
}
