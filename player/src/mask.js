// The walker's mask: where a pose can show, as voxels round its hull mesh grown by a
// margin, and the tiles of pixels a camera sees them in. The frame passes are drawn as
// those tiles, not as frf's whole pixel box: software GL shades every pixel a draw
// covers (SwiftShader runs the shader before the depth test, and every branch of it
// however early it stops), so a frame costs what its tiles cover, about half the box.
//
// The hull is voxelised (every voxel a triangle of it touches, by samples closer than
// half a voxel), its inside filled (what the outside's flood does not reach), grown by
// the margin (a box of voxels: at least the margin in every direction), and the voxels
// on its boundary kept: their projections hold every point within the margin of the
// hull's silhouette.
import { dot, positionsBox, sub } from './geometry.js';

/** Pixels a side of a mask's tile. */
export const TILE_PX = 8;

/** The mask's voxel, in margins: a coarser one grows the mask by up to one voxel more. */
const VOXELS_PER_MARGIN = 4;

/** The fewest voxels a mask's side may take, and the most its grid may hold. */
const MIN_VOXEL_M = 0.01;
const MAX_CELLS = 4e6;

/**
 * The mask of a hull mesh (`positions` xyz flat, `indices` triangles) grown by `marginM`
 * metres: `{ centres: Float32Array (xyz of its boundary voxels), voxelM, marginM }`,
 * no voxels for an empty mesh.
 */
export function maskVoxels(positions, indices, marginM) {
  if (!(marginM >= 0) || !Number.isFinite(marginM)) throw new Error(`mask margin ${marginM} m: expected a finite length >= 0`);
  const empty = { centres: new Float32Array(0), voxelM: 0, marginM };
  if (!positions.length || !indices.length) return empty;
  const [lo, hi] = positionsBox(positions);
  let voxel = Math.max(marginM / VOXELS_PER_MARGIN, MIN_VOXEL_M);
  const cells = (v) => [0, 1, 2].map((a) => Math.ceil((hi[a] - lo[a] + 2 * marginM) / v) + 5);
  while (cells(voxel).reduce((p, n) => p * n, 1) > MAX_CELLS) voxel *= 1.25;
  // A sample lies within half a voxel of any point of its triangle: half a voxel more.
  const grow = Math.ceil(marginM / voxel + 0.5);
  const [nx, ny, nz] = cells(voxel);
  const origin = lo.map((l) => l - marginM - 2.5 * voxel);
  const at = (x, y, z) => (z * ny + y) * nx + x;
  const solid = new Uint8Array(nx * ny * nz);
  touchTriangles(positions, indices, voxel, origin, [nx, ny, nz], (x, y, z) => { solid[at(x, y, z)] = 1; });
  fillInside(solid, nx, ny, nz);
  const grown = dilate(solid, [nx, ny, nz], grow);
  return { centres: boundary(grown, [nx, ny, nz], origin, voxel), voxelM: voxel, marginM };
}

/** Calls `mark` with every voxel a sample of a triangle falls in (samples under half a voxel apart). */
function touchTriangles(positions, indices, voxel, origin, size, mark) {
  const p = (i) => [positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]];
  const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  for (let t = 0; t + 2 < indices.length; t += 3) {
    const [a, b, c] = [p(indices[t]), p(indices[t + 1]), p(indices[t + 2])];
    const n = Math.max(1, Math.ceil((2 * Math.max(dist(a, b), dist(b, c), dist(c, a))) / voxel));
    for (let i = 0; i <= n; i++) {
      for (let j = 0; i + j <= n; j++) {
        const [u, v] = [i / n, j / n];
        const cell = [0, 1, 2].map((k) => Math.floor((a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]) - origin[k]) / voxel));
        if (cell.every((x, k) => x >= 0 && x < size[k])) mark(...cell);
      }
    }
  }
}

/** Fills what the outside (a flood from the grid's border through empty voxels) does not reach. */
function fillInside(solid, nx, ny, nz) {
  const outside = new Uint8Array(solid.length);
  const stack = [];
  const push = (i) => {
    if (!solid[i] && !outside[i]) {
      outside[i] = 1;
      stack.push(i);
    }
  };
  for (let z = 0; z < nz; z++) {
    for (let y = 0; y < ny; y++) {
      for (let x = 0; x < nx; x++) {
        if (x === 0 || y === 0 || z === 0 || x === nx - 1 || y === ny - 1 || z === nz - 1) push((z * ny + y) * nx + x);
      }
    }
  }
  const plane = nx * ny;
  while (stack.length) {
    const i = stack.pop();
    const x = i % nx;
    const y = Math.floor(i / nx) % ny;
    const z = Math.floor(i / plane);
    if (x > 0) push(i - 1);
    if (x < nx - 1) push(i + 1);
    if (y > 0) push(i - nx);
    if (y < ny - 1) push(i + nx);
    if (z > 0) push(i - plane);
    if (z < nz - 1) push(i + plane);
  }
  for (let i = 0; i < solid.length; i++) if (!outside[i]) solid[i] = 1;
}

