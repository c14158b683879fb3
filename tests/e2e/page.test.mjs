// End-to-end test of the demo page (www/) in headless Chromium.
//
//   node --test tests/e2e/          (scripts/test-e2e.sh builds what is missing first)
//
// Starts its own loopback server on a free port (always stopped at the end),
// opens the page in a fresh profile, and checks what a user would see: the
// simulated drive runs (>= 20 scans, plausible numbers), the WebGL canvas
// shows something, a polygon can be picked, a bundled real scan loads through
// the file input and gives polygons, corrupt files give a clear on-page
// message and the page keeps working. Screenshots go to target/e2e/.
// Every wait has a timeout; the whole file takes well under 3 minutes.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { mkdtempSync, mkdirSync, rmSync, writeFileSync, readFileSync, existsSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { decodePng } from './png.mjs';
import { CHROMIUM, FLAGS } from './chromium.mjs';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const WWW = path.join(ROOT, 'www');
const OUT = path.join(ROOT, 'target/e2e');
const require = createRequire(path.join(WWW, 'package.json'));
const { chromium } = require('playwright-core');
const { startServer } = await import(pathToFileURL(path.join(WWW, 'tools/static-server.mjs')).href);

const VIEW = { width: 1280, height: 800 };
const BG = [0x0b, 0x0f, 0x16]; // the page's clear colour

let server;
let context;
let page;
let profile;
let scratch;
const pageErrors = [];
const offLoopback = [];

const stat = (id) => page.evaluate((i) => Number(document.getElementById(i).dataset.value), id);
const text = (sel) => page.evaluate((s) => document.querySelector(s)?.textContent ?? '', sel);

before(async () => {
  assert.ok(existsSync(CHROMIUM), `no browser at ${CHROMIUM}: run scripts/setup.sh browser`);
  assert.ok(existsSync(path.join(WWW, 'pkg/polyscene.js')), 'www/pkg is missing: run scripts/build-wasm.sh');
  mkdirSync(OUT, { recursive: true });
  scratch = mkdtempSync(path.join(os.tmpdir(), 'polyscene-e2e-'));
  profile = path.join(scratch, 'profile');
  server = await startServer({ root: WWW, port: 0, host: '127.0.0.1', mounts: { '/js/': path.join(ROOT, 'js') } });
  context = await chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM,
    headless: true,
    args: FLAGS,
    viewport: VIEW,
    acceptDownloads: true,
    timeout: 30_000,
  });
  context.setDefaultTimeout(30_000);
  // Loopback only: anything else is refused and reported.
  await context.route(
    (url) => !(url.origin === new URL(server.url).origin || url.protocol === 'data:' || url.protocol === 'blob:'),
    (route) => {
      offLoopback.push(route.request().url());
      return route.abort();
    },
  );
  page = context.pages()[0] ?? (await context.newPage());
  page.on('pageerror', (e) => pageErrors.push(e.message));
});

after(async () => {
  await context?.close().catch(() => {});
  await server?.close();
  if (scratch) rmSync(scratch, { recursive: true, force: true });
});

test('the simulated drive runs in the worker and shows plausible numbers', { timeout: 90_000 }, async () => {
  await page.goto(server.url, { waitUntil: 'load' });
  await page.waitForFunction(() => Number(document.getElementById('stat-scan').dataset.value) >= 20, null, { timeout: 75_000 });
  const polygons = await stat('stat-polygons');
  const ms = await stat('stat-time');
  const pps = await stat('stat-pps');
  const share = await stat('stat-expansion');
  assert.ok(polygons > 5, `polygons shown: ${polygons}`);
  assert.ok(ms > 0 && ms < 10_000, `ms per scan shown: ${ms}`);
  assert.match(await text('#stat-time'), /^\d+(\.\d+)?$/);
  assert.ok(pps > 1000, `points per second: ${pps}`);
  assert.ok(share > 0 && share <= 1, `share explained by expansion: ${share}`);
  assert.match(await text('#stats'), /polygons/);
  assert.match(await text('#source-label'), /simulated/i);
  for (const id of ['chart-polygons-value', 'chart-detect-value', 'chart-area-value', 'chart-time-value']) {
    assert.notEqual(await text(`#${id}`), '–', `${id} is empty`);
  }
  await page.screenshot({ path: path.join(OUT, 'simulated.png') });
});

