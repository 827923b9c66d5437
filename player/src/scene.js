// The walker among a three.js scene's own objects: a camera of the scene seen from the
// walker's frame (the walker an Object3D placed and turned in the world), the player's
// frame composited over what the scene drew with the depth of the walker's hull, so that
// an object in front hides it and it hides what is behind it; and its hull as an
// invisible caster in three.js's shadow maps.
import * as THREE from 'three';
import { fullscreen } from './player.js';
import { FULLSCREEN_VERTEX, DEPTH_COMPOSITE_FRAGMENT } from './shaders.js';

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
    const c = d.camera;
    const [r, dn, f] = c.axes;
    u.uFrame.value = frame.texture;
    u.uHullA.value = d.hulls[0].texture;
    u.uHullB.value = (d.hulls[1] ?? d.hulls[0]).texture;
    u.uTwo.value = d.hulls.length > 1 ? 1 : 0;
    u.uEye.value.set(...c.centre);
    u.uAxes.value.set(r[0], dn[0], f[0], r[1], dn[1], f[1], r[2], dn[2], f[2]);
    u.uK.value.set(c.k.fx, c.k.fy, c.k.cx, c.k.cy);
    u.uHeight.value = c.height;
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
