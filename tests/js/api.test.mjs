// The shape of the API: the objects it returns, the simulator, the labels,
// the documentation of the options, the web build without a window.
import { test } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { Worker } from "node:worker_threads";
import { ps, psSim, repoRoot } from "./common.mjs";
import { optionDocs, documentedDefault, sameValue, optionsTable } from "../../scripts/gen-js-docs.mjs";

const POLYGON_KEYS = ["id", "normal", "offset", "vertices", "area", "support", "density", "ground", "bornScan", "lastScan"];
const REPORT_KEYS = ["scan", "points", "alignment", "explainedByExpansion", "sentToDetection", "explainedByDetection", "poolToDetection", "explainedFromPool", "poolPoints", "added", "grown", "merged", "polygonCount", "totalArea", "timeMs"];

test("exports: the simulator in its own module (polyscene/sim), not in the main one", () => {
  for (const name of ["Scenario", "detect", "detectFlat", "detectWithProgress", "defaultOptions", "version"]) {
    assert.ok(name in ps, name);
  }
  for (const name of ["Simulation", "ScanIterator", "simulate"]) {
    assert.ok(!(name in ps), `${name} is not in the main module`);
    assert.ok(name in psSim, `${name} is in polyscene_sim`);
  }
  assert.deepEqual(Object.keys(psSim).sort(), ["ScanIterator", "Simulation", "simulate", "version"]);
  for (const m of [ps, psSim]) assert.ok(!("start" in m), "the start function is private");
  assert.equal(ps.version(), JSON.parse(JSON.stringify(ps.version())));
  assert.match(ps.version(), /^\d+\.\d+\.\d+/);
  assert.equal(psSim.version(), ps.version());
});

test("a simulated scan is JS-owned: it outlives its Simulation and goes into the main module's Scenario (two wasm instances)", () => {
  const sim = psSim.simulate({ layout: "crossing", seed: 4 });
  const scan = sim.scan(3);
  const copy = { points: scan.points.slice(), pose: scan.pose.slice(), labels: scan.labels.slice() };
  sim.free();
  // More simulation in the simulator's memory, detection in the other's.
  const other = psSim.simulate({ layout: "street", seed: 9 });
  for (let k = 0; k < 3; k++) other.next();
  other.free();
  assert.deepEqual(scan.points, copy.points, "points unchanged");
  assert.deepEqual(scan.pose, copy.pose, "pose unchanged");
  assert.deepEqual(scan.labels, copy.labels, "labels unchanged");
  const [a, b] = [new ps.Scenario({ seed: 3 }), new ps.Scenario({ seed: 3 })];
  const ra = a.addScan(scan.points, { stride: scan.stride, pose: scan.pose });
  const rb = b.addScan(copy.points, { stride: 4, pose: copy.pose });
  assert.ok(ra.polygonCount > 5, `${ra.polygonCount} polygons`);
  assert.deepEqual(a.polygons(), b.polygons(), "the same polygons as from a copy");
  assert.equal(ra.polygonCount, rb.polygonCount);
  a.free();
  b.free();
});

