// The demo of a walker among a three.js scene's objects (scene.html): a ground that
// receives shadows, a box, a sky (the walker's L2 light, the scene's LightProbe) and a
// sun (a shadow-casting DirectionalLight, the walker's sun by its normals); the walker
// walks a circle round the box at its captured speed, its clip's time tied to the
// distance walked (docs/export.md, "Root motion"), morphed between poses, its light
// turned into its own frame as it turns, drawn with its hull's depth, casting its hull
// into the sun's shadow map and its captured ground shadow under it.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { FrfPlayer, fullscreen } from './player.js';
import { parseShLight, turnedAboutY } from './sh.js';
import { sunDirection } from './geometry.js';
import { FULLSCREEN_VERTEX, PRESENT_FRAGMENT } from './shaders.js';
import { subjectCamera, DepthComposite, hullCaster, groundShadowMesh } from './scene.js';

THREE.ColorManagement.enabled = false;
const $ = (id) => document.getElementById(id);
/** The loop's radius, metres, and how far the walker's heading turns before it is relit. */
const LOOP_RADIUS_M = 2.2;
const RELIGHT_DEG = 2;
/** The sun: azimuth and elevation (degrees), illuminance. */
const SUN = { az: 60, el: 40, e: 4 };

const renderer = new THREE.WebGLRenderer({ antialias: false });
renderer.setPixelRatio(1);
renderer.shadowMap.enabled = true;
$('view').appendChild(renderer.domElement);
const player = new FrfPlayer(renderer);
const composite = new DepthComposite(renderer);
const camera = new THREE.PerspectiveCamera(40, 1, 0.05, 100);
camera.position.set(0.5, 2.6, 6.5);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(0, 0.8, 0);
controls.update();

const scene = new THREE.Scene();
scene.background = new THREE.Color(0.35, 0.45, 0.6);
const ground = new THREE.Mesh(new THREE.PlaneGeometry(20, 20).rotateX(-Math.PI / 2),
  new THREE.MeshStandardMaterial({ color: new THREE.Color(0.45, 0.42, 0.38), roughness: 0.95 }));
ground.receiveShadow = true;
scene.add(ground);
const box = new THREE.Mesh(new THREE.BoxGeometry(1, 1.2, 1), new THREE.MeshStandardMaterial({ color: new THREE.Color(0.6, 0.15, 0.1) }));
box.position.set(0, 0.6, 0);
box.castShadow = box.receiveShadow = true;
scene.add(box);
const probe = new THREE.LightProbe();
scene.add(probe);
const sunDir = new THREE.Vector3(...sunDirection((SUN.az * Math.PI) / 180, (SUN.el * Math.PI) / 180));
// three.js's DirectionalLight's intensity is the irradiance it gives a surface facing it.
const sun = new THREE.DirectionalLight(0xffffff, SUN.e);
sun.position.copy(sunDir).multiplyScalar(10);
sun.castShadow = true;
sun.shadow.mapSize.set(2048, 2048);
Object.assign(sun.shadow.camera, { left: -5, right: 5, top: 5, bottom: -5, near: 1, far: 30 });
scene.add(sun);
const walker = new THREE.Object3D();
scene.add(walker);

let sh = null;
let caster = null;
let groundShadow = null;
let relitHeading = null;
let distance = 0;
let still = false;
let last = performance.now();
let busy = false;
let sceneTarget = null;
let walkerFrame = null;
const present = new THREE.RawShaderMaterial({
  glslVersion: THREE.GLSL3, vertexShader: FULLSCREEN_VERTEX, fragmentShader: PRESENT_FRAGMENT,
  uniforms: {
    uFrame: { value: null }, uExposure: { value: 1 }, uTop: { value: new THREE.Vector3() },
    uBottom: { value: new THREE.Vector3() }, uSize: { value: new THREE.Vector2() },
  },
});
const presentScene = fullscreen(present);
window.frfSceneFrames = 0;

/** The irradiance (green) an L2 light `sh` gives a surface facing `n`, by quadrature. */
function irradianceAt(sh, n) {
  const count = 2048;
  const basis = new Array(9);
  const d = new THREE.Vector3();
  let e = 0;
  for (let k = 0; k < count; k++) {
    const y = 1 - (2 * k + 1) / count;
    const rho = Math.sqrt(1 - y * y);
    const phi = k * Math.PI * (3 - Math.sqrt(5));
    d.set(rho * Math.cos(phi), y, rho * Math.sin(phi));
    const cos = d.dot(n);
    if (cos <= 0) continue;
    THREE.SphericalHarmonics3.getBasisAt(d, basis);
    let l = 0;
    for (let i = 0; i < 9; i++) l += sh[i][1] * basis[i];
    e += (l * cos * 4 * Math.PI) / count;
  }
  return e;
}

