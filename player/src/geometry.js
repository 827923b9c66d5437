// The geometry a pose is drawn with, computed once per pose on the CPU: the grid's
// cameras, the cylinder of their centres (quads and the walls above and below it) and
// each quad's rectified frame. Twins of frf's `render/src/cylinder.rs`,
// `render/src/rectified.rs` and `render/src/geometry.rs` (docs/design.md sections 4.2
// and 4.3 derive them); the frame shader (shaders.js) reads them from data textures.

const WALL_HEIGHT_M = 1e3;

export const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
export const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
export const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
export const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
export const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
export const length = (a) => Math.sqrt(dot(a, a));
export const normalizeOrZero = (a) => {
  const l = length(a);
  return l > 0 ? scale(a, 1 / l) : [0, 0, 0];
};

/** The box `[lo, hi]` of `positions` (xyz flat); infinite bounds the wrong way round when empty. */
export function positionsBox(positions) {
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; i += 3) {
    for (let a = 0; a < 3; a++) {
      lo[a] = Math.min(lo[a], positions[i + a]);
      hi[a] = Math.max(hi[a], positions[i + a]);
    }
  }
  return [lo, hi];
}

/** A camera's projection of subject-frame point `q` (pixels, centres at integers), or null behind it (frf's `Camera::project`). */
export function project(camera, q) {
  const [r, d, f] = camera.axes;
  const v = sub(q, camera.centre);
  const z = dot(f, v);
  if (z < 1e-3) return null;
  return [(camera.k.fx * dot(r, v)) / z + camera.k.cx, (camera.k.fy * dot(d, v)) / z + camera.k.cy];
}

/** A camera of the extension: intrinsics, rotation columns (right, down, forward), centre. */
export function cameraOf(record) {
  const m = record.world_from_camera;
  const [fx, fy, cx, cy] = record.intrinsics;
  return {
    width: record.width,
    height: record.height,
    k: { fx, fy, cx, cy },
    // Columns of R: the camera's axes in the subject frame.
    axes: [0, 1, 2].map((j) => [m[0][j], m[1][j], m[2][j]]),
    centre: [m[0][3], m[1][3], m[2][3]],
  };
}

/** The camera frf's `Camera::look_at` makes (vertical field of view in radians). */
export function lookAt(eye, target, fovY, width, height) {
  const forward = normalizeOrZero(sub(target, eye));
  const right = normalizeOrZero(cross(forward, [0, 1, 0]));
  if (length(forward) === 0 || length(right) === 0) {
    throw new Error(`camera at ${eye} looking at ${target}: no view direction, or straight up or down`);
  }
  const down = cross(forward, right);
  const f = height / 2 / Math.tan(fovY / 2);
  return {
    width,
    height,
    k: { fx: f, fy: f, cx: (width - 1) / 2, cy: (height - 1) / 2 },
    axes: [right, down, forward],
    centre: eye,
  };
}

// 3x3 matrices as arrays of three columns.
const matMul = (a, b) => b.map((col) => [0, 1, 2].map((r) => a[0][r] * col[0] + a[1][r] * col[1] + a[2][r] * col[2]));
const transpose = (m) => [0, 1, 2].map((c) => [m[0][c], m[1][c], m[2][c]]);
function inverse(m) {
  const [a, b, c] = m; // columns
  const r0 = cross(b, c);
  const r1 = cross(c, a);
  const r2 = cross(a, b);
  const det = dot(a, r0);
  if (!(Math.abs(det) > 0)) return null;
  // Rows of the inverse are r0, r1, r2 over det: as columns, transpose.
  return transpose([scale(r0, 1 / det), scale(r1, 1 / det), scale(r2, 1 / det)]);
}
const kMatrix = (k) => [[k.fx, 0, 0], [0, k.fy, 0], [k.cx, k.cy, 1]];
const kInverse = (k) => [[1 / k.fx, 0, 0], [0, 1 / k.fy, 0], [-k.cx / k.fx, -k.cy / k.fy, 1]];

