// The reference web player of frf's walker exports (docs/export.md): a pose's views are
// relit on the GPU by an L2 light (the SH transfer) and an optional sun (the fitted
// normals and albedo) into pre-lit layers, and each frame re-bins every pixel's ray
// through the cylinder of camera centres and morphs the quad's views by the solved
// four-way morph, as `frf render` does. Between two poses (an instant of the walk) both
// are drawn with their motion toward each other (the views' stored motion morphed into
// the frame as colour is) and morphed in time, as `frf render` does (docs/design.md
// section 4.7). A pose's textures are made when it is first shown and kept; the pre-lit
// layers are redone when the light changes.
import * as THREE from 'three';
import { KTX2Loader } from 'three/addons/loaders/KTX2Loader.js';
import { parseGlb, poseMesh, BadFile, imageBytes } from './glb.js';
import { MAX_SUN_DIAMETER_DEG, MAX_TOTAL_LIGHT } from './sh.js';
import { png, greyJpeg, ktx2Atlas, blocks4, expect } from './images.js';
import {
  poseGeometry, quadTexels, QUAD_TEXELS, frameTexels, FRAME_TEXELS, lookAt, columnIndex, positionsBox,
} from './geometry.js';
import {
  FULLSCREEN_VERTEX, PRELIT_FRAGMENT, HULL_VERTEX, HULL_FRAGMENT, FRAME_FRAGMENT,
  SUN_MAP_VERTEX, SUN_MAP_FRAGMENT, TIME_MORPH_FRAGMENT, GROUND_SHADOW_RELIGHT_FRAGMENT,
  GROUND_SHADOW_LAYER_FRAGMENT, TILE_VERTEX,
} from './shaders.js';
import { instantOf, motionToImage } from './time.js';
import { conditionTable, conditionTexture, luminance, sunViews, INVOLVED, MAX_CONDITIONS, MAX_SUNS, NEAREST } from './sun.js';
import { subjectBounds, flowReachM, viewPixelM, pixelBox, unionBox } from './footprint.js';
import { maskVoxels, maskTiles, unionTiles, TILE_PX } from './mask.js';

/** The sun's map of the hull, texels a side. */
const SUN_MAP_SIZE = 512;
/**
 * How far toward the sun a texel's shadow ray starts from the hull, as a fraction of the
 * hull's height, where the export does not say (frf's `SHADOW_OFFSET_PER_HEIGHT` is of
 * its hull grid's height, which the export gives as `sun_shadow_offset_m`).
 */
const SHADOW_OFFSET_PER_HEIGHT = 0.17;

/**
 * The walker's mask (mask.js) grows its hull by this many of its views' pixels (at the
 * subject): what the views' soft edges, the cycles' disagreement the hull's carving
 * leaves out and the flows' errors put outside the hull. Chosen on the small preset's
 * two-pose oracle field (docs/export.md, "The walker's mask").
 */
export const MASK_VIEW_PX = 8;

const NEIGHBOURS = ['right', 'left', 'up', 'down'];
/** The steps in time a view's motion is stored toward (`motion_to`'s keys). */
const STEPS = ['next', 'prev'];
/** Ground-shadow maps a pose may hold at most (the shader's array of weights). */
const MAX_SHADOW_MAPS = 64;
/** A stored motion code of no motion. */
const MOTION_ZERO = 32768;

function arrayTexture(data, width, height, depth, format, type) {
  const t = new THREE.DataArrayTexture(data, width, height, depth);
  t.format = format;
  t.type = type;
  t.minFilter = THREE.NearestFilter;
  t.magFilter = THREE.NearestFilter;
  t.unpackAlignment = 1;
  t.needsUpdate = true;
  return t;
}

/** Where three's Basis Universal transcoder lives (the KTX2 atlases'). */
const TRANSCODER_PATH = new URL('../node_modules/three/examples/jsm/libs/basis/', import.meta.url).href;

/**
 * An array texture of `depth` layers of a transcoded KTX2 atlas' size and format
 * (`level`, of `ktx2Atlas`): compressed where the GPU took a block format, else RGBA8.
 * Its layers' bytes are `data`, `layerBytes` a layer.
 */
function packedArrayTexture(level, depth) {
  const { width, height, format, type, compressed } = level;
  const data = new Uint8Array(level.data.length * depth);
  const texture = compressed
    ? new THREE.CompressedArrayTexture([{ data, width, height }], width, height, depth, format, type)
    : arrayTexture(data, width, height, depth, THREE.RGBAFormat, THREE.UnsignedByteType);
  texture.minFilter = THREE.NearestFilter;
  texture.magFilter = THREE.NearestFilter;
  texture.generateMipmaps = false;
  texture.needsUpdate = true;
  return { texture, data, layerBytes: level.data.length, format };
}

function dataTexture(data, width, height) {
  const t = new THREE.DataTexture(data, width, height, THREE.RGBAFormat, THREE.FloatType);
  t.minFilter = THREE.NearestFilter;
  t.magFilter = THREE.NearestFilter;
  t.needsUpdate = true;
  return t;
}

/** A scene of one triangle covering the viewport, drawn with `material`. */
export function fullscreen(material) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array([-1, -1, 0, 3, -1, 0, -1, 3, 0]), 3));
  const mesh = new THREE.Mesh(geometry, material);
  mesh.frustumCulled = false;
  const scene = new THREE.Scene();
  scene.add(mesh);
  return scene;
}

/**
 * Sets a pass's camera uniforms from a player camera: uEye (its centre), uAxes (columns:
 * right, down, forward), uK (fx, fy, cx, cy) and uHeight (its rows).
 */
export function cameraUniforms(u, camera) {
  const [r, d, f] = camera.axes;
  u.uEye.value.set(...camera.centre);
  u.uAxes.value.set(r[0], d[0], f[0], r[1], d[1], f[1], r[2], d[2], f[2]);
  u.uK.value.set(camera.k.fx, camera.k.fy, camera.k.cx, camera.k.cy);
  u.uHeight.value = camera.height;
}