async function start() {
  const query = new URLSearchParams(location.search);
  const url = query.get('glb');
  // `walked=M`: start M metres along the loop; `still`: stay there (a screenshot's).
  distance = Number(query.get('walked') ?? 0);
  still = query.has('still');
  if (!url) throw new Error('open this page as scene.html?glb=URL[&sh=URL]');
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: ${r.status}`);
  player.load(new Uint8Array(await r.arrayBuffer()), url.split('/').pop());
  sh = query.get('sh')
    ? parseShLight(await (await fetch(query.get('sh'))).text(), query.get('sh'), player.ext.sh)
    : [[0.9, 0.9, 0.95], [0.45, 0.45, 0.5], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0.05, 0.05, 0.05], [0, 0, 0], [0, 0, 0]];
  // The scene's objects see the same L2 light (three.js's LightProbe takes radiance SH).
  probe.sh.fromArray(sh.flat());
  // Exposed so that white ground under the sky and the sun shows at 0.8, unless given.
  const up = new THREE.Vector3(0, 1, 0);
  const groundRadiance = irradianceAt(sh, up) / Math.PI + (SUN.e * Math.max(sunDir.dot(up), 0)) / Math.PI;
  present.uniforms.uExposure.value = query.has('exposure') ? 2 ** Number(query.get('exposure')) : 0.8 / Math.max(groundRadiance, 1e-6);
  groundShadow = groundShadowMesh(player);
  if (groundShadow) walker.add(groundShadow);
  requestAnimationFrame(tick);
}

async function tick() {
  requestAnimationFrame(tick);
  if (busy) return;
  busy = true;
  try {
    const now = performance.now();
    const dt = Math.min((now - last) / 1000, 0.1);
    last = now;
    const w = $('view').clientWidth;
    const h = $('view').clientHeight;
    if (renderer.domElement.width !== w || renderer.domElement.height !== h) {
      renderer.setSize(w, h, false);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
    }
    if (!sceneTarget || sceneTarget.width !== w || sceneTarget.height !== h) {
      sceneTarget?.dispose();
      walkerFrame?.dispose();
      sceneTarget = new THREE.WebGLRenderTarget(w, h, { type: THREE.HalfFloatType, depthBuffer: true });
      walkerFrame = new THREE.WebGLRenderTarget(w, h, { type: THREE.FloatType, depthBuffer: false });
    }
    const ext = player.ext;
    const speed = ext.walk?.speed_mps ?? 1.2;
    const stride = ext.walk?.stride_m ?? speed * ext.cycle_seconds;
    if (!still) distance += speed * dt;
    // Counter-clockwise round the box, seen from above: the walker's +x along the path.
    const angle = distance / LOOP_RADIUS_M;
    walker.position.set(LOOP_RADIUS_M * Math.cos(angle), 0, -LOOP_RADIUS_M * Math.sin(angle));
    const heading = angle + Math.PI / 2;
    walker.rotation.y = heading;
    const t0 = performance.now();
    // The light in the walker's frame, redone when its heading has turned RELIGHT_DEG.
    if (relitHeading === null || Math.abs(heading - relitHeading) > (RELIGHT_DEG * Math.PI) / 180) {
      const s = sunDir.clone().applyAxisAngle(new THREE.Vector3(0, 1, 0), -heading);
      player.setLight(turnedAboutY(sh, heading), { direction: s.toArray(), illuminance: [SUN.e, SUN.e, SUN.e] });
      relitHeading = heading;
    }
    const at = await player.prepareInstant((distance / stride) * ext.cycle_seconds);
    const t1 = performance.now();
    const pose = at.s < 0.5 ? at.before : at.after;
    if (caster?.userData.pose !== pose) {
      if (caster) walker.remove(caster);
      caster = hullCaster(player, pose);
      caster.userData.pose = pose;
      walker.add(caster);
    }
    groundShadow?.update(at);
    renderer.setRenderTarget(sceneTarget);
    renderer.render(scene, camera);
    const t2 = performance.now();
    player.drawInstant(at, subjectCamera(camera, walker, w, h), walkerFrame);
    const t3 = performance.now();
    composite.draw(player, walkerFrame, camera, walker, sceneTarget);
    present.uniforms.uFrame.value = sceneTarget.texture;
    present.uniforms.uSize.value.set(w, h);
    renderer.setRenderTarget(null);
    renderer.render(presentScene, camera);
    const t4 = performance.now();
    window.frfSceneFrames++;
    const when = at.s > 0 ? `poses ${at.before}-${at.after} at ${at.s.toFixed(2)}` : `pose ${at.before}`;
    $('status').textContent = `${when}; issued in ms: light+poses ${(t1 - t0).toFixed(1)}, scene ${(t2 - t1).toFixed(1)}, walker ${(t3 - t2).toFixed(1)}, composite ${(t4 - t3).toFixed(1)}`;
    $('error').textContent = player.notes.join('\n');
  } catch (e) {
    $('error').textContent = String(e.message ?? e);
    console.error(e);
  } finally {
    busy = false;
  }
}

start().catch((e) => {
  $('error').textContent = String(e.message ?? e);
  console.error(e);
});
