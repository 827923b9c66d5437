// The screenshot flags of a camera blended bilinearly from a pose's grid cameras at
// fractional (U, V): a captured view at integers, a quad's centre at halves.
//   node player/grid-camera.mjs walker.glb U,V [POSE_INDEX]
import { readFileSync } from 'node:fs';
import { parseGlb } from './src/glb.js';

const [path, uv, poseIndex = '0'] = process.argv.slice(2);
const glb = parseGlb(new Uint8Array(readFileSync(path)), path);
const { columns, rows } = glb.ext.grid;
const pose = glb.ext.poses[Number(poseIndex)];
const [u, v] = uv.split(',').map(Number);
const [u0, v0] = [Math.floor(u), Math.floor(v)];
const [fu, fv] = [u - u0, v - v0];
const eye = [0, 0, 0];
const forward = [0, 0, 0];
let fy = 0;
for (const [du, dv, w] of [[0, 0, (1 - fu) * (1 - fv)], [1, 0, fu * (1 - fv)], [0, 1, (1 - fu) * fv], [1, 1, fu * fv]]) {
  if (w === 0) continue;
  const c = pose.cameras[((u0 + du) % columns) * rows + Math.min(v0 + dv, rows - 1)];
  for (let i = 0; i < 3; i++) {
    eye[i] += w * c.world_from_camera[i][3];
    forward[i] += w * c.world_from_camera[i][2];
  }
  fy += w * c.intrinsics[1];
}
const { width, height } = pose.cameras[0];
const fov = (2 * Math.atan(height / 2 / fy) * 180) / Math.PI;
console.log(`--camera=${eye.join(',')} --look-at=${eye.map((e, i) => e + forward[i]).join(',')} --fov ${fov} --size ${width}x${height}`);
