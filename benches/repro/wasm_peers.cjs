#!/usr/bin/env node
// The Node side of the reproduction report (scripts/repro.sh): in ONE Node
// process, on the same clouds as the native runs,
//   1. polyscene's wasm build (pkg/node): one-shot `detect` with gpp1 and gpp2;
//   2. pcl.js 1.16.0 (PCL 1.13 compiled to wasm): a plain RANSAC loop of 15
//      planes (SACSegmentation, SACMODEL_PLANE, SAC_RANSAC, 0.10 m, 1000
//      iterations, coefficients optimised), removing each plane's inliers.
// Rounds are interleaved (one run of every method per round) so the noise of
// the shared machine hits every method alike.
//
//   node benches/repro/wasm_peers.cjs MANIFEST_DIR RESULTS_DIR
//        [--repeat-sim N] [--repeat-real N] [--pcljs-repeat-sim N]
//        [--pcljs-repeat-real N] [--no-wasm] [--no-pcljs] [--clouds A,B]
//
// Writes RESULTS_DIR/wasm_CLOUD_PRESET.json (polygons), RESULTS_DIR/
// pcljs_CLOUD.json + .labels (planes and per-point plane index, for the
// evaluation) and RESULTS_DIR/node_times.json.
"use strict";
const fs = require("node:fs");
const path = require("node:path");
const { createRequire } = require("node:module");

const root = path.resolve(__dirname, "../..");
const [manifestDir, outDir] = process.argv.slice(2);
if (!manifestDir || !outDir) {
  console.error("usage: wasm_peers.cjs MANIFEST_DIR RESULTS_DIR [options]");
  process.exit(2);
}
const opt = (name, def) => {
  const i = process.argv.indexOf(`--${name}`);
  return i > 0 ? process.argv[i + 1] : def;
};
const flag = (name) => process.argv.includes(`--${name}`);
const REP_SIM = Number(opt("repeat-sim", 3));
const REP_REAL = Number(opt("repeat-real", 5));
const PCL_REP_SIM = Number(opt("pcljs-repeat-sim", 1));
const PCL_REP_REAL = Number(opt("pcljs-repeat-real", 3));
// gpp2 on the real scans once more per RANSAC seed 1..SEEDS: how long the
// cascade runs depends on the seed.
const SEEDS = Number(opt("seeds", 12));
const PLANES = 15;
const only = opt("clouds", null)?.split(",");
fs.mkdirSync(outDir, { recursive: true });
const log = (...a) => console.error(...a);
const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  const n = s.length;
  return n === 0 ? null : n % 2 ? s[(n - 1) / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
};

// --- the two libraries ------------------------------------------------------
let ps = null;
let psWhy = "";
if (!flag("no-wasm")) {
  try {
    ps = require(path.join(root, "pkg/node"));
  } catch (e) {
    psWhy = `pkg/node cannot be loaded (${e.message.split("\n")[0]}); run scripts/build-wasm.sh`;
  }
} else psWhy = "disabled (--no-wasm)";
let pcl = null;
let pclWhy = "";
let pclVersion = null;
if (!flag("no-pcljs")) {
  try {
    // Resolve from benches/repro so that the package's "node" export is used.
    const req = createRequire(path.join(__dirname, "package.json"));
    pcl = req("pcl.js");
    pclVersion = JSON.parse(fs.readFileSync(path.join(__dirname, "node_modules/pcl.js/package.json"), "utf8")).version;
  } catch (e) {
    pclWhy = `pcl.js is not installed in benches/repro/node_modules (${e.message.split("\n")[0]}); scripts/setup-peers.sh pcljs installs it`;
    pcl = null;
  }
} else pclWhy = "disabled (--no-pcljs)";

function readCloud(c) {
  const buf = fs.readFileSync(c.bin);
  // Copy to an aligned buffer.
  const f = new Float32Array(buf.length / 4);
  new Uint8Array(f.buffer).set(buf);
  return f;
}

