// A sun relit as frf relights it, where the export holds the views' basis images (`frf
// export --basis`): the twin of frf's `reflectance/src/sun_light.rs` and the parts of
// `light_fit.rs` it reads. Per condition, the light standing for it, its lights' shares and
// cone, and the sun's light per unit of its (a table the pre-lit pass reads); per view, the
// sun's direction in the view's dome (turned by the turntable), its nearest conditions and
// their inverse-angle weights, the conditions that predict each when it is left out (the
// trust's leave-one-out), how compact the sun is against its cell, and the condition whose
// region holds it (what the basis relights the sun by where the normals are not trusted).
// The per-texel half (relight, trust, blend) is `SUN_BASIS_GLSL` in shaders.js.

import * as THREE from 'three';

/** Conditions a texel's sun is carried by (frf's `NEAREST`), weighted by the inverse of their angle to the sun to this power (`WEIGHT_POWER`). */
export const NEAREST = 2;
const WEIGHT_POWER = 2;
/** The most conditions a sun's trust reads at a view: its nearest and those predicting each. */
export const INVOLVED = NEAREST * (1 + NEAREST);
/** The most conditions the pre-lit pass takes. */
export const MAX_CONDITIONS = 32;
/** The most suns relit sharply (frf's `MAX_SUNS`); more join the L2 light. */
export const MAX_SUNS = 4;

/** The luminance of an RGB light (frf's `luminance`). */
export const luminance = (c) => 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
const unit = (v) => {
  const l = Math.hypot(...v);
  return l > 0 ? v.map((x) => x / l) : [0, 0, 0];
};
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const angle = (a, b) => Math.acos(Math.min(Math.max(dot(a, b), -1), 1));
const smoothstep = (a, b, v) => {
  const x = Math.min(Math.max((v - a) / (b - a), 0), 1);
  return x * x * (3 - 2 * x);
};

/**
 * A basis' conditions (the extension's `basis.conditions`) as the sun reads them: per
 * condition the direction standing for its lights (weighted by their luminance) and
 * their summed irradiance, their unit directions and luminance shares, and their cone
 * (`m = Σ share · l` and the bound on `n · m` beyond which a normal sees all or none).
 */
export function conditionTable(conditions) {
  return conditions.map((c) => {
    let d = [0, 0, 0];
    const delivered = [0, 0, 0];
    for (const l of c.lights) {
      const w = luminance(l.intensity);
      unit(l.direction).forEach((x, i) => { d[i] += x * w; });
      l.intensity.forEach((x, i) => { delivered[i] += x; });
    }
    d = unit(d);
    const total = c.lights.reduce((s, l) => s + luminance(l.intensity), 0);
    const lights = c.lights.map((l) => [unit(l.direction), total > 0 ? luminance(l.intensity) / total : 0]);
    return { direction: d, delivered, lights, cone: groupCone(lights) };
  });
}

/** frf's `group_cone`: `[m, bound]`, an infinite bound where the lights span a hemisphere. */
function groupCone(lights) {
  const m = [0, 1, 2].map((i) => lights.reduce((s, [l, share]) => s + l[i] * share, 0));
  const axis = unit(m);
  if (Math.hypot(...m) === 0) return [m, Infinity];
  const widest = lights.filter(([l, share]) => share !== 0 && Math.hypot(...l) > 0)
    .reduce((w, [l]) => Math.min(w, dot(unit(l), axis)), 1);
  if (widest <= 0) return [m, Infinity];
  const sin = Math.sqrt(Math.max(1 - widest * widest, 0));
  return [m, Math.hypot(...m) * (sin + 1e-4)];
}

/** frf's `nearest_weights_by`: the `n` directions nearest `l`, by inverse angle to `power`, summing to 1. */
function nearestWeights(directions, l, n, power = WEIGHT_POWER) {
  const byAngle = directions.map((d, k) => [k, angle(d, l)]).sort((a, b) => a[1] - b[1]).slice(0, Math.max(n, 1));
  if (byAngle[0][1] < 1e-6) return [[byAngle[0][0], 1]];
  const total = byAngle.reduce((s, [, a]) => s + 1 / a ** power, 0);
  return byAngle.map(([k, a]) => [k, 1 / a ** power / total]);
}

