// One-shot detection on real LiDAR scans and on synthetic scenes with known answers.
import { test } from "node:test";
import assert from "node:assert/strict";
import { ps, realScan, polygonArea, floor, throwsError } from "./common.mjs";

function checkPolygon(p, options = {}) {
  assert.equal(Math.hypot(...p.normal).toFixed(9), "1.000000000", "unit normal");
  assert.ok(p.vertices instanceof Float64Array);
  assert.equal(p.vertices.length % 3, 0);
  assert.ok(p.vertices.length >= 9);
  assert.ok(p.vertices.every(Number.isFinite));
  // Counter-clockwise seen from the normal side, with the reported area.
  const a = polygonArea(p.vertices, p.normal);
  assert.ok(Math.abs(a - p.area) < 1e-6 * p.area + 1e-9, `area ${a} vs ${p.area}`);
  assert.ok(p.area >= (options.minArea ?? 1.5));
  for (let i = 0; i < p.vertices.length; i += 3) {
    const d = p.normal[0] * p.vertices[i] + p.normal[1] * p.vertices[i + 1] + p.normal[2] * p.vertices[i + 2] + p.offset;
    assert.ok(Math.abs(d) < 1e-6, "vertices on the plane");
  }
  assert.ok(p.support >= 150);
  assert.ok(Math.abs(p.density - p.support / p.area) < 1e-9 * p.density);
  assert.equal(p.bornScan, 0);
  assert.equal(p.lastScan, 0);
  assert.equal(typeof p.ground, "boolean");
}

test("detect on the real Ouster OS1-64 scan (stride 4) finds polygons and the ground", { timeout: 120_000 }, () => {
  const points = realScan("ouster_os1_64_legacy_f12073.bin");
  assert.equal(points.length, 58_797 * 4);
  const found = ps.detect(points, { stride: 4 });
  assert.ok(found.length >= 5, `${found.length} polygons`);
  found.forEach((p) => checkPolygon(p));
  assert.deepEqual(found.map((p) => p.id), found.map((_, i) => i), "ids 0, 1, ...");
  const ground = found.filter((p) => p.ground);
  assert.ok(ground.length >= 1, "the road is found");
  assert.ok(ground.every((p) => p.normal[2] > 0.95), "the ground faces up");
  // Walls face the sensor at the origin.
  for (const p of found.filter((q) => Math.abs(q.normal[2]) < 0.3)) {
    assert.ok(p.offset > 0, `wall ${p.id} faces the sensor`);
  }
  // gpp1 keeps only large polygons.
  const large = ps.detect(points, { stride: 4, preset: "gpp1" });
  assert.ok(large.length >= 1 && large.length <= found.length);
  large.forEach((p) => checkPolygon(p, { minArea: 7 }));
});

test("detect: a floor seen from above is one polygon of the right size, facing up", () => {
  const found = ps.detect(floor(100, 0.1, 0), { viewpoint: [5, 5, 1.8] });
  assert.equal(found.length, 1);
  checkPolygon(found[0]);
  assert.ok(Math.abs(found[0].area - 99) < 3);
  assert.ok(found[0].ground);
  assert.ok(found[0].normal[2] > 0.999);
  // The same cloud 2 km away, stride 4: the same polygon, moved.
  const far = new Float32Array(100 * 100 * 4);
  const f = floor(100, 0.1, 0);
  for (let i = 0; i < 100 * 100; i++) {
    far[4 * i] = f[3 * i] + 1000;
    far[4 * i + 1] = f[3 * i + 1] - 2000;
    far[4 * i + 2] = 50;
  }
  const moved = ps.detect(far, { stride: 4, viewpoint: [1005, -1995, 51.8] });
  assert.equal(moved.length, 1);
  assert.ok(moved[0].ground);
  assert.ok(Math.abs(moved[0].area - found[0].area) < 0.5);
});

test("detect: degenerate clouds give empty results, not errors", () => {
  const cases = [
    new Float32Array(0),
    Float32Array.from([1, 2, 3]),
    new Float32Array(3000).fill(7), // 1000 copies of one point
    Float32Array.from({ length: 3000 }, (_, i) => (i % 3 === 0 ? i / 3 : 0)), // collinear
  ];
  for (const pts of cases) {
    assert.deepEqual(ps.detect(pts), []);
  }
});

test("detect: a map's sensor positions (viewpoints) drop a patch of laser rings at their height only", () => {
  // A 20 m x 20 m floor and a 3 m x 3 m patch 1.8 m above it, read as a map
  // (no sensor could have stood at the origin, on the floor's corner).
  const ground = floor(100, 0.2, 0);
  const patch = floor(30, 0.1, 1.8).map((v, i) => (i % 3 === 0 ? v + 12 : i % 3 === 1 ? v + 2 : v));
  const cloud = new Float32Array(ground.length + patch.length);
  cloud.set(ground);
  cloud.set(patch, ground.length);
  const patches = (found) => found.filter((p) => p.normal[2] > 0.999 && Math.abs(p.offset + 1.8) < 0.02).length;
  const level = Float64Array.of(2, 3, 1.8, 6, 15, 1.8);
  const dropped = ps.detect(cloud, { viewpoints: level });
  assert.equal(patches(dropped), 0);
  assert.ok(dropped.some((p) => p.ground), "the floor stays");
  // Seen from below by one of them, or as a map with no positions: kept.
  assert.equal(patches(ps.detect(cloud, { viewpoints: [2, 3, 1.8, 6, 15, 2.6] })), 1);
  assert.equal(patches(ps.detect(cloud)), 1);
  // detectFlat and detectWithProgress read them too.
  assert.equal(ps.detectFlat(cloud, { viewpoints: level }).ids.length, dropped.length);
  assert.equal(ps.detectWithProgress(cloud, { viewpoints: level }, () => {}).length, dropped.length);
  for (const [opts, ...patterns] of [
    [{ viewpoints: [1, 2] }, /option 'viewpoints'/, /flat list of x, y, z/, /2 values/],
    [{ viewpoints: [[1, 2, 3], [4, 5, 6]] }, /option 'viewpoints'/, /flat list/],
    [{ viewpoints: [1, 2, "3"] }, /option 'viewpoints'/, /element 2 is not a number/],
    [{ viewpoints: [1, NaN, 3] }, /option 'viewpoints'/, /position 0 is not finite/],
    [{ viewpoints: "here" }, /option 'viewpoints'/, /Float64Array/],
    [{ viewpoints: [1, 2, 3], viewpoint: [1, 2, 3] }, /option 'viewpoint'/, /one or the other/],
  ]) {
    throwsError(assert, () => ps.detect(cloud, opts), ...patterns);
  }
  throwsError(assert, () => new ps.Scenario({ viewpoints: [1, 2, 3] }), /viewpoints/);
  // A scenario takes each scan's sensor position from its pose.
  throwsError(assert, () => new ps.Scenario({ viewpoint: [1, 2, 3] }), /option 'viewpoint'/, /pose/);
  new ps.Scenario({ viewpoint: null }).free();
});
