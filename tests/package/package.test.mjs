// The npm package as a user gets it: pkg/polyscene-*.tgz (scripts/pack.sh)
// installed into a scratch project outside the repository, then used from
// Node (CommonJS and ES module), type-checked with tsc --strict (ES2022
// libs), bundled by Vite and by esbuild and run in headless Chromium. The
// README's JS examples (the blocks after `<!-- example: NAME -->`) are run
// as written, and the package README's copies must equal them.
//
//   scripts/test-package.sh     (packs first; needs scripts/setup.sh all)
//
// Bundlers and tsc come from tests/package/tools/node_modules.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync, spawn, spawnSync } from 'node:child_process';
import net from 'node:net';
import { createRequire } from 'node:module';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { CHROMIUM, FLAGS } from '../e2e/chromium.mjs';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const TOOLS = path.join(ROOT, 'tests/package/tools/node_modules/.bin');
const { chromium } = createRequire(path.join(ROOT, 'www/package.json'))('playwright-core');
const { startServer } = await import(pathToFileURL(path.join(ROOT, 'www/tools/static-server.mjs')).href);

let scratch; // the temp dir
let app; // the scratch project
let tarball;
let browser;

/** The JS block after `<!-- example: name -->` in a markdown file. */
function example(file, name) {
  const text = fs.readFileSync(file, 'utf8');
  const m = text.match(new RegExp(`<!-- example: ${name} -->\\n\`\`\`js\\n([\\s\\S]*?)\`\`\``));
  assert.ok(m, `${path.relative(ROOT, file)} has the example '${name}'`);
  return m[1];
}

/** A tilted plane z = 0.5 x over x in [2, 12], y in [-3, 3], 1 cm noise: x, y, z float32 (JS source). */
const PLANE_JS = `
export function plane() {
  const pts = [];
  let s = 1;
  const rnd = () => ((s = (s * 1103515245 + 12345) % 2147483648) / 2147483648 - 0.5) * 0.02;
  for (let i = 0; i <= 100; i++) for (let j = 0; j <= 60; j++) pts.push(2 + i * 0.1, -3 + j * 0.1, 0.5 * (2 + i * 0.1) + rnd());
  return new Float32Array(pts);
}
export function summary(polygons) {
  return polygons.map((p) => {
    const xs = Array.from(p.vertices).filter((_, k) => k % 3 === 0);
    return { normal: Array.from(p.normal), area: p.area, xmin: Math.min(...xs), xmax: Math.max(...xs) };
  });
}
`;

/** The polygon of the plane: one, normal (-1, 0, 2)/sqrt(5) either way, area 10 * 6 * sqrt(1.25) = 67.1 m^2 within 5 %. */
function assertPlane(found, where) {
  assert.equal(found.length, 1, `${where}: one polygon, got ${JSON.stringify(found)}`);
  const [p] = found;
  const n = [-1 / Math.sqrt(5), 0, 2 / Math.sqrt(5)];
  const dot = Math.abs(p.normal[0] * n[0] + p.normal[1] * n[1] + p.normal[2] * n[2]);
  assert.ok(dot > 0.9999, `${where}: normal ${p.normal}`);
  assert.ok(Math.abs(p.area - 67.08) < 0.05 * 67.08, `${where}: area ${p.area}`);
  assert.ok(p.xmin > 1.9 && p.xmin < 2.3 && p.xmax > 11.7 && p.xmax < 12.1, `${where}: x from ${p.xmin} to ${p.xmax}`);
}

// Tools print plain text here whatever the CI's colour settings, so their
// output can be matched as it reads.
const PLAIN = { ...process.env, NO_COLOR: '1', FORCE_COLOR: '0' };

function run(cmd, args, opts = {}) {
  const r = spawnSync(cmd, args, { cwd: app, encoding: 'utf8', timeout: 180_000, env: PLAIN, ...opts });
  assert.equal(r.status, 0, `${cmd} ${args.join(' ')} failed:\n${r.stdout}\n${r.stderr}`);
  return r;
}

