// L2 light files (`frf env-sh`, format `frf-sh-l2` version 1; docs/export.md): read and
// checked, for the browser and for node alike.

export const SH_FORMAT = 'frf-sh-l2';

/** The nine [r, g, b] radiance coefficients of an SH light file's text (`name` for messages). */
export function parseShLight(text, name, expectedConvention) {
  let doc;
  try {
    doc = JSON.parse(text);
  } catch (e) {
    throw new Error(`${name}: not JSON (${e.message})`);
  }
  if (doc.format !== SH_FORMAT) throw new Error(`${name}: format ${JSON.stringify(doc.format)}, expected ${SH_FORMAT}`);
  if (doc.version !== 1) throw new Error(`${name}: version ${doc.version}, this player reads version 1`);
  const c = doc.coefficients;
  if (!Array.isArray(c) || c.length !== 9 || c.some((x) => !Array.isArray(x) || x.length !== 3 || x.some((v) => typeof v !== 'number' || !Number.isFinite(v)))) {
    throw new Error(`${name}: coefficients must be nine [r, g, b] finite numbers`);
  }
  if (expectedConvention && canonical(doc.convention) !== canonical(expectedConvention)) {
    throw new Error(`${name}: its SH convention differs from the walker's: ${JSON.stringify(doc.convention)}`);
  }
  return c;
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
