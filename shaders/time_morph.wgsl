// The frame between two captured poses (render/src/motion.rs, `time_morph`, its CPU
// twin): pose k's render sampled back along k''s motion toward k, a fraction s of it,
// pose k''s render sampled on along k's motion, a fraction 1 - s, mixed (1 - s, s).
// Motion renders hold (across, along) the subject's axis in metres as
// ((r - b) / a, (g - b) / a); `to_image` takes metres to the frame's pixels.
// Only the walker's pixel box is drawn and morphed, each render packed with others into
// a page: the morph reads them only within the box (transparent beyond it). Every
// walker of a frame is morphed in one dispatch, one layer of workgroups a walker (its
// record in `morphs`); the morphs' pages follow the renders' in the scratch array, so
// that the pass never reads a page it writes.

struct TimeMorph {
    // Columns of the 2x2 map from metres to pixels.
    to_image: vec4<f32>,
    // The walker's pixel box: first column and row, one past the last.
    bounds: vec4<u32>,
    // Where each render holds frame pixel p: at p + its offset in its page
    // (`render/src/atlas.rs`); xy, then zw: before and after, their motions, the morph.
    at_poses: vec4<i32>,
    at_motions: vec4<i32>,
    at_morph: vec4<i32>,
    s: f32,
    // 1: the morph's depth is the nearer of the two poses' renders' depths.
    by_depth: u32,
    // The morph's page among the morphs' pages (`morphed`'s layer).
    morph_page: u32,
    pad: u32,
    // The pages: pose k's render among the subjects, pose k''s and the two poses' motion
    // renders among the scratch renders.
    pages: vec4<u32>,
}

@group(0) @binding(0) var<storage, read> morphs: array<TimeMorph>;
// The frame's subjects, pose k's render in each walker's page.
@group(0) @binding(1) var before: texture_2d_array<f32>;
// The scratch renders: pose k''s and both poses' motion.
@group(0) @binding(2) var renders: texture_2d_array<f32>;
@group(0) @binding(3) var morphed: texture_storage_2d_array<rgba32float, write>;
// With `by_depth`: the two poses' renders' depths (as `before` and `renders`), and the
// morph's (as `morphed`): the nearer (`render/src/proxy.rs`).
@group(0) @binding(4) var before_depth: texture_2d_array<f32>;
@group(0) @binding(5) var render_depths: texture_2d_array<f32>;
@group(0) @binding(6) var morphed_depth: texture_storage_2d_array<r32float, write>;

// The walker morphed by this invocation (`morph_in_time` sets it).
var<private> tm: TimeMorph;

fn motion_at(t: texture_2d_array<f32>, page: u32, p: vec2<i32>, at: vec2<i32>) -> vec2<f32> {
    let m = textureLoad(t, p + at, page, 0);
    if (m.a < 1e-3) {
        return vec2<f32>(0.0);
    }
    let metres = vec2<f32>(m.r - m.b, m.g - m.b) / m.a;
    return tm.to_image.xy * metres.x + tm.to_image.zw * metres.y;
}

// Bilinear, pixel centres at integers, transparent beyond the box (and so beyond the
// frame's edge: the CPU's `Border::Zero`).
fn bilinear_zero(t: texture_2d_array<f32>, page: u32, at: vec2<i32>, q: vec2<f32>) -> vec4<f32> {
    let lo = vec2<i32>(tm.bounds.xy);
    let hi = vec2<i32>(tm.bounds.zw);
    let limit = f32(max(hi.x, hi.y) + 2);
    let c = clamp(q, vec2<f32>(-limit), vec2<f32>(limit));
    let f0 = floor(c);
    let fr = c - f0;
    let i0 = vec2<i32>(f0);
    var acc = vec4<f32>(0.0);
    for (var dy = 0; dy < 2; dy++) {
        for (var dx = 0; dx < 2; dx++) {
            let w = select(1.0 - fr.x, fr.x, dx == 1) * select(1.0 - fr.y, fr.y, dy == 1);
            let p = i0 + vec2<i32>(dx, dy);
            if (w != 0.0 && all(p >= lo) && all(p < hi)) {
                acc += w * textureLoad(t, p + at, page, 0);
            }
        }
    }
    return acc;
}

@compute @workgroup_size(8, 8)
fn morph_in_time(@builtin(global_invocation_id) id: vec3<u32>) {
    tm = morphs[id.z];
    let pixel = id.xy + tm.bounds.xy;
    if (any(pixel >= tm.bounds.zw)) {
        return;
    }
    let p = vec2<i32>(pixel);
    let at = vec2<f32>(pixel);
    let pg = tm.pages;
    let a = bilinear_zero(before, pg.x, tm.at_poses.xy, at + tm.s * motion_at(renders, pg.w, p, tm.at_motions.zw));
    let b = bilinear_zero(renders, pg.y, tm.at_poses.zw, at + (1.0 - tm.s) * motion_at(renders, pg.z, p, tm.at_motions.xy));
    textureStore(morphed, p + tm.at_morph.xy, tm.morph_page, (1.0 - tm.s) * a + tm.s * b);
    if (tm.by_depth == 1u) {
        let d = min(textureLoad(before_depth, p + tm.at_poses.xy, pg.x, 0).x, textureLoad(render_depths, p + tm.at_poses.zw, pg.y, 0).x);
        textureStore(morphed_depth, p + tm.at_morph.xy, tm.morph_page, vec4<f32>(d));
    }
}
