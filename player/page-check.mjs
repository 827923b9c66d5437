// Opens one of the player's pages in headless Chromium (software GL) with a walker, waits
// until it has drawn FRAMES frames (window.frfSceneFrames) or TIMEOUT ms pass, and prints
// its status and error lines as JSON (and a screenshot with --png):
//   node player/page-check.mjs --page scene.html --glb walker.glb [--sh SH.json]
//     [--query 'walked=3.6&still'] [--frames 2] [--size 480x360] [--png OUT.png]
import { basename, resolve } from 'node:path';
import puppeteer from 'puppeteer-core';
import { serve } from './serve.mjs';

const o = { page: 'scene.html', frames: 2, size: '480x360', query: '' };
const argv = process.argv.slice(2);
for (let i = 0; i < argv.length; i += 2) o[argv[i].replace(/^--/, '')] = argv[i + 1];
if (!o.glb) {
  console.error('page-check: --glb is required');
  process.exit(1);
}
const [width, height] = o.size.split('x').map(Number);
const files = { '/job/walker.glb': resolve(o.glb) };
if (o.sh) files['/job/sh.json'] = resolve(o.sh);
const server = await serve(0, files);
const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium', headless: true, pipe: true,
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--no-sandbox',
    '--disable-dev-shm-usage', '--disable-breakpad', '--disable-crash-reporter'],
});
let out;
try {
  const page = await browser.newPage();
  await page.setViewport({ width, height });
  const logs = [];
  page.on('pageerror', (e) => logs.push(String(e)));
  const query = `glb=/job/walker.glb${o.sh ? '&sh=/job/sh.json' : ''}${o.query ? `&${o.query}` : ''}`;
  await page.goto(`http://127.0.0.1:${server.address().port}/${o.page}?${query}`);
  // Until it has drawn the frames, or said an error.
  await page.waitForFunction(`(window.frfSceneFrames ?? 0) >= ${Number(o.frames)} || (document.getElementById('error')?.textContent ?? '') !== ''`, { timeout: 120000 }).catch(() => {});
  const text = (id) => page.$eval(`#${id}`, (e) => e.textContent).catch(() => null);
  out = { page: basename(o.page), frames: await page.evaluate('window.frfSceneFrames ?? 0'), status: await text('status'), error: await text('error'), logs };
  if (o.png) await page.screenshot({ path: o.png });
} finally {
  await browser.close();
  server.close();
}
console.log(JSON.stringify(out));