test("reports, polygons and labels of a street drive", () => {
  const sim = psSim.simulate({ layout: "street", seed: 1 });
  const scenario = new ps.Scenario({ preset: "gpp2", hull: "concave", seed: 7 });
  assert.equal(scenario.scans, 0);
  assert.deepEqual(scenario.lastLabels(), new Uint32Array(0));
  let report;
  for (let k = 0; k < 3; k++) {
    const { points, pose, stride } = sim.next();
    report = scenario.addScan(points, { stride, pose });
    assert.deepEqual(Object.keys(report), REPORT_KEYS);
    assert.deepEqual(Object.keys(report.timeMs).sort(), ["alignment", "detection", "expansion", "merge", "total"]);
    assert.equal(report.scan, k);
    assert.equal(report.points, points.length / 4);
    assert.equal(report.explainedByExpansion + report.sentToDetection, report.points);
    assert.ok(report.explainedByDetection <= report.sentToDetection);
    // The pool holds earlier scans' unexplained points: none at the first scan.
    if (k === 0) assert.equal(report.poolToDetection + report.explainedFromPool, 0);
    assert.ok(report.poolPoints > 0 && report.poolPoints <= 100000);
    for (const m of report.merged) assert.deepEqual(Object.keys(m), ["kept", "removed"]);
    const labels = scenario.lastLabels();
    assert.ok(labels instanceof Uint32Array);
    assert.equal(labels.length, report.points);
    const ids = new Set(scenario.polygons().map((p) => p.id));
    let explained = 0;
    for (const l of labels) {
      if (l !== 0xffffffff) {
        assert.ok(ids.has(l), `label ${l} is a polygon id`);
        explained++;
      }
    }
    // Points taken by expansion keep their label; detection labels its support.
    assert.equal(explained, report.explainedByExpansion + report.explainedByDetection, "labelled = expansion + detection");
    assert.ok(explained > 0.1 * labels.length, `${explained} of ${labels.length} points explained`);
  }
  assert.equal(scenario.scans, 3);
  const polygons = scenario.polygons();
  assert.equal(polygons.length, report.polygonCount);
  assert.equal(scenario.polygonCount, report.polygonCount);
  const total = polygons.reduce((a, p) => a + p.area, 0);
  assert.ok(Math.abs(total - report.totalArea) < 1e-6 * total);
  for (const p of polygons) {
    assert.deepEqual(Object.keys(p), POLYGON_KEYS);
    assert.ok(Array.isArray(p.normal) && p.normal.length === 3);
    assert.ok(p.vertices instanceof Float64Array);
    assert.ok(p.bornScan <= p.lastScan && p.lastScan <= 2);
  }
  assert.deepEqual(polygons.map((p) => p.id), [...polygons.map((p) => p.id)].sort((a, b) => a - b), "sorted by id");
  // Results are plain JS data: JSON-safe and independent of the scenario.
  scenario.free();
  assert.ok(JSON.stringify(polygons).length > 100);
  assert.ok(polygons[0].vertices.length > 0);
  sim.free();
});

test("simulate: next(), scan(k), iteration, reset, ground truth, origin", () => {
  const sim = psSim.simulate({ layout: "street", seed: 2, step: 10 });
  assert.equal(sim.layout, "street");
  assert.equal(sim.seed, 2);
  assert.ok(sim.length >= 15 && sim.length <= 30, `${sim.length} scans`);
  assert.equal(sim.cursor, 0);
  const first = sim.next();
  assert.equal(first.done, false);
  assert.equal(first.index, 0);
  assert.equal(first.stride, 4);
  assert.ok(first.points instanceof Float32Array && first.points.length > 400_000);
  assert.ok(first.pose instanceof Float64Array && first.pose.length === 16);
  assert.deepEqual([first.pose[3], first.pose[7], first.pose[11], first.pose[15]], [0, 0, 0, 1], "column-major");
  assert.ok(Math.abs(first.pose[14] - 1.8) < 0.5, "translation in elements 12..14 (sensor height)");
  assert.ok(first.labels instanceof Uint32Array && first.labels.length === first.points.length / 4);
  assert.equal(sim.cursor, 1);
  // Random access does not move the cursor and gives the same data.
  const again = sim.scan(0);
  assert.deepEqual(again.points, first.points);
  assert.deepEqual(again.pose, first.pose);
  assert.equal(sim.cursor, 1);
  // The iterator protocol runs through the remaining scans.
  const indices = [];
  for (const scan of sim) indices.push(scan.index);
  assert.deepEqual(indices, Array.from({ length: sim.length - 1 }, (_, i) => i + 1));
  assert.deepEqual(sim.next(), { done: true });
  assert.equal(sim.cursor, sim.length);
  sim.reset();
  assert.equal(sim.next().index, 0);
  assert.equal([...sim].length, sim.length - 1);
  const it = sim[Symbol.iterator]();
  assert.equal(it[Symbol.iterator]().next().done, true);
  assert.deepEqual(it.next(), { value: undefined, done: true });
  // Ground truth.
  const gt = sim.groundTruth();
  assert.ok(gt.length > 100);
  const kinds = new Set(["road", "sidewalk", "curb", "facade", "door", "wall", "vehicle", "ramp"]);
  gt.forEach((g, i) => {
    assert.equal(g.id, i);
    assert.ok(kinds.has(g.kind), g.kind);
    assert.ok(g.area > 0 && g.vertices instanceof Float64Array && g.vertices.length >= 9);
  });
  assert.ok(gt.some((g) => g.kind === "road"));
  // Scene origin far away: the poses move, the sensor-frame points do not.
  const far = psSim.simulate({ layout: "street", seed: 2, step: 10, origin: [500_000, 4_500_000, 50] });
  const s0 = far.scan(0);
  assert.deepEqual(s0.points, first.points);
  assert.equal(s0.pose[12], first.pose[12] + 500_000);
  assert.equal(far.groundTruth()[0].vertices[1], gt[0].vertices[1] + 4_500_000);
  far.free();
  sim.free();
});

