// End-to-end test of the map dashboard (www/map.html) and of loading a
// snapshot in the main page, in headless Chromium (as tests/e2e/page.test.mjs:
// its own loopback server, a fresh profile, every request off the loopback
// refused and reported).
//
// The known corner: a snapshot made here with the Node package (pkg/node)
// after 5 scans of the simulated drive; its largest ground polygon's vertex
// farthest from the origin, in world metres, is placed by hand (WGS84 radii
// of curvature at the origin, not polyscene/geo) at a lon/lat, which the
// map's source data must hold to 1 cm (a heading 0.02 degrees off fails),
// and the map must draw that polygon under the screen point it projects an
// interior point of the polygon to.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { mkdtempSync, mkdirSync, rmSync, writeFileSync, existsSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { CHROMIUM, FLAGS } from './chromium.mjs';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const WWW = path.join(ROOT, 'www');
const OUT = path.join(ROOT, 'target/e2e');
const require = createRequire(path.join(WWW, 'package.json'));
const { chromium } = require('playwright-core');
const { startServer } = await import(pathToFileURL(path.join(WWW, 'tools/static-server.mjs')).href);
const ps = createRequire(import.meta.url)(path.join(ROOT, 'pkg/node'));
const psSim = createRequire(import.meta.url)(path.join(ROOT, 'pkg/node/polyscene_sim.js'));

const VIEW = { width: 1280, height: 800 };

// The frame of the test: an origin and a heading that is not 90 (x not east).
const ORIGIN = { lat: 45.5, lon: 7.25, alt: 300 };
const HEADING = 60;

// WGS84 by hand.
const A = 6378137.0;
const F = 1 / 298.257223563;
const E2 = F * (2 - F);
const RAD = Math.PI / 180;

/** World metres (x along the heading, y to its left) to lon/lat, by hand: good to millimetres within a few hundred metres. */
function lonLatByHand(x, y) {
  const phi = ORIGIN.lat * RAD;
  const w = 1 - E2 * Math.sin(phi) ** 2;
  const m = (A * (1 - E2)) / w ** 1.5 + ORIGIN.alt; // meridian radius at the origin's height
  const nc = (A / Math.sqrt(w) + ORIGIN.alt) * Math.cos(phi); // radius of the parallel
  const h = HEADING * RAD;
  const east = x * Math.sin(h) - y * Math.cos(h);
  const north = x * Math.cos(h) + y * Math.sin(h);
  const delta = (east * east) / (2 * nc); // the tangent plane leaves the parallel outwards
  return [ORIGIN.lon + Math.atan(east / nc) / RAD, ORIGIN.lat + (Math.atan(north / m) - (delta * Math.sin(phi)) / m) / RAD];
}

/** Metres between two lon/lat points near the origin. */
function metresApart([lo1, la1], [lo2, la2]) {
  const phi = ORIGIN.lat * RAD;
  return Math.hypot((lo2 - lo1) * RAD * A * Math.cos(phi), (la2 - la1) * RAD * A);
}

let server;
let context;
let scratch;
let snapshotFile;
let known; // { id, corner: [x, y, z], inside: [x, y, z], count }
const pageErrors = [];
const offLoopback = [];

