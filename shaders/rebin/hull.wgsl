// Walking a visual hull's voxels along a ray (3D DDA), read from `hull_bits`: the frame
// pass's proxy (`proxy.wgsl`, one pose's hull at word 0) and the suns' maps
// (`sun_depth.wgsl`, every walker's hull at its own word) both walk it. Twin of
// `VoxelHull::first_hit`.

// Bit c of a grid of `dims` stored x fastest in `hull_bits` from word `at`; outside the
// grid is 0.
fn hull_bit(at: u32, dims: vec3<i32>, c: vec3<i32>) -> bool {
    if (any(c < vec3<i32>(0)) || any(c >= dims)) {
        return false;
    }
    let index = u32((c.z * dims.y + c.y) * dims.x + c.x);
    return ((hull_bits[at + index / 32u] >> (index % 32u)) & 1u) == 1u;
}

// A ray's walk through the cells of a grid (3D DDA): its cell, where it crosses the next
// boundary along each axis, how far apart those are, and its step along each.
struct Walk {
    cell: vec3<i32>,
    t_next: vec3<f32>,
    t_delta: vec3<f32>,
    step: vec3<i32>,
}

// The walk of `origin + t dir` from t = `enter` through the grid of lowest corner `lo`,
// cell side `side` and `dims`.
fn walk_from(origin: vec3<f32>, dir: vec3<f32>, lo: vec3<f32>, side: f32, dims: vec3<i32>, enter: f32) -> Walk {
    let p = origin + dir * enter;
    var w = Walk(vec3<i32>(0), vec3<f32>(3.4e38), vec3<f32>(3.4e38), vec3<i32>(0));
    for (var a = 0; a < 3; a++) {
        w.cell[a] = clamp(i32(floor((p[a] - lo[a]) / side)), 0, dims[a] - 1);
        if (dir[a] != 0.0) {
            w.step[a] = select(-1, 1, dir[a] > 0.0);
            let boundary = lo[a] + f32(w.cell[a] + select(0, 1, w.step[a] > 0)) * side;
            w.t_next[a] = (boundary - origin[a]) / dir[a];
            w.t_delta[a] = side / abs(dir[a]);
        }
    }
    return w;
}

// The axis whose boundary the walk crosses next.
fn walk_axis(w: Walk) -> i32 {
    if (w.t_next.x <= w.t_next.y && w.t_next.x <= w.t_next.z) {
        return 0;
    }
    return select(2, 1, w.t_next.y <= w.t_next.z);
}

// Where the ray `origin + t dir` (t >= 0) enters the first occupied voxel of the hull `h`
// whose words start at word `at` of `hull_bits`, or -1: twin of `VoxelHull::first_hit`
// (a 3D DDA over the blocks, and inside each occupied block over its voxels).
fn hull_first_hit_of(h: Proxy, at: u32, origin: vec3<f32>, dir: vec3<f32>) -> f32 {
    if (h.present == 0u) {
        return -1.0;
    }
    let lo = h.origin;
    let hi = lo + vec3<f32>(h.dims) * h.voxel;
    var enter = 0.0;
    var exit = 3.4e38;
    for (var a = 0; a < 3; a++) {
        if (dir[a] == 0.0) {
            if (origin[a] < lo[a] || origin[a] > hi[a]) {
                return -1.0;
            }
            continue;
        }
        let t0 = (lo[a] - origin[a]) / dir[a];
        let t1 = (hi[a] - origin[a]) / dir[a];
        enter = max(enter, min(t0, t1));
        exit = min(exit, max(t0, t1));
    }
    if (enter > exit) {
        return -1.0;
    }
    let dims = vec3<i32>(h.dims);
    let block = i32(h.block);
    let blocks = (dims + vec3<i32>(block - 1)) / block;
    var b = walk_from(origin, dir, lo, h.voxel * f32(block), blocks, enter);
    var t_block = enter;
    let steps = blocks.x + blocks.y + blocks.z + 3;
    for (var i = 0; i < steps; i++) {
        let a = walk_axis(b);
        let leave = min(b.t_next[a], exit);
        if (hull_bit(at + h.block_words_at, blocks, b.cell)) {
            var f = walk_from(origin, dir, lo, h.voxel, dims, t_block);
            var t_cell = t_block;
            for (var j = 0; j < 3 * block + 3; j++) {
                if (hull_bit(at, dims, f.cell)) {
                    return t_cell;
                }
                let fa = walk_axis(f);
                if (f.t_next[fa] > leave) {
                    break;
                }
                t_cell = f.t_next[fa];
                f.cell[fa] += f.step[fa];
                f.t_next[fa] += f.t_delta[fa];
                if (f.cell[fa] < 0 || f.cell[fa] >= dims[fa]) {
                    break;
                }
            }
        }
        if (b.t_next[a] > exit) {
            return -1.0;
        }
        t_block = b.t_next[a];
        b.cell[a] += b.step[a];
        b.t_next[a] += b.t_delta[a];
        if (b.cell[a] < 0 || b.cell[a] >= blocks[a]) {
            return -1.0;
        }
    }
    return -1.0;
}