test("a Scenario far from the origin gives the same polygons, moved", () => {
  const near = psSim.simulate({ seed: 6 });
  const far = psSim.simulate({ seed: 6, origin: [500_000, 4_500_000, 50] });
  const [a, b] = [new ps.Scenario(), new ps.Scenario()];
  for (let k = 0; k < 3; k++) {
    const s = near.scan(k);
    a.addScan(s.points, { stride: 4, pose: s.pose });
    const t = far.scan(k);
    b.addScan(t.points, { stride: 4, pose: t.pose });
  }
  const [pa, pb] = [a.polygons(), b.polygons()];
  assert.equal(pb.length, pa.length);
  for (let i = 0; i < pa.length; i++) {
    assert.ok(Math.abs(pa[i].area - pb[i].area) < 0.05 * pa[i].area + 0.5, `polygon ${i}`);
  }
  const mb = b.mesh();
  assert.ok(Math.abs(mb.origin[0] - 500_000) < 1000 && Math.abs(mb.origin[1] - 4_500_000) < 1000);
  assert.ok(mb.positions.every((x) => Math.abs(x) < 1000), "positions are small, relative to the origin");
  for (const x of [a, b, near, far]) x.free();
});

test("the .d.ts interfaces have the objects' keys and typed arrays (both come from one Rust struct)", () => {
  const read = (name) => fs.readFileSync(path.join(repoRoot, `pkg/node/${name}.d.ts`), "utf8");
  const [main, simDts] = [read("polyscene"), read("polyscene_sim")];
  for (const name of ["SimulatedScan", "GroundTruthPolygon", "SimulateOptions", "SimulationStep"]) {
    assert.ok(!main.includes(` ${name} `), `${name} is not declared by the main module`);
  }
  const dts = `${main}\n${simDts}`;
  /** key -> type of `interface name` in the .d.ts. */
  const declared = (name) => {
    const start = dts.indexOf(`export interface ${name} `);
    assert.ok(start >= 0, `interface ${name} in the .d.ts`);
    const block = dts.slice(start, dts.indexOf("\n}", start));
    return new Map([...block.matchAll(/^\s+(\w+)\??: ([^;]+);$/gm)].map((m) => [m[1], m[2]]));
  };
  const check = (name, object) => {
    const keys = declared(name);
    assert.deepEqual(Object.keys(object), [...keys.keys()], `keys of ${name}`);
    for (const [key, type] of keys) {
      if (/^(Float32|Float64|Uint32)Array$/.test(type)) {
        assert.equal(object[key]?.constructor?.name, type, `${name}.${key}`);
      } else if (type === "number") {
        assert.equal(typeof object[key], "number", `${name}.${key}`);
      }
    }
  };
  const sim = psSim.simulate({ seed: 3 });
  const scan = sim.scan(0);
  check("SimulatedScan", scan);
  check("GroundTruthPolygon", sim.groundTruth()[0]);
  const s = new ps.Scenario();
  const report = s.addScan(scan.points, { stride: 4, pose: scan.pose });
  check("ScanReport", report);
  check("StageTimes", report.timeMs);
  check("Alignment", report.alignment);
  check("Polygon", s.polygons()[0]);
  check("Mesh", s.mesh());
  for (const m of report.merged) check("MergeEvent", m);
  for (const x of [s, sim]) x.free();
});