before(async () => {
  assert.ok(existsSync(CHROMIUM), `no browser at ${CHROMIUM}: run scripts/setup.sh browser`);
  assert.ok(existsSync(path.join(WWW, 'pkg/polyscene.js')), 'www/pkg is missing: run scripts/build-wasm.sh');
  assert.ok(existsSync(path.join(WWW, 'node_modules/maplibre-gl/dist/maplibre-gl.mjs')), 'www/node_modules/maplibre-gl is missing: run scripts/setup.sh npm');
  mkdirSync(OUT, { recursive: true });
  scratch = mkdtempSync(path.join(os.tmpdir(), 'polyscene-map-e2e-'));

  // The snapshot and its known polygon, from the Node package.
  const sim = psSim.simulate({ seed: 1 });
  const s = new ps.Scenario({ preset: 'gpp2' });
  for (let k = 0; k < 5; k++) {
    const scan = sim.scan(k);
    s.addScan(scan.points, { stride: 4, pose: scan.pose });
  }
  const polygons = s.polygons();
  const ground = polygons.filter((p) => p.ground).sort((a, b) => b.area - a.area)[0];
  assert.ok(ground && ground.area > 50, 'a large ground polygon in the snapshot');
  // An interior point: the centroid of the polygon's largest triangle.
  const mesh = s.mesh();
  let best = null;
  for (let t = 0; t < mesh.polygonIds.length; t++) {
    if (mesh.polygonIds[t] !== ground.id) continue;
    const v = [0, 1, 2].map((k) => {
      const i = mesh.indices[3 * t + k];
      return [0, 1, 2].map((a) => mesh.origin[a] + mesh.positions[3 * i + a]);
    });
    const area = Math.abs((v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1])) / 2;
    if (!best || area > best.area) best = { area, c: [0, 1, 2].map((a) => (v[0][a] + v[1][a] + v[2][a]) / 3) };
  }
  // Its corner farthest from the origin: the most sensitive to a wrong heading.
  let far = 0;
  for (let i = 0; i < ground.vertices.length; i += 3) {
    if (Math.hypot(ground.vertices[i], ground.vertices[i + 1]) > Math.hypot(ground.vertices[far], ground.vertices[far + 1])) far = i;
  }
  known = { id: ground.id, vertex: far / 3, corner: [...ground.vertices.subarray(far, far + 3)], inside: best.c, count: polygons.length };
  snapshotFile = path.join(scratch, 'drive-snapshot.json');
  writeFileSync(snapshotFile, s.toJSONString());
  s.free();
  sim.free();

  server = await startServer({ root: WWW, port: 0, host: '127.0.0.1', mounts: { '/js/': path.join(ROOT, 'js') } });
  context = await chromium.launchPersistentContext(path.join(scratch, 'profile'), {
    executablePath: CHROMIUM,
    headless: true,
    args: FLAGS,
    viewport: VIEW,
    timeout: 30_000,
  });
  context.setDefaultTimeout(30_000);
  await context.route(
    (url) => !(url.origin === new URL(server.url).origin || url.protocol === 'data:' || url.protocol === 'blob:'),
    (route) => {
      offLoopback.push(route.request().url());
      return route.abort();
    },
  );
  context.on('page', (p) => p.on('pageerror', (e) => pageErrors.push(`${p.url()}: ${e.message}`)));
});

after(async () => {
  await context?.close().catch(() => {});
  await server?.close();
  if (scratch) rmSync(scratch, { recursive: true, force: true });
});

const mapUrl = () => `${server.url}map.html?lat=${ORIGIN.lat}&lon=${ORIGIN.lon}&alt=${ORIGIN.alt}&heading=${HEADING}`;

test('the map page runs the simulated drive live: footprints, walls and the vehicle at the right lon/lat', { timeout: 120_000 }, async () => {
  const page = await context.newPage();
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(mapUrl(), { waitUntil: 'load' });
  await page.waitForFunction(() => window.polysceneMap?.state.mapReady && window.polysceneMap.state.scans >= 10, null, { timeout: 100_000 });
  const got = await page.evaluate(async () => {
    const { map, state } = window.polysceneMap;
    const vehicle = await map.getSource('vehicle').getData();
    const footprints = await map.getSource('footprints').getData();
    return {
      pose: state.poses.at(-1),
      vehicle: vehicle.geometry.coordinates,
      kinds: footprints.features.map((f) => f.properties.kind),
      walls: footprints.features.filter((f) => f.properties.kind === 'wall').map((f) => f.properties),
      mapError: state.mapError,
    };
  });
  assert.equal(got.mapError, null);
  assert.ok(got.kinds.filter((k) => k === 'ground').length >= 1, `kinds ${got.kinds}`);
  assert.ok(got.walls.length >= 2, `${got.walls.length} walls`);
  for (const w of got.walls) assert.ok(w.height > w.base && w.height < 40, `wall ${w.id}: base ${w.base}, height ${w.height}`);
  // The vehicle marker: the last pose's position, placed by hand.
  const d = metresApart(got.vehicle, lonLatByHand(got.pose[0], got.pose[1]));
  assert.ok(d < 0.01, `vehicle ${d} m off`);
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(OUT, 'map-live.png') });
  await page.close();
});

