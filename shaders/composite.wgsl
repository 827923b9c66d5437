// The composite pass (docs/design.md section 4.4): per pixel, the backdrop seen along the
// ray (environment, plate or nothing), the relative irradiance S of the ground where the
// ray meets the plane y = 0 (the relit shadow, bilinear, 1 off its patch), and the
// rendered subject over the shadowed backdrop (Porter–Duff over, premultiplied). Writes
// the composite and, as layers, S and the backdrop without shadow. Twin of `compose` in
// `render/src/composite.rs`. Compiled after `common.wgsl`.
//
// Bind group 0 holds per-frame data (the camera and these settings), group 1 the images.

struct Composite {
    // 0: none (transparent, the shadow a black layer), 1: environment, 2: plate.
    backdrop: u32,
    // Environment ground: 0 the environment's lower hemisphere, 1 a Lambertian ground.
    ground_look: u32,
    // 1 when the pose has a relit shadow.
    has_shadow: u32,
    // Texels per side of the relit shadow.
    shadow_texels: u32,
    // Radiance of the Lambertian ground (rgb).
    ground_radiance: vec4<f32>,
    // Size of the environment map.
    env_size: vec2<u32>,
    // Yaw of the environment, radians.
    env_yaw: f32,
    // Side of the shadow's ground patch, metres.
    shadow_extent: f32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> params: Composite;

// The rendered subject, premultiplied linear RGBA, one texel per pixel.
@group(1) @binding(0) var subject: texture_2d<f32>;
// The environment, latitude-longitude radiance (rgb).
@group(1) @binding(1) var env: texture_2d<f32>;
// The plate, linear rgb, one texel per pixel.
@group(1) @binding(2) var plate: texture_2d<f32>;
// The relit shadow (rgb), rows along +z.
@group(1) @binding(3) var shadow: texture_2d<f32>;

struct Layers {
    @location(0) composite: vec4<f32>,
    @location(1) shadow: vec4<f32>,
    @location(2) backdrop: vec4<f32>,
}

const PI: f32 = 3.14159265358979;

// Bilinear sample of a texture at continuous texel coordinates (centres at integers),
// edges clamped.
fn bilinear(t: texture_2d<f32>, p: vec2<f32>) -> vec4<f32> {
    let size = vec2<i32>(textureDimensions(t));
    let p0 = floor(p);
    let f = p - p0;
    let i0 = vec2<i32>(p0);
    var out = vec4<f32>(0.0);
    for (var dy = 0; dy < 2; dy++) {
        let wy = select(f.y, 1.0 - f.y, dy == 0);
        for (var dx = 0; dx < 2; dx++) {
            let wx = select(f.x, 1.0 - f.x, dx == 0);
            let q = clamp(i0 + vec2<i32>(dx, dy), vec2<i32>(0), size - vec2<i32>(1));
            out += textureLoad(t, q, 0) * (wx * wy);
        }
    }
    return out;
}

// Radiance of the environment arriving from direction d (subject frame): the map's
// yaw undone, the ICT latitude-longitude mapping, bilinear, wrapping in azimuth. Twin of
// `EnvMap::radiance`.
fn env_radiance(d_in: vec3<f32>) -> vec3<f32> {
    let c = cos(-params.env_yaw);
    let s = sin(-params.env_yaw);
    let d = normalize_or_zero(vec3<f32>(c * d_in.x + s * d_in.z, d_in.y, -s * d_in.x + c * d_in.z));
    let w = f32(params.env_size.x);
    let h = f32(params.env_size.y);
    let u = (1.0 + atan2(d.x, -d.z) / PI) / 2.0;
    let v = acos(clamp(d.y, -1.0, 1.0)) / PI;
    let tx = u * w - 0.5;
    let ty = v * h - 0.5;
    let x = tx - floor(tx / w) * w;
    if (x > w - 1.0) {
        let f = x - (w - 1.0);
        let a = bilinear(env, vec2<f32>(w - 1.0, ty)).xyz;
        let b = bilinear(env, vec2<f32>(0.0, ty)).xyz;
        return a * (1.0 - f) + b * f;
    }
    return bilinear(env, vec2<f32>(x, ty)).xyz;
}

// The relative irradiance at ground point (x, z): 1 off the patch. Twin of
// `RelitShadow::at`.
fn shadow_at(x: f32, z: f32) -> vec3<f32> {
    let half = 0.5 * params.shadow_extent;
    if (params.has_shadow == 0u || abs(x) > half || abs(z) > half) {
        return vec3<f32>(1.0);
    }
    let s = params.shadow_extent / f32(params.shadow_texels);
    return bilinear(shadow, vec2<f32>((x + half) / s - 0.5, (z + half) / s - 0.5)).xyz;
}

fn luminance(c: vec3<f32>) -> f32 {
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

@fragment
fn fs_composite(@builtin(position) position: vec4<f32>) -> Layers {
    let pixel = vec2<i32>(floor(position.xy));
    let dir = pixel_ray(frame, position);
    let origin = frame.centre.xyz;
    // The ground y = 0, met from above.
    var hits_ground = false;
    var s = vec3<f32>(1.0);
    if (origin.y > 0.0 && dir.y < 0.0) {
        let p = origin + dir * (-origin.y / dir.y);
        if (finite(p.x) && finite(p.z)) {
            hits_ground = true;
            s = shadow_at(p.x, p.z);
        }
    }
    var back = vec4<f32>(0.0);
    if (params.backdrop == 1u) {
        var c = env_radiance(dir);
        if (hits_ground && params.ground_look == 1u) {
            c = params.ground_radiance.xyz;
        }
        back = vec4<f32>(c, 1.0);
    } else if (params.backdrop == 2u) {
        back = vec4<f32>(textureLoad(plate, pixel, 0).xyz, 1.0);
    }
    var under = vec4<f32>(back.xyz * s, back.w);
    if (params.backdrop == 0u) {
        under = vec4<f32>(0.0, 0.0, 0.0, clamp(1.0 - luminance(s), 0.0, 1.0));
    }
    let front = textureLoad(subject, pixel, 0);
    var out: Layers;
    out.composite = front + (1.0 - clamp(front.w, 0.0, 1.0)) * under;
    out.shadow = vec4<f32>(s, 1.0);
    out.backdrop = back;
    return out;
}
