// Renders one frame of a walker (`frf export`) in headless Chromium (software GL) and
// writes it as a PNG (8-bit sRGB, straight alpha: as `frf render` writes its frames):
//
//   node player/screenshot.mjs --glb F [--pose N | --time SECONDS [--interpolate flow|nearest]] \
//     --camera X,Y,Z --look-at X,Y,Z --fov DEG --size WxH --sh SH.json [--sun AZ,EL[,DIAM[,E]]] \
//     --out OUT.png [--time-frames K] [--box X,Y,Z,SX,SY,SZ,R,G,B ...] [--no-depth]
//     [--shadow-out SHADOW.png] [--all-views] [--mask VIEW_PX|none] [--json]
//
// `--pose N` draws a pose; `--time SECONDS` an instant of the walk (from pose 0's, looping
// every cycle), between two poses morphed in time by their motion as frf does (`flow`), or
// the nearest pose (`nearest`, as frf's `interpolate = "nearest"`). Each `--box` puts an
// unlit box (centre, size in metres, linear colour) in a three.js scene with the walker,
// which is drawn with its hull's depth against them (laid over them with `--no-depth`).
// `--shadow-out` also writes the ground's relative irradiance under the walker as the
// camera sees the ground (frf's shadow layer; 1 unshadowed) as a 16-bit linear RGB PNG.
// The camera is frf's `look_at` (subject frame, +y up, vertical field of view in
// degrees); `--sh` an L2 light of `frf env-sh`; `--sun` a sun as frf's `--sun`: azimuth AZ
// (from +z toward +x) and elevation EL, degrees, a disc DIAM degrees across (0.53 when
// not given; it matters to a sun relit by the basis) and illuminance E (10 when not
// given), lighting by the normals (below the horizon, softly through the L2 light); the
// light file's own suns (`frf env-sh --suns`) light it too. Only the views the camera's
// rays reach are decoded (`views_decoded` in the JSON); `--all-views` decodes every view.
// The passes shade only the walker's mask, its hull grown by `--mask` of its views'
// pixels (8 when not given; `none`: every pixel of the walker's box, as frf).
// `--time-frames K` times K frames after the first (ms per frame). Chromium is found at
// $CHROMIUM, else /usr/bin/chromium (scripts/setup.sh installs it).
import { readFile, writeFile, rename, stat, unlink } from 'node:fs/promises';
import { basename, dirname, resolve } from 'node:path';
import puppeteer from 'puppeteer-core';
import { encode } from 'fast-png';
import { serve } from './serve.mjs';

function fail(message) {
  console.error(`screenshot: ${message}`);
  process.exit(1);
}