test('a snapshot on the map: the known ground corner at its lon/lat (1 cm), drawn where the map projects it', { timeout: 60_000 }, async () => {
  const page = await context.newPage();
  await page.goto(mapUrl(), { waitUntil: 'load' });
  await page.waitForFunction(() => window.polysceneMap?.state.mapReady, null, { timeout: 30_000 });
  await page.setInputFiles('#snapshot-input', snapshotFile);
  await page.waitForFunction(() => window.polysceneMap.state.restored, null, { timeout: 30_000 });
  await page.waitForFunction(() => window.polysceneMap.map.loaded() && !window.polysceneMap.map.isMoving(), null, { timeout: 15_000 });
  const expectedCorner = lonLatByHand(known.corner[0], known.corner[1]);
  const inside = lonLatByHand(known.inside[0], known.inside[1]);
  const got = await page.evaluate(
    async ({ id, vertex, inside }) => {
      const { map, state } = window.polysceneMap;
      const data = await map.getSource('footprints').getData();
      const f = data.features.find((x) => x.properties.id === id);
      await new Promise((r) => (map.loaded() ? r() : map.once('idle', r)));
      const p = map.project(inside);
      const c = map.getCanvas();
      const hits = map.queryRenderedFeatures([p.x, p.y], { layers: ['ground'] }).map((x) => x.properties.id);
      return { count: data.features.length, kind: f?.properties.kind, corner: f?.geometry.coordinates[0][vertex], point: [p.x, p.y], size: [c.clientWidth, c.clientHeight], hits, scans: state.scans };
    },
    { id: known.id, vertex: known.vertex, inside },
  );
  assert.equal(got.count, known.count, 'one feature per polygon of the snapshot');
  assert.equal(got.scans, 5);
  assert.equal(got.kind, 'ground');
  const d = metresApart(got.corner, expectedCorner);
  assert.ok(d < 0.01, `corner of polygon ${known.id}: ${got.corner} is ${d} m from ${expectedCorner}`);
  assert.ok(got.point[0] > 0 && got.point[1] > 0 && got.point[0] < got.size[0] && got.point[1] < got.size[1], `inside point on screen: ${got.point}`);
  assert.ok(got.hits.includes(known.id), `the map draws polygon ${known.id} at ${got.point}: hits ${got.hits}`);
  await page.screenshot({ path: path.join(OUT, 'map-snapshot.png') });
  await page.close();
});

test('a KITTI .bin on the map: polygons around the origin of the form; a bad file says so', { timeout: 60_000 }, async () => {
  const page = await context.newPage();
  await page.goto(mapUrl(), { waitUntil: 'load' });
  await page.waitForFunction(() => window.polysceneMap?.state.mapReady, null, { timeout: 30_000 });
  // A new origin through the form: the scan's sensor (world 0, 0, 0) is placed there.
  await page.fill('#f-lat', '-33.8688');
  await page.fill('#f-lon', '151.2093');
  await page.fill('#f-alt', '20');
  await page.fill('#f-heading', '0');
  await page.click('#frame-form button[type=submit]');
  await page.setInputFiles('#scan-input', path.join(WWW, 'data/ouster_os1_64_legacy_f12073.bin'));
  await page.waitForFunction(
    () => window.polysceneMap.state.source.includes('ouster_os1_64_legacy_f12073.bin') && window.polysceneMap.state.scans === 1,
    null,
    { timeout: 45_000 },
  );
  const got = await page.evaluate(async () => {
    const { map } = window.polysceneMap;
    const vehicle = await map.getSource('vehicle').getData();
    const footprints = await map.getSource('footprints').getData();
    return { vehicle: vehicle.geometry.coordinates, rings: footprints.features.map((f) => f.geometry.coordinates[0]) };
  });
  assert.ok(Math.abs(got.vehicle[0] - 151.2093) < 1e-9 && Math.abs(got.vehicle[1] + 33.8688) < 1e-9, `sensor at ${got.vehicle}`);
  assert.ok(got.rings.length > 3, `${got.rings.length} polygons`);
  for (const ring of got.rings) {
    for (const [lon, lat] of ring) assert.ok(Math.abs(lon - 151.2093) < 0.003 && Math.abs(lat + 33.8688) < 0.003, `${lon}, ${lat} is far from the origin`);
  }
  const bad = path.join(scratch, 'broken.bin');
  writeFileSync(bad, Buffer.alloc(16 * 10 + 4, 1));
  await page.setInputFiles('#scan-input', bad);
  await page.locator('.toast.error', { hasText: 'broken.bin' }).waitFor({ timeout: 10_000 });
  await page.close();
});