function pcdOf(f, idx) {
  const n = idx.length;
  const head = Buffer.from(
    `VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH ${n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS ${n}\nDATA binary\n`,
  );
  const body = new Float32Array(3 * n);
  for (let k = 0; k < n; k++) {
    const i = idx[k];
    body[3 * k] = f[4 * i];
    body[3 * k + 1] = f[4 * i + 1];
    body[3 * k + 2] = f[4 * i + 2];
  }
  const all = new Uint8Array(head.length + body.byteLength);
  all.set(head, 0);
  all.set(new Uint8Array(body.buffer), head.length);
  return all.buffer;
}

// A plain RANSAC loop of PLANES planes. Returns the time spent in segment()
// (the RANSAC itself) and the whole loop's wall time (segment plus taking the
// inliers out: rebuilding the remaining cloud from JS, since pcl.js has no
// ExtractIndices), the planes and a per-point label.
function pclLoop(f) {
  const n = f.length / 4;
  let remaining = Int32Array.from({ length: n }, (_, i) => i);
  const labels = new Uint32Array(n).fill(0xffffffff);
  const planes = [];
  let segMs = 0;
  const t0 = performance.now();
  for (let k = 0; k < PLANES && remaining.length >= 3; k++) {
    const cloud = pcl.loadPCDData(pcdOf(f, remaining), pcl.PointXYZ);
    const seg = new pcl.SACSegmentation();
    seg.setOptimizeCoefficients(true);
    seg.setModelType(pcl.SacModelTypes.SACMODEL_PLANE);
    seg.setMethodType(pcl.SacMethodTypes.SAC_RANSAC);
    seg.setDistanceThreshold(0.1);
    seg.setMaxIterations(1000);
    seg.setInputCloud(cloud);
    const inliers = new pcl.PointIndices();
    const coeffs = new pcl.ModelCoefficients();
    const ts = performance.now();
    seg.segment(inliers, coeffs);
    segMs += performance.now() - ts;
    // PointIndices.indices is a copy taken at construction: read a fresh one.
    const idx = new pcl.PointIndices(inliers._native).indices.data;
    const c = coeffs.values.data;
    if (idx.length < 3 || c.length !== 4) break;
    const taken = new Uint8Array(remaining.length);
    for (const j of idx) {
      taken[j] = 1;
      labels[remaining[j]] = planes.length;
    }
    planes.push({ normal: [c[0], c[1], c[2]], offset: c[3], inliers: idx.length });
    remaining = remaining.filter((_, j) => !taken[j]);
    try {
      cloud.manager?.delete?.();
    } catch {}
  }
  return { segMs, loopMs: performance.now() - t0, planes, labels };
}

