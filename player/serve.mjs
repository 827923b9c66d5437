// A static file server for the player's pages: the player's own directory at `/`, and
// files the caller names at fixed paths (screenshot.mjs hands the walker in this way).
//   node player/serve.mjs [PORT] [--glb walker.glb]   then open http://localhost:PORT/
import http from 'node:http';
import { readFile } from 'node:fs/promises';
import { extname, join, normalize, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = dirname(fileURLToPath(import.meta.url));
const TYPES = {
  '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json',
  '.glb': 'model/gltf-binary', '.css': 'text/css', '.png': 'image/png', '.wasm': 'application/wasm',
};

/** Serves the player on `port` (0: any free one); `extra` maps URL paths to files. */
export function serve(port = 0, extra = {}) {
  const server = http.createServer(async (req, res) => {
    const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    const file = extra[path] ?? join(root, normalize(path === '/' ? '/index.html' : path));
    if (!extra[path] && !resolve(file).startsWith(root)) {
      res.writeHead(403).end();
      return;
    }
    try {
      const body = await readFile(file);
      res.writeHead(200, { 'content-type': TYPES[extname(file)] ?? 'application/octet-stream' }).end(body);
    } catch {
      res.writeHead(404).end(`${path}: not found`);
    }
  });
  return new Promise((ok) => server.listen(port, '127.0.0.1', () => ok(server)));
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const args = process.argv.slice(2);
  const at = args.indexOf('--glb');
  const extra = at >= 0 ? { '/walker.glb': resolve(args[at + 1]) } : {};
  const port = Number(args.find((a, i) => /^\d+$/.test(a) && args[i - 1] !== '--glb') ?? 8080);
  const server = await serve(port, extra);
  const url = `http://localhost:${server.address().port}/${at >= 0 ? '?glb=/walker.glb' : ''}`;
  console.log(`frf player at ${url}`);
}