/** Latitude (degrees) on the central meridian of a transverse Mercator zone (k0 0.9996) at a northing: the meridian arc, by Simpson's rule and bisection. */
function latitudeOfNorthing(northing) {
  const M = (phi) => (A * (1 - E2)) / (1 - E2 * Math.sin(phi) ** 2) ** 1.5;
  const arc = (phi) => {
    const n = 2000;
    const h = phi / n;
    let s = M(0) + M(phi);
    for (let i = 1; i < n; i++) s += (i % 2 ? 4 : 2) * M(i * h);
    return (s * h) / 3;
  };
  let [lo, hi] = [0, Math.PI / 2];
  for (let k = 0; k < 60; k++) {
    const mid = (lo + hi) / 2;
    if (0.9996 * arc(mid) < northing) lo = mid;
    else hi = mid;
  }
  return lo / RAD;
}

test('a LAS with its CRS on the map (polyscene/io): the frame becomes EPSG:32632 and the floor lands at its UTM square; a bad LAS says so', { timeout: 60_000 }, async () => {
  const fx = await import(pathToFileURL(path.join(ROOT, 'tests/js/io-fixtures.mjs')).href);
  // A 10 m x 10 m floor from (500000, 4500000) in UTM zone 32N: easting 500000 is its central meridian, 9 degrees east.
  const pts = [];
  for (let i = 0; i <= 100; i++) for (let j = 0; j <= 100; j++) pts.push([i / 10, j / 10, 0]);
  const las = path.join(scratch, 'floor-utm32.las');
  writeFileSync(las, fx.las(pts, [500_000, 4_500_000, 50], { crs: { epsg: 32632 } }));
  const page = await context.newPage();
  await page.goto(mapUrl(), { waitUntil: 'load' });
  await page.waitForFunction(() => window.polysceneMap?.state.mapReady, null, { timeout: 30_000 });
  await page.setInputFiles('#scan-input', las);
  await page.waitForFunction(() => window.polysceneMap.state.source.includes('floor-utm32.las'), null, { timeout: 45_000 });
  const got = await page.evaluate(async () => {
    const { map, state } = window.polysceneMap;
    const footprints = await map.getSource('footprints').getData();
    return { source: state.source, crs: document.getElementById('f-crs').value, rings: footprints.features.map((f) => [f.properties.kind, f.geometry.coordinates[0]]) };
  });
  assert.match(got.source, /LAS · one-shot · placed by its CRS, EPSG:32632/);
  assert.equal(got.crs, 'EPSG:32632');
  assert.equal(got.rings.length, 1, JSON.stringify(got.rings));
  const [kind, ring] = got.rings[0];
  assert.equal(kind, 'ground');
  // Back to metres east and north of the square's corner (scale 0.9996 on the central meridian).
  const phi0 = latitudeOfNorthing(4_500_000);
  const w = 1 - E2 * Math.sin(phi0 * RAD) ** 2;
  const east = (lon) => (lon - 9) * RAD * (A / Math.sqrt(w)) * Math.cos(phi0 * RAD) * 0.9996;
  const north = (lat) => (lat - phi0) * RAD * ((A * (1 - E2)) / w ** 1.5) * 0.9996;
  const es = ring.map(([lon]) => east(lon));
  const ns = ring.map(([, lat]) => north(lat));
  const box = [Math.min(...es), Math.max(...es), Math.min(...ns), Math.max(...ns)];
  for (const [v, want] of box.map((v, k) => [v, [0, 10, 0, 10][k]])) assert.ok(Math.abs(v - want) < 0.3, `the floor spans ${box.map((b) => b.toFixed(3))} m, not 0..10 x 0..10`);
  await page.screenshot({ path: path.join(OUT, 'map-las.png') });
  const bad = path.join(scratch, 'cut.las');
  writeFileSync(bad, fx.las(pts, [500_000, 4_500_000, 50]).subarray(0, 100));
  await page.setInputFiles('#scan-input', bad);
  await page.locator('.toast.error', { hasText: 'cut.las: LAS header cut short' }).waitFor({ timeout: 10_000 });
  await page.close();
});

