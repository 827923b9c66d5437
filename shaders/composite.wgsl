// The composite pass (docs/design.md section 4.4): per pixel, the rendered walkers each
// over the ones behind it, the backdrop seen along the ray (environment, plate or
// nothing), the relative irradiance S of the ground where the ray meets the plane y = 0
// (the product of every walker's relit shadow, each in its own subject frame, bilinear,
// 1 off its patch), and the walkers over the shadowed backdrop (Porter–Duff over,
// premultiplied). Writes the composite and, as layers, S, the backdrop without shadow and
// the walkers alone. Twin of `compose` in `render/src/composite.rs`. Compiled after
// `common.wgsl`.
//
// A compute pass, 8 x 8 pixels a workgroup: drawn as a full-screen fragment pass it took
// an H100 4.7 ms at 1920x1080, as compute 0.1 ms (docs/design.md section 4.5).
//
// Bind group 0 holds per-frame data (the camera and these settings) and the four
// targets, group 1 the images.

struct Composite {
    // 0: none (transparent, the shadow a black layer), 1: environment, 2: plate.
    backdrop: u32,
    // Environment ground: 0 the environment's lower hemisphere, 1 a Lambertian ground.
    ground_look: u32,
    // 1 when the pose has a relit shadow.
    has_shadow: u32,
    // Texels per side of the layers of `shadows` (the finest walker's).
    shadow_texels: u32,
    // Radiance of the Lambertian ground (rgb).
    ground_radiance: vec4<f32>,
    // Size of the environment map.
    env_size: vec2<u32>,
    // Yaw of the environment, radians.
    env_yaw: f32,
    // Side of the shadow's ground patch, metres.
    shadow_extent: f32,
    // Walkers drawn (layers of `subjects` and `shadows`, back to front).
    instances: u32,
    // Tiles in a row of `tiles`, and their side in pixels.
    tile_columns: u32,
    tile_side: u32,
    // 1: walkers that overlap at a pixel go over each other by their depths there.
    by_depth: u32,
}

