// Reading a walker exported by `frf export` (docs/export.md): the GLB container's chunks
// checked, the extension `FRF_flowed_reflectance_field` found at a version this player
// knows, and its images and meshes taken out of the binary chunk. Every refusal names the
// file and the problem, as frf's own reader (export/src/read.rs) does.

export const EXTENSION = 'FRF_flowed_reflectance_field';
export const VERSION = 1;

/** A refusal of a file, naming it. */
export class BadFile extends Error {
  constructor(name, problem) {
    super(`${name}: ${problem}`);
    this.name = 'BadFile';
  }
}

/**
 * Parses the bytes of a .glb (`name` for messages) into its glTF document, its binary
 * chunk and the extension.
 */
export function parseGlb(bytes, name) {
  const bad = (problem) => new BadFile(name, problem);
  const data = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const word = (at) => (at + 4 <= bytes.byteLength ? data.getUint32(at, true) : null);
  const tag = (at) => (at + 4 <= bytes.byteLength
    ? String.fromCharCode(...bytes.subarray(at, at + 4)) : '');
  if (tag(0) !== 'glTF') throw bad('not a binary glTF file (no glTF magic)');
  if (word(4) !== 2) throw bad(`glTF container version ${word(4)}, expected 2`);
  const total = word(8);
  if (total !== bytes.byteLength) {
    throw bad(`its header says ${total} bytes and it has ${bytes.byteLength}: truncated or appended to`);
  }
  const jsonLength = word(12);
  if (jsonLength === null || tag(16) !== 'JSON' || 20 + jsonLength > bytes.byteLength) {
    throw bad('the first chunk is not a whole JSON chunk');
  }
  let document;
  try {
    document = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
  } catch (e) {
    throw bad(`its JSON chunk does not parse: ${e.message}`);
  }
  const at = 20 + jsonLength;
  const binLength = word(at);
  if (binLength === null || tag(at + 4) !== 'BIN\0' || at + 8 + binLength > bytes.byteLength) {
    throw bad('the second chunk is not a whole binary chunk');
  }
  const bin = bytes.subarray(at + 8, at + 8 + binLength);
  const ext = document.extensions?.[EXTENSION];
  if (!ext) throw bad(`it holds no ${EXTENSION}: a glTF file, but not a walker exported by frf`);
  if (ext.version !== VERSION) {
    throw bad(`${EXTENSION} version ${ext.version}; this player knows version ${VERSION}`);
  }
  checkExtension(ext, bad);
  return { document, bin, ext, name };
}

/** The fields the player relies on, present and of the right kind. */
function checkExtension(ext, bad) {
  const g = ext.grid;
  const positive = (x) => Number.isInteger(x) && x > 0;
  if (!g || ![g.columns, g.rows, g.width, g.height].every(positive)) {
    throw bad(`${EXTENSION}.grid lacks columns, rows, width or height`);
  }
  if (!Array.isArray(ext.poses) || ext.poses.length === 0) throw bad(`${EXTENSION} holds no pose`);
  for (const p of ext.poses) {
    if (!Array.isArray(p.cameras) || p.cameras.length !== g.columns * g.rows) {
      throw bad(`pose ${p.pose}: ${p.cameras?.length ?? 0} grid cameras for a ${g.columns}x${g.rows} grid`);
    }
    for (const v of p.views ?? []) {
      if (!(v.u < g.columns && v.v < g.rows) || !v.transfer || v.alpha === undefined) {
        throw bad(`pose ${p.pose}: a view (${v.u},${v.v}) outside the grid or without transfer or alpha`);
      }
      // The numbers a view is relit by, each present and finite (a `scale` of null was read
      // as 0: a black view).
      const triples = (x, n) => Array.isArray(x) && x.length === n
        && x.every((t) => Array.isArray(t) && t.length === 3 && t.every((c) => typeof c === 'number' && Number.isFinite(c)));
      const triple = (x) => triples([x], 1);
      const where = `pose ${p.pose}, view (${v.u},${v.v})`;
      if (!triples(v.transfer.scale, 9) || !triples(v.transfer.offset, 9)) {
        throw bad(`${where}: transfer scale and offset must be nine [r, g, b] finite numbers each`);
      }
      if (v.albedo && !triple(v.albedo.scale)) throw bad(`${where}: albedo scale must be three finite numbers`);
      if (v.transfer.colour && !triple(v.transfer.colour.scale)) {
        throw bad(`${where}: transfer colour scale must be three finite numbers`);
      }
    }
  }
  if (!['full', 'compact', undefined].includes(ext.tier)) throw bad(`unknown tier ${ext.tier}`);
}

/** The bytes and MIME type of image `index` of the document. */
export function imageBytes(glb, index) {
  const image = glb.document.images?.[index];
  if (!image) throw new BadFile(glb.name, `image ${index} does not exist`);
  return { bytes: viewBytes(glb, image.bufferView), mime: image.mimeType };
}

function viewBytes(glb, index) {
  const view = glb.document.bufferViews?.[index];
  if (!view) throw new BadFile(glb.name, `buffer view ${index} does not exist`);
  const start = view.byteOffset ?? 0;
  if (start + view.byteLength > glb.bin.byteLength) {
    throw new BadFile(glb.name, `buffer view ${index} reaches beyond the binary chunk`);
  }
  return glb.bin.subarray(start, start + view.byteLength);
}

/** The typed array of accessor `index` (FLOAT VEC3 positions, UNSIGNED_INT/SHORT indices). */
export function accessorArray(glb, index) {
  const a = glb.document.accessors?.[index];
  if (!a) throw new BadFile(glb.name, `accessor ${index} does not exist`);
  const kinds = { 5126: Float32Array, 5125: Uint32Array, 5123: Uint16Array };
  const Kind = kinds[a.componentType];
  const per = { SCALAR: 1, VEC3: 3 }[a.type];
  if (!Kind || !per) throw new BadFile(glb.name, `accessor ${index}: type ${a.type}/${a.componentType} not read`);
  const bytes = viewBytes(glb, a.bufferView);
  const start = a.byteOffset ?? 0;
  const count = a.count * per;
  if (start + count * Kind.BYTES_PER_ELEMENT > bytes.byteLength) {
    throw new BadFile(glb.name, `accessor ${index} reaches beyond its buffer view`);
  }
  const copy = bytes.slice(start, start + count * Kind.BYTES_PER_ELEMENT);
  return new Kind(copy.buffer, 0, count);
}

/** The hull mesh of a pose: positions and triangle indices. */
export function poseMesh(glb, pose) {
  const node = glb.document.nodes?.[pose.node];
  const mesh = glb.document.meshes?.[node?.mesh];
  const prim = mesh?.primitives?.[0];
  if (!prim) throw new BadFile(glb.name, `pose ${pose.pose}: its node holds no hull mesh`);
  return {
    positions: accessorArray(glb, prim.attributes.POSITION),
    indices: accessorArray(glb, prim.indices),
  };
}