/** The point nearest, in the least-squares sense, to the optical axes of `cams`. */
function fixation(cams) {
  let a = [[0, 0, 0], [0, 0, 0], [0, 0, 0]];
  let b = [0, 0, 0];
  for (const c of cams) {
    const d = c.axes[2];
    const m = [0, 1, 2].map((j) => [0, 1, 2].map((i) => (i === j ? 1 : 0) - d[i] * d[j]));
    a = a.map((col, j) => add(col, m[j]));
    b = add(b, matMul(m, [c.centre])[0]);
  }
  const det = dot(a[0], cross(a[1], a[2]));
  if (Math.abs(det) <= 1e-9) return null;
  return matMul(inverse(a), [b])[0];
}

/** The rectified frame of the quad of cameras [A, B, C, D] (twin of `QuadFrame::new`), or null. */
export function quadFrame(cams) {
  const c = cams.map((k) => k.centre);
  const forward = cams.reduce((s, k) => add(s, k.axes[2]), [0, 0, 0]);
  const diagonal = cross(sub(c[3], c[0]), sub(c[2], c[1]));
  const d30 = sub(c[3], c[0]);
  let n = length(diagonal) > 1e-6 * Math.max(dot(d30, d30), 1e-12)
    ? normalizeOrZero(diagonal)
    : normalizeOrZero(cross(sub(c[1], c[0]), [0, 1, 0]));
  if (dot(n, forward) < 0) n = scale(n, -1);
  if (length(n) === 0 || dot(n, normalizeOrZero(forward)) < 0.2) return null;
  const right = cams.reduce((s, k) => add(s, k.axes[0]), [0, 0, 0]);
  const x = normalizeOrZero(sub(right, scale(n, dot(right, n))));
  if (length(x) === 0) return null;
  const rotation = [x, cross(n, x), n];
  const mean = (f) => cams.reduce((s, k) => s + f(k.k), 0) / 4;
  const k = { fx: mean((q) => q.fx), fy: mean((q) => q.fy), cx: mean((q) => q.cx), cy: mean((q) => q.cy) };
  const kq = kMatrix(k);
  const rt = transpose(rotation);
  const toRectified = cams.map((cam) => matMul(matMul(matMul(kq, rt), cam.axes), kInverse(cam.k)));
  const fromRectified = toRectified.map(inverse);
  if (fromRectified.some((h) => !h || h.flat().some((v) => !Number.isFinite(v)))) return null;
  const centres = c.map((p) => matMul(rt, [p])[0].slice(0, 2));
  const meanCentre = scale(c.reduce(add, [0, 0, 0]), 0.25);
  const p = fixation(cams);
  let depth = p ? dot(n, sub(p, meanCentre)) : NaN;
  if (!(Number.isFinite(depth) && depth > 1e-3)) depth = 1;
  return { rotation, k, toRectified, fromRectified, centres, fixationDepth: depth };
}

/** One quad of the cylinder (twin of `Quad::new`): wall 0 inside, 1 above, 2 below. */
function quad(u, v, [p00, p10, p01, p11], wall, wallGamma) {
  return {
    u, v, p00,
    e1: sub(p10, p00),
    e2: sub(p01, p00),
    e3: add(sub(sub(p00, p10), p01), p11),
    normal: normalizeOrZero(cross(sub(p11, p00), sub(p01, p10))),
    wall, wallGamma,
  };
}

/**
 * A pose's geometry: the grid's cameras (u-major), the cylinder's quads (twin of
 * `Cylinder::new`), the rectified frames (twin of `PoseGeometry::new`) and the
 * fallback axis of the proxy (the hull's box centre).
 */
export function poseGeometry(grid, cameraRecords, hullPositions) {
  const { columns, rows, wraps } = grid;
  const cameras = cameraRecords.map(cameraOf);
  const at = (u, v) => cameras[(u % columns) * rows + Math.min(v, rows - 1)];
  const centre = (u, v) => at(u, v).centre;
  const spans = wraps ? columns : columns - 1;
  const up = [0, WALL_HEIGHT_M, 0];
  const quads = [];
  for (let u = 0; u < spans; u++) {
    for (let v = 0; v + 1 < rows; v++) {
      quads.push(quad(u, v, [centre(u, v), centre(u + 1, v), centre(u, v + 1), centre(u + 1, v + 1)], 0, 0));
    }
    const top = rows - 1;
    const [vt, gt] = rows >= 2 ? [rows - 2, 1] : [0, 0];
    quads.push(quad(u, vt, [centre(u, top), centre(u + 1, top), add(centre(u, top), up), add(centre(u + 1, top), up)], 1, gt));
    quads.push(quad(u, 0, [centre(u, 0), centre(u + 1, 0), sub(centre(u, 0), up), sub(centre(u + 1, 0), up)], 2, 0));
  }
  const frameRows = Math.max(rows - 1, 1);
  const frames = [];
  for (let i = 0; i < columns * frameRows; i++) {
    const u = Math.floor(i / frameRows);
    const v = i % frameRows;
    const top = rows > 1 ? v + 1 : v;
    frames.push(quadFrame([at(u, v), at(u + 1, v), at(u, top), at(u + 1, top)]));
  }
  const [lo, hi] = positionsBox(hullPositions);
  const axis = hullPositions.length ? [(lo[0] + hi[0]) / 2, (lo[2] + hi[2]) / 2] : [0, 0];
  return { cameras, quads, frames, frameRows, axis, hasHull: hullPositions.length > 0 };
}

