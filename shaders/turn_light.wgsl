// The light at a view's turn, on the device (docs/design.md section 4.1, *A light on the
// device*): the relighting coefficients `relight.wgsl` reads, written for every view of
// every batch relit before a submission, in one dispatch (a row of workgroups a batch),
// from the lights' yaw tables held on the GPU, so that a light that turns and walkers
// that turn cost the host one small record per relight instead of the views'
// coefficients, and the device one dispatch whatever the walkers (section 4.9). Twin of `packed_coefficients` (`render/src/gpu/relight.rs`) over the
// lighting of `relighting` (`render/src/resident.rs`): the tables' samples interpolated at
// each map's turn (`YawTable::coefficients`, `reflectance/src/yaw_table.rs`), each sun's
// slot as `SunLight::new` makes it (`reflectance/src/sun_light.rs`) and the floor
// conditions' shares reweighted by the ground (`floor_shares`,
// `reflectance/src/floor_light.rs`). Writes every entry of a job but where its conditions'
// lights are (the range's first two values, and the lights after the jobs), which do
// not change with the light. Compiled after `common.wgsl`.

struct TurnParams {
    // Relights in the dispatch (a row of workgroups each).
    relights: u32,
    // Samples of a table per turn.
    samples: u32,
    // Sun slots per job.
    sun_slots: u32,
    // A table's coarse map, texels across and down.
    coarse_w: u32,
    coarse_h: u32,
    // `RATIO_FLOOR` (`reflectance/src/light_fit.rs`) and `TRUST_ERROR`
    // (`reflectance/src/sun_light.rs`), which the slots carry to `relight.wgsl`.
    ratio_floor: f32,
    trust_low: f32,
    trust_high: f32,
}

// One batch of a pose's views relit under one light: where its jobs (two `vec4`s each),
// the field's conditions (four each) and its words (the jobs' images' scales, then the
// plan's mask of conditions, 1: used; four a `vec4`) lie in `data`, where its light's
// record lies in `lights` and its coefficients in `coefficients` (all in `vec4`s).
struct TurnRelight {
    jobs_at: u32,
    jobs: u32,
    // Threads per job: its most conditions and the sun slots.
    items: u32,
    conditions_at: u32,
    conditions: u32,
    words_at: u32,
    // Where the mask starts among its words.
    mask: u32,
    light_at: u32,
    coefficients_at: u32,
    pad1: u32,
    pad2: u32,
    pad3: u32,
}

// One view of a batch: where its coefficients start (in its relight's), its basis images,
// its turntable angle (a fraction of a turn), whether it holds normals (room for the
// floor conditions' shares after its sun slots) and where its images' scales are among
// its relight's words.
struct TurnJob {
    coefficient_offset: u32,
    tiles: u32,
    turn: f32,
    normals: u32,
    scales: u32,
    pad1: u32,
    pad2: u32,
    pad3: u32,
}

@group(0) @binding(0) var<uniform> params: TurnParams;
@group(0) @binding(1) var<storage, read> relights: array<TurnRelight>;
// Every relight's jobs, conditions and words (a page shared by many poses).
@group(0) @binding(2) var<storage, read> data: array<vec4<f32>>;
// Every table the device holds: per table, its samples of the whole map (`samples` x
// `conditions`, rgb), of what its suns leave, its coarse map's luminance (one a vec4, x),
// and per sun its illuminance (rgb; w: luminance) and its radius (x).
@group(0) @binding(3) var<storage, read> tables: array<vec4<f32>>;
// Every relight's light: (terms, suns, the ground's weight, 0); per term (where its
// whole samples are, where those less its suns are or -1, where its coarse map is or -1,
// its weight) and (its turn, a fraction of a turn on from the samples' origin; its yaw;
// 0; 0); per sun taken, five: (where it is in `tables`, 0, its term's weight, 0), then
// the four its slot holds of its map (`pack_sun`, `render/src/gpu/relight.rs`).
@group(0) @binding(4) var<storage, read> lights: array<vec4<f32>>;
// Every relight's coefficients (a page shared by many poses).
@group(0) @binding(5) var<storage, read_write> coefficients: array<vec4<f32>>;

// The relight this invocation serves (copied once from `relights`).
var<private> relight: TurnRelight;