export class FrfPlayer {
  /** `renderer`: a THREE.WebGLRenderer (WebGL 2). */
  constructor(renderer) {
    this.renderer = renderer;
    this.poses = new Map();
    this.sh = Array.from({ length: 9 }, () => [0, 0, 0]);
    this.suns = [];
    this.lightVersion = 0;
    // With `measure`, each part of a frame is waited for and timed into `partsMs` (ms,
    // summed until reset): what a frame costs by part, at the price of the waits.
    this.measure = false;
    this.partsMs = {};
    this.camera = new THREE.Camera();
    this.prelitMaterial = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: FULLSCREEN_VERTEX, fragmentShader: PRELIT_FRAGMENT,
      uniforms: {
        uAtlas: { value: null }, uAlpha: { value: null }, uNormals: { value: null }, uAlbedo: { value: null },
        uLayer: { value: 0 }, uCompact: { value: 0 }, uAtlasPacked: { value: 0 }, uBasisPacked: { value: 0 },
        uScale: { value: [] }, uOffset: { value: [] }, uSh: { value: [] },
        uAlbedoScale: { value: new THREE.Vector3() }, uColourScale: { value: new THREE.Vector3() },
        uSunCount: { value: 0 }, uSunDirs: { value: vectors(MAX_SUNS) }, uSunEs: { value: vectors(MAX_SUNS) }, uHasNormals: { value: 0 },
        uViewHull: { value: null }, uViewCentre: { value: new THREE.Vector3() }, uViewAxes: { value: new THREE.Matrix3() },
        uViewK: { value: new THREE.Vector4() }, uSunMaps: { value: null }, uSunAxesX: { value: vectors(MAX_SUNS) },
        uSunAxesY: { value: vectors(MAX_SUNS) }, uSunBoxes: { value: Array.from({ length: MAX_SUNS }, () => new THREE.Vector4()) },
        uSunOffset: { value: -1 },
        uBasisSun: { value: 0 }, uBasis: { value: null }, uConditions: { value: null }, uBasisColumns: { value: 1 },
        uConditionCount: { value: 0 }, uLightsPer: { value: 0 },
        uBasisScale: { value: Array.from({ length: MAX_CONDITIONS }, () => new THREE.Vector3()) },
        uBasisOffset: { value: Array.from({ length: MAX_CONDITIONS }, () => new THREE.Vector3()) },
        uDomeFromSubject: { value: new THREE.Matrix3() }, uSunDomes: { value: vectors(MAX_SUNS) },
        uInvolved: { value: new Array(INVOLVED * MAX_SUNS).fill(0) }, uInvolvedCount: { value: new Array(MAX_SUNS).fill(0) },
        uNearestCount: { value: new Array(MAX_SUNS).fill(0) }, uNearestW: { value: new Array(NEAREST * MAX_SUNS).fill(0) },
        uHeldPlace: { value: new Array(2 * NEAREST * MAX_SUNS).fill(0) }, uHeldW: { value: new Array(2 * NEAREST * MAX_SUNS).fill(0) },
        uCompactness: { value: new Array(MAX_SUNS).fill(0) }, uRegion: { value: new Array(MAX_SUNS).fill(0) },
        uSunLum: { value: new Array(MAX_SUNS).fill(0) },
      },
      depthTest: false, depthWrite: false,
    });
    this.prelitScene = fullscreen(this.prelitMaterial);
    this.frameMaterial = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: TILE_VERTEX, fragmentShader: FRAME_FRAGMENT,
      uniforms: {
        uEye: { value: new THREE.Vector3() }, uAxes: { value: new THREE.Matrix3() }, uK: { value: new THREE.Vector4() },
        uHeight: { value: 0 }, uQuads: { value: null }, uQuadCount: { value: 0 }, uFrames: { value: null },
        uViews: { value: null }, uColumns: { value: 0 }, uRows: { value: 0 }, uFrameRows: { value: 0 },
        uPrelit: { value: null }, uMotion: { value: null }, uWithMotion: { value: 0 }, uQuadIds: { value: 0 }, uFlows: { value: null }, uHullT: { value: null }, uHasHull: { value: 0 },
        uAxis: { value: new THREE.Vector2() }, uRanges: { value: null }, uIndexed: { value: 0 },
        uColAxis: { value: new THREE.Vector2() }, uColReference: { value: new THREE.Vector2() },
        uColOrientation: { value: 1 }, uRMin: { value: 0 }, uRMax: { value: 0 }, uSpans: { value: 0 },
        uQuadsPerSpan: { value: 0 },
      },
      depthTest: false, depthWrite: false, transparent: false, blending: THREE.NoBlending,
    });
    this.frameScene = tiled(this.frameMaterial);
    this.sunMapMaterial = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: SUN_MAP_VERTEX, fragmentShader: SUN_MAP_FRAGMENT,
      uniforms: {
        uSunDir: { value: new THREE.Vector3() }, uSunAxisX: { value: new THREE.Vector3() },
        uSunAxisY: { value: new THREE.Vector3() }, uSunBox: { value: new THREE.Vector4() }, uReach: { value: new THREE.Vector2() },
      },
      side: THREE.DoubleSide,
    });
    this.groundMaterial = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: FULLSCREEN_VERTEX, fragmentShader: GROUND_SHADOW_RELIGHT_FRAGMENT,
      uniforms: { uMaps: { value: null }, uWeights: { value: [] }, uCount: { value: 0 } },
      depthTest: false, depthWrite: false, blending: THREE.NoBlending,
    });
    this.groundScene = fullscreen(this.groundMaterial);
    this.timeMaterial = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: TILE_VERTEX, fragmentShader: TIME_MORPH_FRAGMENT,
      uniforms: {
        uBefore: { value: null }, uAfter: { value: null }, uBeforeMotion: { value: null }, uAfterMotion: { value: null },
        uToImage: { value: new THREE.Matrix2() }, uS: { value: 0 }, uHeight: { value: 0 },
      },
      depthTest: false, depthWrite: false, transparent: false, blending: THREE.NoBlending,
    });
    this.timeScene = tiled(this.timeMaterial);
    // The mask's margin in views' pixels (MASK_VIEW_PX), or null: no mask (every pixel
    // of the walker's box shaded, as frf).
    this.maskViewPx = MASK_VIEW_PX;
    this.pointSizes = renderer.getContext().getParameter(renderer.getContext().ALIASED_POINT_SIZE_RANGE);
    this.hullMaterial = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: HULL_VERTEX, fragmentShader: HULL_FRAGMENT,
      uniforms: { uViewProjection: { value: new THREE.Matrix4() }, uEye: { value: new THREE.Vector3() } },
      side: THREE.DoubleSide,
    });
  }

  /** Reads an export's bytes (`name` for messages); throws BadFile on a bad file. */
  load(bytes, name) {
    this.glb = parseGlb(bytes, name);
    this.ext = this.glb.ext;
    this.grid = this.ext.grid;
    // Whether the basis atlases are KTX2 (known at the first decoded).
    this.basisPacked = undefined;
    this.notes = [];
    if (this.ext.poses.some((p) => p.views.some((v) => v.normals === null || v.normals === undefined))) {
      this.notes.push(`${name} holds no fitted normals for some views: a sun lights only the SH part there`);
    }
    // A ray is drawn through a quad of four views; an export of fewer (one view, one ring)
    // draws part of the walker or none of it, and says so.
    const { columns, rows, wraps } = this.grid;
    const spans = wraps ? columns : columns - 1;
    for (const p of this.ext.poses) {
      const have = new Set(p.views.map((v) => v.u * rows + v.v));
      let whole = 0;
      for (let u = 0; u < spans; u++) {
        for (let v = 0; v + 1 < rows; v++) {
          const u1 = (u + 1) % columns;
          if ([u * rows + v, u * rows + v + 1, u1 * rows + v, u1 * rows + v + 1].every((k) => have.has(k))) whole++;
        }
      }
      const quads = spans * Math.max(rows - 1, 0);
      if (whole < quads) {
        this.notes.push(`pose ${p.pose}: ${whole} of the grid's ${quads} quads hold their four views: the walker is drawn ${whole === 0 ? 'nowhere' : 'only'} where a camera's rays pass through ${whole === 0 ? 'one' : 'those'} (export every view for all of it)`);
      }
    }
    this.#checkBasis(name);
    for (const p of this.poses.values()) p.dispose();
    this.poses.clear();
    this.conditionTable = null;
    return this.ext;
  }

  /** Refuses, by name, basis images the pre-lit pass cannot read as the extension says. */
  #checkBasis(name) {
    const basis = this.ext.basis;
    if (basis === null || basis === undefined) return;
    const count = basis.conditions?.length;
    if (!(count >= 2 && count <= MAX_CONDITIONS)) throw new BadFile(name, `basis: ${count} conditions, this player takes 2 to ${MAX_CONDITIONS}`);
    if (!(Number.isInteger(basis.columns) && basis.columns >= 1)) throw new BadFile(name, `basis: columns ${basis.columns} is not a positive integer`);
    for (const [k, c] of basis.conditions.entries()) {
      const ok = Array.isArray(c.lights) && c.lights.length > 0 && c.lights.every((l) => [l.direction, l.intensity].every((v) => Array.isArray(v) && v.length === 3 && v.every(Number.isFinite)));
      if (!ok) throw new BadFile(name, `basis condition ${k} (${c.name}): its lights are not directions and intensities of three numbers`);
    }
    for (const p of this.ext.poses) {
      for (const v of p.views) {
        const b = v.basis;
        // Three grey JPEGs, or one KTX2 image of the three channels.
        const atlases = b?.images?.length === 1 && imageBytes(this.glb, b.images[0]).mime === 'image/ktx2' ? 1 : 3;
        if (!b || b.scale?.length !== count || b.offset?.length !== count || b.images?.length !== atlases) {
          throw new BadFile(name, `pose ${p.pose} view ${v.u},${v.v}: its basis holds no three atlases (or one KTX2) and ${count} scales and offsets, as the export's ${count} conditions ask`);
        }
      }
    }
  }

  /** Per pose made ready: its views decoded and its views in all, `{ pose: [decoded, views] }`. */
  viewsDecoded() {
    return Object.fromEntries([...this.poses].map(([k, p]) => [k, [p.decoded.filter(Boolean).length, p.n]]));
  }

  /** The pose numbers the export holds, in order. */
  poseNumbers() { return this.ext.poses.map((p) => p.pose); }

  /**
   * The L2 light (9 RGB radiance coefficients) and suns: none, one or a list of
   * { direction, illuminance RGB, diameter_deg (0.53 where not given) }. The brightest
   * MAX_SUNS (4, as frf) above the horizon are relit sharply (by the basis as frf relights
   * them where the export holds its images, else by albedo and normal); any others join
   * the L2 light, and a note says so. A sun at or below the horizon lights the walker as frf lights it, from
   * below and softly (through its floor conditions there): its L2 projection joins the
   * light, with no sharp shading or shadow, and a note says so.
   */
  setLight(sh, suns = []) {
    if (!Array.isArray(sh) || sh.length !== 9 || sh.some((c) => c.length !== 3 || c.some((v) => !Number.isFinite(v)))) {
      throw new Error('an L2 light is nine finite [r, g, b] coefficients');
    }
    const checked = (Array.isArray(suns) ? suns : [suns]).map((sun) => {
      const e = sun.illuminance;
      if (!Array.isArray(e) || e.length !== 3 || e.some((v) => !(Number.isFinite(v) && v >= 0 && v <= MAX_TOTAL_LIGHT))) {
        throw new Error('a sun\'s illuminance is three finite values from 0 to 1e30 (as frf takes)');
      }
      const d = new THREE.Vector3(...sun.direction);
      if (!(d.length() > 0) || !Number.isFinite(d.length())) throw new Error('a sun\'s direction is a non-zero vector');
      const diameter = sun.diameter_deg ?? 0.53;
      if (!(diameter > 0 && diameter <= MAX_SUN_DIAMETER_DEG)) throw new Error(`a sun's angular diameter is above 0 and at most ${MAX_SUN_DIAMETER_DEG} degrees`);
      return { direction: d.normalize().toArray(), illuminance: [...e], diameter_deg: diameter };
    }).filter((s) => s.illuminance.some((v) => v > 0));
    this.sh = sh.map((c) => [...c]);
    // A sun as L2: its radiance coefficients, c_i = E Y_i(d).
    const intoL2 = (s) => {
      const basis = new Array(9);
      THREE.SphericalHarmonics3.getBasisAt(new THREE.Vector3(...s.direction), basis);
      for (let i = 0; i < 9; i++) for (let c = 0; c < 3; c++) this.sh[i][c] += s.illuminance[c] * basis[i];
    };
    const note = (text) => { if (!this.notes?.includes(text)) (this.notes ??= []).push(text); };
    const below = checked.filter((s) => s.direction[1] <= 0);
    below.forEach(intoL2);
    if (below.length > 0) note('the sun is below the horizon: it lights the walker from below as its L2 light, softly, with no sharp shading or shadow (as frf lights it through the floor conditions)');
    const above = checked.filter((s) => s.direction[1] > 0).sort((a, b) => luminance(b.illuminance) - luminance(a.illuminance));
    this.suns = above.slice(0, MAX_SUNS);
    above.slice(MAX_SUNS).forEach(intoL2);
    if (above.length > MAX_SUNS) note(`${above.length} suns: the brightest ${MAX_SUNS} are relit sharply, the other ${above.length - MAX_SUNS} join the L2 light (as frf)`);
    this.lightVersion++;
  }

  /**
   * Makes pose `number` ready to draw and relit: with `cameras` (FrfPlayer.camera), ready
   * for those alone, its views decoded where their rays reach them (as frf's plan reads a
   * shot's views; more are decoded when another camera needs them); without, every view.
   */
  async preparePose(number, cameras = null) {
    let pose = this.poses.get(number);
    if (!pose) {
      const record = this.ext.poses.find((p) => p.pose === number);
      if (!record) throw new BadFile(this.glb.name, `pose ${number} is not in the export (it has ${this.poseNumbers().join(', ')})`);
      pose = await this.#makePose(record);
      this.poses.set(number, pose);
    }
    const all = pose.record.views.map((_, i) => i);
    const t = performance.now();
    const which = cameras ? this.#viewsReached(pose, cameras) : all;
    pose.loadMs.reach = (pose.loadMs.reach ?? 0) + performance.now() - t;
    await this.#decodeViews(pose, which);
    if (pose.lightVersion !== this.lightVersion) {
      if (this.#basisSun()) await this.#decodeBasis(pose);
      const t0 = performance.now();
      this.#relight(pose);
      pose.relightMs = performance.now() - t0;
      pose.lightVersion = this.lightVersion;
    }
    return pose;
  }

  /**
   * A pose ready to decode: its mesh, geometry and empty view textures (every view's
   * layer and flow layer placed), and where the walker can show. Its views' images are
   * decoded by `#decodeViews`, all of them or those a camera's rays reach.
   */
  async #makePose(record) {
    const { width: w, height: h, columns, rows } = this.grid;
    const glb = this.glb;
    const compact = this.ext.tier === 'compact';
    const views = record.views;
    const n = views.length;
    const mesh = poseMesh(glb, record);
    const geometry = poseGeometry(this.grid, record.cameras, mesh.positions);
    const channels = compact ? 1 : 3;
    // A KTX2 atlas holds a view's channels in one image (layer): it is made at the first
    // view transcoded, of the GPU's block format.
    const packed = imageBytes(glb, views[0].transfer.images[0]).mime === 'image/ktx2';
    const data = {
      atlas: packed ? null : new Uint8Array(9 * w * h * channels * n),
      alpha: new Uint8Array(w * h * n),
      normals: new Uint8Array(4 * w * h * n),
      albedo: new Uint8Array(4 * w * h * 2 * n),
    };
    // Each view's flows' layers, in the views' order.
    const flowLayers = [];
    let flowCount = 0;
    views.forEach((v) => {
      flowLayers.push(NEIGHBOURS.map((k) => (v.flows?.[k] === undefined ? -1 : flowCount++)));
    });
    data.flows = new Float32Array(2 * w * h * Math.max(flowCount, 1));
    const viewTable = new Float32Array(columns * rows * 2 * 4).fill(-1);
    geometry.cameras.forEach((c, g) => viewTable.set([...c.centre, -1], g * 8));
    views.forEach((v, i) => {
      const g = v.u * rows + v.v;
      viewTable[g * 8 + 3] = i;
      flowLayers[i].forEach((layer, d) => { if (layer >= 0) viewTable[g * 8 + 4 + d] = layer; });
    });
    const started = performance.now();
    const motion = this.#motionTextures(record);
    const groundShadow = this.#groundShadowMaps(record);
    const pose = {
      record, geometry, n, motion, groundShadow, data, flowLayers, packed,
      decoded: new Array(n).fill(false),
      atlas: packed ? null : arrayTexture(data.atlas, 3 * w, 3 * h, n * channels, THREE.RedFormat, THREE.UnsignedByteType),
      alpha: arrayTexture(data.alpha, w, h, n, THREE.RedFormat, THREE.UnsignedByteType),
      normals: arrayTexture(data.normals, w, h, n, THREE.RGBAFormat, THREE.UnsignedByteType),
      albedo: arrayTexture(data.albedo, w, h, 2 * n, THREE.RGBAFormat, THREE.UnsignedByteType),
      flows: arrayTexture(data.flows, w, h, Math.max(flowCount, 1), THREE.RGFormat, THREE.FloatType),
      views: dataTexture(viewTable, 2, columns * rows),
      quads: dataTexture(quadTexels(geometry.quads), QUAD_TEXELS, geometry.quads.length),
      frames: dataTexture(frameTexels(geometry.frames), FRAME_TEXELS, geometry.frames.length),
      index: columnIndex(geometry.quads, rows + 1, geometry.cameras, rows),
      prelit: new THREE.WebGLArrayRenderTarget(w, h, n, {
        type: THREE.HalfFloatType, format: THREE.RGBAFormat, depthBuffer: false,
        minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
      }),
      hull: this.#hullMesh(mesh),
      mesh,
      viewHull: new THREE.WebGLArrayRenderTarget(w, h, n, {
        type: THREE.FloatType, format: THREE.RedFormat, depthBuffer: true,
        minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
      }),
      // Where the walker can show (frf's SubjectBounds::of_pose): the frame passes shade
      // only the pixels that see it.
      maxFlow: 0,
      shadowOffset: record.sun_shadow_offset_m ?? SHADOW_OFFSET_PER_HEIGHT * meshHeight(mesh.positions),
      lightVersion: -1,
      hasNormals: views.map((v) => v.normals !== null && v.normals !== undefined),
      dispose() {
        for (const t of [this.atlas, this.alpha, this.normals, this.albedo, this.flows, this.views, this.quads, this.frames]) t?.dispose();
        for (const t of Object.values(this.motion)) t.dispose();
        this.groundShadow?.maps.dispose();
        this.groundShadow?.relit.dispose();
        this.ranges?.dispose();
        this.basis?.dispose();
        this.prelit.dispose();
        this.viewHull.dispose();
        this.hull.mesh.geometry.dispose();
      },
    };
    if (pose.index) {
      const r = new Float32Array(pose.index.ranges.length * 4);
      pose.index.ranges.forEach(([lo, hi], i) => r.set([lo, hi, 0, 0], 4 * i));
      pose.ranges = dataTexture(r, pose.index.ranges.length, 1);
    }
    // What loading took, by part (ms; the GPU's work as it was issued; the views' images
    // and hulls are added as `#decodeViews` decodes them).
    pose.loadMs = { atlases: 0, png: 0, motion: performance.now() - started, hull: 0 };
    // Where the walker can show (frf's SubjectBounds::of_pose): the hull grown by the
    // flows' reach, which the export states (else every view is decoded to find it). The
    // frame passes shade only the pixels that see it.
    if (!Number.isFinite(record.max_flow_px)) await this.#decodeViews(pose, views.map((_, i) => i));
    const viewCameras = views.map((v) => geometry.cameras[v.u * rows + v.v]);
    pose.bounds = subjectBounds(mesh.positions, flowReachM(record.max_flow_px ?? pose.maxFlow, viewCameras));
    pose.viewPixelM = viewPixelM(viewCameras);
    return pose;
  }

  /**
   * Decodes views `which` (indices into the pose's views) not decoded yet into the pose's
   * view textures: the JPEG atlases together (the browser decodes them off the page's
   * thread), then the PNGs on it, view by view. Their pre-lit colour is made at the
   * next relight.
   */
  async #decodeViews(pose, which) {
    const { width: w, height: h } = this.grid;
    const { glb } = this;
    const { record, data } = pose;
    const compact = this.ext.tier === 'compact';
    const channels = compact ? 1 : 3;
    const todo = [...new Set(which)].filter((i) => !pose.decoded[i]).sort((a, b) => a - b);
    if (todo.length === 0) return;
    const started = performance.now();
    if (pose.packed) {
      const what = (i) => `pose ${record.pose} view ${record.views[i].u},${record.views[i].v} transfer`;
      await this.#packedInto(pose, 'atlas', todo, (i) => record.views[i].transfer.images[0], [3 * w, 3 * h], what);
    } else await Promise.all(todo.flatMap((i) => Array.from({ length: channels }, (_, c) => {
      const v = record.views[i];
      const what = `pose ${record.pose} view ${v.u},${v.v} transfer`;
      return greyJpeg(glb, v.transfer.images[c], what).then((img) => {
        expect(glb, img, 3 * w, 3 * h, null, `${what} atlas`);
        data.atlas.set(img.data, (i * channels + c) * 9 * w * h);
      });
    })));
    const decodedJpeg = performance.now();
    for (const i of todo) {
      const v = record.views[i];
      const what = (s) => `pose ${record.pose} view ${v.u},${v.v} ${s}`;
      const a = png(glb, v.alpha, what('alpha'));
      expect(glb, a, w, h, 1, what('alpha'));
      data.alpha.set(a.data, i * w * h);
      if (v.normals !== null && v.normals !== undefined) {
        const nm = png(glb, v.normals, what('normals'));
        expect(glb, nm, w, h, 4, what('normals'));
        data.normals.set(nm.data, i * 4 * w * h);
      }
      const rgbInto = (img, layer) => {
        const d = img.data;
        for (let t = 0, o = layer * w * h * 4; t < w * h; t++, o += 4) {
          data.albedo[o] = d[3 * t];
          data.albedo[o + 1] = d[3 * t + 1];
          data.albedo[o + 2] = d[3 * t + 2];
          data.albedo[o + 3] = 255;
        }
      };
      const al = png(glb, v.albedo.image, what('albedo'));
      expect(glb, al, w, h, 3, what('albedo'));
      rgbInto(al, 2 * i);
      if (compact) {
        const col = png(glb, v.transfer.colour.image, what('transfer colour'));
        expect(glb, col, w, h, 3, what('transfer colour'));
        rgbInto(col, 2 * i + 1);
      }
      NEIGHBOURS.forEach((k, d) => {
        const layer = pose.flowLayers[i][d];
        if (layer < 0) return;
        const f = png(glb, v.flows[k], what(`flow ${k}`));
        expect(glb, f, w, h, 2, what(`flow ${k}`));
        if (f.depth !== 16) throw new BadFile(glb.name, `${what(`flow ${k}`)}: ${f.depth}-bit, expected 16-bit`);
        const out = data.flows.subarray(layer * 2 * w * h, (layer + 1) * 2 * w * h);
        for (let t = 0; t < 2 * w * h; t++) {
          out[t] = f.data[t] / 256 - 128;
          pose.maxFlow = Math.max(pose.maxFlow, Math.abs(out[t]));
        }
      });
      pose.decoded[i] = true;
    }
    for (const t of [pose.atlas, pose.alpha, pose.normals, pose.albedo, pose.flows]) t.needsUpdate = true;
    // Each view texel's distance to the hull along its ray (the sun's shadow rays start there).
    const decodedPng = performance.now();
    for (const i of todo) {
      const v = record.views[i];
      this.#drawHull(pose, pose.geometry.cameras[v.u * this.grid.rows + v.v], pose.viewHull, i, false);
    }
    pose.loadMs.hull += performance.now() - decodedPng;
    // Relit again (the new views' colour), and their basis images decoded with a sun.
    pose.lightVersion = -1;
    pose.loadMs.atlases += decodedJpeg - started;
    pose.loadMs.png += decodedPng - decodedJpeg;
  }

  /**
   * A pose's motion toward the poses its `motion_to` names, by step: one RG32F layer a
   * view (metres across the axis and up it; a view without it stands still), read by
   * the frame pass in place of the pre-lit colour (alpha 1 where a view is held).
   */
  #motionTextures(record) {
    const { width: w, height: h } = this.grid;
    const glb = this.glb;
    const out = {};
    for (const step of STEPS) {
      if (record.motion_to?.[step] === undefined) continue;
      if (!record.views.some((v) => v.motion?.[step] !== undefined)) continue;
      const data = new Float32Array(2 * w * h * record.views.length);
      record.views.forEach((v, i) => {
        const m = v.motion?.[step];
        if (m === undefined) return;
        const what = `pose ${record.pose} view ${v.u},${v.v} motion ${step}`;
        if (!(Number.isFinite(m.step_m) && m.step_m > 0)) throw new BadFile(glb.name, `${what}: step_m ${m.step_m}, expected metres above 0`);
        const img = png(glb, m.image, what);
        expect(glb, img, w, h, 2, what);
        if (img.depth !== 16) throw new BadFile(glb.name, `${what}: ${img.depth}-bit, expected 16-bit`);
        const layer = data.subarray(i * 2 * w * h, (i + 1) * 2 * w * h);
        for (let t = 0; t < 2 * w * h; t++) layer[t] = (img.data[t] - MOTION_ZERO) * m.step_m;
      });
      out[step] = arrayTexture(data, w, h, record.views.length, THREE.RGFormat, THREE.FloatType);
    }
    return out;
  }

  /**
   * A pose's ground-shadow maps (one R8 layer a map) and the target they are relit into
   * (`relit`: the ground's relative irradiance S, RGB, texels a side, rows along +z);
   * null where the export holds none.
   */
  #groundShadowMaps(record) {
    const g = this.ext.ground_shadow;
    if (record.ground_shadow === null || record.ground_shadow === undefined || !g) return null;
    const what = `pose ${record.pose} ground shadow`;
    const m = g.weights.length;
    if (!(m >= 1 && m <= MAX_SHADOW_MAPS)) throw new BadFile(this.glb.name, `${what}: ${m} maps, expected 1 to ${MAX_SHADOW_MAPS}`);
    const img = png(this.glb, record.ground_shadow, what);
    expect(this.glb, img, g.texels, g.texels * m, 1, what);
    return {
      maps: arrayTexture(img.data, g.texels, g.texels, m, THREE.RedFormat, THREE.UnsignedByteType),
      relit: new THREE.WebGLRenderTarget(g.texels, g.texels, {
        type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false,
        minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
      }),
    };
  }

  /** Relights a pose's ground-shadow maps by the light (frf's `ShadowMaps::relight`). */
  #relightGroundShadow(pose) {
    const g = this.ext.ground_shadow;
    const u = this.groundMaterial.uniforms;
    // w_m = Σ_i c_i weights[m][i], per channel.
    const w = g.weights.map((byI) => new THREE.Vector3(...[0, 1, 2].map((c) => byI.reduce((sum, wi, i) => sum + this.sh[i][c] * wi[c], 0))));
    while (w.length < MAX_SHADOW_MAPS) w.push(new THREE.Vector3());
    u.uMaps.value = pose.groundShadow.maps;
    u.uWeights.value = w;
    u.uCount.value = g.weights.length;
    const saved = this.renderer.getRenderTarget();
    this.renderer.setRenderTarget(pose.groundShadow.relit);
    this.renderer.render(this.groundScene, this.camera);
    this.renderer.setRenderTarget(saved);
  }

  /**
   * The relit ground shadow of the pose drawn at instant `at` (the nearer pose's between
   * two, as frf), or null: { texture, extent_m, texels, edge_fade_from }.
   */
  groundShadow(at) {
    const number = at.s < 0.5 ? at.before : at.after;
    const pose = this.#prepared(number);
    if (!pose.groundShadow) return null;
    const g = this.ext.ground_shadow;
    return { texture: pose.groundShadow.relit.texture, extent: g.extent_m, texels: g.texels, fadeFrom: g.edge_fade_from };
  }

  /**
   * Draws the ground's relative irradiance under the walker at instant `at` as `camera`
   * sees the ground y = 0 (1 where a ray misses it or the patch, frf's shadow layer)
   * into `target`; false where the export holds no ground shadow.
   */
  drawGroundShadowLayer(at, camera, target) {
    const shadow = this.groundShadow(at);
    if (!shadow) return false;
    this.layerMaterial ??= new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: FULLSCREEN_VERTEX, fragmentShader: GROUND_SHADOW_LAYER_FRAGMENT,
      uniforms: {
        uEye: { value: new THREE.Vector3() }, uAxes: { value: new THREE.Matrix3() }, uK: { value: new THREE.Vector4() },
        uHeight: { value: 0 }, uShadow: { value: null }, uShadowExtent: { value: 0 }, uShadowFadeFrom: { value: 0 },
      },
      depthTest: false, depthWrite: false, blending: THREE.NoBlending,
    });
    this.layerScene ??= fullscreen(this.layerMaterial);
    const u = this.layerMaterial.uniforms;
    cameraUniforms(u, camera);
    u.uShadow.value = shadow.texture;
    u.uShadowExtent.value = shadow.extent;
    u.uShadowFadeFrom.value = shadow.fadeFrom;
    const saved = this.renderer.getRenderTarget();
    this.renderer.setRenderTarget(target);
    this.renderer.render(this.layerScene, this.camera);
    this.renderer.setRenderTarget(saved);
    return true;
  }

  /**
   * The pose's mask (mask.js) for the current margin (`maskViewPx` of its views' pixels),
   * made when first drawn; null with the mask off.
   */
  #mask(pose) {
    if (this.maskViewPx === null) return null;
    if (pose.mask?.viewPx !== this.maskViewPx) {
      const t = performance.now();
      const marginM = this.maskViewPx * pose.viewPixelM;
      pose.mask = { viewPx: this.maskViewPx, ...maskVoxels(pose.mesh.positions, pose.mesh.indices, marginM) };
      pose.loadMs.mask = performance.now() - t;
    }
    return pose.mask;
  }

  /**
   * The tiles of `box` where `camera` sees `pose`'s mask (mask.js `maskTiles`), or null
   * for the whole box: with the mask off, a camera amid the mask, or point sprites too
   * small for a tile.
   */
  #tilesOf(pose, camera, box) {
    const mask = this.#mask(pose);
    return mask && this.pointSizes[1] >= TILE_PX ? maskTiles(mask, camera, box) : null;
  }

  /**
   * Has `scene` (a pass of `tiled`) cover `tiles` (of `#tilesOf`), or the whole `box`
   * where they are null. Returns how many pixels it covers.
   */
  #tile(scene, tiles, camera, box) {
    const [points, whole] = scene.children;
    points.visible = Boolean(tiles);
    whole.visible = !tiles;
    const [g, xy] = tiles ? [points.geometry, tiles.centres] : [whole.geometry, boxTriangles(box, camera)];
    let a = g.getAttribute('position');
    if (!a || a.array.length < xy.length) {
      a = new THREE.BufferAttribute(new Float32Array(Math.max(xy.length, 12)), 2);
      a.setUsage(THREE.DynamicDrawUsage);
      g.setAttribute('position', a);
    }
    a.array.set(xy);
    a.needsUpdate = true;
    g.setDrawRange(0, xy.length / 2);
    return tiles ? tiles.pixels : (box.x1 - box.x0) * (box.y1 - box.y0);
  }

  #hullMesh(mesh) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(mesh.positions, 3));
    g.setIndex(new THREE.BufferAttribute(mesh.indices, 1));
    const m = new THREE.Mesh(g, this.hullMaterial);
    m.frustumCulled = false;
    const scene = new THREE.Scene();
    scene.add(m);
    return { mesh: m, scene };
  }

  /**
   * Transcodes views `todo`'s KTX2 atlases (image `imageOf(view)`, `size` texels before
   * their padding to whole blocks) into one layer a view of `pose[key]`, an array texture
   * made at the first of them (every view's of one format).
   */
  async #packedInto(pose, key, todo, imageOf, [width, height], what) {
    this.ktx2Loader ??= new KTX2Loader().setTranscoderPath(TRANSCODER_PATH).detectSupport(this.renderer);
    const levels = await Promise.all(todo.map((i) => ktx2Atlas(this.glb, imageOf(i), what(i), this.ktx2Loader)));
    const store = (pose.packedStores ??= {});
    levels.forEach((level, k) => {
      const i = todo[k];
      expect(this.glb, level, blocks4(width), blocks4(height), null, `${what(i)} atlas`);
      store[key] ??= packedArrayTexture(level, pose.record.views.length);
      pose[key] = store[key].texture;
      if (level.format !== store[key].format || level.data.length !== store[key].layerBytes) {
        throw new BadFile(this.glb.name, `${what(i)} atlas: transcoded to another format or size than its pose's other views`);
      }
      store[key].data.set(level.data, i * store[key].layerBytes);
    });
    if (pose[key]) pose[key].needsUpdate = true;
  }

  /** Whether the sun is relit as frf relights it: a sun, and the export's basis images. */
  #basisSun() {
    return Boolean(this.ext.basis) && this.suns.length > 0;
  }

  /**
   * A pose's basis images, for the views decoded, into one R8 array texture (layer
   * 3 * view + channel): decoded when a sun first lights them.
   */
  async #decodeBasis(pose) {
    const { width: w, height: h } = this.grid;
    const { columns, conditions } = this.ext.basis;
    const [aw, ah] = [columns * w, Math.ceil(conditions.length / columns) * h];
    const { record } = pose;
    const n = record.views.length;
    this.basisPacked ??= imageBytes(this.glb, record.views[0].basis.images[0]).mime === 'image/ktx2';
    pose.basisDecoded ??= new Array(n).fill(false);
    if (!pose.basis && !this.basisPacked) {
      pose.basis = arrayTexture(new Uint8Array(aw * ah * 3 * n), aw, ah, 3 * n, THREE.RedFormat, THREE.UnsignedByteType);
    }
    const todo = record.views.map((_, i) => i).filter((i) => pose.decoded[i] && !pose.basisDecoded[i]);
    if (todo.length === 0) return;
    if (this.basisPacked) {
      const what = (i) => `pose ${record.pose} view ${record.views[i].u},${record.views[i].v} basis`;
      await this.#packedInto(pose, 'basis', todo, (i) => record.views[i].basis.images[0], [aw, ah], what);
      todo.forEach((i) => { pose.basisDecoded[i] = true; });
      return;
    }
    const data = pose.basis.image.data;
    await Promise.all(todo.flatMap((i) => [0, 1, 2].map(async (c) => {
      const v = record.views[i];
      const what = `pose ${record.pose} view ${v.u},${v.v} basis`;
      const img = await greyJpeg(this.glb, v.basis.images[c], what);
      expect(this.glb, img, aw, ah, null, `${what} atlas`);
      data.set(img.data, (3 * i + c) * aw * ah);
    })));
    todo.forEach((i) => { pose.basisDecoded[i] = true; });
    pose.basis.needsUpdate = true;
  }

  /**
   * The views (indices into the pose's views) whose quads `cameras`' rays through the
   * walker's pixel box reach: the frame pass run in its quad mode (each pixel's quad, as
   * the pass re-bins its ray through the cylinder of camera centres from the hull's hit)
   * and read back. What the frame pass reads is those quads' four views and their flows.
   */
  #viewsReached(pose, cameras) {
    const { rows, columns } = this.grid;
    const index = new Map(pose.record.views.map((v, i) => [v.u * rows + v.v, i]));
    const reached = new Set();
    for (const camera of cameras) {
      const box = pixelBox(pose.bounds, camera);
      if (!box) continue;
      const hull = this.#hullTarget(camera.width, camera.height, 0);
      this.quadTarget = sized(this.quadTarget, camera.width, camera.height);
      const target = this.quadTarget;
      this.#clearBoxed([hull, target], box);
      this.#tile(this.frameScene, this.#tilesOf(pose, camera, box), camera, box);
      this.#drawHull(pose, camera, hull, 0, true);
      this.#frame(pose, camera, pose.prelit.texture, hull, target, null, true);
      this.#unboxed([hull, target]);
      const [w, h] = [box.x1 - box.x0, box.y1 - box.y0];
      const px = new Float32Array(4 * w * h);
      this.renderer.readRenderTargetPixels(target, box.x0, target.height - box.y1, w, h, px);
      for (let p = 0; p < w * h; p++) {
        if (px[4 * p + 2] === 0) continue;
        const [u, v] = [px[4 * p], px[4 * p + 1]];
        // The quad's four views (the frame pass' quadViews).
        const bottom = Math.min(v, rows - 1);
        const upper = Math.min(rows > 1 ? v + 1 : v, rows - 1);
        for (const uu of [u % columns, (u + 1) % columns]) {
          for (const vv of [bottom, upper]) {
            const i = index.get(uu * rows + vv);
            if (i !== undefined) reached.add(i);
          }
        }
      }
    }
    return [...reached];
  }

  /**
   * Sets the pre-lit pass' suns-by-the-basis uniforms for the light, and returns each
   * sun's views (`[sun][view]`).
   */
  #basisSunUniforms(pose, u) {
    u.uBasisSun.value = this.#basisSun() ? 1 : 0;
    if (!u.uBasisSun.value) return null;
    const { columns, conditions } = this.ext.basis;
    this.conditionTable ??= conditionTable(conditions);
    this.conditionTexture?.texture.dispose();
    this.conditionTexture = conditionTexture(this.conditionTable, this.suns.map((s) => s.illuminance));
    u.uBasis.value = pose.basis;
    u.uBasisPacked.value = this.basisPacked ? 1 : 0;
    u.uConditions.value = this.conditionTexture.texture;
    u.uBasisColumns.value = columns;
    u.uConditionCount.value = conditions.length;
    u.uLightsPer.value = this.conditionTexture.lights;
    const turntables = pose.record.views.map((v) => v.turntable_deg);
    this.suns.forEach((sun, s) => { u.uSunLum.value[s] = luminance(sun.illuminance); });
    return this.suns.map((sun) => sunViews(this.conditionTable, sun.direction, (sun.diameter_deg * Math.PI) / 360, turntables));
  }

  /** Sets view `v`'s suns (`suns[s]` sun s's view, of `#basisSunUniforms`) in the pre-lit pass' uniforms. */
  static #viewSuns(u, v, suns) {
    v.basis.scale.forEach((c, k) => u.uBasisScale.value[k].set(...c));
    v.basis.offset.forEach((c, k) => u.uBasisOffset.value[k].set(...c));
    const t = (v.turntable_deg * Math.PI) / 180;
    const [c, s] = [Math.cos(t), Math.sin(t)];
    u.uDomeFromSubject.value.set(c, 0, s, 0, 1, 0, -s, 0, c);
    suns.forEach((sun, k) => {
      u.uSunDomes.value[k].set(...sun.direction);
      for (let j = 0; j < INVOLVED; j++) u.uInvolved.value[INVOLVED * k + j] = sun.involved[j] ?? 0;
      u.uInvolvedCount.value[k] = sun.involved.length;
      u.uNearestCount.value[k] = sun.nearest.length;
      for (let j = 0; j < NEAREST; j++) u.uNearestW.value[NEAREST * k + j] = sun.nearest[j]?.[1] ?? 0;
      for (let j = 0; j < 2 * NEAREST; j++) {
        const held = sun.heldAt[j >> 1]?.[j & 1];
        u.uHeldPlace.value[2 * NEAREST * k + j] = held?.[0] ?? 0;
        u.uHeldW.value[2 * NEAREST * k + j] = held?.[1] ?? 0;
      }
      u.uCompactness.value[k] = sun.compactness;
      u.uRegion.value[k] = sun.region;
    });
  }

  #relight(pose) {
    const u = this.prelitMaterial.uniforms;
    const compact = this.ext.tier === 'compact';
    u.uAtlas.value = pose.atlas;
    u.uAlpha.value = pose.alpha;
    u.uNormals.value = pose.normals;
    u.uAlbedo.value = pose.albedo;
    u.uCompact.value = compact ? 1 : 0;
    u.uAtlasPacked.value = pose.packed ? 1 : 0;
    u.uSh.value = this.sh.map((c) => new THREE.Vector3(...c));
    u.uSunCount.value = this.suns.length;
    this.suns.forEach((sun, s) => {
      u.uSunDirs.value[s].set(...sun.direction);
      u.uSunEs.value[s].set(...sun.illuminance);
    });
    u.uViewHull.value = pose.viewHull.texture;
    const shadows = this.suns.length > 0 && pose.geometry.hasHull;
    u.uSunOffset.value = shadows ? pose.shadowOffset : -1;
    this.sunTargets ??= new THREE.WebGLArrayRenderTarget(SUN_MAP_SIZE, SUN_MAP_SIZE, MAX_SUNS, {
      type: THREE.FloatType, format: THREE.RedFormat, depthBuffer: true,
      minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
    });
    u.uSunMaps.value = this.sunTargets.texture;
    if (shadows) this.suns.forEach((sun, s) => this.#sunMap(pose, u, s));
    if (pose.groundShadow) this.#relightGroundShadow(pose);
    const suns = this.#basisSunUniforms(pose, u);
    const saved = this.renderer.getRenderTarget();
    pose.record.views.forEach((v, i) => {
      // A view not decoded (no camera's rays reach it yet) is relit once it is.
      if (!pose.decoded[i]) return;
      if (suns) FrfPlayer.#viewSuns(u, v, suns.map((views) => views[i]));
      const camera = pose.geometry.cameras[v.u * this.grid.rows + v.v];
      const [r, d, f] = camera.axes;
      u.uViewCentre.value.set(...camera.centre);
      u.uViewAxes.value.set(r[0], d[0], f[0], r[1], d[1], f[1], r[2], d[2], f[2]);
      u.uViewK.value.set(camera.k.fx, camera.k.fy, camera.k.cx, camera.k.cy);
      u.uLayer.value = i;
      u.uScale.value = v.transfer.scale.map((c) => new THREE.Vector3(...c));
      u.uOffset.value = v.transfer.offset.map((c) => new THREE.Vector3(...c));
      u.uAlbedoScale.value.set(...v.albedo.scale);
      if (compact) u.uColourScale.value.set(...v.transfer.colour.scale);
      u.uHasNormals.value = pose.hasNormals[i] ? 1 : 0;
      this.renderer.setRenderTarget(pose.prelit, i);
      this.renderer.render(this.prelitScene, this.camera);
    });
    this.renderer.setRenderTarget(saved);
  }

  /** The camera frf's `Camera::look_at` makes: eye, target (metres), vertical fov (degrees). */
  static camera(eye, target, fovDeg, width, height) {
    return lookAt(eye, target, (fovDeg * Math.PI) / 180, width, height);
  }

  /**
   * Draws pose `number` (prepared) from `camera` (FrfPlayer.camera) into `target` (a
   * render target of the camera's size, or null for the canvas): premultiplied linear RGBA.
   */
  draw(number, camera, target) {
    const pose = this.#prepared(number);
    const hull = this.#hullTarget(camera.width, camera.height, 0);
    this.drawn = { camera, hulls: [hull], axis: pose.geometry.axis, shadedPixels: 0 };
    const box = pixelBox(pose.bounds, camera);
    this.#clearBoxed([hull, target], box);
    if (box) {
      this.drawn.shadedPixels = this.#part('mask', null, () => this.#tile(this.frameScene, this.#tilesOf(pose, camera, box), camera, box));
      this.#part('hull', hull, () => this.#drawHull(pose, camera, hull, 0, true));
      this.#part('frame', target, () => this.#frame(pose, camera, pose.prelit.texture, hull, target));
    }
    this.#unboxed([hull, target]);
  }

  /**
   * The export's poses around instant `timeS` (seconds; `instantOf`), made ready to draw;
   * with `interpolate` 'nearest' the nearest pose alone, as frf's `interpolate =
   * "nearest"`. Where the two poses' motion does not lead to each other (an export of
   * some of a field's poses) the nearest is drawn, and a note says so.
   */
  async prepareInstant(timeS, interpolate = 'flow', cameras = null) {
    if (!['flow', 'nearest'].includes(interpolate)) throw new Error(`interpolate ${interpolate}: expected flow or nearest`);
    let at = instantOf(this.ext, timeS);
    if (at.s > 0) {
      const record = (p) => this.ext.poses.find((q) => q.pose === p);
      const linked = record(at.before).motion_to?.next === at.after && record(at.after).motion_to?.prev === at.before;
      if (interpolate === 'nearest' || !linked) {
        if (interpolate === 'flow') {
          const note = `poses ${at.before} and ${at.after} hold no motion toward each other (the export holds some of the field's poses, or a field without pose-to-pose flows): the nearest pose is drawn between them`;
          if (!this.notes.includes(note)) this.notes.push(note);
        }
        const p = at.s < 0.5 ? at.before : at.after;
        at = { before: p, after: p, s: 0 };
      }
    }
    await this.preparePose(at.before, cameras);
    if (at.s > 0) {
      await this.preparePose(at.after, cameras);
      for (const [p, step] of [[at.before, 'next'], [at.after, 'prev']]) {
        if (!this.poses.get(p).motion[step]) throw new BadFile(this.glb.name, `pose ${p} holds no view's motion ${step} though motion_to names it`);
      }
    }
    return at;
  }

  /**
   * Draws instant `at` (of `prepareInstant`) from `camera` into `target`: at a pose the
   * pose; between two, each pose and its motion toward the other drawn into targets of
   * their own and morphed in time (frf's `time_morph`).
   */
  drawInstant(at, camera, target) {
    if (at.s === 0) {
      this.draw(at.before, camera, target);
      return;
    }
    const [before, after] = [this.#prepared(at.before), this.#prepared(at.after)];
    const t = this.#timeTargets(camera.width, camera.height);
    const hulls = [0, 1].map((k) => this.#hullTarget(camera.width, camera.height, k));
    this.drawn = { camera, hulls, axis: before.geometry.axis, shadedPixels: 0 };
    const box = unionBox(pixelBox(before.bounds, camera), pixelBox(after.bounds, camera));
    const targets = [...t, ...hulls, target];
    this.#clearBoxed(targets, box);
    if (!box) {
      this.#unboxed(targets);
      return;
    }
    // Each pose's colour and its motion toward the other in one frame pass (two outputs),
    // over its mask's tiles; the morph in time over either's.
    const tiles = this.#part('mask', null, () => [before, after].map((pose) => this.#tilesOf(pose, camera, box)));
    for (const [pose, step, both, hull, k] of [[before, 'next', t[0], hulls[0], 0], [after, 'prev', t[1], hulls[1], 1]]) {
      this.drawn.shadedPixels += this.#part('mask', null, () => this.#tile(this.frameScene, tiles[k], camera, box));
      this.#part('hull', hull, () => this.#drawHull(pose, camera, hull, 0, true));
      this.#part('frame', both, () => this.#frame(pose, camera, pose.prelit.texture, hull, both, pose.motion[step]));
    }
    const u = this.timeMaterial.uniforms;
    [u.uBefore.value, u.uBeforeMotion.value] = t[0].textures;
    [u.uAfter.value, u.uAfterMotion.value] = t[1].textures;
    const m = motionToImage(camera);
    u.uToImage.value.set(m[0][0], m[1][0], m[0][1], m[1][1]);
    u.uS.value = at.s;
    u.uHeight.value = camera.height;
    const saved = this.renderer.getRenderTarget();
    this.#part('mask', null, () => this.#tile(this.timeScene, unionTiles(...tiles, camera, box), camera, box));
    this.renderer.setRenderTarget(target);
    this.#part('time morph', target, () => this.renderer.render(this.timeScene, this.camera));
    this.renderer.setRenderTarget(saved);
    this.#unboxed(targets);
  }

  /**
   * Clears `targets` (render targets of a frame's size; null ones are skipped) whole and,
   * with a pixel box `box` (frf's walker pixel box), has the passes that follow draw only
   * its pixels: outside it the walker is transparent.
   */
  #clearBoxed(targets, box) {
    const saved = this.renderer.getRenderTarget();
    for (const t of targets.filter(Boolean)) {
      t.scissorTest = false;
      this.renderer.setRenderTarget(t);
      this.renderer.setClearColor(0x000000, 0);
      this.renderer.clear(true, true, false);
      if (box) {
        t.scissor.set(box.x0, t.height - box.y1, box.x1 - box.x0, box.y1 - box.y0);
        t.scissorTest = true;
      }
    }
    this.renderer.setRenderTarget(saved);
  }

  /** Ends `#clearBoxed`: `targets` drawn whole again. */
  #unboxed(targets) {
    for (const t of targets.filter(Boolean)) t.scissorTest = false;
  }

  /**
   * Runs `draw` (into render target `target`), timed into `partsMs[name]` with `measure`:
   * waited for on both sides by reading a pixel of `target` back (gl.finish does not wait
   * in Chromium, nor does a read of another target on SwiftShader).
   */
  #part(name, target, draw) {
    if (!this.measure) return draw();
    const pixel = new Float32Array(4);
    if (target) this.renderer.readRenderTargetPixels(target, 0, 0, 1, 1, pixel);
    const t0 = performance.now();
    const out = draw();
    if (target) this.renderer.readRenderTargetPixels(target, 0, 0, 1, 1, pixel);
    this.partsMs[name] = (this.partsMs[name] ?? 0) + performance.now() - t0;
    return out;
  }

  #prepared(number) {
    const pose = this.poses.get(number);
    if (!pose || pose.lightVersion !== this.lightVersion) throw new Error(`pose ${number} is not prepared`);
    return pose;
  }

  /** Two float targets of a frame's size, two textures each: a pose's colour and motion. */
  #timeTargets(width, height) {
    if (!this.timeTargets || this.timeTargets[0].width !== width || this.timeTargets[0].height !== height) {
      this.timeTargets?.forEach((x) => x.dispose());
      this.timeTargets = [0, 1].map(() => new THREE.WebGLRenderTarget(width, height, {
        type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false, count: 2,
        minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
      }));
    }
    return this.timeTargets;
  }

  /**
   * The frame pass of `pose` (its hull pass drawn into `hullTarget`) reading `views`
   * (pre-lit colour) and, with `motion` (its motion views), morphing those too into the
   * target's second texture.
   */
  #frame(pose, camera, views, hullTarget, target, motion = null, quadsOnly = false) {
    const saved = this.renderer.getRenderTarget();
    const u = this.frameMaterial.uniforms;
    cameraUniforms(u, camera);
    u.uQuads.value = pose.quads;
    u.uQuadCount.value = pose.geometry.quads.length;
    u.uFrames.value = pose.frames;
    u.uViews.value = pose.views;
    u.uColumns.value = this.grid.columns;
    u.uRows.value = this.grid.rows;
    u.uFrameRows.value = pose.geometry.frameRows;
    u.uPrelit.value = views;
    u.uMotion.value = motion ?? views;
    u.uWithMotion.value = motion ? 1 : 0;
    // The quad mode reads no flow: the pose's (not decoded yet) are not uploaded for it.
    this.noFlows ??= arrayTexture(new Float32Array(2), 1, 1, 1, THREE.RGFormat, THREE.FloatType);
    u.uFlows.value = quadsOnly ? this.noFlows : pose.flows;
    u.uQuadIds.value = quadsOnly ? 1 : 0;
    u.uHullT.value = hullTarget.texture;
    u.uHasHull.value = pose.geometry.hasHull ? 1 : 0;
    u.uAxis.value.set(...pose.geometry.axis);
    const c = pose.index;
    u.uIndexed.value = c ? 1 : 0;
    if (c) {
      u.uRanges.value = pose.ranges;
      u.uColAxis.value.set(...c.axis);
      u.uColReference.value.set(...c.reference);
      u.uColOrientation.value = c.orientation;
      u.uRMin.value = c.rMin;
      u.uRMax.value = c.rMax;
      u.uSpans.value = c.ranges.length;
      u.uQuadsPerSpan.value = c.quadsPerSpan;
    }
    this.renderer.setRenderTarget(target);
    this.renderer.render(this.frameScene, this.camera);
    this.renderer.setRenderTarget(saved);
  }

  /**
   * The hull pass: each pixel's distance to the hull along its ray plus 1, 0 where none,
   * into `target` (layer `layer` of an array target); rows bottom up when `flipRows` (a
   * frame), top down (a view's layer, read as its data textures are).
   */
  #drawHull(pose, camera, target, layer, flipRows) {
    const hu = this.hullMaterial.uniforms;
    hu.uViewProjection.value.copy(viewProjection(camera, flipRows));
    hu.uEye.value.set(...camera.centre);
    const saved = this.renderer.getRenderTarget();
    this.renderer.setRenderTarget(target, layer);
    this.renderer.setClearColor(0x000000, 0);
    this.renderer.clear(true, true, false);
    this.renderer.render(pose.hull.scene, this.camera);
    this.renderer.setRenderTarget(saved);
  }

  /** Sun `s`'s map of the pose's hull (`SunDepth` of frf) into layer `s` of the suns' maps, and its uniforms in `u`. */
  #sunMap(pose, u, s) {
    const l = this.suns[s].direction;
    const axisX = new THREE.Vector3(...l).cross(Math.abs(l[1]) < 0.9 ? new THREE.Vector3(0, 1, 0) : new THREE.Vector3(1, 0, 0)).normalize();
    const axisY = new THREE.Vector3(...l).cross(axisX).normalize();
    const p = pose.mesh.positions;
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    const sun = new THREE.Vector3(...l);
    const q = new THREE.Vector3();
    for (let i = 0; i < p.length; i += 3) {
      q.set(p[i], p[i + 1], p[i + 2]);
      const v = [axisX.dot(q), axisY.dot(q), sun.dot(q)];
      for (let a = 0; a < 3; a++) {
        lo[a] = Math.min(lo[a], v[a]);
        hi[a] = Math.max(hi[a], v[a]);
      }
    }
    const margin = 0.05;
    const box = new THREE.Vector4(lo[0] - margin, lo[1] - margin, hi[0] + margin, hi[1] + margin);
    const m = this.sunMapMaterial.uniforms;
    m.uSunDir.value.copy(sun);
    m.uSunAxisX.value.copy(axisX);
    m.uSunAxisY.value.copy(axisY);
    m.uSunBox.value.copy(box);
    m.uReach.value.set(lo[2] - margin, hi[2] + margin);
    const saved = this.renderer.getRenderTarget();
    this.renderer.setRenderTarget(this.sunTargets, s);
    this.renderer.setClearColor(0x000000, 0);
    this.renderer.clear(true, true, false);
    const mesh = new THREE.Mesh(pose.hull.mesh.geometry, this.sunMapMaterial);
    mesh.frustumCulled = false;
    const scene = new THREE.Scene();
    scene.add(mesh);
    this.renderer.render(scene, this.camera);
    this.renderer.setRenderTarget(saved);
    u.uSunAxesX.value[s].copy(axisX);
    u.uSunAxesY.value[s].copy(axisY);
    u.uSunBoxes.value[s].copy(box);
  }

  /** Hull target `k` of a frame's size (two: the poses either side of an instant). */
  #hullTarget(width, height, k) {
    this.hullTargets ??= [];
    const h = this.hullTargets[k];
    if (!h || h.width !== width || h.height !== height) {
      h?.dispose();
      this.hullTargets[k] = new THREE.WebGLRenderTarget(width, height, {
        type: THREE.FloatType, format: THREE.RedFormat, depthBuffer: true,
        minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
      });
    }
    return this.hullTargets[k];
  }
}

