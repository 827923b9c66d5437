// The morphs of Einarsson et al.: nearest view, linear blend, two-way and four-way
// flowed morphs read at the pixel of the interpolated camera, with the occlusion cue.
// Twin of `render/src/morph/e06.rs` (whose documentation derives them); part of the
// frame pass (composed after `rebin.wgsl`).

fn opposite(dir: u32) -> u32 {
    return dir ^ 1u;
}

// The occlusion cue's factor for a squared, fraction-weighted flow inconsistency
// (twin of `morph::e06::confidence`; sigma 2 px, floor 1e-3).
fn confidence(err2: f32) -> f32 {
    return max(exp(-err2 / 4.0), 1e-3);
}

// The displacement of a source by the flow stored on `view` toward `dir`, a fraction
// `frac` of it, and (when occlusion-aware) the squared inconsistency of that flow with
// the flow back from the source `src` (x, y: displacement; z: inconsistency).
fn displaced(src: u32, view: u32, dir: u32, back: u32, frac: f32, s: vec2<f32>, occlusion: bool) -> vec3<f32> {
    if (frac == 0.0) {
        return vec3<f32>(0.0);
    }
    let f = sample_flow(view, dir, s);
    var err2 = 0.0;
    if (occlusion) {
        let e = frac * (f + sample_flow(src, back, s + f));
        err2 = dot(e, e);
    }
    return vec3<f32>(frac * f, err2);
}

// E06's morphs of the quad's views at s (see `render/src/morph/e06.rs` for the derivation and
// the occlusion cue).
fn morph(hit: Hit, s: vec2<f32>) -> vec4<f32> {
    let q = quad_views(hit, frame.columns, frame.rows);
    let beta = hit.beta;
    let gamma = hit.gamma;
    let b = 1.0 - beta;
    let g = 1.0 - gamma;
    let w = bilinear_weights(beta, gamma);
    let occlusion = (FLAGS & 2u) != 0u;
    var out = vec4<f32>(0.0);
    switch KIND {
        case 0u: {
            // Nearest: the last vertex of largest weight.
            var k = 0u;
            for (var i = 1u; i < 4u; i++) {
                if (w[i] >= w[k]) {
                    k = i;
                }
            }
            out = sample_prelit(q[k], s);
        }
        case 1u: {
            for (var i = 0u; i < 4u; i++) {
                if (w[i] > 0.0) {
                    out += sample_prelit(q[i], s) * w[i];
                }
            }
        }
        default: {
            // Per source: its view, weight, and its two flows (stored on, toward, back
            // toward, fraction); the two-way morph uses the nearer row's two sources.
            var src = q;
            var weight = w;
            var flow_view = array<vec2<u32>, 4>(
                vec2<u32>(q.y, q.z), vec2<u32>(q.x, q.w), vec2<u32>(q.w, q.x), vec2<u32>(q.z, q.y),
            );
            let toward = array<vec2<u32>, 4>(
                vec2<u32>(LEFT, DOWN), vec2<u32>(RIGHT, DOWN), vec2<u32>(LEFT, UP), vec2<u32>(RIGHT, UP),
            );
            var frac = array<vec2<f32>, 4>(
                vec2<f32>(beta, gamma), vec2<f32>(b, gamma), vec2<f32>(beta, g), vec2<f32>(b, g),
            );
            if (KIND == 2u) {
                var p = q.x;
                var r = q.y;
                if (gamma >= 0.5) {
                    p = q.z;
                    r = q.w;
                }
                src = vec4<u32>(p, r, p, r);
                weight = vec4<f32>(b, beta, 0.0, 0.0);
                flow_view[0] = vec2<u32>(r, p);
                flow_view[1] = vec2<u32>(p, p);
                frac[0] = vec2<f32>(beta, 0.0);
                frac[1] = vec2<f32>(b, 0.0);
            }
            var total = 0.0;
            for (var i = 0u; i < 4u; i++) {
                if (weight[i] > 0.0) {
                    let d0 = displaced(src[i], flow_view[i].x, toward[i].x, opposite(toward[i].x), frac[i].x, s, occlusion);
                    let d1 = displaced(src[i], flow_view[i].y, toward[i].y, opposite(toward[i].y), frac[i].y, s, occlusion);
                    var wi = weight[i];
                    if (occlusion) {
                        wi *= confidence(d0.z + d1.z);
                    }
                    out += sample_prelit(src[i], s + (d0.xy + d1.xy)) * wi;
                    total += wi;
                }
            }
            if (occlusion && total > 0.0) {
                out /= total;
            }
        }
    }
    return out;
}
