// The page the headless screenshot drives (screenshot.mjs): renders one frame of a pose
// into a float target and hands back straight-alpha sRGB codes, as `frf render` writes
// its PNG frames, and the time per frame.
import * as THREE from 'three';
import { FrfPlayer } from './player.js';
import { parseShLight, parseShSuns } from './sh.js';
import { sunDirection } from './geometry.js';
import { subjectCamera, DepthComposite } from './scene.js';

THREE.ColorManagement.enabled = false;

/** Bytes as base64 (handed back to node through the page's JSON). */
function base64(bytes) {
  let binary = '';
  for (let i = 0; i < bytes.length; i += 0x8000) binary += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(binary);
}

/** linear -> sRGB code, clamped. */
function srgbCode(x) {
  const v = Math.min(Math.max(x, 0), 1);
  const s = v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
  return Math.round(s * 255);
}

/**
 * A frame of the walker (at the origin, unturned) among `job.boxes` (each centre, size
 * and linear colour, unlit), drawn into `target` by the returned function.
 */
function sceneDraw(renderer, player, job, at, target) {
  const scene = new THREE.Scene();
  for (const [x, y, z, sx, sy, sz, r, g, b] of job.boxes) {
    const box = new THREE.Mesh(new THREE.BoxGeometry(sx, sy, sz), new THREE.MeshBasicMaterial({ color: new THREE.Color(r, g, b) }));
    box.position.set(x, y, z);
    scene.add(box);
  }
  const camera = new THREE.PerspectiveCamera(job.fov, job.width / job.height, 0.01, 100);
  camera.position.set(...job.camera);
  camera.lookAt(...job.lookAt);
  const walker = new THREE.Object3D();
  const walkerFrame = new THREE.WebGLRenderTarget(job.width, job.height, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false });
  const composite = new DepthComposite(renderer);
  return () => {
    player.drawInstant(at, subjectCamera(camera, walker, job.width, job.height), walkerFrame);
    renderer.setRenderTarget(target);
    renderer.setClearColor(0x000000, 0);
    renderer.clear(true, true, false);
    renderer.render(scene, camera);
    composite.draw(player, walkerFrame, camera, walker, target, job.depth !== false);
    renderer.setRenderTarget(null);
  };
}