/** `count` zero vectors (a uniform array's value). */
function vectors(count) {
  return Array.from({ length: count }, () => new THREE.Vector3());
}

/** `target` if it is `width` x `height`, else a float RGBA target of that size (the old one disposed). */
function sized(target, width, height) {
  if (target && target.width === width && target.height === height) return target;
  target?.dispose();
  return new THREE.WebGLRenderTarget(width, height, {
    type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false,
    minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
  });
}

/**
 * A pass (`material`) drawn where `#tile` says: as point sprites, a mask's tiles (no
 * diagonal splits a tile: two triangles would shade the pixels along it twice), or as
 * two triangles, a whole box.
 */
function tiled(material) {
  material.uniforms.uPointSize = { value: TILE_PX };
  const scene = new THREE.Scene();
  for (const kind of [THREE.Points, THREE.Mesh]) {
    const object = new kind(new THREE.BufferGeometry(), material);
    object.frustumCulled = false;
    scene.add(object);
  }
  return scene;
}

/** The pixel box `box` (rows down) of `camera`'s frame as two triangles in clip space (rows bottom up). */
function boxTriangles(box, camera) {
  const [xa, xb] = [(2 * box.x0) / camera.width - 1, (2 * box.x1) / camera.width - 1];
  const [ya, yb] = [1 - (2 * box.y0) / camera.height, 1 - (2 * box.y1) / camera.height];
  return new Float32Array([xa, yb, xb, yb, xb, ya, xa, yb, xb, ya, xa, ya]);
}

