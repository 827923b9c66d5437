// The walk in time (frf's docs/design.md section 4.7): which exported poses an instant
// falls between and how far, and the map from the subject's motion (metres across its
// axis and up it, as the export stores it) into a camera's pixels. Twins of frf's
// `scene/src/plan.rs` (`poses_around`) and `core/src/subject_motion.rs`
// (`motion_to_image`).
import { dot, cross, normalizeOrZero, project } from './geometry.js';

const STEP_M = 0.01;

/** Fractions of a pose's step this close to a pose draw that pose alone (frf's `AT_POSE`). */
const AT_POSE = 1e-3;

/**
 * Where instant `timeS` (seconds from pose 0's, the walk looping every `cycle_seconds`)
 * falls among the export's poses: `{ before, after, s }`, pose numbers and the fraction
 * of the way from `before` to `after`; `after` is `before` and `s` 0 at (or within
 * `AT_POSE` of) a pose's own instant, or where the export holds one pose.
 */
export function instantOf(ext, timeS) {
  if (!Number.isFinite(timeS)) throw new Error(`time ${timeS}: expected finite seconds`);
  const n = Math.max(ext.poses_per_cycle, 1);
  const rem = (x, m) => ((x % m) + m) % m;
  const at = rem(timeS / ext.cycle_seconds, 1) * n;
  const held = ext.poses.map((q) => q.pose).sort((a, b) => a - b);
  const before = [...held].reverse().find((q) => q <= at) ?? held[held.length - 1];
  const after = held.find((q) => q > before) ?? held[0];
  const gap = rem(after - before, n);
  if (held.length < 2 || gap === 0) return { before, after: before, s: 0 };
  const s = rem(at - before, n) / gap;
  if (s < AT_POSE) return { before, after: before, s: 0 };
  if (s > 1 - AT_POSE) return { before: after, after, s: 0 };
  return { before, after, s };
}

/**
 * The 2x2 map (columns, pixels per metre) from a subject motion at the axis (metres
 * across the axis, tangential to the circle of cameras, and up it) to what `camera`
 * sees, linearised where it looks at the axis; zeros where it does not see that point.
 */
export function motionToImage(camera) {
  const c = camera.centre;
  const f = camera.axes[2];
  const h2 = f[0] * f[0] + f[2] * f[2];
  const s = h2 > 1e-12 ? -(c[0] * f[0] + c[2] * f[2]) / h2 : 0;
  const p = [0, c[1] + s * f[1], 0];
  const radial = [c[0], 0, c[2]];
  let across;
  if (dot(radial, radial) > 1e-8) {
    across = normalizeOrZero(cross([0, 1, 0], radial));
  } else {
    const r = camera.axes[0];
    across = normalizeOrZero([r[0], 0, r[2]]);
    if (dot(across, across) === 0) across = [1, 0, 0];
  }
  const p0 = project(camera, p);
  const pa = project(camera, [p[0] + across[0] * STEP_M, p[1] + across[1] * STEP_M, p[2] + across[2] * STEP_M]);
  const py = project(camera, [p[0], p[1] + STEP_M, p[2]]);
  if (!p0 || !pa || !py) return [[0, 0], [0, 0]];
  return [[(pa[0] - p0[0]) / STEP_M, (pa[1] - p0[1]) / STEP_M], [(py[0] - p0[0]) / STEP_M, (py[1] - p0[1]) / STEP_M]];
}