// Entry i of its light's record.
fn light(i: u32) -> vec4<f32> {
    return lights[relight.light_at + i];
}

// Entry i of the field's conditions.
fn condition(i: u32) -> vec4<f32> {
    return data[relight.conditions_at + i];
}

// Word i of its words.
fn word(i: u32) -> f32 {
    let w = relight.words_at * 4u + i;
    return data[w / 4u][w % 4u];
}

// Its coefficient i, and its writing.
fn coefficient(i: u32) -> vec4<f32> {
    return coefficients[relight.coefficients_at + i];
}

fn put(i: u32, v: vec4<f32>) {
    coefficients[relight.coefficients_at + i] = v;
}

// Its job j.
fn job_of(j: u32) -> TurnJob {
    let a = bitcast<vec4<u32>>(data[relight.jobs_at + 2u * j]);
    let b = bitcast<vec4<u32>>(data[relight.jobs_at + 2u * j + 1u]);
    return TurnJob(a.x, a.y, bitcast<f32>(a.z), a.w, b.x, b.y, b.z, b.w);
}

const TERM: u32 = 2u;
const SUN: u32 = 5u;
// Coefficients (vec4) of a sun's slot after its per-image ones (`SUN_HEAD`).
const SUN_HEAD: u32 = 10u;
const PI: f32 = 3.14159265358979;

// Term t's samples at turn `c` (a fraction of a turn): the two around it and the second's
// weight.
fn bracket(c: f32) -> vec3<f32> {
    let n = f32(params.samples);
    let f = fract(c) * n;
    let i0 = min(floor(f), n - 1.0);
    let i1 = select(i0 + 1.0, 0.0, i0 + 1.0 >= n);
    return vec3<f32>(i0, i1, f - i0);
}

// Sample `s` of condition k in the samples starting at `at`.
fn sample(at: u32, s: f32, k: u32) -> vec3<f32> {
    return tables[at + u32(s) * relight.conditions + k].xyz;
}

// Condition k's coefficients at a view of turntable turn `turn`: the light's, and what its
// suns add where the basis relights them.
fn condition_light(k: u32, turn: f32) -> array<vec3<f32>, 2> {
    let terms = u32(light(0).x);
    let is_floor = condition(4u * k).w > 0.5;
    var c = vec3<f32>(0.0);
    var d = vec3<f32>(0.0);
    for (var t = 0u; t < terms; t++) {
        let head = light(1u + TERM * t);
        let b = bracket(light(2u + TERM * t).x + turn);
        let whole_at = u32(head.x);
        let whole = mix(sample(whole_at, b.x, k), sample(whole_at, b.y, k), b.z);
        if (head.y < 0.0 || is_floor) {
            c += head.w * whole;
        } else {
            let less_at = u32(head.y);
            let less = mix(sample(less_at, b.x, k), sample(less_at, b.y, k), b.z);
            c += head.w * less;
            d += head.w * whole - head.w * less;
        }
    }
    return array<vec3<f32>, 2>(c, d);
}

// `v` turned by `a` radians about +y (glam's `Mat3::from_rotation_y`).
fn turned(v: vec3<f32>, a: f32) -> vec3<f32> {
    let c = cos(a);
    let s = sin(a);
    return vec3<f32>(c * v.x + s * v.z, v.y, -s * v.x + c * v.z);
}

// A coarse map's texel (x, y), clamped to the map.
fn coarse_texel(at: u32, x: i32, y: i32) -> f32 {
    let w = i32(params.coarse_w);
    let h = i32(params.coarse_h);
    return tables[at + u32(clamp(y, 0, h - 1) * w + clamp(x, 0, w - 1))].x;
}

fn coarse_bilinear(at: u32, x: f32, y: f32) -> f32 {
    let x0 = floor(x);
    let y0 = floor(y);
    let f = vec2<f32>(x - x0, y - y0);
    let xi = i32(x0);
    let yi = i32(y0);
    let top = mix(coarse_texel(at, xi, yi), coarse_texel(at, xi + 1, yi), f.x);
    let bottom = mix(coarse_texel(at, xi, yi + 1), coarse_texel(at, xi + 1, yi + 1), f.x);
    return mix(top, bottom, f.y);
}