test('the WebGL canvas shows the scan and the polygons', { timeout: 30_000 }, async () => {
  // The middle of the view, away from the panels.
  const clip = { x: 320, y: 90, width: 640, height: 560 };
  const png = decodePng(await page.screenshot({ clip }));
  let lit = 0;
  const hues = new Set();
  for (let i = 0; i < png.data.length; i += png.channels) {
    const r = png.data[i];
    const g = png.data[i + 1];
    const b = png.data[i + 2];
    const diff = Math.abs(r - BG[0]) + Math.abs(g - BG[1]) + Math.abs(b - BG[2]);
    if (diff > 90) {
      lit++;
      const max = Math.max(r, g, b);
      const min = Math.min(r, g, b);
      if (max - min > 40) {
        // coarse hue bucket of a saturated pixel
        const h = max === r ? (g - b) / (max - min) : max === g ? 2 + (b - r) / (max - min) : 4 + (r - g) / (max - min);
        hues.add(Math.round(((h + 6) % 6) * 4));
      }
    }
  }
  const share = lit / (png.width * png.height);
  assert.ok(share > 0.03, `only ${(share * 100).toFixed(2)} % of the view is drawn`);
  assert.ok(hues.size >= 6, `only ${hues.size} hues drawn: the polygons' colours are missing`);
});