/** RGBA32F texels a quad: its corners and normal, then its plane and edges' tests. */
export const QUAD_TEXELS = 10;

/** How far outside its unit square (bilinear units) a point still meets a quad (frf's `EDGE_SLACK`). */
const EDGE_SLACK = 1e-4;

/**
 * Quads as RGBA32F texels, `QUAD_TEXELS` a quad: p00+u, e1+v, e2+wall, e3+wallGamma,
 * normal; then its plane (n, n . p00) and, per edge i of the corner cycle p00, p10,
 * p11, p01, the test (m, k) with m = n x edge: a point p of the plane is inside the
 * quad where m . p >= k on every edge (the slack of frf's `EDGE_SLACK` added, scaled
 * by the edges' lengths).
 */
export function quadTexels(quads) {
  const out = new Float32Array(quads.length * QUAD_TEXELS * 4);
  quads.forEach((q, i) => {
    const n = q.normal;
    const p10 = add(q.p00, q.e1);
    const p01 = add(q.p00, q.e2);
    const corners = [q.p00, p10, add(p10, add(q.e2, q.e3)), p01];
    const slack = EDGE_SLACK * length(q.e1) * length(q.e2);
    const edges = corners.flatMap((c, j) => {
      const m = cross(n, sub(corners[(j + 1) % 4], c));
      return [...m, dot(c, m) - slack];
    });
    out.set([...q.p00, q.u, ...q.e1, q.v, ...q.e2, q.wall, ...q.e3, q.wallGamma, ...n, 0, ...n, dot(n, q.p00), ...edges], i * QUAD_TEXELS * 4);
  });
  return out;
}

/** Per frame 32 RGBA32F texels (the layout `frameTexel` of shaders.js reads). */
export const FRAME_TEXELS = 32;
export function frameTexels(frames) {
  const out = new Float32Array(frames.length * FRAME_TEXELS * 4);
  frames.forEach((f, i) => {
    if (!f) return; // valid = 0
    const t = [];
    t.push(...f.rotation[0], 1, ...f.rotation[1], 0, ...f.rotation[2], 0);
    t.push(f.k.fx, f.k.fy, f.k.cx, f.k.cy);
    for (const h of f.toRectified) for (const col of h) t.push(...col, 0);
    for (const h of f.fromRectified) for (const col of h) t.push(...col, 0);
    const c = f.centres;
    t.push(c[0][0], c[0][1], c[1][0], c[1][1], c[2][0], c[2][1], c[3][0], c[3][1]);
    t.push(f.fixationDepth, 0, 0, 0);
    out.set(t, i * FRAME_TEXELS * 4);
  });
  return out;
}

/** The direction toward a sun at `azimuth`, `elevation` (radians): frf's convention. */
export function sunDirection(azimuth, elevation) {
  return [Math.sin(azimuth) * Math.cos(elevation), Math.sin(elevation), Math.cos(azimuth) * Math.cos(elevation)];
}

/**
 * Which column spans of quads a ray's line can reach, seen from above (twin of frf's
 * `render/src/cylinder/column_index.rs`): each span's quads lie within a range of
 * azimuths about the mean of the camera centres, and all of them in an annulus about
 * it; a ray tests only the spans whose ranges meet the azimuths its line sweeps across
 * the annulus. Null where the grid does not allow it (every quad is tested then).
 */