test('KITTI scans with camera poses and calib.txt on the map (polyscene/io): the vehicle at the LiDAR positions', { timeout: 60_000 }, async () => {
  const fx = await import(pathToFileURL(path.join(ROOT, 'tests/js/io-fixtures.mjs')).href);
  const sim = psSim.simulate({ layout: 'street', seed: 2 });
  const dir = path.join(scratch, 'kitti');
  mkdirSync(dir, { recursive: true });
  const tr = fx.calibTr();
  const files = [];
  const lidar = [];
  const lines = [];
  for (let k = 0; k < 3; k++) {
    const s = sim.scan(k * 4);
    const f = path.join(dir, `${String(k).padStart(6, '0')}.bin`);
    writeFileSync(f, new Uint8Array(s.points.buffer, s.points.byteOffset, s.points.byteLength));
    files.push(f);
    lidar.push([s.pose[12], s.pose[13]]);
    lines.push(fx.poseLine(fx.mat4Mul(fx.mat4Mul(tr, Float64Array.from(s.pose)), fx.mat4Inverse(tr))));
  }
  sim.free();
  writeFileSync(path.join(dir, '00.txt'), `${lines.join('\n')}\n`);
  writeFileSync(path.join(dir, 'calib.txt'), fx.CALIB_00);
  const page = await context.newPage();
  await page.goto(mapUrl(), { waitUntil: 'load' });
  await page.waitForFunction(() => window.polysceneMap?.state.mapReady, null, { timeout: 30_000 });
  await page.setInputFiles('#scan-input', [...files, path.join(dir, '00.txt'), path.join(dir, 'calib.txt')]);
  await page.waitForFunction(() => window.polysceneMap.state.source.includes('calib.txt') && window.polysceneMap.state.scans === 3, null, { timeout: 45_000 });
  const trail = await page.evaluate(async () => {
    const data = await window.polysceneMap.map.getSource('trail').getData();
    return data.geometry.coordinates;
  });
  assert.equal(trail.length, 3);
  trail.forEach((p, k) => {
    const d = metresApart(p, lonLatByHand(lidar[k][0], lidar[k][1]));
    assert.ok(d < 0.01, `scan ${k}: the vehicle is ${d} m from its LiDAR position`);
  });
  await page.close();
});

test('the main page links to the map and loads a snapshot', { timeout: 60_000 }, async () => {
  const page = await context.newPage();
  await page.goto(server.url, { waitUntil: 'load' });
  assert.equal(await page.getAttribute('#link-map', 'href'), './map.html');
  await page.waitForFunction(() => Number(document.getElementById('stat-scan').dataset.value) >= 1, null, { timeout: 30_000 });
  await page.setInputFiles('#snapshot-input', snapshotFile);
  await page.waitForFunction(
    (n) => document.getElementById('source-label').textContent.includes('drive-snapshot.json') && Number(document.getElementById('stat-polygons').dataset.value) === n,
    known.count,
    { timeout: 30_000 },
  );
  const latest = await page.evaluate(() => window.polyscene.app.latest.polygons.map((p) => p.id));
  assert.equal(latest.length, known.count);
  assert.ok(latest.includes(known.id));
  // A file that is not a snapshot says so, and the page keeps its polygons.
  const bad = path.join(scratch, 'not-a-snapshot.json');
  writeFileSync(bad, '{"hello": 1}');
  await page.setInputFiles('#snapshot-input', bad);
  await page.locator('#toasts .toast.error', { hasText: 'not-a-snapshot.json' }).waitFor({ timeout: 10_000 });
  assert.equal(Number(await page.getAttribute('#stat-polygons', 'data-value')), known.count);
  await page.screenshot({ path: path.join(OUT, 'main-snapshot.png') });
  await page.close();
});

test('map: no uncaught page errors and no request left the loopback', () => {
  assert.deepEqual(pageErrors, []);
  assert.deepEqual(offLoopback, []);
});