window.frfRender = async (job) => {
  const canvas = document.createElement('canvas');
  canvas.width = job.width;
  canvas.height = job.height;
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, alpha: true, preserveDrawingBuffer: true });
  const player = new FrfPlayer(renderer);
  if (job.mask !== undefined) player.maskViewPx = job.mask;
  const response = await fetch(job.glbUrl);
  if (!response.ok) throw new Error(`${job.glbName}: ${response.status} ${response.statusText}`);
  const bytes = new Uint8Array(await response.arrayBuffer());
  const started = performance.now();
  const ext = player.load(bytes, job.glbName);
  const sh = parseShLight(job.shText, job.shName, ext.sh);
  // `AZ,EL[,DIAM[,E]]` as frf's --sun (the disc's diameter matters to a sun relit by the
  // basis, through its compactness against a condition's cell; E 10 when not given, as in
  // frf).
  const e = job.sun?.[3] ?? 10;
  const sun = job.sun
    ? {
      direction: sunDirection(job.sun[0] * Math.PI / 180, job.sun[1] * Math.PI / 180),
      illuminance: [e, e, e],
      diameter_deg: job.sun[2] ?? 0.53,
    }
    : undefined;
  // The suns the light file carries (found in a map by `frf env-sh --suns`), and --sun.
  const suns = [...parseShSuns(job.shText, job.shName), ...(sun ? [sun] : [])];
  player.setLight(sh, suns);
  // A pose's own instant, or an instant of the walk between poses.
  // Only the views the camera's rays reach are decoded (every view where the walker
  // stands among boxes: the scene's camera sees it from its own frame).
  const camera = FrfPlayer.camera(job.camera, job.lookAt, job.fov, job.width, job.height);
  const cameras = job.boxes?.length || job.allViews ? null : [camera];
  let at;
  if (job.time === null || job.time === undefined) {
    const pose = job.pose ?? player.poseNumbers()[0];
    await player.preparePose(pose, cameras);
    at = { before: pose, after: pose, s: 0 };
  } else {
    at = await player.prepareInstant(job.time, job.interpolate ?? 'flow', cameras);
  }
  const loadMs = performance.now() - started;
  const target = new THREE.WebGLRenderTarget(job.width, job.height, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: Boolean(job.boxes?.length) });
  // With boxes, the walker stands among them in a three.js scene (its depth against
  // theirs, or laid over them without `depth`): `draw` leaves that frame in `target`.
  let draw = () => player.drawInstant(at, camera, target);
  if (job.boxes?.length) draw = sceneDraw(renderer, player, job, at, target);
  const pixels = new Float32Array(4 * job.width * job.height);
  const gl = renderer.getContext();
  // One frame to compile, then the timed ones (each waits for the GPU by a readback).
  draw();
  renderer.readRenderTargetPixels(target, 0, 0, 1, 1, new Float32Array(4));
  const t0 = performance.now();
  for (let i = 0; i < job.timedFrames; i++) {
    draw();
    gl.finish();
    renderer.readRenderTargetPixels(target, 0, 0, 1, 1, new Float32Array(4));
  }
  const msPerFrame = job.timedFrames > 0 ? (performance.now() - t0) / job.timedFrames : null;
  // The same frames again, each part waited for and timed (the sum exceeds a frame's time
  // by the waits).
  let partsMs = null;
  if (job.timedFrames > 0) {
    player.measure = true;
    player.partsMs = {};
    for (let i = 0; i < job.timedFrames; i++) draw();
    player.measure = false;
    partsMs = Object.fromEntries(Object.entries(player.partsMs).map(([k, v]) => [k, v / job.timedFrames]));
  }
  renderer.readRenderTargetPixels(target, 0, 0, job.width, job.height, pixels);
  // Rows bottom up in the target; the PNG's top down. Straight alpha, sRGB.
  const out = new Uint8Array(4 * job.width * job.height);
  let covered = 0;
  for (let i = 3; i < pixels.length; i += 4) if (pixels[i] > 0) covered++;
  if (covered === 0) {
    player.notes.push('nothing of the walker is in the frame: the camera sees none of it through the views exported (a camera far above or below the grid of cameras, or looking away)');
  }
  for (let y = 0; y < job.height; y++) {
    for (let x = 0; x < job.width; x++) {
      const i = 4 * ((job.height - 1 - y) * job.width + x);
      const o = 4 * (y * job.width + x);
      const a = Math.min(Math.max(pixels[i + 3], 0), 1);
      for (let c = 0; c < 3; c++) out[o + c] = a > 0 ? srgbCode(pixels[i + c] / a) : 0;
      out[o + 3] = Math.round(a * 255);
    }
  }
  // The ground shadow as a layer (frf's frame_NNNN_shadow.exr): linear RGB floats.
  let shadow = null;
  if (job.shadowLayer) {
    const layer = new THREE.WebGLRenderTarget(job.width, job.height, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false });
    if (!player.drawGroundShadowLayer(at, camera, layer)) throw new Error(`${job.glbName} holds no ground shadow (exported from a field without shadow maps)`);
    const s = new Float32Array(4 * job.width * job.height);
    renderer.readRenderTargetPixels(layer, 0, 0, job.width, job.height, s);
    const top = new Uint16Array(3 * job.width * job.height);
    for (let y = 0; y < job.height; y++) {
      for (let x = 0; x < job.width; x++) {
        const i = 4 * ((job.height - 1 - y) * job.width + x);
        for (let c = 0; c < 3; c++) top[3 * (y * job.width + x) + c] = Math.round(Math.min(Math.max(s[i + c], 0), 1) * 65535);
      }
    }
    shadow = base64(new Uint8Array(top.buffer));
  }
  const parts = player.poses.get(at.before);
  const loadParts = { ...parts.loadMs, relight: parts.relightMs };
  const viewsDecoded = player.viewsDecoded();
  const m = parts.mask;
  const mask = m ? { view_px: m.viewPx, margin_m: m.marginM, voxel_m: m.voxelM, voxels: m.centres.length / 3 } : null;
  return { rgba: base64(out), shadow, msPerFrame, partsMs, loadMs, loadParts, at, notes: player.notes, renderer: gl.getParameter(gl.RENDERER), viewsDecoded, mask, shadedPixels: player.drawn?.shadedPixels ?? 0 };
};
window.frfReady = true;