before(async () => {
  const packed = fs.readFileSync(path.join(ROOT, 'pkg/npm-pack.txt'), 'utf8').split(':')[0];
  tarball = path.join(ROOT, 'pkg', packed);
  assert.ok(fs.existsSync(tarball), `${tarball} is missing: run scripts/pack.sh`);
  assert.ok(fs.existsSync(path.join(TOOLS, 'vite')), 'tests/package/tools is not installed: run scripts/setup.sh npm');
  scratch = fs.mkdtempSync(path.join(os.tmpdir(), 'polyscene-package-'));
  app = path.join(scratch, 'app');
  fs.mkdirSync(app);
  fs.writeFileSync(path.join(app, 'package.json'), JSON.stringify({ name: 'scratch', private: true, version: '1.0.0' }));
  run('npm', ['install', '--no-audit', '--no-fund', '--loglevel=error', tarball]);
  fs.writeFileSync(path.join(app, 'plane.mjs'), PLANE_JS);
  browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: FLAGS, timeout: 30_000 });
});

after(async () => {
  await browser?.close();
  if (scratch && !process.env.KEEP_SCRATCH) fs.rmSync(scratch, { recursive: true, force: true });
  else if (scratch) console.log(`scratch project kept: ${app}`);
});

test('the tarball: one package, licences, types, an exports map, no placeholder URL', () => {
  const files = execFileSync('tar', ['tzf', tarball], { encoding: 'utf8' }).split('\n').filter(Boolean);
  for (const f of ['LICENSE-MIT', 'LICENSE-APACHE', 'README.md', 'web/polyscene.d.ts', 'web/polyscene_bg.wasm', 'node/polyscene.cjs', 'web/polyscene_sim.d.ts', 'web/polyscene_sim_bg.wasm', 'node/polyscene_sim.cjs', 'worker/worker.js', 'geo/index.js', 'geo/index.d.ts', 'io/index.js', 'io/index.d.ts']) {
    assert.ok(files.includes(`package/${f}`), `${f} in the tarball`);
  }
  assert.deepEqual(files.filter((f) => f.endsWith('.wasm')).sort(), ['package/web/polyscene_bg.wasm', 'package/web/polyscene_sim_bg.wasm'], 'one copy of each wasm');
  const dir = path.join(app, 'node_modules/polyscene');
  const manifest = JSON.parse(fs.readFileSync(path.join(dir, 'package.json'), 'utf8'));
  assert.equal(manifest.name, 'polyscene');
  assert.equal(manifest.license, 'MIT OR Apache-2.0');
  assert.ok(manifest.engines?.node && manifest.exports['.'] && manifest.exports['./worker'] && manifest.exports['./sim'] && manifest.types);
  assert.equal(manifest.sideEffects, false);
  assert.match(fs.readFileSync(path.join(dir, 'LICENSE-APACHE'), 'utf8'), /Apache License\s+Version 2\.0/);
  assert.match(fs.readFileSync(path.join(dir, 'LICENSE-MIT'), 'utf8'), /Permission is hereby granted/);
  for (const f of files) {
    if (f.endsWith('.wasm')) continue;
    assert.ok(!fs.readFileSync(path.join(scratch, 'app/node_modules/polyscene', f.slice('package/'.length)), 'utf8').includes('example.invalid'), f);
  }
  const readme = fs.readFileSync(path.join(dir, 'README.md'), 'utf8');
  for (const [, link] of readme.matchAll(/\]\(([^)]+)\)/g)) assert.match(link, /^https?:/, `README link ${link}`);
});

test('Node ESM: polyscene/geo places a detected polygon at its lon/lat (proj4 installed as a dependency)', () => {
  fs.writeFileSync(
    path.join(app, 'geo.mjs'),
    `import { detect } from "polyscene";
     import { geoFrame, toGeoJSON } from "polyscene/geo";
     import { plane } from "./plane.mjs";
     const frame = geoFrame({ origin: { lon: 8.4037, lat: 49.0069, alt: 115 }, heading: 90 });
     const fc = toGeoJSON(detect(plane(), { stride: 3 }), frame);
     console.log(JSON.stringify(fc.features.map((f) => f.geometry.coordinates[0])));`,
  );
  const rings = JSON.parse(run('node', ['geo.mjs']).stdout);
  assert.equal(rings.length, 1, 'one polygon');
  // x is east (heading 90): the plane's x from 2 to 12 m is 2 to 12 m east of the origin,
  // its y from -3 to 3 m as far north and south (a metre of longitude there: 111,320 cos(lat) m a degree).
  const east = (lon) => (lon - 8.4037) * 111320 * Math.cos((49.0069 * Math.PI) / 180);
  const north = (lat) => (lat - 49.0069) * 110_900;
  const es = rings[0].map(([lon]) => east(lon));
  const ns = rings[0].map(([, lat]) => north(lat));
  assert.ok(Math.min(...es) > 1.5 && Math.min(...es) < 2.5 && Math.max(...es) > 11.5 && Math.max(...es) < 12.5, `east ${es}`);
  assert.ok(Math.min(...ns) > -3.5 && Math.max(...ns) < 3.5, `north ${ns}`);
});

