// L2 light files (`frf env-sh`, format `frf-sh-l2` version 1; docs/export.md): read and
// checked, for the browser and for node alike; and turned into a walker's frame.

import * as THREE from 'three';

export const SH_FORMAT = 'frf-sh-l2';

/** The most total light a light may carry (`∫ L dω`, any channel), as frf takes (1e30). */
export const MAX_TOTAL_LIGHT = 1e30;
/** The widest sun taken, degrees (frf's `MAX_SUN_DIAMETER_DEG`). */
export const MAX_SUN_DIAMETER_DEG = 20;

/** The nine [r, g, b] radiance coefficients of an SH light file's text (`name` for messages). */
export function parseShLight(text, name, expectedConvention) {
  let doc;
  try {
    // A byte-order mark some editors write is not JSON: read past it (as frf does).
    doc = JSON.parse(text.replace(/^\uFEFF/, ''));
  } catch (e) {
    throw new Error(`${name}: not JSON (${e.message})`);
  }
  if (doc.format !== SH_FORMAT) throw new Error(`${name}: format ${JSON.stringify(doc.format)}, expected ${SH_FORMAT}`);
  if (typeof doc.version !== 'number') {
    throw new Error(`${name}: version ${JSON.stringify(doc.version)} is not a number (this player reads version 1)`);
  }
  if (doc.version !== 1) throw new Error(`${name}: version ${doc.version}, this player reads version 1`);
  const c = doc.coefficients;
  if (!Array.isArray(c) || c.length !== 9 || c.some((x) => !Array.isArray(x) || x.length !== 3 || x.some((v) => typeof v !== 'number' || !Number.isFinite(v)))) {
    throw new Error(`${name}: coefficients must be nine [r, g, b] finite numbers`);
  }
  // What frf refuses, the player refuses too: a negative band 0 (negative total light)
  // and a total light beyond what relighting sums in 32-bit floats.
  const negative = c[0].findIndex((v) => v < 0);
  if (negative >= 0) {
    throw new Error(`${name}: band 0 (its total light) is negative in channel ${negative}: a light cannot take light away`);
  }
  const total = Math.max(...c[0]) * Math.sqrt(4 * Math.PI);
  if (total > MAX_TOTAL_LIGHT) {
    throw new Error(`${name}: its total light ${total.toExponential(1)} is beyond what relighting can sum (at most 1e30)`);
  }
  if (expectedConvention) {
    const differ = Object.keys({ ...expectedConvention, ...(doc.convention ?? {}) }).sort()
      .filter((k) => canonical(doc.convention?.[k]) !== canonical(expectedConvention[k]))
      .map((k) => `${k} ${canonical(doc.convention?.[k])}, the walker's ${canonical(expectedConvention[k])}`);
    if (differ.length > 0) throw new Error(`${name}: its SH convention differs from the walker's: ${differ.join('; ')}`);
  }
  return c;
}

/**
 * The suns a light file carries beside its coefficients (`frf env-sh --suns`: the suns found
 * in a map, the coefficients those of the map less them), checked as frf checks them:
 * [{ direction, illuminance, diameter_deg }], none where it holds none.
 */
export function parseShSuns(text, name) {
  const suns = JSON.parse(text.replace(/^\uFEFF/, '')).suns ?? [];
  if (!Array.isArray(suns)) throw new Error(`${name}: suns must be a list`);
  return suns.map((s, k) => {
    const three = (v) => Array.isArray(v) && v.length === 3 && v.every((x) => typeof x === 'number' && Number.isFinite(x));
    if (!three(s?.direction) || Math.max(...s.direction.map(Math.abs)) <= 0) throw new Error(`${name}: sun ${k}'s direction ${JSON.stringify(s?.direction)} is not a direction`);
    if (!(s.diameter_deg > 0 && s.diameter_deg <= MAX_SUN_DIAMETER_DEG)) throw new Error(`${name}: sun ${k}'s diameter ${s.diameter_deg}° is not within (0, ${MAX_SUN_DIAMETER_DEG}]°`);
    if (!three(s.illuminance) || s.illuminance.some((v) => v < 0 || v > MAX_TOTAL_LIGHT)) throw new Error(`${name}: sun ${k}'s illuminance ${JSON.stringify(s.illuminance)} is not a finite, non-negative light`);
    return { direction: s.direction, illuminance: s.illuminance, diameter_deg: s.diameter_deg };
  });
}

/** JSON with object keys sorted: two conventions compare whole, whatever their key order. */
function canonical(value) {
  if (Array.isArray(value)) return `[${value.map(canonical).join(',')}]`;
  if (value && typeof value === 'object') {
    return `{${Object.keys(value).sort().map((k) => `${JSON.stringify(k)}:${canonical(value[k])}`).join(',')}}`;
  }
  return JSON.stringify(value);
}

/** Nine [r, g, b] coefficients from a three.js LightProbe's `sh` (SphericalHarmonics3). */
export function fromLightProbe(probe) {
  return probe.sh.coefficients.map((v) => [v.x, v.y, v.z]);
}

/**
 * The L2 light `sh` (nine RGB, three.js order) as seen from a frame turned by `angle`
 * radians about +y (a walker whose heading is `angle`): the light at direction d of that
 * frame is the world's at d turned by `angle`. Projected back by quadrature over 4096
 * directions of a Fibonacci sphere (a rotation keeps each band: exact but for rounding).
 */
export function turnedAboutY(sh, angle) {
  const n = 4096;
  const out = Array.from({ length: 9 }, () => [0, 0, 0]);
  const basis = new Array(9);
  const turned = new Array(9);
  const d = new THREE.Vector3();
  const r = new THREE.Vector3();
  const [c, s] = [Math.cos(angle), Math.sin(angle)];
  for (let k = 0; k < n; k++) {
    const y = 1 - (2 * k + 1) / n;
    const rho = Math.sqrt(1 - y * y);
    const phi = k * Math.PI * (3 - Math.sqrt(5));
    d.set(rho * Math.cos(phi), y, rho * Math.sin(phi));
    // Turned by `angle` about +y (three.js's rotation.y).
    r.set(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
    THREE.SphericalHarmonics3.getBasisAt(d, basis);
    THREE.SphericalHarmonics3.getBasisAt(r, turned);
    for (let ch = 0; ch < 3; ch++) {
      let l = 0;
      for (let i = 0; i < 9; i++) l += sh[i][ch] * turned[i];
      for (let i = 0; i < 9; i++) out[i][ch] += (l * basis[i] * 4 * Math.PI) / n;
    }
  }
  return out;
}