function parse(argv) {
  const o = { pose: null, time: null, interpolate: 'flow', fov: 35, timeFrames: 0, json: false, boxes: [], depth: true };
  const numbers = (flag, text, n, most = n) => {
    const v = text.split(',').map((x) => (x.trim() === '' ? NaN : Number(x)));
    if (v.length < n || v.length > most || v.some((x) => !Number.isFinite(x))) {
      fail(`${flag} ${text}: expected ${n === most ? n : `${n} to ${most}`} numbers separated by commas`);
    }
    return v;
  };
  // `--flag value` or `--flag=value` (the form for values starting with a minus sign).
  argv = argv.flatMap((a) => (/^--[a-z-]+=/.test(a) ? [a.slice(0, a.indexOf('=')), a.slice(a.indexOf('=') + 1)] : [a]));
  for (let i = 0; i < argv.length; i++) {
    const flag = argv[i];
    const value = () => {
      if (i + 1 >= argv.length) fail(`${flag} needs a value`);
      return argv[++i];
    };
    switch (flag) {
      case '--glb': o.glb = value(); break;
      case '--pose': o.pose = numbers(flag, value(), 1)[0]; break;
      case '--time': o.time = numbers(flag, value(), 1)[0]; break;
      case '--interpolate': o.interpolate = value(); break;
      case '--camera': o.camera = numbers(flag, value(), 3); break;
      case '--look-at': o.lookAt = numbers(flag, value(), 3); break;
      case '--fov': o.fov = numbers(flag, value(), 1)[0]; break;
      case '--size': {
        const m = /^(\d+)x(\d+)$/.exec(value());
        if (!m) fail(`--size ${argv[i]}: expected WxH`);
        [o.width, o.height] = [Number(m[1]), Number(m[2])];
        break;
      }
      case '--sh': o.sh = value(); break;
      case '--sun': o.sun = numbers(flag, value(), 2, 4); break;
      case '--out': o.out = value(); break;
      case '--time-frames': o.timeFrames = numbers(flag, value(), 1)[0]; break;
      case '--json': o.json = true; break;
      case '--box': o.boxes.push(numbers(flag, value(), 9)); break;
      case '--no-depth': o.depth = false; break;
      case '--all-views': o.allViews = true; break;
      case '--mask': {
        const v = value();
        o.mask = v === 'none' ? null : numbers(flag, v, 1)[0];
        if (o.mask !== null && !(o.mask >= 0 && o.mask <= 1000)) fail(`--mask ${v}: expected views' pixels from 0 to 1000, or none`);
        break;
      }
      case '--shadow-out': o.shadowOut = value(); break;
      default: fail(`unknown flag ${flag}`);
    }
  }
  for (const k of ['glb', 'camera', 'sh', 'out', 'width']) {
    if (o[k] === undefined) fail(`--${k === 'width' ? 'size' : k} is required`);
  }
  o.lookAt ??= [0, 0.9, 0];
  if (o.pose !== null && o.time !== null) fail('--pose and --time: give one (a pose, or an instant of the walk)');
  if (o.time !== null && Math.abs(o.time) > 1e9) fail(`--time ${o.time}: expected seconds within ±1e9`);
  if (!['flow', 'nearest'].includes(o.interpolate)) fail(`--interpolate ${o.interpolate}: expected flow or nearest`);
  if (!(o.width >= 1 && o.height >= 1 && o.width <= 8192 && o.height <= 8192)) fail(`--size ${o.width}x${o.height}: 1 to 8192 pixels a side`);
  if (!(o.fov > 0.1 && o.fov < 170)) fail(`--fov ${o.fov}: expected degrees in (0.1, 170)`);
  if (!(Number.isInteger(o.timeFrames) && o.timeFrames >= 0 && o.timeFrames <= 1000)) fail(`--time-frames ${o.timeFrames}: 0 to 1000`);
  if (o.sun) {
    const [, el, diam = 0.53, e = 10] = o.sun;
    if (!(el >= -90 && el <= 90)) fail(`--sun ${o.sun}: elevation ${el}° is not within ±90°`);
    if (!(diam > 0 && diam <= 20)) fail(`--sun ${o.sun}: diameter ${diam}° is not within (0, 20]°`);
    if (!(e >= 0 && e <= 1e30)) fail(`--sun ${o.sun}: illuminance ${e} is not from 0 to 1e30 (as frf takes)`);
  }
  return o;
}

