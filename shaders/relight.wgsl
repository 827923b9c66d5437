// The relighting pass (docs/design.md section 4.1), every view of every pose copy relit in
// a submission at once (one row of workgroups per view, its job): the weighted sum of each view's basis images (JPEG-decoded 8-bit
// gamma-2.2 codes, linearized through the table the CPU uses), then its encoding into its
// layer of the pose's pre-lit range as sRGB codes of colour / scale, the scale being the
// view's brightest value, which the encoding also writes in the view's head (the frame
// pass reads it there: nothing goes back to the host). Every buffer is a shared page (or
// the submission's own): a job names where its parts lie in each. The codes stay resident
// between relights; a new light rewrites only the coefficients. Twin of
// `ResidentPose::relight_cpu` in `render/src/resident.rs`. Compiled after `common.wgsl`.
//
// Each sun the environment held is added per texel by the view's fitted normals (twin of
// `SunLight::texel`, `reflectance/src/sun_light.rs`): the nearest conditions' images per
// unit of their light, times the ratio of the normal's shading under the sun to its
// shading under them; where they barely reach the texel, the normal's shading under the
// sun times the least-squares ratio of every image to its shading under its condition.

// One view of a copy (`GpuRelightJob`, `shaders/src/types.rs`, says what each holds).
struct Job {
    basis_offset: u32,
    coefficients_at: u32,
    coefficient_offset: u32,
    tiles: u32,
    view: u32,
    layer: u32,
    relit_offset: u32,
    // 1 when its codes are followed by its texels' points on the hull (`t` along their
    // camera rays, as f32 bits).
    surface: u32,
    peak: u32,
    heads_at: u32,
    codes_at: u32,
    texels: u32,
    width: u32,
    x0: u32,
    y0: u32,
    sun_slots: u32,
    camera: View,
}

// Per view, tiles x texels, packed RGBA8: the basis codes; tile 0's alpha byte holds the
// view's alpha code. A page of every pose's.
@group(0) @binding(1) var<storage, read> basis: array<u32>;
// A page of every copy's coefficients: each copy's batch's from its job's
// `coefficients_at` on, every index below counting from there ([`co`]). Per view, from its
// `coefficient_offset`: per tile, rgb = coefficient x tile scale and
// w = 0 when the condition is not used (by the light or its suns); per tile, where its
// condition's lights are (x: its cone, its lights after it, y: how many, as f32; for a floor condition relit
// by the ground's shape, z: where its lights' reweighted shares are, one a vec4 in x,
// and w: the ratio's floor, else 0); per tile, the suns'
// coefficient x tile scale (what the basis adds for them); then `sun_slots` slots of a sun, those in use
// first: per tile, the sun per unit of the condition's light x tile scale (rgb); the
// sun's direction (xyz, the view's dome frame; w = 0 for an unused slot), the nearest
// conditions (xyz, as f32; w: how many) and their weights (xyz; w: the ratio's floor),
// its direction in the subject frame (xyz; w: how far from the hull's surface its shadow
// ray starts, 0 for no shadow); its map of the hull (`SunDepth`,
// `reflectance/src/sun_depth.rs`): its x axis (xyz) and corner's x (w), its y axis and
// corner's y, and (texel side, texels along x, along y, where its values start in
// `sun_depths`, as f32); the conditions that predict each of the two nearest left out
// (xy: the first's, zw: the second's, as f32) and their weights; (its compactness, its
// luminance, the trust's error bounds). After every view's, per condition: its lights'
// cone (`group_cone`: the sum of their directions by share, xyz, and the bound on a
// normal's dot product with it beyond which it sees all or none of them, w), then its
// lights, each its direction (xyz, dome frame) and share of its condition's light (w).
@group(0) @binding(2) var<storage, read> coefficients: array<vec4<f32>>;
// Code -> (code / 255)^2.2.
@group(0) @binding(0) var<uniform> gamma: array<vec4<f32>, 64>;
// The relit colour (and alpha code) of every texel of every job, between the passes.
@group(0) @binding(3) var<storage, read_write> relit: array<vec4<f32>>;
// Per job: the largest relit value, as the bits of a non-negative f32 (whose order
// `atomicMax` on u32 preserves).
@group(0) @binding(4) var<storage, read_write> peaks: array<atomic<u32>>;
// A page of the copies' pre-lit ranges (`render/src/gpu/prelit.rs`): per view its head
// of 8 words from its job's `heads_at`, its scale first (f32 bits), then from its
// `codes_at` per layer its texels, each packed RGBA8 (the sRGB codes of colour / scale,
// the alpha code).
@group(0) @binding(5) var<storage, read_write> prelit: array<u32>;
@group(0) @binding(6) var<storage, read> jobs: array<Job>;
// The suns' maps of the hulls, one after the other: per texel (x fastest), how far toward
// its sun the hull reaches along its line.
@group(0) @binding(7) var<storage, read> sun_depths: array<f32>;