/** frf's `held_out_weights`: the `NEAREST` others nearest condition `k`'s direction. */
function heldOut(directions, k) {
  const others = directions.map((_, j) => j).filter((j) => j !== k);
  if (others.length === 0) return [];
  return nearestWeights(others.map((j) => directions[j]), directions[k], NEAREST).map(([j, w]) => [others[j], w]);
}

/** frf's `cell_width`: the angle from condition `k`'s direction to its nearest other's. */
function cellWidth(directions, k) {
  return directions.reduce((w, d, j) => (j !== k && Math.hypot(...d) > 0 ? Math.min(w, angle(d, directions[k])) : w), Math.PI);
}

/**
 * Per view (`turntablesDeg`), the sun (unit `direction` toward it, subject frame; angular
 * `radius`, radians) against the basis `table`: { nearest: [[k, w]], involved: [k],
 * heldAt: per nearest [[place in involved, w]], compactness, region } (frf's `SunView`;
 * `region` the condition whose projector region holds the sun: the one of its nearest
 * light among all lights).
 */
export function sunViews(table, direction, radius, turntablesDeg) {
  const directions = table.map((c) => c.direction);
  const lights = table.flatMap((c, k) => c.lights.map(([l]) => [l, k]));
  const cache = new Map();
  return turntablesDeg.map((deg) => {
    if (cache.has(deg)) return cache.get(deg);
    const t = (deg * Math.PI) / 180;
    // R_y(θ) d: the dome turned with the subject.
    const d = unit([Math.cos(t) * direction[0] + Math.sin(t) * direction[2], direction[1],
      -Math.sin(t) * direction[0] + Math.cos(t) * direction[2]]);
    const nearest = nearestWeights(directions, d, NEAREST);
    const held = nearest.map(([k]) => heldOut(directions, k));
    const involved = nearest.map(([k]) => k);
    for (const [k] of held.flat()) if (!involved.includes(k)) involved.push(k);
    const heldAt = held.map((h) => h.map(([k, w]) => [involved.indexOf(k), w]));
    const cell = cellWidth(directions, nearest[0][0]);
    const compactness = 1 - smoothstep(cell, 2 * cell, 2 * radius);
    const region = lights.reduce((best, [l, k]) => (dot(l, d) > best[0] ? [dot(l, d), k] : best), [-Infinity, 0])[1];
    const view = { direction: d, nearest, involved, heldAt, compactness, region };
    cache.set(deg, view);
    return view;
  });
}

/**
 * The table as a float texture the pre-lit pass reads (`uConditions`): column `k` per
 * condition; row 0 its cone (m, bound; bound 1e30 for an infinite one), row 1 + s sun
 * s's light per unit of the condition's (`illuminance / delivered`, 0 where it delivers
 * none; `illuminances` one RGB a sun, up to MAX_SUNS), rows 1 + MAX_SUNS.. its lights
 * (unit direction, share; share 0 beyond its count).
 */
export function conditionTexture(table, illuminances) {
  const first = 1 + MAX_SUNS;
  const rows = first + Math.max(...table.map((c) => c.lights.length));
  const data = new Float32Array(table.length * rows * 4);
  const set = (k, row, v) => data.set(v, (row * table.length + k) * 4);
  table.forEach((c, k) => {
    set(k, 0, [...c.cone[0], Number.isFinite(c.cone[1]) ? c.cone[1] : 1e30]);
    illuminances.slice(0, MAX_SUNS).forEach((e, s) => {
      set(k, 1 + s, [...[0, 1, 2].map((i) => (c.delivered[i] > 0 ? e[i] / c.delivered[i] : 0)), 0]);
    });
    c.lights.forEach(([l, share], j) => set(k, first + j, [...l, share]));
  });
  const texture = new THREE.DataTexture(data, table.length, rows, THREE.RGBAFormat, THREE.FloatType);
  texture.needsUpdate = true;
  return { texture, lights: rows - first };
}