const o = parse(process.argv.slice(2));
const glbPath = resolve(o.glb);
const glbStat = await stat(glbPath).catch(() => fail(`${o.glb}: no such file`));
if (!glbStat.isFile()) fail(`${o.glb}: not a file (a .glb of frf export)`);
const shText = await readFile(o.sh, 'utf8').catch((e) => fail(`${o.sh}: ${e.message}`));
// The output's place is checked before anything renders: a directory, or a folder that
// is not there, failed only after the render (leaving its temporary file).
const outStat = await stat(o.out).catch(() => null);
if (outStat?.isDirectory()) fail(`--out ${o.out}: a directory; give the PNG's file name`);
const outDir = await stat(dirname(resolve(o.out))).catch(() => null);
if (!outDir?.isDirectory()) fail(`--out ${o.out}: the folder ${dirname(o.out)} does not exist`);
const server = await serve(0, { '/job/walker.glb': glbPath });
const base = `http://127.0.0.1:${server.address().port}`;
// Talking to Chromium over a pipe: if this process is killed (even by SIGKILL) the pipe
// closes and Chromium ends with it, crash handler and all.
const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  pipe: true,
  handleSIGINT: false,
  handleSIGTERM: false,
  handleSIGHUP: false,
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--no-sandbox',
    '--disable-dev-shm-usage', '--disable-breakpad', '--disable-crash-reporter',
    '--js-flags=--max-old-space-size=8192'],
});
// A signal ends the run plainly: the browser closed, nothing written, 128 + its number
// (the page's work it cuts short is not reported as an error of its own).
let interrupted = false;
for (const [signal, number] of [['SIGINT', 2], ['SIGTERM', 15], ['SIGHUP', 1]]) {
  process.on(signal, async () => {
    interrupted = true;
    console.error(`screenshot: interrupted (${signal}); nothing written`);
    await browser.close().catch(() => {});
    server.close();
    process.exit(128 + number);
  });
}
let result;
try {
  const page = await browser.newPage();
  const logs = [];
  page.on('console', (m) => logs.push(m.text()));
  page.on('pageerror', (e) => logs.push(String(e)));
  await page.goto(`${base}/headless.html`);
  await page.waitForFunction('window.frfReady === true', { timeout: 60000 }).catch(() => {
    throw new Error(`the player's page did not start: ${logs.join(' | ')}`);
  });
  result = await page.evaluate((job) => window.frfRender(job), {
    glbUrl: '/job/walker.glb', glbName: basename(o.glb), shText, shName: basename(o.sh),
    pose: o.pose, time: o.time, interpolate: o.interpolate, camera: o.camera, lookAt: o.lookAt, fov: o.fov, width: o.width, height: o.height,
    sun: o.sun ?? null, timedFrames: o.timeFrames, boxes: o.boxes, depth: o.depth, shadowLayer: Boolean(o.shadowOut),
    allViews: Boolean(o.allViews), mask: o.mask,
  });
} catch (e) {
  if (interrupted) await new Promise(() => {});
  await browser.close();
  server.close();
  fail(String(e.message ?? e).replace(/^Error: /, '').split('\n')[0]);
}
await browser.close();
server.close();
const rgba = Buffer.from(result.rgba, 'base64');
const png = encode({ width: o.width, height: o.height, data: new Uint8Array(rgba), channels: 4, depth: 8 });
/** Writes `bytes` to `path` through a temporary file, or fails naming `flag`. */
async function writeWhole(path, bytes, flag) {
  const tmp = `${path}.tmp-${process.pid}`;
  try {
    await writeFile(tmp, bytes);
    await rename(tmp, path);
  } catch (e) {
    await unlink(tmp).catch(() => {});
    fail(`${flag} ${path}: ${e.message}`);
  }
}
await writeWhole(o.out, png, '--out');
if (o.shadowOut) {
  const b = Buffer.from(result.shadow, 'base64');
  const data = new Uint16Array(new Uint8Array(b).buffer);
  await writeWhole(o.shadowOut, encode({ width: o.width, height: o.height, data, channels: 3, depth: 16 }), '--shadow-out');
}
const report = {
  out: o.out, pose: result.at.before, between: result.at.s > 0 ? { after: result.at.after, s: result.at.s } : null, width: o.width, height: o.height,
  ms_per_frame: result.msPerFrame, frame_parts_ms: result.partsMs, timed_frames: o.timeFrames, load_ms: result.loadMs, load_parts_ms: result.loadParts,
  gl_renderer: result.renderer, notes: result.notes, views_decoded: result.viewsDecoded, mask: result.mask, shaded_pixels: result.shadedPixels,
};
console.log(o.json ? JSON.stringify(report) : `wrote ${o.out} (${o.width}x${o.height}, pose ${result.at.before}${result.at.s > 0 ? ` to ${result.at.after} at ${result.at.s.toFixed(3)}` : ''}${result.msPerFrame ? `, ${result.msPerFrame.toFixed(1)} ms per frame on ${result.renderer}` : ''})`);
