// Where a pixel's ray enters the cylinder of camera centres: the quads of the column
// spans its line can reach, each solved by the inverse bilinear map of `common.wgsl`.
// Twin of `render/src/cylinder.rs` and `render/src/cylinder/column_index.rs`; part of
// the frame pass (composed after `rebin.wgsl`, whose bindings it reads).

const TAU: f32 = 6.2831855;

// What the search over quads keeps: the hit of smallest t (of equal ones, the first
// quad's, whatever the order), and whether any lies ahead. Twin of `Nearest`.
struct Nearest {
    hit: Hit,
    index: u32,
    any_ahead: bool,
}

// Offers the hit of the ray on quad i, if any (twin of `Quad::hit` and `Nearest::offer`).
fn offer(i: u32, origin: vec3<f32>, dir: vec3<f32>, n: ptr<function, Nearest>) {
    let q = quads[i];
    let denom = dot(q.normal, dir);
    if (abs(denom) < 1e-9) {
        return;
    }
    let t = dot(q.normal, q.p00 - origin) / denom;
    let p = origin + dir * t;
    let r = inverse_bilinear(p, q.p00, q.e1, q.e2, q.e3, q.normal);
    if (!r.ok || outside(r.bg) > 1e-4) {
        return;
    }
    if (t >= 0.0) {
        (*n).any_ahead = true;
    }
    if (t < (*n).hit.t || (t == (*n).hit.t && i < (*n).index)) {
        var gamma = clamp(r.bg.y, 0.0, 1.0);
        var clamped = 0u;
        if (q.wall != 0u) {
            gamma = q.wall_gamma;
            clamped = q.wall;
        }
        (*n).hit = Hit(q.u, q.v, clamp(r.bg.x, 0.0, 1.0), gamma, p, t, clamped);
        (*n).index = i;
    }
}

// The signed angle turning `start` into `end`, in (-pi, pi].
fn turn(start: vec2<f32>, end: vec2<f32>) -> f32 {
    return atan2(cross2(start, end), dot(start, end));
}

// Azimuth of v (relative to the axis point) in [0, 2 pi) (twin of `ColumnIndex::azimuth`).
fn column_azimuth(v: vec2<f32>) -> f32 {
    let s = column_index.header.orientation * turn(column_index.header.reference, v);
    return select(s, s + TAU, s < 0.0);
}

// Offers the quads of every span whose range meets the azimuths swept from `start` to
// `end` (twin of `ColumnIndex::walk`).
fn walk_spans(start: vec2<f32>, end: vec2<f32>, origin: vec3<f32>, dir: vec3<f32>, n: ptr<function, Nearest>) {
    let c = column_index.header;
    let sweep = c.orientation * turn(start, end);
    var a = column_azimuth(start);
    var len = sweep;
    if (sweep < 0.0) {
        a = column_azimuth(end);
        len = -sweep;
    }
    // Into (hi_last - 2 pi, hi_last].
    let last = column_index.ranges[c.spans - 1u].y;
    a -= TAU * ceil((a - last) / TAU);
    if (a > last) {
        a -= TAU;
    }
    if (a <= last - TAU) {
        a += TAU;
    }
    let b = a + len;
    // The first span whose range ends at or after a.
    var lo = 0u;
    var hi = c.spans;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (column_index.ranges[mid].y < a) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    for (var u = lo; u < c.spans && column_index.ranges[u].x <= b; u++) {
        for (var k = 0u; k < c.quads_per_span; k++) {
            offer(u * c.quads_per_span + k, origin, dir, n);
        }
    }
    // The same spans a turn later.
    for (var u = 0u; u < c.spans && column_index.ranges[u].x + TAU <= b; u++) {
        for (var k = 0u; k < c.quads_per_span; k++) {
            offer(u * c.quads_per_span + k, origin, dir, n);
        }
    }
}

// Where the ray `origin + t dir` enters the cylinder: the smallest parameter of all
// intersections, unless all lie behind the camera. Only the quads of the spans its line
// can reach are solved (twin of `ColumnIndex::spans_along`); all of them without an index.
fn intersect(origin: vec3<f32>, dir: vec3<f32>) -> Hit {
    var n = Nearest(Hit(0u, 0u, 0.0, 0.0, vec3<f32>(0.0), 3.4e38, 3u), 0xffffffffu, false);
    let c = column_index.header;
    let big = vec3<f32>(3.4e38);
    let finite_ray = all(abs(origin) <= big) && all(abs(dir) <= big);
    if (c.enabled == 0u || !finite_ray) {
        for (var i = 0u; i < frame.quad_count; i++) {
            offer(i, origin, dir, &n);
        }
    } else {
        let o = origin.xz - c.axis;
        let m = max(abs(dir.x), abs(dir.z));
        if (m == 0.0) {
            // Vertical: a point.
            let r = length(o);
            if (r >= c.r_min && r <= c.r_max) {
                walk_spans(o, o, origin, dir, &n);
            }
        } else {
            let d = normalize(dir.xz / m);
            let across = vec2<f32>(-d.y, d.x);
            let h = dot(o, across);
            if (abs(h) <= c.r_max) {
                let foot = across * h;
                let outer = sqrt(c.r_max * c.r_max - h * h);
                if (abs(h) >= c.r_min) {
                    walk_spans(foot - d * outer, foot + d * outer, origin, dir, &n);
                } else {
                    let inner = sqrt(c.r_min * c.r_min - h * h);
                    walk_spans(foot - d * outer, foot - d * inner, origin, dir, &n);
                    walk_spans(foot + d * inner, foot + d * outer, origin, dir, &n);
                }
            }
        }
    }
    var best = n.hit;
    if (!n.any_ahead) {
        best.clamped = 3u;
    }
    return best;
}