test("the package README's examples are the README's", () => {
  for (const name of ['browser', 'node', 'worker']) {
    assert.equal(example(path.join(ROOT, 'npm/README.md'), name), example(path.join(ROOT, 'README.md'), name), name);
  }
});

test('Node CommonJS: require("polyscene") detects the plane; the README example runs', () => {
  fs.writeFileSync(
    path.join(app, 'plane.cjs'),
    `const { detect } = require("polyscene");
     import("./plane.mjs").then(({ plane, summary }) => console.log(JSON.stringify(summary(detect(plane(), { stride: 3 })))));`,
  );
  assertPlane(JSON.parse(run('node', ['plane.cjs']).stdout), 'CJS');
  // The README's example reads scan.bin: one simulated scan, KITTI layout.
  fs.writeFileSync(
    path.join(app, 'make-scan.cjs'),
    `const { simulate } = require("polyscene/sim");
     const s = simulate({ seed: 1 }).scan(0).points;
     require("node:fs").writeFileSync("scan.bin", Buffer.from(s.buffer, s.byteOffset, s.byteLength));`,
  );
  run('node', ['make-scan.cjs']);
  fs.writeFileSync(path.join(app, 'readme-node.cjs'), example(path.join(ROOT, 'README.md'), 'node'));
  const out = run('node', ['readme-node.cjs']).stdout;
  assert.ok((out.match(/#\d+ \d+\.\d m\^2/g) ?? []).length >= 5, `README's Node example printed: ${out}`);
});

test('Node ES module: import gives the same instance as require; the README page example runs', () => {
  fs.writeFileSync(
    path.join(app, 'plane-esm.mjs'),
    `import init, { detect, Scenario } from "polyscene";
     import { createRequire } from "node:module";
     import { plane, summary } from "./plane.mjs";
     await init();
     const same = createRequire(import.meta.url)("polyscene").Scenario === Scenario;
     console.log(JSON.stringify({ same, found: summary(detect(plane(), { stride: 3 })) }));`,
  );
  const r = JSON.parse(run('node', ['plane-esm.mjs']).stdout);
  assert.equal(r.same, true, 'one wasm instance for import and require');
  assertPlane(r.found, 'ESM');
  fs.writeFileSync(path.join(app, 'readme-browser.mjs'), `${example(path.join(ROOT, 'README.md'), 'browser')}
console.log(JSON.stringify({ polygons: polygons.length, triangles: mesh.indices.length / 3 }));`);
  const out = JSON.parse(run('node', ['readme-browser.mjs']).stdout);
  assert.ok(out.polygons > 10 && out.triangles > out.polygons, JSON.stringify(out));
});

test('the .d.ts compiles under tsc --strict with the ES2022 libs (bundler and node16 resolution)', () => {
  fs.writeFileSync(
    path.join(app, 'typed.ts'),
    `import init, { Scenario, detect, defaultOptions, type Polygon } from "polyscene";
import initSim, { simulate, type SimulatedScan } from "polyscene/sim";
import { PolysceneClient } from "polyscene/worker";
import { readPoints, kittiSequence, type PointCloud } from "polyscene/io";
await init();
await initSim();
const s = new Scenario();
const sim = simulate();
const scan: SimulatedScan = sim.scan(0);
const report = s.addScan(scan.points, { stride: 4, pose: scan.pose });
const n: number = report.polygonCount;
const found: Polygon[] = detect(new Float32Array(9));
const d = defaultOptions();
s[Symbol.dispose]();
const client = new PolysceneClient();
client.addEventListener("scan", (e) => console.log(e.detail.report.polygonCount));
const p: Promise<Polygon[]> = client.detect(new Float32Array(9), { stride: 3 }, { signal: new AbortController().signal });
console.log(n, found, d.minArea, p);
const cloud: PointCloud = await readPoints(new Uint8Array(16), { name: "scan.bin", stride: 4 });
const epsg: string | undefined = cloud.crs?.definition;
const seq = await kittiSequence({ scans: [new File([new Uint8Array(16)], "000000.bin")], poses: "1 0 0 0 0 1 0 0 0 0 1 0", calib: "Tr: 1 0 0 0 0 1 0 0 0 0 1 0" });
for await (const k of seq) s.addScan(k.points, { stride: k.stride, pose: k.pose });
console.log(detect(cloud.points, { stride: cloud.stride }), epsg);
`,
  );
  const tsc = path.join(TOOLS, 'tsc');
  // target es2022 and no "lib": TypeScript's default libs for ES2022 (with the DOM); no @types.
  const config = (module, files) =>
    JSON.stringify({ compilerOptions: { strict: true, noEmit: true, target: 'es2022', module, moduleResolution: module, types: [] }, files });
  fs.writeFileSync(path.join(app, 'tsconfig.bundler.json'), config('preserve', ['typed.ts']).replace('"moduleResolution":"preserve"', '"moduleResolution":"bundler"'));
  run(tsc, ['-p', 'tsconfig.bundler.json']);
  fs.writeFileSync(
    path.join(app, 'typed-node.mts'),
    `import init, { detect } from "polyscene";\nimport { simulate } from "polyscene/sim";\nimport { readPointsFile, openKittiSequence } from "polyscene/io/node";\nawait init();\nconst n: number = detect(new Float32Array(9), { stride: 3 }).length;\nconst pts: Float32Array = simulate({ seed: 2 }).scan(0).points;\nconst c = await readPointsFile("scan.las");\nconst seq = await openKittiSequence("kitti", { sequence: "00", calib: "calib.txt" });\nconsole.log(n, pts.length, c.crs?.epsg, seq.length);\n`,
  );
  fs.writeFileSync(
    path.join(app, 'typed-node.cts'),
    `import ps = require("polyscene");\nimport sim = require("polyscene/sim");\nconst s = new ps.Scenario({ preset: "gpp1" });\nconst n: number = s.polygonCount + sim.simulate().length;\ns.free();\nexport = n;\n`,
  );
  fs.writeFileSync(path.join(app, 'tsconfig.node.json'), config('node16', ['typed-node.mts', 'typed-node.cts']));
  run(tsc, ['-p', 'tsconfig.node.json']);
});

const FIXTURES = pathToFileURL(path.join(ROOT, 'tests/js/io-fixtures.mjs')).href;

test('Node ESM: polyscene/io reads LAS at UTM (with its CRS, through @loaders.gl/las installed as a dependency), PCD, PLY and a KITTI sequence with calib; polygons equal the local .bin\'s to 1 mm', () => {
  fs.writeFileSync(
    path.join(app, 'io.mjs'),
    `import { detect, Scenario } from "polyscene";
     import { simulate } from "polyscene/sim";
     import { readPoints, readKittiBin, kittiSequence } from "polyscene/io";
     import * as fx from "${FIXTURES}";
     const sim = simulate({ layout: "street", seed: 1 });
     const pts = fx.onGrid(sim.scan(0).points, 4);
     const local = await readKittiBin(fx.rawBin(pts), { name: "local.bin" });
     const want = detect(local.points, { stride: local.stride, viewpoint: [0, 0, 0] });
     /** Largest vertex distance (m) to want's once moved back by shift, or a mismatch. */
     const gap = (got, shift, ref = want) => {
       if (got.length !== ref.length) return "count " + got.length + " vs " + ref.length;
       let d = 0;
       got.forEach((p, k) => {
         if (p.vertices.length !== ref[k].vertices.length) d = Infinity;
         else p.vertices.forEach((v, j) => (d = Math.max(d, Math.abs(v - shift[j % 3] - ref[k].vertices[j]))));
       });
       return d;
     };
     const out = { polygons: want.length, files: {} };
     for (const [name, bytes, shift] of [
       ["utm.las", fx.las(pts, fx.UTM, { crs: { epsg: 32632 } }), fx.UTM],
       ["utm-1.4.las", fx.las(pts, fx.UTM, { version: "1.4" }), fx.UTM],
       ["utm-binary.pcd", fx.pcd(pts, "binary", fx.UTM), fx.UTM],
       ["ascii.pcd", fx.pcd(pts, "ascii"), [0, 0, 0]],
       ["utm-binary.ply", fx.ply(pts, "le64", fx.UTM), fx.UTM],
       ["ascii.ply", fx.ply(pts, "ascii"), [0, 0, 0]],
     ]) {
       const c = await readPoints(bytes, { name });
       out.files[name] = { format: c.format, crs: c.crs?.definition, f64: c.points instanceof Float64Array, gap: gap(detect(c.points, { stride: c.stride, viewpoint: shift }), shift) };
     }
     try { await readPoints(fx.ply(pts.slice(0, 500), "le64", fx.UTM).subarray(0, 3000), { name: "cut.ply" }); } catch (e) { out.cut = e.message; }
     // A KITTI sequence: camera poses and calib.txt.
     const drive = simulate({ layout: "street", seed: 2 });
     const scans = [0, 1, 2, 3].map((k) => drive.scan(k));
     const tr = fx.calibTr();
     const poses = scans.map((s) => fx.poseLine(fx.mat4Mul(fx.mat4Mul(tr, Float64Array.from(s.pose)), fx.mat4Inverse(tr)))).join("\\n");
     const map = async (list) => {
       const sc = new Scenario();
       for await (const s of list) sc.addScan(s.points, { stride: 4, pose: s.pose });
       return sc.polygons();
     };
     const seq = await kittiSequence({ scans: scans.map((s, k) => ({ name: "00000" + k + ".bin", data: s.points })), poses, calib: fx.CALIB_00 });
     const ref = await map(scans);
     out.kitti = { polygons: ref.length, gap: gap(await map(seq), [0, 0, 0], ref) };
     console.log(JSON.stringify(out));`,
  );
  const out = JSON.parse(run('node', ['io.mjs']).stdout);
  assert.ok(out.polygons >= 10, `${out.polygons} polygons`);
  for (const [name, r] of Object.entries(out.files)) {
    assert.ok(typeof r.gap === 'number' && r.gap <= 1e-3, `${name}: ${JSON.stringify(r)}`);
    assert.equal(r.f64, name.startsWith('utm'), `${name}: float64 at map coordinates`);
  }
  assert.equal(out.files['utm.las'].crs, 'EPSG:32632');
  assert.equal(out.files['utm.las'].format, 'las');
  assert.match(out.cut, /cut\.ply: PLY vertex \d+ of 500: the file ends there/);
  assert.ok(out.kitti.polygons >= 5 && out.kitti.gap <= 1e-3, `KITTI: ${JSON.stringify(out.kitti)}`);
});

test('Vite and esbuild: polyscene/io in a production build, in Chromium: a LAS at UTM with its CRS (@loaders.gl/las bundled) and a binary PLY', async () => {
  const dir = path.join(app, 'vite-io');
  fs.mkdirSync(dir, { recursive: true });
  fs.copyFileSync(fileURLToPath(FIXTURES), path.join(dir, 'io-fixtures.mjs'));
  fs.writeFileSync(
    path.join(dir, 'main.mjs'),
    `import init, { detect } from "polyscene";
import { readPoints } from "polyscene/io";
import { las, ply, UTM } from "./io-fixtures.mjs";
const out = {};
try {
  await init();
  // A 10 m x 10 m floor, 10 cm spacing, at UTM coordinates.
  const pts = [];
  for (let i = 0; i <= 100; i++) for (let j = 0; j <= 100; j++) pts.push([i / 10, j / 10, 0]);
  for (const [name, bytes] of [["floor.las", las(pts, UTM, { crs: { epsg: 32632 } })], ["floor.ply", ply(pts, "le64", UTM)]]) {
    const c = await readPoints(new File([bytes], name));
    const found = detect(c.points, { stride: c.stride, viewpoint: [UTM[0] + 5, UTM[1] + 5, UTM[2] + 2] });
    out[name] = { format: c.format, count: c.count, crs: c.crs?.definition, f64: c.points instanceof Float64Array, polygons: found.length, area: found[0]?.area, x0: Math.min(...Array.from(found[0]?.vertices ?? []).filter((_, k) => k % 3 === 0)) };
  }
} catch (e) {
  out.error = String((e && e.stack) || e);
}
window.__results = out;
`,
  );
  fs.writeFileSync(path.join(dir, 'index.html'), '<!doctype html><meta charset="utf-8"><script type="module" src="./main.mjs"></script>');
  const r = run(path.join(TOOLS, 'vite'), ['build', '--logLevel', 'warn', '--outDir', 'dist', '--emptyOutDir'], { cwd: dir });
  // @loaders.gl/las's bundled LAZ decoder (laz-perf, emscripten) assigns
  // module.exports behind a typeof check; Rolldown notes it. Nothing else.
  const warnings = (r.stdout + r.stderr).split('\n').filter((l) => /warn|\[[A-Z_]+\]/i.test(l));
  assert.ok(warnings.every((l) => /COMMONJS_VARIABLE_IN_ESM/.test(l)), `Vite warned: ${warnings.join('\n')}`);
  const { results } = await inChromium(path.join(dir, 'dist'));
  assert.equal(results.error, undefined, results.error);
  for (const name of ['floor.las', 'floor.ply']) {
    const f = results[name];
    assert.ok(f.f64 && f.count === 101 * 101 && f.polygons === 1, `${name}: ${JSON.stringify(f)}`);
    assert.ok(Math.abs(f.area - 100) < 2 && Math.abs(f.x0 - 500_000) < 0.2, `${name}: ${JSON.stringify(f)}`);
  }
  assert.equal(results['floor.las'].format, 'las');
  assert.equal(results['floor.las'].crs, 'EPSG:32632');

  // esbuild, no config (polyscene/inline for the wasm): no warning, same results.
  const main = fs.readFileSync(path.join(dir, 'main.mjs'), 'utf8').replace('from "polyscene";', 'from "polyscene/inline";');
  fs.writeFileSync(path.join(dir, 'main-esbuild.mjs'), main);
  const es = run(path.join(TOOLS, 'esbuild'), ['main-esbuild.mjs', '--bundle', '--format=esm', '--splitting', '--outdir=dist-esbuild'], { cwd: dir });
  assert.doesNotMatch(es.stderr, /warning/i, `esbuild warned: ${es.stderr}`);
  fs.writeFileSync(path.join(dir, 'dist-esbuild/index.html'), '<!doctype html><meta charset="utf-8"><script type="module" src="./main-esbuild.js"></script>');
  const again = (await inChromium(path.join(dir, 'dist-esbuild'))).results;
  assert.deepEqual(again, results, 'esbuild gives what Vite gives');
});

/** Serve `dir`, open `page` in Chromium, wait for window.__results (and a console line matching `waitLog`); return it and the console lines. */
async function inChromium(dir, { page = 'index.html', waitLog, url } = {}) {
  const server = url ? { url, close: async () => {} } : await startServer({ root: dir, port: 0, host: '127.0.0.1' });
  const context = await browser.newContext();
  const offLoopback = [];
  await context.route((url) => url.origin !== new URL(server.url).origin, (route) => {
    offLoopback.push(route.request().url());
    return route.abort();
  });
  const tab = await context.newPage();
  const logs = [];
  const errors = [];
  tab.on('console', (m) => logs.push(m.text()));
  tab.on('pageerror', (e) => errors.push(e.message));
  try {
    await tab.goto(new URL(page, server.url).href);
    const failed = new Promise((_, reject) => tab.on('pageerror', (e) => reject(new Error(`page error: ${e.message}`))));
    await Promise.race([tab.waitForFunction(() => window.__results !== undefined, null, { timeout: 60_000 }), failed]);
    const results = await tab.evaluate(() => window.__results);
    // The README worker example's run streams on after its detect resolved.
    for (const t0 = Date.now(); waitLog && !logs.some((l) => waitLog.test(l)) && Date.now() - t0 < 60_000; ) {
      await new Promise((r) => setTimeout(r, 100));
    }
    assert.deepEqual(errors, [], 'no page errors');
    assert.deepEqual(offLoopback, [], 'no request off the loopback server');
    return { results, logs };
  } finally {
    await context.close();
    await server.close();
  }
}

/** The browser test app: direct detect, the README page example, optionally the worker client and the README worker example. */
function browserApp({ importFrom, initArg = '', worker }) {
  // The README page example's initSim() finds the simulator loaded when the
  // app loaded it first: inlined, or from the file esbuild emitted.
  const inline = importFrom === 'polyscene/inline';
  return `import init, { detect } from "${importFrom}";
${initArg ? `import wasmUrl from "polyscene/polyscene_bg.wasm";\nimport simWasmUrl from "polyscene/polyscene_sim_bg.wasm";\nimport initSim from "polyscene/sim";` : ''}
${inline ? `import initSim from "polyscene/sim/inline";` : ''}
${worker ? `import { PolysceneClient } from "polyscene/worker";` : ''}
import { plane, summary } from "./plane.mjs";
const out = {};
try {
  await init(${initArg});
  ${initArg ? 'await initSim({ module_or_path: simWasmUrl });' : inline ? 'await initSim();' : ''}
  out.direct = summary(detect(plane(), { stride: 3 }));
  const readme = await import("./readme-browser.mjs");
  out.readme = readme.result;
  ${
    worker
      ? `const client = new PolysceneClient();
  const early = client.detect(plane(), { stride: 3 });     // sent before the wasm is loaded
  out.defaults = Object.keys((await client.ready).defaults.gpp2).length;
  out.early = summary(await early);
  const controller = new AbortController();
  const first = client.worker;
  let started = 0;
  const big = new Float32Array(3 * 400_000).map((_, k) => (k % 3 === 2 ? 0 : Math.sin(k * 12.9898) * 40));
  try {
    await client.detect(big, { stride: 3 }, { signal: controller.signal, onProgress: (p) => { started = p.points; controller.abort(); } });
    out.aborted = "resolved";
  } catch (e) {
    out.aborted = e.name;
  }
  out.started = started;
  out.replaced = client.worker !== first;
  out.after = summary(await client.detect(plane(), { stride: 3 }));
  client.terminate();
  const w = await import("./readme-worker.mjs");
  out.readmeWorker = w.result;`
      : ''
  }
} catch (e) {
  out.error = String((e && e.stack) || e);
}
window.__results = out;
`;
}

function writeBrowserSources(dir) {
  fs.mkdirSync(dir, { recursive: true });
  fs.copyFileSync(path.join(app, 'plane.mjs'), path.join(dir, 'plane.mjs'));
  fs.writeFileSync(
    path.join(dir, 'readme-browser.mjs'),
    `${example(path.join(ROOT, 'README.md'), 'browser')}
export const result = { polygons: polygons.length, triangles: mesh.indices.length / 3 };`,
  );
  fs.writeFileSync(
    path.join(dir, 'readme-worker.mjs'),
    `${example(path.join(ROOT, 'README.md'), 'worker')}
export const result = { polygons: summary(polygons) };
import { summary } from "./plane.mjs";`,
  );
}

function checkBrowser({ results, logs }, where, { worker }) {
  assert.equal(results.error, undefined, `${where}: ${results.error}`);
  assertPlane(results.direct, `${where}, detect`);
  assert.ok(results.readme.polygons > 10 && results.readme.triangles > results.readme.polygons, `${where}, README page example: ${JSON.stringify(results.readme)}`);
  if (!worker) return;
  assert.ok(results.defaults > 20, `${where}: ready handshake with the option defaults`);
  assertPlane(results.early, `${where}, worker, sent before ready`);
  assert.equal(results.aborted, 'AbortError', `${where}: the aborted call rejects with the signal's reason`);
  assert.equal(results.started, 400_000, `${where}: progress 'started' with the point count`);
  assert.equal(results.replaced, true, `${where}: the busy worker was replaced`);
  assertPlane(results.after, `${where}, worker after an abort`);
  assertPlane(results.readmeWorker.polygons, `${where}, README worker example`);
  for (let k = 0; k <= 9; k++) {
    assert.ok(logs.some((l) => new RegExp(`^scan ${k}: [1-9]\\d* polygons$`).test(l)), `${where}: README worker example logged scan ${k}: ${logs.join(' | ')}`);
  }
  assert.ok(logs.includes('detect started: 6161 of 6161 points left'), `${where}: README worker example's progress: ${logs.join(' | ')}`);
  assert.ok(logs.some((l) => /^detect round: \d+ of 6161 points left$/.test(l)), `${where}: README worker example's progress after a round: ${logs.join(' | ')}`);
}

test('Vite: a production build with no config; in Chromium: detect, the README examples, the worker with its handshake and abort', async () => {
  const dir = path.join(app, 'vite-app');
  writeBrowserSources(dir);
  fs.writeFileSync(path.join(dir, 'main.mjs'), browserApp({ importFrom: 'polyscene', worker: true }));
  fs.writeFileSync(path.join(dir, 'index.html'), '<!doctype html><meta charset="utf-8"><script type="module" src="./main.mjs"></script>');
  fs.mkdirSync(path.join(dir, 'public'));
  fs.writeFileSync(path.join(dir, 'public/cloud.bin'), Buffer.from((await import(pathToFileURL(path.join(dir, 'plane.mjs')).href)).plane().buffer));
  const r = run(path.join(TOOLS, 'vite'), ['build', '--logLevel', 'warn', '--outDir', 'dist', '--emptyOutDir'], { cwd: dir });
  assert.doesNotMatch(r.stdout + r.stderr, /Duplicate member|warn/i, 'Vite builds without warnings');
  checkBrowser(await inChromium(path.join(dir, 'dist'), { waitLog: /^scan 9: / }), 'Vite', { worker: true });
});

test("Vite's dev server, no config: the same app in Chromium", async () => {
  const dir = path.join(app, 'vite-app'); // written by the build test above
  const port = await new Promise((resolve) => {
    const probe = net.createServer().listen(0, '127.0.0.1', () => {
      const { port: p } = probe.address();
      probe.close(() => resolve(p));
    });
  });
  const dev = spawn(path.join(TOOLS, 'vite'), ['--port', String(port), '--strictPort', '--host', '127.0.0.1'], {
    cwd: dir,
    stdio: ['ignore', 'pipe', 'pipe'],
    env: PLAIN,
  });
  let output = '';
  dev.stdout.on('data', (d) => (output += d));
  dev.stderr.on('data', (d) => (output += d));
  try {
    // Vite may still colour its banner (the port in bold) when the CI sets
    // FORCE_COLOR, so escape sequences are dropped before looking for it.
    const plain = () => output.replace(/\x1b\[[0-9;]*m/g, '');
    for (const t0 = Date.now(); !plain().includes(`:${port}/`); ) {
      assert.ok(Date.now() - t0 < 30_000 && dev.exitCode === null, `vite dev did not start: ${output}`);
      await new Promise((r) => setTimeout(r, 100));
    }
    checkBrowser(await inChromium(null, { url: `http://127.0.0.1:${port}/`, waitLog: /^scan 9: / }), 'Vite dev', { worker: true });
  } finally {
    dev.kill();
  }
});

test('esbuild: polyscene/inline with no config, and polyscene with --loader:.wasm=file; in Chromium', async () => {
  const dir = path.join(app, 'esbuild-app');
  writeBrowserSources(dir);
  const esbuild = path.join(TOOLS, 'esbuild');
  const html = '<!doctype html><meta charset="utf-8"><script type="module" src="./main.js"></script>';
  // Zero config: the inlined wasm (polyscene/inline, polyscene/sim/inline).
  // (The README example's "polyscene" and "polyscene/sim" are the same module
  // instances, so their init() finds the wasm loaded.)
  fs.writeFileSync(path.join(dir, 'main.mjs'), browserApp({ importFrom: 'polyscene/inline', worker: false }));
  let r = run(esbuild, ['main.mjs', '--bundle', '--format=esm', '--splitting', '--outdir=dist-inline'], { cwd: dir });
  assert.doesNotMatch(r.stderr, /warning|Duplicate member/i, `esbuild (inline) warned: ${r.stderr}`);
  fs.writeFileSync(path.join(dir, 'dist-inline/index.html'), html);
  checkBrowser(await inChromium(path.join(dir, 'dist-inline')), 'esbuild inline', { worker: false });
  // The wasm as a file, with one loader flag.
  fs.writeFileSync(path.join(dir, 'main.mjs'), browserApp({ importFrom: 'polyscene', initArg: '{ module_or_path: wasmUrl }', worker: false }));
  r = run(esbuild, ['main.mjs', '--bundle', '--format=esm', '--splitting', '--loader:.wasm=file', '--outdir=dist'], { cwd: dir });
  assert.doesNotMatch(r.stderr, /warning|Duplicate member/i, `esbuild warned: ${r.stderr}`);
  fs.writeFileSync(path.join(dir, 'dist/index.html'), html);
  assert.ok(fs.readdirSync(path.join(dir, 'dist')).some((f) => f.endsWith('.wasm')), 'esbuild emitted the wasm');
  checkBrowser(await inChromium(path.join(dir, 'dist')), 'esbuild', { worker: false });
});