test("the .d.ts documents every option, with the preset's default", () => {
  const docs = optionDocs();
  const gpp2 = ps.defaultOptions("gpp2");
  const gpp1 = ps.defaultOptions("gpp1");
  assert.deepEqual([...docs.keys()].filter((k) => k !== "preset").sort(), Object.keys(gpp2).sort(), "every key, no other");
  const problems = [];
  for (const [key, value] of Object.entries(gpp2)) {
    const { doc } = docs.get(key);
    const stated = documentedDefault(doc);
    if (stated === undefined || !sameValue(stated, value)) {
      problems.push(`${key}: the doc says default ${stated}, gpp2 has ${JSON.stringify(value)}`);
    }
    if (JSON.stringify(gpp1[key]) !== JSON.stringify(value)) {
      const g = doc.match(/gpp1:?\s+([-+.\deE]+)/);
      if (!g || Number(g[1]) !== gpp1[key]) {
        problems.push(`${key}: the doc does not give gpp1's ${JSON.stringify(gpp1[key])}`);
      }
    }
  }
  assert.deepEqual(problems, [], "option docs in src/params/table.rs");
});

test("docs/API.md's options table is current (node scripts/gen-js-docs.mjs)", () => {
  const readme = fs.readFileSync(path.join(repoRoot, "docs/API.md"), "utf8");
  assert.ok(readme.includes(optionsTable()), "regenerate it with: node scripts/gen-js-docs.mjs");
});

test("the web build (ES modules, pkg/web) runs in a worker thread, without window; the simulator's scans go into the other wasm's Scenario", async () => {
  const file = (name) => path.join(repoRoot, "pkg/web", name);
  const workerData = {
    url: new URL(`file://${file("polyscene.js")}`).href,
    wasm: file("polyscene_bg.wasm"),
    simUrl: new URL(`file://${file("polyscene_sim.js")}`).href,
    simWasm: file("polyscene_sim_bg.wasm"),
  };
  const code = `
    import { parentPort, workerData } from "node:worker_threads";
    import fs from "node:fs";
    const { default: init, Scenario, detect } = await import(workerData.url);
    const { default: initSim, simulate } = await import(workerData.simUrl);
    await init({ module_or_path: fs.readFileSync(workerData.wasm) });
    await initSim({ module_or_path: fs.readFileSync(workerData.simWasm) });
    if (typeof window !== "undefined") throw new Error("window exists");
    const sim = simulate({ seed: 1 });
    const { points, pose } = sim.next();
    const s = new Scenario();
    const r = s.addScan(points, { stride: 4, pose });
    parentPort.postMessage({ count: r.polygonCount, total: r.timeMs.total, labels: s.lastLabels().length },
      );
  `;
  const result = await new Promise((resolve, reject) => {
    const w = new Worker(new URL(`data:text/javascript,${encodeURIComponent(code)}`), { workerData });
    w.once("message", resolve);
    w.once("error", reject);
  });
  assert.ok(result.count > 5, `${result.count} polygons`);
  assert.ok(result.total > 0, "performance.now() clock installed");
  assert.ok(result.labels > 100_000);
});