test('clicking a polygon shows its id, area, normal and scans', { timeout: 30_000 }, async () => {
  // Pause, so the polygons stay put.
  if (await page.evaluate(() => document.body.classList.contains('playing'))) await page.click('#btn-play');
  await page.waitForFunction(() => !document.body.classList.contains('playing'), null, { timeout: 5_000 });
  await page.waitForTimeout(400);
  const targets = await page.evaluate(() => {
    const { view, latest } = window.polyscene.app;
    const r = view.renderer.domElement.getBoundingClientRect();
    const out = [];
    for (const p of [...latest.polygons].sort((a, b) => b.area - a.area)) {
      const m = p.vertices.length / 3;
      const c = [0, 0, 0];
      for (let i = 0; i < m; i++) for (let a = 0; a < 3; a++) c[a] += p.vertices[i * 3 + a] / m;
      const v = view.camera.position.clone().set(c[0] - view.origin[0], c[1] - view.origin[1], c[2] - view.origin[2]).project(view.camera);
      if (Math.abs(v.x) < 0.45 && Math.abs(v.y) < 0.6 && v.z < 1) out.push({ x: ((v.x + 1) / 2) * r.width, y: ((1 - v.y) / 2) * r.height });
    }
    return out.slice(0, 8);
  });
  assert.ok(targets.length > 0, 'no polygon in view to click');
  let shown = false;
  for (const t of targets) {
    await page.mouse.click(t.x, t.y);
    shown = await page
      .waitForSelector('#pick:not([hidden])', { timeout: 1_500 })
      .then(() => true)
      .catch(() => false);
    if (shown) break;
  }
  assert.ok(shown, 'no polygon details after clicking on polygons');
  const card = await text('#pick');
  for (const word of ['area', 'normal', 'support', 'born at scan', 'last grown at scan']) assert.ok(card.includes(word), `'${word}' missing in: ${card}`);
  assert.match(await text('#pick-id'), /^#\d+$/);
  await page.screenshot({ path: path.join(OUT, 'picked.png') });
  await page.click('#pick-close', { timeout: 5_000 }); // not covered by another panel
  await page.waitForSelector('#pick', { state: 'hidden', timeout: 5_000 });
});

test('a bundled real scan loads through the file input and gives polygons', { timeout: 60_000 }, async () => {
  const file = path.join(WWW, 'data/ouster_os1_64_legacy_f12073.bin');
  await page.setInputFiles('#file-input', file);
  await page.waitForFunction(
    () =>
      document.getElementById('source-label').textContent.includes('ouster_os1_64_legacy_f12073.bin') &&
      Number(document.getElementById('stat-scan').dataset.value) === 1,
    null,
    { timeout: 45_000 },
  );
  const polygons = await stat('stat-polygons');
  assert.ok(polygons > 3, `polygons from the real scan: ${polygons}`);
  assert.ok((await stat('stat-time')) > 0);
  await page.waitForTimeout(500);
  await page.screenshot({ path: path.join(OUT, 'real-scan.png') });
});

test('corrupt and unsupported files give a clear message; the page keeps working', { timeout: 90_000 }, async () => {
  const bad = path.join(scratch, 'broken_scan.bin');
  writeFileSync(bad, Buffer.alloc(16 * 100 + 8, 1)); // not a multiple of 16 bytes
  const pcd = path.join(scratch, 'garbage.pcd');
  writeFileSync(pcd, Buffer.from('this is not a point cloud\n\x00\x01\x02\x03 at all\n'));
  const txt = path.join(scratch, 'notes.xyz');
  writeFileSync(txt, '1 2 3\n');
  const polygonsBefore = await stat('stat-polygons');

  const expectToast = async (needle, also) => {
    const el = page.locator('#toasts .toast.error', { hasText: needle }).last();
    await el.waitFor({ state: 'visible', timeout: 10_000 });
    const msg = await el.textContent();
    if (also) assert.match(msg, also);
    return msg;
  };
  await page.setInputFiles('#file-input', bad);
  await expectToast('broken_scan.bin', /whole number of KITTI points/);
  await page.screenshot({ path: path.join(OUT, 'error-message.png') });
  await page.setInputFiles('#file-input', pcd);
  await expectToast('garbage.pcd', /PCD/);
  await page.setInputFiles('#file-input', txt);
  await expectToast('notes.xyz', /unsupported/);

  // The run that was there is untouched.
  assert.match(await text('#source-label'), /ouster_os1_64_legacy_f12073\.bin/);
  assert.equal(await stat('stat-polygons'), polygonsBefore);

  // And the page still works: another real scan, then back to the simulated drive.
  await page.setInputFiles('#file-input', path.join(WWW, 'data/ouster_os0_128_single_scan_016.bin'));
  await page.waitForFunction(
    () =>
      document.getElementById('source-label').textContent.includes('ouster_os0_128_single_scan_016.bin') &&
      Number(document.getElementById('stat-scan').dataset.value) === 1 &&
      Number(document.getElementById('stat-polygons').dataset.value) > 3,
    null,
    { timeout: 45_000 },
  );
  const source = page.locator('.lil-gui .lil-controller', { hasText: 'source' }).locator('select');
  await source.selectOption({ label: 'Simulated HDL-64E drive' }); // a new source plays at once
  await page.waitForFunction(
    () => /simulated/i.test(document.getElementById('source-label').textContent) && Number(document.getElementById('stat-scan').dataset.value) >= 3,
    null,
    { timeout: 30_000 },
  );
  assert.ok((await stat('stat-polygons')) > 0);
  await page.screenshot({ path: path.join(OUT, 'after-errors.png') });
});

test('a KITTI sequence with poses.txt runs as a scenario in name order', { timeout: 60_000 }, async () => {
  // Three scans (the same real scan, driven 0.25 m forward each time, the
  // spacing of a real sequence at 2.5 m/s) named out of order.
  const dir = path.join(scratch, 'seq');
  mkdirSync(dir);
  const scan = readFileSync(path.join(WWW, 'data/ouster_os1_64_legacy_f12073.bin'));
  const names = ['000002.bin', '000000.bin', '000001.bin'];
  for (const n of names) writeFileSync(path.join(dir, n), scan);
  const pose = (i) => `1 0 0 ${0.25 * i} 0 1 0 0 0 0 1 0`;
  writeFileSync(path.join(dir, 'short_poses.txt'), `${pose(0)}\n${pose(1)}\n`);
  writeFileSync(path.join(dir, 'poses.txt'), `${pose(0)}\n${pose(1)}\n${pose(2)}\n`);

  await page.setInputFiles('#file-input', [...names.map((n) => path.join(dir, n)), path.join(dir, 'short_poses.txt')]);
  await page.locator('#toasts .toast.error', { hasText: '2 poses for 3 scans' }).waitFor({ timeout: 10_000 });

  await page.setInputFiles('#file-input', [...names.map((n) => path.join(dir, n)), path.join(dir, 'poses.txt')]);
  await page.waitForFunction(
    () => /3 scans · 000000\.bin … 000002\.bin · with poses/.test(document.getElementById('source-label').textContent) && Number(document.getElementById('stat-scan').dataset.value) === 3,
    null,
    { timeout: 45_000 },
  );
  assert.ok((await stat('stat-polygons')) > 3);
  // Scans 2 and 3 repeat scan 1 0.25 m further along x: the ground and the
  // facades along x still fit, so expansion takes most of what detection
  // explained in scan 1 (planes across x moved by 0.25-0.5 m do not fit).
  const reports = await page.evaluate(() => window.polyscene.app.reports);
  assert.deepEqual(reports.map((r) => r.scan), [0, 1, 2]);
  const first = reports[0].explainedByDetection;
  assert.ok(first > 0.2 * reports[0].points, `scan 1: detection explained ${first} of ${reports[0].points}`);
  for (const r of reports.slice(1)) {
    assert.ok(r.explainedByExpansion > 0.75 * first, `scan ${r.scan + 1}: expansion ${r.explainedByExpansion}, scan 1 detection ${first}`);
  }
  const trail = await page.evaluate(() => window.polyscene.app.view.trailCount);
  assert.equal(trail, 3);
});

test('exports: JSON, GeoJSON (with a geographic origin), glTF and OBJ', { timeout: 60_000 }, async () => {
  const polygons = await stat('stat-polygons');
  const gui = page.locator('.lil-gui.lil-root');
  const folder = async (name) => {
    const title = gui.locator('.lil-title', { hasText: name }).first();
    if ((await title.getAttribute('aria-expanded')) === 'false') await title.click();
  };
  await folder('Export');
  const save = async (label) => {
    const [dl] = await Promise.all([page.waitForEvent('download', { timeout: 15_000 }), gui.locator('button', { hasText: label }).click()]);
    const file = path.join(OUT, dl.suggestedFilename());
    await dl.saveAs(file);
    return readFileSync(file);
  };
  const json = JSON.parse(await save('polygons · JSON'));
  assert.equal(json.polygons.length, polygons);
  assert.ok(json.polygons.every((p) => p.vertices.length >= 3 && p.area > 0 && p.normal.length === 3));

  const local = JSON.parse(await save('polygons · GeoJSON'));
  assert.equal(local.type, 'FeatureCollection');
  assert.equal(local.features.length, polygons);
  assert.match(local.polyscene.coordinates, /local metres/);

  await folder('Geographic origin');
  await gui.locator('.lil-controller', { hasText: 'use origin' }).locator('input').check();
  const geo = JSON.parse(await save('polygons · GeoJSON'));
  for (const f of geo.features) {
    assert.equal(f.geometry.type, 'Polygon');
    const ring = f.geometry.coordinates[0];
    assert.deepEqual(ring[0], ring[ring.length - 1]);
    for (const [lon, lat] of ring) {
      assert.ok(Math.abs(lon - 8.4037) < 0.01 && Math.abs(lat - 49.0069) < 0.01, `${lon}, ${lat} is not near the origin`);
    }
    for (const k of ['id', 'kind', 'area', 'normal', 'ground']) assert.ok(k in f.properties, `property ${k}`);
  }

  const glb = await save('glTF');
  assert.equal(glb.toString('latin1', 0, 4), 'glTF');
  const obj = (await save('OBJ')).toString();
  assert.match(obj, /^o polygon-\d+/m);
  assert.match(obj, /^f \d+/m);
});

test('no uncaught page errors and no request left the loopback', () => {
  assert.deepEqual(pageErrors, []);
  assert.deepEqual(offLoopback, []);
});