// Where the invocation's job's coefficients start in their page (`coefficients_at`).
var<private> coefficients_at: u32;

// The coefficient `i` places from the invocation's job's copy's first.
fn co(i: u32) -> vec4<f32> {
    return coefficients[coefficients_at + i];
}

fn gamma_value(code: u32) -> f32 {
    return gamma[code / 4u][code % 4u];
}

// Tile k's linear value at texel i of `job`, per unit of its scale.
fn tile_value(job: Job, k: u32, i: u32) -> vec3<f32> {
    let code = basis[job.basis_offset + k * job.texels + i];
    return vec3<f32>(
        gamma_value(code & 255u),
        gamma_value((code >> 8u) & 255u),
        gamma_value((code >> 16u) & 255u),
    );
}

// The unit normal of octahedral codes (`reflectance/src/normalcodec.rs`), zero for
// `(0, 0)` (none fitted).
fn normal_of(cx: u32, cy: u32) -> vec3<f32> {
    if (cx == 0u && cy == 0u) {
        return vec3<f32>(0.0);
    }
    let x = (f32(max(cx, 1u)) - 1.0) / 254.0 * 2.0 - 1.0;
    let y = (f32(max(cy, 1u)) - 1.0) / 254.0 * 2.0 - 1.0;
    let z = 1.0 - abs(x) - abs(y);
    let t = max(-z, 0.0);
    return normalize(vec3<f32>(select(x + t, x - t, x >= 0.0), select(y + t, y - t, y >= 0.0), z));
}

// Condition k's shading of normal n per unit of its light (`cone_shading`,
// `reflectance/src/light_fit.rs`): its lights' max(n . l, 0) weighted by their shares;
// n . m where n sees every light of its cone, 0 where it sees none.
fn shading(lights: vec4<f32>, n: vec3<f32>) -> f32 {
    let first = u32(lights.x);
    let cone = co(first);
    let d = dot(n, cone.xyz);
    if (d >= cone.w) {
        return d;
    }
    if (d <= -cone.w) {
        return 0.0;
    }
    var s = 0.0;
    for (var j = first + 1u; j <= first + u32(lights.y); j++) {
        let l = co(j);
        s += l.w * max(dot(n, l.xyz), 0.0);
    }
    return s;
}

// The ratio a floor condition's image is relit by at a texel of normal n (zero: none):
// its shading under its lights reweighted by the ground's shape over its own. Twin of
// `floor_ratio` (`reflectance/src/floor_light.rs`).
fn floor_ratio(range: vec4<f32>, n: vec3<f32>) -> f32 {
    if (all(n == vec3<f32>(0.0))) {
        return 1.0;
    }
    let first = u32(range.x) + 1u;
    let shares = u32(range.z);
    var own = 0.0;
    var env = 0.0;
    for (var j = 0u; j < u32(range.y); j++) {
        let l = co(first + j);
        let d = max(dot(n, l.xyz), 0.0);
        own += l.w * d;
        env += co(shares + j).x * d;
    }
    if (own > 0.0 && own >= range.w * env) {
        return env / own;
    }
    return 1.0;
}

// Where sun slot `s` of `job` starts (its per-tile units; its ten follow them).
fn sun_slot(job: Job, s: u32) -> u32 {
    return job.coefficient_offset + 3u * job.tiles + s * (job.tiles + 10u);
}

// Tile k's linear value at texel i of `job` times the sun of `slot` per unit of k's light.
fn sunned(job: Job, slot: u32, k: u32, i: u32) -> vec3<f32> {
    return co(slot + k).rgb * tile_value(job, k, i);
}