// A walker's subject frame: `subject_from_world`, as columns and translation; the
// translation's w is the texels a side of its relit shadow (its level of detail; 0
// without one), which fill the corner of its layer of `shadows`. It is transparent
// outside `bounds` ([x0, y0, x1, y1], ends exclusive); within, pixel p of its render lies
// at texel p + place.xy of layer place.z of `subjects` (`render/src/atlas.rs`).
struct Instance {
    col_x: vec4<f32>,
    col_y: vec4<f32>,
    col_z: vec4<f32>,
    translation: vec4<f32>,
    bounds: vec4<u32>,
    place: vec4<i32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> params: Composite;
@group(0) @binding(2) var<storage, read> instances: array<Instance>;
// Per tile of the frame (row after row): the index in this array of its first walker and
// their count; then the lists, indices into `instances` back to front. A walker a tile
// does not list is transparent and casts no shadow there (`TileLists` in
// render/src/footprint.rs).
@group(0) @binding(3) var<storage, read> tiles: array<u32>;
// The targets: the composite, the relative irradiance S, the backdrop, the walkers alone.
@group(0) @binding(4) var composite_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var shadow_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var backdrop_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(7) var subject_out: texture_storage_2d<rgba32float, write>;

// The rendered walkers, premultiplied linear RGBA, one texel per pixel, packed into
// pages (each walker's `place`).
@group(1) @binding(0) var subjects: texture_2d_array<f32>;
// The environment, latitude-longitude radiance (rgb).
@group(1) @binding(1) var env: texture_2d<f32>;
// The plate, linear rgb, one texel per pixel.
@group(1) @binding(2) var plate: texture_2d<f32>;
// The walkers' relit shadows (rgb), rows along +z, one layer each.
@group(1) @binding(3) var shadows: texture_2d_array<f32>;
// Each walker's depth at its pixels, beside its render in `subjects` (metres along the
// pixel's ray, `subject_depth` of the frame pass); read when `params.by_depth` is 1.
@group(1) @binding(4) var depths: texture_2d_array<f32>;

// The most walkers a pixel orders by depth: twin of `composite::MAX_OVERLAP`.
const MAX_OVERLAP: u32 = 16u;

struct Layers {
    composite: vec4<f32>,
    shadow: vec4<f32>,
    backdrop: vec4<f32>,
    subject: vec4<f32>,
}

const PI: f32 = 3.14159265358979;

// Bilinear weights and corner of continuous texel coordinates p (centres at integers).
struct Footprint {
    i0: vec2<i32>,
    f: vec2<f32>,
}

fn footprint(p: vec2<f32>) -> Footprint {
    let p0 = floor(p);
    return Footprint(vec2<i32>(p0), p - p0);
}

// Bilinear sample of a texture, edges clamped.
fn bilinear(t: texture_2d<f32>, p: vec2<f32>) -> vec4<f32> {
    let size = vec2<i32>(textureDimensions(t));
    let q = footprint(p);
    var out = vec4<f32>(0.0);
    for (var dy = 0; dy < 2; dy++) {
        let wy = select(q.f.y, 1.0 - q.f.y, dy == 0);
        for (var dx = 0; dx < 2; dx++) {
            let wx = select(q.f.x, 1.0 - q.f.x, dx == 0);
            let c = clamp(q.i0 + vec2<i32>(dx, dy), vec2<i32>(0), size - vec2<i32>(1));
            out += textureLoad(t, c, 0) * (wx * wy);
        }
    }
    return out;
}

// The same for the `size` x `size` corner of one layer of an array texture.
fn bilinear_layer(t: texture_2d_array<f32>, layer: u32, size1: i32, p: vec2<f32>) -> vec4<f32> {
    let size = vec2<i32>(size1);
    let q = footprint(p);
    var out = vec4<f32>(0.0);
    for (var dy = 0; dy < 2; dy++) {
        let wy = select(q.f.y, 1.0 - q.f.y, dy == 0);
        for (var dx = 0; dx < 2; dx++) {
            let wx = select(q.f.x, 1.0 - q.f.x, dx == 0);
            let c = clamp(q.i0 + vec2<i32>(dx, dy), vec2<i32>(0), size - vec2<i32>(1));
            out += textureLoad(t, c, i32(layer), 0) * (wx * wy);
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

// Where the fade toward the patch's edge begins, as a fraction of the half side: twin of
// `EDGE_FADE_FROM` in render/src/shadow.rs.
const EDGE_FADE_FROM: f32 = 0.8;

// The weight of 1 (unshadowed) at subject-frame ground point q: twin of `edge_fade`.
fn edge_fade(q: vec3<f32>, half: f32) -> f32 {
    let t = clamp((max(abs(q.x), abs(q.z)) / half - EDGE_FADE_FROM) / (1.0 - EDGE_FADE_FROM), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// The relative irradiance at the world's ground point p under walker i's shadow: faded to
// 1 toward the edge of its patch, 1 off it. Twin of `RelitShadow::at` in the walker's
// subject frame.
fn shadow_at(i: u32, p: vec3<f32>) -> vec3<f32> {
    let m = instances[i];
    let q = m.col_x.xyz * p.x + m.col_y.xyz * p.y + m.col_z.xyz * p.z + m.translation.xyz;
    let half = 0.5 * params.shadow_extent;
    let texels = m.translation.w;
    if (params.has_shadow == 0u || texels == 0.0 || abs(q.x) > half || abs(q.z) > half) {
        return vec3<f32>(1.0);
    }
    let s = params.shadow_extent / texels;
    let map = bilinear_layer(shadows, i, i32(texels), vec2<f32>((q.x + half) / s - 0.5, (q.z + half) / s - 0.5)).xyz;
    return mix(map, vec3<f32>(1.0), edge_fade(q, half));
}

fn luminance(c: vec3<f32>) -> f32 {
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

// The layers of the pixel at `pixel`.
fn composite_pixel(pixel: vec2<i32>) -> Layers {
    let position = vec4<f32>(vec2<f32>(pixel) + 0.5, 0.0, 1.0);
    let tile = (u32(pixel.y) / params.tile_side) * params.tile_columns + u32(pixel.x) / params.tile_side;
    let first = tiles[2u * tile];
    let listed = tiles[2u * tile + 1u];
    let dir = pixel_ray(frame, position);
    let origin = frame.centre.xyz;
    // The ground y = 0, met from above.
    var hits_ground = false;
    var s = vec3<f32>(1.0);
    if (origin.y > 0.0 && dir.y < 0.0) {
        let p = origin + dir * (-origin.y / dir.y);
        if (finite(p.x) && finite(p.z)) {
            hits_ground = true;
            for (var j = 0u; j < listed; j++) {
                s *= shadow_at(tiles[first + j], vec3<f32>(p.x, 0.0, p.z));
            }
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
    // The walkers, each over the ones behind it: in the listed order (back to front by
    // their positions), or by their depths at this pixel (twin of `stack_by_depth`).
    var front = vec4<f32>(0.0);
    // The walkers covering the pixel beyond the last MAX_OVERLAP go under, in order;
    // those are sorted farthest first (an insertion sort, ties in the listed order).
    var near: array<vec2<f32>, MAX_OVERLAP>;
    var count = 0u;
    for (var j = 0u; j < listed; j++) {
        let i = tiles[first + j];
        let b = instances[i].bounds;
        if (any(vec2<u32>(pixel) < b.xy) || any(vec2<u32>(pixel) >= b.zw)) {
            continue;
        }
        let place = instances[i].place;
        let at = vec2<i32>(pixel) + place.xy;
        let layer = textureLoad(subjects, at, place.z, 0);
        if (params.by_depth == 0u) {
            front = layer + (1.0 - clamp(layer.w, 0.0, 1.0)) * front;
            continue;
        }
        if (layer.w <= 0.0) {
            continue;
        }
        if (count == MAX_OVERLAP) {
            // The oldest kept goes under now.
            let k = u32(near[0].y);
            let under = textureLoad(subjects, vec2<i32>(pixel) + instances[k].place.xy, instances[k].place.z, 0);
            front = under + (1.0 - clamp(under.w, 0.0, 1.0)) * front;
            for (var m = 1u; m < MAX_OVERLAP; m++) {
                near[m - 1u] = near[m];
            }
            count -= 1u;
        }
        near[count] = vec2<f32>(textureLoad(depths, at, place.z, 0).x, f32(i));
        count += 1u;
    }
    // Farthest first; a stable insertion sort keeps the listed order among equals.
    for (var m = 1u; m < count; m++) {
        let e = near[m];
        var n = m;
        while (n > 0u && near[n - 1u].x < e.x) {
            near[n] = near[n - 1u];
            n -= 1u;
        }
        near[n] = e;
    }
    for (var m = 0u; m < count; m++) {
        let k = u32(near[m].y);
        let place = instances[k].place;
        let layer = textureLoad(subjects, vec2<i32>(pixel) + place.xy, place.z, 0);
        front = layer + (1.0 - clamp(layer.w, 0.0, 1.0)) * front;
    }
    var out: Layers;
    out.composite = front + (1.0 - clamp(front.w, 0.0, 1.0)) * under;
    out.shadow = vec4<f32>(s, 1.0);
    out.backdrop = back;
    out.subject = front;
    return out;
}

@compute @workgroup_size(8, 8)
fn cs_composite(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id.xy >= frame.size)) {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let out = composite_pixel(pixel);
    textureStore(composite_out, pixel, out.composite);
    textureStore(shadow_out, pixel, out.shadow);
    textureStore(backdrop_out, pixel, out.backdrop);
    textureStore(subject_out, pixel, out.subject);
}