(async () => {
  const manifest = JSON.parse(fs.readFileSync(path.join(manifestDir, "manifest.json"), "utf8"));
  if (pcl) {
    try {
      await pcl.init();
    } catch (e) {
      pclWhy = `pcl.js init failed: ${e.message}`;
      pcl = null;
    }
  }
  const out = {
    node: process.version,
    wasm: ps ? { available: true, version: ps.version?.() } : { available: false, why: psWhy },
    pcljs: pcl ? { available: true, version: pclVersion, planes: PLANES } : { available: false, why: pclWhy, version: pclVersion },
    results: [],
  };
  if (!ps) log(`node: wasm rows skipped: ${psWhy}`);
  if (!pcl) log(`node: pcl.js rows skipped: ${pclWhy}`);
  for (const c of manifest.clouds) {
    if (only && !only.includes(c.name)) continue;
    const f = readCloud(c);
    const sim = c.kind === "sim";
    const reps = sim ? REP_SIM : REP_REAL;
    const pclReps = sim ? PCL_REP_SIM : PCL_REP_REAL;
    const wasm = { gpp1: [], gpp2: [] };
    const last = {};
    const pclRuns = [];
    let pclLast = null;
    const rounds = Math.max(ps ? reps : 0, pcl ? pclReps : 0);
    for (let r = 0; r < rounds; r++) {
      if (ps && r < reps) {
        for (const preset of ["gpp1", "gpp2"]) {
          const t = performance.now();
          const polys = ps.detect(f, { preset, stride: 4, viewpoint: c.viewpoint });
          const ms = performance.now() - t;
          wasm[preset].push(ms);
          last[preset] = polys;
          log(`  wasm   ${c.name.padEnd(8)} ${preset.padEnd(12)} run ${r + 1}/${reps}: ${ms.toFixed(1).padStart(8)} ms, ${polys.length} polygons`);
        }
      }
      if (pcl && r < pclReps) {
        const res = pclLoop(f);
        pclRuns.push({ segMs: res.segMs, loopMs: res.loopMs });
        pclLast = res;
        log(`  pcl.js ${c.name.padEnd(8)} ${"15 planes".padEnd(12)} run ${r + 1}/${pclReps}: ${res.segMs.toFixed(1).padStart(8)} ms in segment(), ${res.loopMs.toFixed(1)} ms loop`);
      }
    }
    const entry = { cloud: c.name, points: f.length / 4 };
    if (ps && !sim && SEEDS > 0) {
      const timesMs = [];
      const polygons = [];
      for (let seed = 1; seed <= SEEDS; seed++) {
        const t = performance.now();
        const n = ps.detect(f, { preset: "gpp2", stride: 4, viewpoint: c.viewpoint, seed }).length;
        timesMs.push(performance.now() - t);
        polygons.push(n);
      }
      entry.wasm_gpp2_seeds = { seeds: SEEDS, timesMs, medianMs: median(timesMs), polygons };
      log(`  wasm   ${c.name.padEnd(8)} gpp2 seeds 1-${SEEDS}: median ${median(timesMs).toFixed(1)} ms (${Math.min(...timesMs).toFixed(1)}-${Math.max(...timesMs).toFixed(1)})`);
    }
    if (ps) {
      for (const preset of ["gpp1", "gpp2"]) {
        const polygons = last[preset].map((p) => {
          const v = p.vertices;
          const verts = [];
          for (let i = 0; i < v.length; i += 3) verts.push([v[i], v[i + 1], v[i + 2]]);
          return { id: p.id, normal: p.normal, offset: p.offset, vertices: verts, area: p.area, support: p.support, ground: p.ground };
        });
        fs.writeFileSync(path.join(outDir, `wasm_${c.name}_${preset}.json`), JSON.stringify({ polygons }));
        entry[`wasm_${preset}`] = { timesMs: wasm[preset], medianMs: median(wasm[preset]), polygons: polygons.length };
      }
    }
    if (pcl && pclLast) {
      fs.writeFileSync(path.join(outDir, `pcljs_${c.name}.labels`), Buffer.from(pclLast.labels.buffer));
      fs.writeFileSync(
        path.join(outDir, `pcljs_${c.name}.json`),
        JSON.stringify({ planes: pclLast.planes, labels: `pcljs_${c.name}.labels` }),
      );
      entry.pcljs = {
        segMs: pclRuns.map((r) => r.segMs),
        loopMs: pclRuns.map((r) => r.loopMs),
        medianSegMs: median(pclRuns.map((r) => r.segMs)),
        medianLoopMs: median(pclRuns.map((r) => r.loopMs)),
        planes: pclLast.planes.length,
        inliers: pclLast.planes.reduce((s, p) => s + p.inliers, 0),
      };
    }
    out.results.push(entry);
    fs.writeFileSync(path.join(outDir, "node_times.json"), JSON.stringify(out, null, 1));
  }
  fs.writeFileSync(path.join(outDir, "node_times.json"), JSON.stringify(out, null, 1));
})().catch((e) => {
  console.error(`node: ${e.stack || e}`);
  process.exit(1);
});