fn lum(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// How far the normals' sun of `slot` is trusted at texel i of `job`, normal n (zero:
// none fitted, no trust). Twin of `SunLight::trust` (`reflectance/src/sun_light.rs`).
fn trust(job: Job, slot: u32, i: u32, n: vec3<f32>) -> f32 {
    let head = slot + job.tiles;
    let bounds = co(head + 9u);
    if (all(n == vec3<f32>(0.0)) || bounds.x <= 0.0) {
        return 0.0;
    }
    let directions = job.coefficient_offset + job.tiles;
    let nearest = co(head + 1u);
    let weights = co(head + 2u);
    let held = co(head + 7u);
    let held_weights = co(head + 8u);
    var error = 0.0;
    var plain = 0.0;
    for (var j = 0u; j < min(u32(nearest.w), 2u); j++) {
        let k = u32(nearest[j]);
        let actual = lum(sunned(job, slot, k, i));
        let wanted = shading(co(directions + k), n);
        var shaded = 0.0;
        var interpolated = 0.0;
        for (var m = 0u; m < 2u; m++) {
            let w = held_weights[2u * j + m];
            if (w == 0.0) {
                continue;
            }
            let o = u32(held[2u * j + m]);
            shaded += w * shading(co(directions + o), n);
            interpolated += w * lum(sunned(job, slot, o, i));
        }
        // As the sun is relit: dark where the normal faces away.
        var predicted = interpolated;
        if (wanted <= 0.0) {
            predicted = 0.0;
        } else if (shaded >= weights.w * wanted) {
            predicted = interpolated * wanted / shaded;
        }
        error += weights[j] * abs(predicted - actual);
        plain += weights[j] * abs(interpolated - actual);
    }
    // The model's error against the plain interpolation's (what the basis does).
    var e = 0.0;
    if (plain > 0.0) {
        e = error / plain;
    } else if (error > 0.0) {
        return 0.0;
    }
    return bounds.x * (1.0 - smoothstep(bounds.z, bounds.w, e));
}

// Where texel i of `job`'s camera ray meets the visual hull (xyz, w = 1), or w = 2 where it
// misses or there is none: `t` along the ray, found at load, follows the job's codes.
fn texel_surface(job: Job, i: u32) -> vec4<f32> {
    if (job.surface == 0u) {
        return vec4<f32>(0.0, 0.0, 0.0, 2.0);
    }
    let t = bitcast<f32>(basis[job.basis_offset + job.tiles * job.texels + i]);
    let view = job.camera;
    let k = view.intrinsics;
    let pixel = vec2<f32>(f32(job.x0 + i % job.width), f32(job.y0 + i / job.width));
    let dc = vec3<f32>((pixel.x - k.z) / k.x, (pixel.y - k.w) / k.y, 1.0);
    let dir = normalize(quat_to_axes(view.rotation) * dc);
    if (t < 0.0) {
        return vec4<f32>(0.0, 0.0, 0.0, 2.0);
    }
    return vec4<f32>(view.centre + dir * t, 1.0);
}

// Whether the sun of `slot` reaches `surface`, a texel's point on the hull, as far as the
// hull can tell: from the slot's offset toward the sun on, the hull does not lie between
// it and the sun along its line of the sun's map. Twin of `SunLight::sunlit`
// (`reflectance/src/sun_light.rs`).
fn sunlit(job: Job, slot: u32, surface: vec3<f32>) -> bool {
    let head = slot + job.tiles;
    let subject = co(head + 3u);
    if (subject.w <= 0.0) {
        return true;
    }
    let ax = co(head + 4u);
    let ay = co(head + 5u);
    let m = co(head + 6u);
    let p = surface + subject.xyz * subject.w;
    let c = floor((vec2<f32>(dot(ax.xyz, p), dot(ay.xyz, p)) - vec2<f32>(ax.w, ay.w)) / m.x);
    if (!(c.x >= 0.0 && c.y >= 0.0 && c.x < m.y && c.y < m.z)) {
        return true;
    }
    let reach = sun_depths[u32(m.w) + u32(c.y) * u32(m.y) + u32(c.x)];
    return !(reach > dot(subject.xyz, p));
}

// The light of the sun of `slot` at texel i of `job`, whose normal is n (see the file's
// text).
fn sun_light(job: Job, slot: u32, i: u32, n: vec3<f32>) -> vec3<f32> {
    let directions = job.coefficient_offset + job.tiles;
    let head = slot + job.tiles;
    let sun = co(head);
    let nearest = co(head + 1u);
    let weights = co(head + 2u);
    let none = all(n == vec3<f32>(0.0));
    let wanted = max(dot(n, sun.xyz), 0.0);
    if (!none && wanted <= 0.0) {
        return vec3<f32>(0.0);
    }
    var interpolated = vec3<f32>(0.0);
    var shaded = 0.0;
    for (var j = 0u; j < u32(nearest.w); j++) {
        let k = u32(nearest[j]);
        interpolated += weights[j] * sunned(job, slot, k, i);
        shaded += weights[j] * shading(co(directions + k), n);
    }
    if (none) {
        return interpolated;
    }
    if (shaded >= weights.w * wanted) {
        return interpolated * wanted / shaded;
    }
    var num = vec3<f32>(0.0);
    var den = 0.0;
    for (var k = 0u; k < job.tiles; k++) {
        let m = shading(co(directions + k), n);
        if (m > 0.0) {
            num += sunned(job, slot, k, i) * m;
            den += m * m;
        }
    }
    if (den <= 0.0) {
        return vec3<f32>(0.0);
    }
    return wanted * num / den;
}

@compute @workgroup_size(64)
fn relight(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.y >= arrayLength(&jobs)) {
        return;
    }
    let job = jobs[id.y];
    let i = id.x;
    if (i >= job.texels) {
        return;
    }
    coefficients_at = job.coefficients_at;
    // A transparent texel holds no light (the colour is premultiplied): not relit.
    let alpha = basis[job.basis_offset + i] >> 24u;
    if (alpha == 0u) {
        relit[job.relit_offset + i] = vec4<f32>(0.0);
        return;
    }
    // A view with suns holds its suns' coefficients, and its normals where it has them:
    // their codes are the alpha bytes of tiles 1 and 2.
    let suns = job.sun_slots > 0u && co(sun_slot(job, 0u) + job.tiles).w != 0.0;
    // The texel's normal, where its view holds them (zero: none).
    var normal = vec3<f32>(0.0);
    if (job.tiles >= 3u) {
        normal = normal_of(
            basis[job.basis_offset + job.texels + i] >> 24u,
            basis[job.basis_offset + 2u * job.texels + i] >> 24u,
        );
    }
    var out = vec3<f32>(0.0);
    var basis_sun = vec3<f32>(0.0);
    for (var k = 0u; k < job.tiles; k++) {
        let c = co(job.coefficient_offset + k);
        if (c.w == 0.0) {
            continue;
        }
        let code = basis[job.basis_offset + k * job.texels + i];
        let v = vec3<f32>(
            gamma_value(code & 255u),
            gamma_value((code >> 8u) & 255u),
            gamma_value((code >> 16u) & 255u),
        );
        // A floor condition relit by the ground's shape.
        let range = co(job.coefficient_offset + job.tiles + k);
        if (range.w > 0.0) {
            out += c.rgb * v * floor_ratio(range, normal);
        } else {
            out += c.rgb * v;
        }
        if (suns) {
            basis_sun += co(job.coefficient_offset + 2u * job.tiles + k).rgb * v;
        }
    }
    if (suns) {
        let n = normal;
        var trusted = 0.0;
        var total = 0.0;
        for (var s = 0u; s < job.sun_slots; s++) {
            let slot = sun_slot(job, s);
            if (co(slot + job.tiles).w == 0.0) {
                break;
            }
            let weight = co(slot + job.tiles + 9u).y;
            trusted += weight * trust(job, slot, i, n);
            total += weight;
        }
        var t = 0.0;
        if (total > 0.0) {
            t = trusted / total;
        }
        var lit = vec3<f32>(0.0);
        if (t > 0.0) {
            var surface = vec4<f32>(0.0);
            for (var s = 0u; s < job.sun_slots; s++) {
                let slot = sun_slot(job, s);
                if (co(slot + job.tiles).w == 0.0) {
                    break;
                }
                // The texel's point on the hull is found once, where a sun would light.
                let sun = sun_light(job, slot, i, n);
                if (any(sun != vec3<f32>(0.0))) {
                    if (surface.w == 0.0) {
                        surface = texel_surface(job, i);
                    }
                    if (surface.w == 2.0 || sunlit(job, slot, surface.xyz)) {
                        lit += sun;
                    }
                }
            }
        }
        out += basis_sun + t * (lit - basis_sun);
    }
    relit[job.relit_offset + i] = vec4<f32>(out, f32(alpha));
    // The bits of a non-negative float order as the float does; a negative texel (a
    // light with negative lobes, as an L2 light has) would read as the largest.
    // Most texels are below the peak already found: read before writing, so that the
    // view's one counter is written (and contended) only while its peak still grows.
    let peak = bitcast<u32>(max(max(out.x, max(out.y, out.z)), 0.0));
    if (peak > atomicLoad(&peaks[job.peak])) {
        atomicMax(&peaks[job.peak], peak);
    }
}

fn srgb_encode(v: f32) -> f32 {
    let x = clamp(v, 0.0, 1.0);
    if (x <= 0.0031308) {
        return 12.92 * x;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

@compute @workgroup_size(64)
fn encode(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.y >= arrayLength(&jobs)) {
        return;
    }
    let job = jobs[id.y];
    let i = id.x;
    if (i >= job.texels) {
        return;
    }
    var scale = bitcast<f32>(atomicLoad(&peaks[job.peak]));
    if (scale <= 0.0) {
        scale = 1.0;
    }
    if (i == 0u) {
        prelit[job.heads_at + job.view * 8u] = bitcast<u32>(scale);
    }
    let r = relit[job.relit_offset + i];
    let code = u32(round(srgb_encode(r.x / scale) * 255.0))
        | (u32(round(srgb_encode(r.y / scale) * 255.0)) << 8u)
        | (u32(round(srgb_encode(r.z / scale) * 255.0)) << 16u)
        | (u32(r.w) << 24u);
    prelit[job.codes_at + job.layer * job.texels + i] = code;
}