/** The height of a mesh's positions' box (0: none). */
function meshHeight(positions) {
  const [lo, hi] = positionsBox(positions);
  return positions.length ? hi[1] - lo[1] : 0;
}

/**
 * The clip transform of a camera whose pixel (x, y) (y down, centres at integers) lands
 * on the centre of the render target's fragment (x, height - 1 - y), or (x, y) without
 * `flipRows`.
 */
export function viewProjection(camera, flipRows = true) {
  const { width: w, height: h } = camera;
  const { fx, fy, cx, cy } = camera.k;
  const [r, d, f] = camera.axes;
  const e = camera.centre;
  const near = 0.01;
  const far = 1000;
  const a = (far + near) / (far - near);
  const b = (-2 * far * near) / (far - near);
  // Camera coordinates (x right, y down, z forward) from world.
  const view = new THREE.Matrix4().set(
    r[0], r[1], r[2], -(r[0] * e[0] + r[1] * e[1] + r[2] * e[2]),
    d[0], d[1], d[2], -(d[0] * e[0] + d[1] * e[1] + d[2] * e[2]),
    f[0], f[1], f[2], -(f[0] * e[0] + f[1] * e[1] + f[2] * e[2]),
    0, 0, 0, 1,
  );
  // ndc x = 2 (fx x / z + cx + 0.5) / w - 1; ndc y = 2 (h - 0.5 - (fy y / z + cy)) / h - 1
  // with rows flipped, else 2 (fy y / z + cy + 0.5) / h - 1.
  const sy = flipRows ? -1 : 1;
  const ty = flipRows ? (2 * (h - 0.5 - cy)) / h - 1 : (2 * (cy + 0.5)) / h - 1;
  const projection = new THREE.Matrix4().set(
    (2 * fx) / w, 0, (2 * (cx + 0.5)) / w - 1, 0,
    0, (sy * 2 * fy) / h, ty, 0,
    0, 0, a, b,
    0, 0, 1, 0,
  );
  return projection.multiply(view);
}