export function columnIndex(quads, quadsPerSpan, cameras, rows) {
  const xz = (p) => [p[0], p[2]];
  const sub2 = (a, b) => [a[0] - b[0], a[1] - b[1]];
  const len2 = (a) => Math.hypot(a[0], a[1]);
  const turn = (s, e) => Math.atan2(s[0] * e[1] - s[1] * e[0], s[0] * e[0] + s[1] * e[1]);
  const mean = (ps) => ps.reduce((s, p) => [s[0] + p[0] / ps.length, s[1] + p[1] / ps.length], [0, 0]);
  const centres = cameras.map((c) => xz(c.centre));
  if (!quads.length || centres.length < rows) return null;
  const axis = mean(centres);
  const segment = (a, b) => {
    const ab = sub2(b, a);
    const l = ab[0] * ab[0] + ab[1] * ab[1];
    const k = l > 0 ? Math.min(Math.max(-(a[0] * ab[0] + a[1] * ab[1]) / l, 0), 1) : 0;
    return len2([a[0] + ab[0] * k, a[1] + ab[1] * k]);
  };
  const footprints = [];
  for (let s = 0; s < quads.length; s += quadsPerSpan) {
    const f = { corners: [], reach: 0, near: Infinity, far: 0 };
    for (const q of quads.slice(s, s + quadsPerSpan)) {
      if (len2([q.normal[0], q.normal[2]]) === 0 && q.normal[1] === 0) continue;
      const p10 = add(q.p00, q.e1);
      const p01 = add(q.p00, q.e2);
      const c = [q.p00, p10, p01, add(p10, add(q.e2, q.e3))].map((p) => sub2(xz(p), axis));
      const longest = Math.max(...[[1, 0], [3, 2], [2, 0], [3, 1]].map(([i, j]) => len2(sub2(c[i], c[j]))));
      const twist = len2([c[0][0] - c[1][0] - c[2][0] + c[3][0], c[0][1] - c[1][1] - c[2][1] + c[3][1]]);
      f.reach = Math.max(f.reach, 2 * 1e-4 * (longest + twist));
      for (let i = 0; i < 4; i++) {
        f.far = Math.max(f.far, len2(c[i]));
        for (let j = i + 1; j < 4; j++) f.near = Math.min(f.near, segment(c[i], c[j]));
      }
      f.corners.push(...c);
    }
    if (!f.corners.length) return null;
    footprints.push(f);
  }
  const norm = (v) => { const l = len2(v); return l > 0 ? [v[0] / l, v[1] / l] : null; };
  const reference = norm(sub2(mean(centres.slice(0, rows)), axis));
  if (!reference) return null;
  const centreOf = (f) => mean(f.corners);
  const first = turn(reference, centreOf(footprints[0]));
  if (first === 0) return null;
  const orientation = Math.sign(first);
  const reach = Math.max(...footprints.map((f) => f.reach));
  const far = Math.max(...footprints.map((f) => f.far));
  const near = Math.min(...footprints.map((f) => f.near));
  const rMax = far + reach + 1e-3 * far;
  const rMin = near - reach - 1e-3 * far;
  if (!(rMin > 1e-2 * rMax && Number.isFinite(rMax))) return null;
  const ranges = [];
  let previous = [0, reference];
  for (const f of footprints) {
    const centre = centreOf(f);
    const s = previous[0] + orientation * turn(previous[1], centre);
    previous = [s, centre];
    let lo = 0;
    let hi = 0;
    for (const c of f.corners) {
      const a = orientation * turn(centre, c);
      lo = Math.min(lo, a);
      hi = Math.max(hi, a);
    }
    if (f.reach >= 0.5 * f.near) return null;
    // frf's margin, and 0.01 rad more: the corners here are not carried into each
    // quad's plane (the grid's quads are planar to a fraction of a millimetre).
    const margin = 1e-3 + 0.01 + (2 * f.reach) / f.near;
    const range = [s + lo - margin, s + hi + margin];
    if (!(range[1] - range[0] < Math.PI)) return null;
    ranges.push(range);
  }
  for (let i = 1; i < ranges.length; i++) {
    if (!(ranges[i - 1][0] < ranges[i][0] && ranges[i - 1][1] < ranges[i][1])) return null;
  }
  const TAU = 2 * Math.PI;
  if (!(ranges.at(-1)[1] - ranges[0][1] < TAU && ranges.at(-1)[1] - ranges[0][0] < 3 * Math.PI)) return null;
  return { axis, reference, orientation, rMin, rMax, ranges, quadsPerSpan };
}
