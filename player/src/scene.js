// The walker among a three.js scene's own objects: a camera of the scene seen from the
// walker's frame (the walker an Object3D placed and turned in the world), the player's
// frame composited over what the scene drew with the depth of the walker's hull, so that
// an object in front hides it and it hides what is behind it; its hull as an invisible
// caster in three.js's shadow maps; and the exported ground-shadow basis, relit by the
// walker's light, darkening the ground under it as frf's composite does.
import * as THREE from 'three';
import { fullscreen, cameraUniforms } from './player.js';
import { FULLSCREEN_VERTEX, DEPTH_COMPOSITE_FRAGMENT, GROUND_SHADOW_AT } from './shaders.js';

/**
 * The player's camera (subject frame: the walker's) of a three.js PerspectiveCamera
 * drawing `width x height` pixels, the walker being `walker` (its world matrix, scale 1).
 */
export function subjectCamera(camera, walker, width, height) {
  camera.updateMatrixWorld();
  walker.updateMatrixWorld();
  const m = walker.matrixWorld.clone().invert().multiply(camera.matrixWorld);
  const e = m.elements;
  const column = (j) => new THREE.Vector3(e[4 * j], e[4 * j + 1], e[4 * j + 2]).normalize();
  const [x, y, z] = [column(0), column(1), column(2)];
  const f = height / 2 / Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2);
  return {
    width,
    height,
    k: { fx: f, fy: f, cx: (width - 1) / 2, cy: (height - 1) / 2 },
    axes: [x.toArray(), y.negate().toArray(), z.negate().toArray()],
    centre: [e[12], e[13], e[14]],
  };
}

/** Composites the walker's frames into a three.js scene's target with their depth. */
export class DepthComposite {
  constructor(renderer) {
    this.renderer = renderer;
    this.material = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: FULLSCREEN_VERTEX, fragmentShader: DEPTH_COMPOSITE_FRAGMENT,
      uniforms: {
        uFrame: { value: null }, uHullA: { value: null }, uHullB: { value: null }, uTwo: { value: 0 },
        uEye: { value: new THREE.Vector3() }, uAxes: { value: new THREE.Matrix3() }, uK: { value: new THREE.Vector4() },
        uHeight: { value: 0 }, uAxis: { value: new THREE.Vector2() }, uSubjectToClip: { value: new THREE.Matrix4() },
        uDepth: { value: 1 },
      },
      depthTest: true, depthWrite: true, transparent: true,
      blending: THREE.CustomBlending, blendSrc: THREE.OneFactor, blendDst: THREE.OneMinusSrcAlphaFactor,
      blendSrcAlpha: THREE.OneFactor, blendDstAlpha: THREE.OneMinusSrcAlphaFactor,
    });
    this.scene = fullscreen(this.material);
    this.camera = new THREE.Camera();
  }

  /**
   * Draws `frame` (the player's last frame of the walker, premultiplied, drawn from
   * `player.drawn.camera`) over `target` (null: the canvas), whose depth buffer holds
   * the scene drawn from `camera`, the walker being `walker`. Without `depth` the walker
   * is laid over everything (the control of the tests).
   */
  draw(player, frame, camera, walker, target, depth = true) {
    const u = this.material.uniforms;
    const d = player.drawn;
    u.uFrame.value = frame.texture;
    u.uHullA.value = d.hulls[0].texture;
    u.uHullB.value = (d.hulls[1] ?? d.hulls[0]).texture;
    u.uTwo.value = d.hulls.length > 1 ? 1 : 0;
    cameraUniforms(u, d.camera);
    u.uAxis.value.set(...d.axis);
    camera.updateMatrixWorld();
    walker.updateMatrixWorld();
    u.uSubjectToClip.value.copy(camera.projectionMatrix).multiply(camera.matrixWorldInverse).multiply(walker.matrixWorld);
    u.uDepth.value = depth ? 1 : 0;
    this.material.depthTest = depth;
    const saved = this.renderer.getRenderTarget();
    const autoClear = this.renderer.autoClear;
    this.renderer.autoClear = false;
    this.renderer.setRenderTarget(target);
    this.renderer.render(this.scene, this.camera);
    this.renderer.setRenderTarget(saved);
    this.renderer.autoClear = autoClear;
  }
}

/**
 * The hull of pose `number` (prepared) as an invisible mesh that casts the walker's
 * shadow into three.js's shadow maps: add it to the walker's Object3D, and turn on the
 * renderer's shadow map and the light's castShadow.
 */
export function hullCaster(player, number) {
  const pose = player.poses.get(number);
  if (!pose) throw new Error(`pose ${number} is not prepared`);
  const material = new THREE.MeshBasicMaterial({ colorWrite: false, depthWrite: false });
  const mesh = new THREE.Mesh(pose.hull.mesh.geometry, material);
  mesh.castShadow = true;
  mesh.receiveShadow = false;
  mesh.name = `hull of pose ${number}`;
  return mesh;
}

const GROUND_VERTEX = /* glsl */ `
precision highp float;
in vec3 position;
uniform mat4 modelMatrix;
uniform mat4 viewMatrix;
uniform mat4 projectionMatrix;
out vec2 vXz;
void main() {
  vXz = position.xz;
  gl_Position = projectionMatrix * viewMatrix * modelMatrix * vec4(position, 1.0);
}
`;
const GROUND_FRAGMENT = /* glsl */ `
precision highp float;
in vec2 vXz;
uniform sampler2D uShadow;
uniform float uShadowExtent;
uniform float uShadowFadeFrom;
out vec4 outColor;
${GROUND_SHADOW_AT}
void main() { outColor = vec4(groundShadowAt(vXz), 1.0); }
`;

/**
 * The walker's ground shadow as a mesh to add to its Object3D: a square of the patch's
 * side just above y = 0 that multiplies what the scene drew under it by the ground's
 * relative irradiance (frf's composite: ground × S). `update(at)` follows the pose drawn
 * and the light; null where the export holds no ground shadow.
 */
export function groundShadowMesh(player) {
  const g = player.ext.ground_shadow;
  if (!g) return null;
  const geometry = new THREE.PlaneGeometry(g.extent_m, g.extent_m);
  geometry.rotateX(-Math.PI / 2);
  const material = new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3, vertexShader: GROUND_VERTEX, fragmentShader: GROUND_FRAGMENT,
    uniforms: { uShadow: { value: null }, uShadowExtent: { value: g.extent_m }, uShadowFadeFrom: { value: g.edge_fade_from } },
    transparent: true, depthWrite: false,
    blending: THREE.CustomBlending, blendSrc: THREE.ZeroFactor, blendDst: THREE.SrcColorFactor,
    polygonOffset: true, polygonOffsetFactor: -1, polygonOffsetUnits: -1,
  });
  const mesh = new THREE.Mesh(geometry, material);
  mesh.position.y = 1e-3;
  mesh.renderOrder = 1;
  mesh.name = 'walker ground shadow';
  mesh.update = (at) => {
    const shadow = player.groundShadow(at);
    material.uniforms.uShadow.value = shadow?.texture ?? null;
    mesh.visible = Boolean(shadow);
  };
  return mesh;
}