// The luminance a coarse map holds toward `direction` (`EnvMap::radiance`, bilinear,
// wrapping in azimuth).
fn coarse_radiance(at: u32, direction: vec3<f32>) -> f32 {
    let d = normalize(direction);
    let w = f32(params.coarse_w);
    let u = (1.0 + atan2(d.x, -d.z) / PI) / 2.0;
    let v = acos(clamp(d.y, -1.0, 1.0)) / PI;
    let tx = u * w - 0.5;
    let ty = v * f32(params.coarse_h) - 0.5;
    let x = tx - floor(tx / w) * w;
    if (x > w - 1.0) {
        let f = x - (w - 1.0);
        return mix(coarse_bilinear(at, w - 1.0, ty), coarse_bilinear(at, 0.0, ty), f);
    }
    return coarse_bilinear(at, x, ty);
}

// The light's ground toward `d` (subject frame), luminance.
fn ground_radiance(d: vec3<f32>) -> f32 {
    var r = 0.0;
    for (var t = 0u; t < u32(light(0).x); t++) {
        let head = light(1u + TERM * t);
        let yaw = light(2u + TERM * t).y;
        r += head.w * coarse_radiance(u32(head.z), turned(d, -yaw));
    }
    return r;
}

// The angle between two unit vectors as `nearest_weights_by` takes it.
fn angle(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return acos(clamp(dot(a, b), -1.0, 1.0));
}

// Where floor condition k's shares go in job `at`'s coefficients: after its sun slots,
// the floor conditions before it taking as many as they have lights.
fn room_of(at: u32, tiles: u32, k: u32) -> u32 {
    var room = at + 3u * tiles + params.sun_slots * (tiles + SUN_HEAD);
    for (var j = 0u; j < k; j++) {
        if (condition(4u * j).w > 0.5) {
            room += u32(condition(4u * j + 2u).w);
        }
    }
    return room;
}

// Condition k of a job (below `tiles`): its coefficient and whether it is used, what the
// suns add, each sun's light per unit of its own, and for a floor condition of a view
// with normals its lights' shares reweighted by the ground (its range's last two values
// say where).
fn condition_item(job: TurnJob, k: u32) {
    let tiles = job.tiles;
    let at = job.coefficient_offset;
    let s = word(job.scales + k);
    let cd = condition_light(k, job.turn);
    let used_by_plan = word(relight.mask + k) > 0.5;
    let c = select(vec3<f32>(0.0), cd[0], used_by_plan);
    let d = select(vec3<f32>(0.0), cd[1], used_by_plan);
    let used = select(0.0, 1.0, any(c != vec3<f32>(0.0)) || any(d != vec3<f32>(0.0)));
    put(at + k, vec4<f32>(c * s, used));
    put(at + 2u * tiles + k, vec4<f32>(d * s, 0.0));
    let suns = u32(light(0).y);
    let slots = at + 3u * tiles;
    let delivered = condition(4u * k + 1u).xyz;
    for (var j = 0u; j < params.sun_slots; j++) {
        var unit = vec3<f32>(0.0);
        if (j < suns) {
            let head = light(1u + TERM * u32(light(0).x) + SUN * j);
            let e = tables[u32(head.x)].xyz * head.z;
            unit = select(vec3<f32>(0.0), e / delivered, delivered > vec3<f32>(0.0));
        }
        put(slots + j * (tiles + SUN_HEAD) + k, vec4<f32>(unit * s, 0.0));
    }
    if (job.normals == 0u || condition(4u * k).w < 0.5) {
        return;
    }
    let ground = light(0).z;
    let range = coefficient(at + tiles + k);
    let first = u32(range.x) + 1u;
    let count = u32(range.y);
    let room = room_of(at, tiles, k);
    // Each light's share weighted by the ground it sees, kept in its room, then
    // normalised there.
    var total = 0.0;
    for (var j = 0u; j < count; j++) {
        var w = 0.0;
        if (ground > 0.0) {
            let l = coefficient(first + j);
            w = l.w * max(ground_radiance(turned(l.xyz, -job.turn * 2.0 * PI)), 0.0);
        }
        put(room + j, vec4<f32>(w, 0.0, 0.0, 0.0));
        total += w;
    }
    let reweighted = ground > 0.0 && total > 0.0 && total < 3.0e38;
    for (var j = 0u; j < count; j++) {
        var share = 0.0;
        if (reweighted) {
            let own = coefficient(first + j).w;
            share = own + ground * (coefficient(room + j).x / total - own);
        }
        put(room + j, vec4<f32>(share, 0.0, 0.0, 0.0));
    }
    put(at + tiles + k, vec4<f32>(
        range.xy,
        select(0.0, f32(room), reweighted),
        select(0.0, params.ratio_floor, reweighted),
    ));
}

