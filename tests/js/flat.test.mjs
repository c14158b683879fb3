// Columnar polygons (polygonsFlat, detectFlat) against the object form.
import test from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { ps, psSim, repoRoot } from "./common.mjs";

/** The columns hold exactly what polygons() holds, row by row. */
function assertSame(flat, polygons) {
  const n = polygons.length;
  assert.equal(flat.ids.length, n);
  assert.equal(flat.ringOffsets.length, n + 1);
  assert.equal(flat.ringOffsets[0], 0);
  assert.equal(flat.normals.length, 3 * n);
  assert.equal(flat.areas.length, n);
  assert.equal(flat.kinds.length, n);
  assert.equal(flat.positions.length, 3 * flat.ringOffsets[n]);
  polygons.forEach((p, i) => {
    assert.equal(flat.ids[i], p.id);
    assert.equal(flat.areas[i], p.area);
    assert.deepEqual([...flat.normals.subarray(3 * i, 3 * i + 3)], p.normal);
    const ring = flat.positions.subarray(3 * flat.ringOffsets[i], 3 * flat.ringOffsets[i + 1]);
    assert.deepEqual([...ring], [...p.vertices], `polygon ${p.id}`);
    const wall = !p.ground && Math.abs(p.normal[2]) <= Math.sin((20 * Math.PI) / 180);
    assert.equal(flat.kinds[i], p.ground ? 0 : wall ? 1 : 2, `kind of polygon ${p.id}`);
  });
}

test("scenario.polygonsFlat() holds polygons() as typed columns", () => {
  const sim = psSim.simulate({ seed: 1 });
  const s = new ps.Scenario();
  for (let k = 0; k < 4; k++) {
    const scan = sim.scan(k);
    s.addScan(scan.points, { stride: 4, pose: scan.pose });
  }
  const flat = s.polygonsFlat();
  const polygons = s.polygons();
  assert.ok(polygons.length > 5, `${polygons.length} polygons`);
  const types = { positions: Float64Array, ringOffsets: Uint32Array, ids: Uint32Array, normals: Float64Array, areas: Float64Array, kinds: Uint8Array };
  assert.deepEqual(Object.keys(flat), Object.keys(types));
  for (const [k, T] of Object.entries(types)) assert.ok(flat[k] instanceof T, `${k} is a ${T.name}`);
  assertSame(flat, polygons);
  // A street has ground and walls.
  assert.ok(flat.kinds.includes(0) && flat.kinds.includes(1), `kinds ${[...new Set(flat.kinds)]}`);
  // Empty scenario: empty columns, one offset.
  const empty = new ps.Scenario();
  assert.deepEqual([...empty.polygonsFlat().ringOffsets], [0]);
  assert.equal(empty.polygonsFlat().positions.length, 0);
  for (const x of [s, sim, empty]) x.free();
  assert.throws(() => s.polygonsFlat(), /freed/);
});

test("detectFlat gives detect()'s polygons as columns, and detect()'s errors", () => {
  const sim = psSim.simulate({ seed: 2 });
  const scan = sim.scan(0);
  const options = { stride: 4 };
  assertSame(ps.detectFlat(scan.points, options), ps.detect(scan.points, options));
  assert.throws(() => ps.detectFlat(new Float32Array(7), { stride: 4 }), /stride|divisible/);
  assert.throws(() => ps.detectFlat(scan.points, { stride: 4, noSuchKey: 1 }), /noSuchKey/);
  sim.free();
});

test("the .d.ts declares FlatPolygons with the columns' types", () => {
  const dts = fs.readFileSync(path.join(repoRoot, "pkg/node/polyscene.d.ts"), "utf8");
  const start = dts.indexOf("export interface FlatPolygons ");
  assert.ok(start >= 0);
  const block = dts.slice(start, dts.indexOf("\n}", start));
  const keys = [...block.matchAll(/^\s+(\w+): ([^;]+);$/gm)].map((m) => `${m[1]}: ${m[2]}`);
  assert.deepEqual(keys, ["positions: Float64Array", "ringOffsets: Uint32Array", "ids: Uint32Array", "normals: Float64Array", "areas: Float64Array", "kinds: Uint8Array"]);
  assert.match(dts, /polygonsFlat\(\): FlatPolygons;/);
  // detectFlat takes what detect takes.
  const params = (name) => dts.match(new RegExp(`export function ${name}\\(([^)]*)\\)`))?.[1];
  assert.ok(params("detect"));
  assert.equal(params("detectFlat"), params("detect"));
});
