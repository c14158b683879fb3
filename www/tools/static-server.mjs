// A tiny static file server for the demo page: no dependencies, loopback only,
// correct MIME types (application/wasm for the module, text/javascript for ES
// modules), no caching (a rebuilt www/pkg is picked up on reload).
//
//   node www/tools/static-server.mjs [--port 8080] [--root www] [--host 127.0.0.1]
//                                    [--mount /js/=js ...]
//
// or, from a script or test:
//   import { startServer } from './www/tools/static-server.mjs';
//   const server = await startServer({ root, port: 0 }); // server.url, server.close()
//
// A mount serves a folder outside the root under a URL prefix: the map page
// imports the package's own JS modules (js/geo.mjs) as /js/geo.mjs.

import { createServer } from 'node:http';
import { createReadStream, promises as fs } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const MIME = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json; charset=utf-8',
  '.map': 'application/json; charset=utf-8',
  '.wasm': 'application/wasm',
  '.png': 'image/png',
  '.svg': 'image/svg+xml',
  '.ico': 'image/x-icon',
  '.md': 'text/plain; charset=utf-8',
  '.txt': 'text/plain; charset=utf-8',
  '.ts': 'text/plain; charset=utf-8',
  '.bin': 'application/octet-stream',
  '.pcd': 'application/octet-stream',
  '.ply': 'application/octet-stream',
};

const LOOPBACK = new Set(['127.0.0.1', '::1', 'localhost']);

function mimeOf(file) {
  const ext = path.extname(file).toLowerCase();
  if (MIME[ext]) return MIME[ext];
  // LICENSE.ouster-sdk and friends are plain text.
  if (path.basename(file).startsWith('LICENSE')) return 'text/plain; charset=utf-8';
  return 'application/octet-stream';
}

/**
 * Serve `root` on http://host:port/. Resolves once listening, with
 * `{ url, port, close() }` (close resolves when the server has stopped).
 * `port: 0` picks a free port.
 */
export function startServer({ root, port = 8080, host = '127.0.0.1', quiet = true, mounts = {} } = {}) {
  if (!LOOPBACK.has(host)) throw new Error(`refusing to bind ${host}: the demo server is loopback only`);
  const rootDir = path.resolve(root);
  // Longest prefix first; each prefix is '/name/'.
  const mounted = Object.entries(mounts)
    .map(([prefix, dir]) => {
      if (!/^\/[^/]+(\/[^/]+)*\/$/.test(prefix)) throw new Error(`mount prefix '${prefix}' must look like /name/`);
      return [prefix, path.resolve(dir)];
    })
    .sort((a, b) => b[0].length - a[0].length);
  const server = createServer(async (req, res) => {
    try {
      if (req.method !== 'GET' && req.method !== 'HEAD') {
        res.writeHead(405, { Allow: 'GET, HEAD' }).end();
        return;
      }
      const url = new URL(req.url, 'http://localhost');
      let rel = decodeURIComponent(url.pathname);
      let base = rootDir;
      let inBase = rel;
      for (const [prefix, dir] of mounted) {
        if (rel.startsWith(prefix)) {
          base = dir;
          inBase = rel.slice(prefix.length - 1);
          break;
        }
      }
      let file = path.resolve(base, '.' + inBase);
      if (file !== base && !file.startsWith(base + path.sep)) {
        res.writeHead(403).end('forbidden');
        return;
      }
      let stat = await fs.stat(file).catch(() => null);
      if (stat && stat.isDirectory()) {
        file = path.join(file, 'index.html');
        stat = await fs.stat(file).catch(() => null);
      }
      if (!stat || !stat.isFile()) {
        res.writeHead(404, { 'Content-Type': 'text/plain; charset=utf-8' }).end(`not found: ${rel}\n`);
        return;
      }
      res.writeHead(200, {
        'Content-Type': mimeOf(file),
        'Content-Length': stat.size,
        'Cache-Control': 'no-cache',
        'X-Content-Type-Options': 'nosniff',
      });
      if (req.method === 'HEAD') return res.end();
      createReadStream(file).pipe(res);
    } catch (e) {
      res.writeHead(500).end(String(e));
    } finally {
      if (!quiet) console.log(`${req.method} ${req.url}`);
    }
  });
  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(port, host, () => {
      const actual = server.address().port;
      const shown = host.includes(':') ? `[${host}]` : host;
      resolve({
        url: `http://${shown}:${actual}/`,
        port: actual,
        close: () =>
          new Promise((done) => {
            server.closeAllConnections?.();
            server.close(() => done());
          }),
      });
    });
  });
}

// Command line.
if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const args = process.argv.slice(2);
  const opt = (name, dflt) => {
    const i = args.indexOf(`--${name}`);
    return i >= 0 && i + 1 < args.length ? args[i + 1] : dflt;
  };
  const root = opt('root', path.join(path.dirname(fileURLToPath(import.meta.url)), '..'));
  const port = Number(opt('port', '8080'));
  const host = opt('host', '127.0.0.1');
  const mounts = {};
  args.forEach((a, i) => {
    if (a !== '--mount') return;
    const [prefix, dir] = String(args[i + 1] ?? '').split('=');
    if (!prefix || !dir) {
      console.error(`serve: --mount wants /prefix/=folder, got '${args[i + 1] ?? ''}'`);
      process.exit(2);
    }
    mounts[prefix] = dir;
  });
  if (!Number.isInteger(port) || port < 0 || port > 65535) {
    console.error(`serve: bad port '${opt('port')}'`);
    process.exit(2);
  }
  startServer({ root, port, host, mounts, quiet: !args.includes('--verbose') })
    .then((s) => {
      console.log(`polyscene demo: ${s.url}  (serving ${path.resolve(root)}; Ctrl-C to stop)`);
      const stop = () => s.close().then(() => process.exit(0));
      process.on('SIGINT', stop);
      process.on('SIGTERM', stop);
    })
    .catch((e) => {
      const hint = e.code === 'EADDRINUSE' ? ` (port ${port} is in use: try make demo PORT=NNNN)` : '';
      console.error(`serve: cannot listen on ${host}:${port}: ${e.message}${hint}`);
      process.exit(1);
    });
}
