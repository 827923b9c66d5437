// Where a pose's walker can show (frf's `render/src/footprint.rs`): a vertical cylinder
// round its hull mesh's box grown by the reach of its flows, and the box of pixels where
// a camera sees it. The player's passes shade only that box: outside it no ray can show
// the walker, which is transparent there.
import { positionsBox, project } from './geometry.js';

/** Where on the subject's axis pixels per metre are measured (metres up: mid-body). */
const AXIS_POINT_M = 1.0;

/** Pixels per metre a camera sees at the subject's axis. */
export function pixelsPerMetre(camera) {
  const [x, y, z] = camera.centre;
  const d = Math.hypot(x, y - AXIS_POINT_M, z);
  return Math.max(Math.abs(camera.k.fx), Math.abs(camera.k.fy)) / Math.max(d, 1e-3);
}

/**
 * The cylinder `{ axis: [x, z], radius, heights: [lo, hi] }` round the box of `positions`
 * (a hull mesh's, xyz flat) grown by `margin` metres on every side.
 */
export function subjectBounds(positions, margin) {
  const [lo, hi] = positionsBox(positions);
  return {
    axis: [(lo[0] + hi[0]) / 2, (lo[2] + hi[2]) / 2],
    radius: Math.hypot((hi[0] - lo[0]) / 2, (hi[2] - lo[2]) / 2) + margin,
    heights: [lo[1] - margin, hi[1] + margin],
  };
}

/**
 * How far (metres, at the subject's axis) a pose's flows carry a sample: their largest
 * component `maxFlowPx` (frf: its quantizer's range) times √2, and a pixel for the
 * bilinear footprint, at the median pixels per metre of the views' `cameras`.
 */
export function flowReachM(maxFlowPx, cameras) {
  return (maxFlowPx * Math.SQRT2 + 1) * viewPixelM(cameras);
}

/** A view's pixel at the subject's axis, in metres: at the median pixels per metre of `cameras`. */
export function viewPixelM(cameras) {
  const ppm = cameras.map(pixelsPerMetre).sort((a, b) => a - b);
  const median = ppm[Math.floor(ppm.length / 2)] ?? 0;
  return 1 / median;
}

/**
 * The box of pixels `{ x0, y0, x1, y1 }` (rows down, ends exclusive) where `camera` sees
 * `bounds`, a pixel's bilinear footprint either side: the whole frame when part of them
 * is behind the camera, null when it sees none.
 */
export function pixelBox(bounds, camera) {
  const { width: w, height: h } = camera;
  // The 16-gon's circumradius, so that it holds the circle.
  const r = bounds.radius / Math.cos(Math.PI / 16);
  let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
  for (let k = 0; k < 16; k++) {
    const a = (k * 2 * Math.PI) / 16;
    for (const y of bounds.heights) {
      const p = project(camera, [bounds.axis[0] + r * Math.cos(a), y, bounds.axis[1] + r * Math.sin(a)]);
      if (!p) return { x0: 0, y0: 0, x1: w, y1: h };
      [x0, y0, x1, y1] = [Math.min(x0, p[0]), Math.min(y0, p[1]), Math.max(x1, p[0]), Math.max(y1, p[1])];
    }
  }
  if (x1 < 0 || y1 < 0 || x0 > w - 1 || y0 > h - 1) return null;
  const clamp = (v, max) => Math.min(Math.max(v, 0), max);
  return {
    x0: clamp(Math.floor(x0) - 1, w), y0: clamp(Math.floor(y0) - 1, h),
    x1: clamp(Math.ceil(x1) + 2, w), y1: clamp(Math.ceil(y1) + 2, h),
  };
}

/** The smallest box holding both (null: none). */
export function unionBox(a, b) {
  if (!a) return b;
  if (!b) return a;
  return { x0: Math.min(a.x0, b.x0), y0: Math.min(a.y0, b.y0), x1: Math.max(a.x1, b.x1), y1: Math.max(a.y1, b.y1) };
}