// Sun slot j of a job: the sun in the view's dome frame, its nearest conditions and
// their weights, its map, the conditions that predict each nearest, its compactness and
// luminance; zero past the suns taken.
fn sun_item(job: TurnJob, j: u32) {
    let tiles = job.tiles;
    let h = job.coefficient_offset + 3u * tiles + j * (tiles + SUN_HEAD) + tiles;
    if (j >= u32(light(0).y)) {
        for (var m = 0u; m < SUN_HEAD; m++) {
            put(h + m, vec4<f32>(0.0));
        }
        return;
    }
    let r = 1u + TERM * u32(light(0).x) + SUN * j;
    let weight = light(r).z;
    let e = tables[u32(light(r).x)];
    let radius = tables[u32(light(r).x) + 1u].x;
    let direction = normalize(turned(light(r + 1u).xyz, job.turn * 2.0 * PI));
    // Its two nearest conditions by angle (the first of equals first).
    var first = 0u;
    var second = 0u;
    var a0 = 1e30;
    var a1 = 1e30;
    for (var k = 0u; k < relight.conditions; k++) {
        let a = angle(condition(4u * k).xyz, direction);
        if (a < a0) {
            second = first;
            a1 = a0;
            first = k;
            a0 = a;
        } else if (a < a1) {
            second = k;
            a1 = a;
        }
    }
    var nearest = vec4<f32>(f32(first), 0.0, 0.0, 1.0);
    var weights = vec4<f32>(1.0, 0.0, 0.0, params.ratio_floor);
    if (a0 >= 1e-6 && relight.conditions > 1u) {
        let w0 = 1.0 / (a0 * a0);
        let w1 = 1.0 / (a1 * a1);
        nearest = vec4<f32>(f32(first), f32(second), 0.0, 2.0);
        weights = vec4<f32>(w0 / (w0 + w1), w1 / (w0 + w1), 0.0, params.ratio_floor);
    }
    put(h, vec4<f32>(direction, 1.0));
    put(h + 1u, nearest);
    put(h + 2u, weights);
    for (var m = 0u; m < 4u; m++) {
        put(h + 3u + m, light(r + 1u + m));
    }
    var held = vec4<f32>(0.0);
    var held_weights = vec4<f32>(0.0);
    for (var n = 0u; n < u32(nearest.w); n++) {
        let k = u32(nearest[n]);
        let predict = condition(4u * k + 2u);
        let by = condition(4u * k + 3u);
        for (var m = 0u; m < u32(predict.z); m++) {
            held[2u * n + m] = predict[m];
            held_weights[2u * n + m] = by[m];
        }
    }
    put(h + 7u, held);
    put(h + 8u, held_weights);
    let cell = condition(4u * first + 1u).w;
    let compact = 1.0 - smoothstep(cell, 2.0 * cell, 2.0 * radius);
    put(h + 9u, vec4<f32>(compact, e.w * weight, params.trust_low, params.trust_high));
}

// One item of one job a thread, a row of workgroups a relight: `items` per job, its
// conditions first, then its sun slots (a job of fewer conditions leaves the rest idle).
@compute @workgroup_size(64)
fn turn_light(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.y >= params.relights) {
        return;
    }
    relight = relights[id.y];
    let job_index = id.x / relight.items;
    let item = id.x % relight.items;
    if (job_index >= relight.jobs) {
        return;
    }
    let job = job_of(job_index);
    if (item < job.tiles) {
        condition_item(job, item);
    } else if (item - job.tiles < params.sun_slots) {
        sun_item(job, item - job.tiles);
    }
}
