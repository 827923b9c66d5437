// The player's page: a walker drawn from a camera the mouse orbits (three.js
// OrbitControls), relit by an L2 light (an `frf env-sh` file, or a three.js LightProbe
// through `fromLightProbe`) and an optional sun by the normals, the walk played at the
// capture's rate and morphed in time between its poses (or pose by pose, unticked).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { FrfPlayer, fullscreen } from './player.js';
import { parseShLight, parseShSuns } from './sh.js';
import { sunDirection } from './geometry.js';
import { FULLSCREEN_VERTEX, PRESENT_FRAGMENT } from './shaders.js';

THREE.ColorManagement.enabled = false;
const $ = (id) => document.getElementById(id);
const view = $('view');
const renderer = new THREE.WebGLRenderer({ antialias: false });
renderer.setPixelRatio(1);
view.appendChild(renderer.domElement);
const player = new FrfPlayer(renderer);
const camera = new THREE.PerspectiveCamera(35, 1, 0.05, 100);
camera.position.set(0, 1.3, 4.2);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(0, 0.9, 0);
controls.update();

// A soft default light until one is loaded: a white sky above a darker ground (L2).
let sh = [[0.9, 0.9, 0.95], [0.45, 0.45, 0.5], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0.05, 0.05, 0.05], [0, 0, 0], [0, 0, 0]];
let fileSuns = [];
let loaded = false;
let frameTarget = null;
const present = new THREE.RawShaderMaterial({
  glslVersion: THREE.GLSL3, vertexShader: FULLSCREEN_VERTEX, fragmentShader: PRESENT_FRAGMENT,
  uniforms: {
    uFrame: { value: null }, uExposure: { value: 1 }, uTop: { value: new THREE.Vector3(0.10, 0.12, 0.16) },
    uBottom: { value: new THREE.Vector3(0.03, 0.03, 0.035) }, uSize: { value: new THREE.Vector2() },
  },
});
const presentScene = fullscreen(present);

function showError(e) {
  $('error').textContent = String(e.message ?? e);
  console.error(e);
}

function applyLight() {
  if (!loaded) return;
  const sun = $('sun').checked
    ? { direction: sunDirection(($('az').value * Math.PI) / 180, ($('el').value * Math.PI) / 180), illuminance: Array(3).fill(Number($('e').value)) }
    : undefined;
  // The light file's own suns (found in a map by `frf env-sh --suns`), and the page's.
  player.setLight(sh, [...fileSuns, ...(sun ? [sun] : [])]);
}

async function loadGlb(bytes, name) {
  try {
    player.load(bytes, name);
    loaded = true;
    $('error').textContent = player.notes.join('\n');
    applyLight();
    clock = 0;
  } catch (e) {
    loaded = false;
    showError(e);
  }
}

async function loadSh(text, name) {
  try {
    sh = parseShLight(text, name, loaded ? player.ext.sh : undefined);
    fileSuns = parseShSuns(text, name);
    applyLight();
  } catch (e) {
    showError(e);
  }
}

$('glb').onchange = async (e) => {
  const f = e.target.files[0];
  if (f) await loadGlb(new Uint8Array(await f.arrayBuffer()), f.name);
};
$('sh').onchange = async (e) => {
  const f = e.target.files[0];
  if (f) await loadSh(await f.text(), f.name);
};
for (const id of ['sun', 'az', 'el', 'e']) $(id).oninput = applyLight;
view.ondragover = (e) => e.preventDefault();
view.ondrop = async (e) => {
  e.preventDefault();
  for (const f of e.dataTransfer.files) {
    if (f.name.endsWith('.json')) await loadSh(await f.text(), f.name);
    else await loadGlb(new Uint8Array(await f.arrayBuffer()), f.name);
  }
};

const query = new URLSearchParams(location.search);
if (query.get('glb')) {
  const url = query.get('glb');
  fetch(url).then((r) => (r.ok ? r.arrayBuffer() : Promise.reject(new Error(`${url}: ${r.status}`))))
    .then((b) => loadGlb(new Uint8Array(b), url.split('/').pop()))
    .then(() => (query.get('sh') ? fetch(query.get('sh')).then((r) => r.text()).then((t) => loadSh(t, query.get('sh'))) : null))
    .catch(showError);
}

let clock = 0;
let last = performance.now();
let busy = false;
let drawMs = 0;

async function tick() {
  requestAnimationFrame(tick);
  if (busy) return;
  const now = performance.now();
  const dt = (now - last) / 1000;
  last = now;
  const w = view.clientWidth;
  const h = view.clientHeight;
  if (renderer.domElement.width !== w || renderer.domElement.height !== h) {
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }
  if (!loaded) {
    renderer.setClearColor(0x222222, 1);
    renderer.clear();
    return;
  }
  const ext = player.ext;
  if ($('play').checked) clock = (clock + dt) % ext.cycle_seconds;
  busy = true;
  try {
    const at = await player.prepareInstant(clock, $('morph').checked ? 'flow' : 'nearest');
    if (!frameTarget || frameTarget.width !== w || frameTarget.height !== h) {
      frameTarget?.dispose();
      frameTarget = new THREE.WebGLRenderTarget(w, h, { type: THREE.HalfFloatType, depthBuffer: false });
    }
    const eye = camera.position.toArray();
    const target = controls.target.toArray();
    const t0 = performance.now();
    player.measure = $('measure').checked;
    player.partsMs = {};
    player.drawInstant(at, FrfPlayer.camera(eye, target, camera.fov, w, h), frameTarget);
    present.uniforms.uFrame.value = frameTarget.texture;
    present.uniforms.uExposure.value = 2 ** Number($('exposure').value);
    present.uniforms.uSize.value.set(w, h);
    renderer.setRenderTarget(null);
    renderer.render(presentScene, camera);
    drawMs = 0.9 * drawMs + 0.1 * (performance.now() - t0);
    const when = at.s > 0 ? `poses ${at.before} to ${at.after} at ${at.s.toFixed(2)}` : `pose ${at.before}`;
    $('status').textContent = `${clock.toFixed(3)} s: ${when} (${ext.poses.length} exported), ${ext.grid.columns}x${ext.grid.rows} views of ${ext.grid.width}x${ext.grid.height}\n` +
      `${w}x${h} pixels, ${drawMs.toFixed(1)} ms to issue a frame` +
      (player.measure ? `\nwaited for, ms: ${Object.entries(player.partsMs).map(([k, v]) => `${k} ${v.toFixed(1)}`).join(', ')}` : '');
  } catch (e) {
    showError(e);
    loaded = false;
  } finally {
    busy = false;
  }
}
requestAnimationFrame(tick);