/** `solid` grown by `r` voxels along each axis in turn (a box of side 2r + 1). */
function dilate(solid, size, r) {
  let from = solid;
  const stride = [1, size[0], size[0] * size[1]];
  for (let axis = 0; axis < 3; axis++) {
    const to = new Uint8Array(from.length);
    const n = size[axis];
    const s = stride[axis];
    for (let i = 0; i < from.length; i++) {
      if (!from[i]) continue;
      const c = Math.floor(i / s) % n;
      for (let d = Math.max(-r, -c); d <= Math.min(r, n - 1 - c); d++) to[i + d * s] = 1;
    }
    from = to;
  }
  return from;
}

/** The centres of the filled voxels with an empty neighbour (of six), xyz flat. */
function boundary(solid, [nx, ny, nz], origin, voxel) {
  const out = [];
  const filled = (x, y, z) => x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz && solid[(z * ny + y) * nx + x] === 1;
  for (let z = 0; z < nz; z++) {
    for (let y = 0; y < ny; y++) {
      for (let x = 0; x < nx; x++) {
        if (!filled(x, y, z)) continue;
        if (filled(x - 1, y, z) && filled(x + 1, y, z) && filled(x, y - 1, z) && filled(x, y + 1, z) && filled(x, y, z - 1) && filled(x, y, z + 1)) continue;
        out.push(origin[0] + (x + 0.5) * voxel, origin[1] + (y + 0.5) * voxel, origin[2] + (z + 0.5) * voxel);
      }
    }
  }
  return new Float32Array(out);
}

/**
 * The tiles (`TILE_PX` a side, on the frame's grid) of `box` (a pixel box, rows down)
 * where `camera` sees `mask`'s voxels (each voxel's bounding sphere, and a pixel's
 * bilinear footprint beyond): `{ covered, centres, pixels }`, the tiles marked (a
 * frame's grid of them, rows down), the centres of point sprites
 * `TILE_PX` across in clip space (xy pairs; the target's rows bottom up; a tile the
 * frame's edge cuts is moved in, so that its centre, which decides whether a point is
 * drawn, lies in the frame) and how many of the box's pixels they cover. Null where a
 * voxel is near or behind the camera: the whole box is needed.
 */
export function maskTiles(mask, camera, box) {
  const { width: w, height: h } = camera;
  const [cols, rows] = [Math.ceil(w / TILE_PX), Math.ceil(h / TILE_PX)];
  const [tx0, ty0] = [Math.floor(box.x0 / TILE_PX), Math.floor(box.y0 / TILE_PX)];
  const [tx1, ty1] = [Math.ceil(box.x1 / TILE_PX), Math.ceil(box.y1 / TILE_PX)];
  const covered = new Uint8Array(cols * rows);
  const [r, d, f] = camera.axes;
  const { fx, fy, cx, cy } = camera.k;
  const c = mask.centres;
  const radius = (mask.voxelM * Math.sqrt(3)) / 2;
  for (let i = 0; i < c.length; i += 3) {
    const v = sub([c[i], c[i + 1], c[i + 2]], camera.centre);
    const z = dot(f, v);
    if (z < radius + 1e-3) return null;
    // A point e from the centre moves its pixel by at most f |e| sqrt(1 + tan^2) / (z - |e|)
    // along each axis (tan: the centre's off the axis).
    const tx = dot(r, v) / z;
    const ty = dot(d, v) / z;
    const px = fx * tx + cx;
    const py = fy * ty + cy;
    const rx = (Math.abs(fx) * radius * Math.sqrt(1 + tx * tx)) / (z - radius) + 1;
    const ry = (Math.abs(fy) * radius * Math.sqrt(1 + ty * ty)) / (z - radius) + 1;
    const [a0, a1] = [Math.max(Math.floor((px - rx) / TILE_PX), tx0), Math.min(Math.floor((px + rx) / TILE_PX), tx1 - 1)];
    const [b0, b1] = [Math.max(Math.floor((py - ry) / TILE_PX), ty0), Math.min(Math.floor((py + ry) / TILE_PX), ty1 - 1)];
    for (let b = b0; b <= b1; b++) for (let a = a0; a <= a1; a++) covered[b * cols + a] = 1;
  }
  return tilesOf(covered, camera, box);
}

/** The tiles either of two `maskTiles` of the same camera and box holds (null: either is the whole box). */
export function unionTiles(a, b, camera, box) {
  if (!a || !b) return null;
  return tilesOf(a.covered.map((t, i) => t | b.covered[i]), camera, box);
}

/** The point sprites of the tiles `covered` marks in `box`, and the box's pixels they cover. */
function tilesOf(covered, camera, box) {
  const { width: w, height: h } = camera;
  const cols = Math.ceil(w / TILE_PX);
  const out = [];
  let pixels = 0;
  const centre = (t, size) => Math.min((t + 0.5) * TILE_PX, size - TILE_PX / 2);
  const inBox = (t, lo, hi) => Math.max(Math.min((t + 1) * TILE_PX, hi) - Math.max(t * TILE_PX, lo), 0);
  for (let b = Math.floor(box.y0 / TILE_PX); b < Math.ceil(box.y1 / TILE_PX); b++) {
    for (let a = Math.floor(box.x0 / TILE_PX); a < Math.ceil(box.x1 / TILE_PX); a++) {
      if (!covered[b * cols + a]) continue;
      out.push((2 * centre(a, w)) / w - 1, 1 - (2 * centre(b, h)) / h);
      pixels += inBox(a, box.x0, box.x1) * inBox(b, box.y0, box.y1);
    }
  }
  return { covered, centres: new Float32Array(out), pixels };
}
