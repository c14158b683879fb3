#!/usr/bin/env node
// Benchmark of the wasm build (pkg/node) against the native build, on demand
// (not part of `make test`):
//   1. a 100-scan simulated street drive (seed 1, gpp2): median per-scan
//      `addScan` time in wasm vs the native CLI replay of the same scans;
//   2. one-shot `detect` on both real scans bundled in www/data (stride 4).
// Both sides time the same thing: the core's own clock (`timeMs.total` of
// each scan report, `timeMs` of the CLI's detect output); wasm wall time
// (JS call included: copying the points in, the report out) is shown too.
//
//   scripts/build-wasm.sh && cargo build --release --bin polyscene
//   node benches/wasm_bench.mjs [--scans N] [--repeat R]
import { createRequire } from "node:module";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..");
const arg = (name, def) => {
  const i = process.argv.indexOf(`--${name}`);
  return i > 0 ? Number(process.argv[i + 1]) : def;
};
const SCANS = arg("scans", 100);
const REPEAT = arg("repeat", 3);

const ps = createRequire(import.meta.url)(path.join(root, "pkg/node"));
const psSim = createRequire(import.meta.url)(path.join(root, "pkg/node/polyscene_sim.js"));
const bin = path.join(process.env.CARGO_TARGET_DIR ?? path.join(root, "target"), "release", "polyscene");
if (!fs.existsSync(bin)) {
  console.error(`${bin} is missing: cargo build --release --bin polyscene`);
  process.exit(1);
}
const cli = (...args) => execFileSync(bin, args, { encoding: "utf8", maxBuffer: 1 << 28 });
const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  const n = s.length;
  return n % 2 ? s[(n - 1) / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
};
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "polyscene-bench-"));
process.on("exit", () => fs.rmSync(tmp, { recursive: true, force: true }));

// 1. The drive. Scans are simulated before timing.
const sim = psSim.simulate({ layout: "street", seed: 1 });
const scans = Array.from({ length: SCANS }, (_, k) => sim.scan(k));
sim.free();
// The drive is replayed REPEAT times from a fresh scenario, as the native
// CLI is below, and each side takes per scan its fastest run: the same rule
// for both (the first wasm run also pays for V8's tier-up from baseline to
// optimised code).
const wasmCoreRuns = [];
const wasmWallRuns = [];
let counts;
for (let r = 0; r < REPEAT; r++) {
  const scenario = new ps.Scenario({ preset: "gpp2" });
  const core = [];
  const wall = [];
  const runCounts = [];
  for (const { points, pose } of scans) {
    const t0 = performance.now();
    const rep = scenario.addScan(points, { stride: 4, pose });
    wall.push(performance.now() - t0);
    core.push(rep.timeMs.total);
    runCounts.push(rep.polygonCount);
  }
  scenario.free();
  if (counts && JSON.stringify(counts) !== JSON.stringify(runCounts)) {
    console.error("wasm replays differ between runs: not deterministic");
    process.exit(1);
  }
  counts = runCounts;
  wasmCoreRuns.push(core);
  wasmWallRuns.push(wall);
}
const fastest = (runs) => runs[0].map((_, k) => Math.min(...runs.map((run) => run[k])));
const wasmCore = fastest(wasmCoreRuns);
const wasmWall = fastest(wasmWallRuns);

const drive = path.join(tmp, "drive");
cli("simulate", "street", "--seed", "1", "--scans", String(SCANS), "--out", drive);
const nativeRuns = [];
let nativeCounts;
for (let r = 0; r < REPEAT; r++) {
  const report = path.join(tmp, "replay.jsonl");
  cli("replay", drive, "--report", report, "--out", path.join(tmp, "replay.json"));
  const lines = fs.readFileSync(report, "utf8").split("\n").filter(Boolean).map((l) => JSON.parse(l));
  nativeRuns.push(lines.map((l) => l.timeMs.total));
  nativeCounts = lines.map((l) => l.polygonCount);
}
// Per scan, the fastest of the native runs (least disturbed), then the median.
const nativeCore = fastest(nativeRuns);
const same = JSON.stringify(counts) === JSON.stringify(nativeCounts);

// 2. One-shot detection on the real scans.
const detectRows = [];
for (const file of ["ouster_os1_64_legacy_f12073.bin", "ouster_os0_128_single_scan_016.bin"]) {
  const p = path.resolve(root, "www/data", file);
  if (!fs.existsSync(p)) {
    console.error(`missing ${p}`);
    process.exit(1);
  }
  const bytes = fs.readFileSync(p);
  const points = new Float32Array(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength));
  const wall = [];
  let found;
  for (let r = 0; r < REPEAT; r++) {
    const t0 = performance.now();
    found = ps.detect(points, { stride: 4 });
    wall.push(performance.now() - t0);
  }
  const native = [];
  let nativeFound;
  for (let r = 0; r < REPEAT; r++) {
    const doc = JSON.parse(cli("detect", p, "--stride", "4"));
    native.push(doc.timeMs);
    nativeFound = doc.polygons.length;
  }
  detectRows.push({ file, n: points.length / 4, wasm: median(wall), native: median(native), polygons: found.length, nativeFound });
}

// The table.
const f = (x) => x.toFixed(1).padStart(8);
const cpu = os.cpus();
console.log(`\npolyscene wasm benchmark: ${cpu[0]?.model ?? "unknown CPU"} (${cpu.length} logical cores), Node ${process.version}, ${os.platform()} ${os.arch()}`);
const size = path.join(root, "pkg/wasm-size.txt");
if (fs.existsSync(size)) console.log(fs.readFileSync(size, "utf8").trim());
console.log("");
console.log("| workload | wasm (ms) | native (ms) | wasm / native |");
console.log("| --- | ---: | ---: | ---: |");
const mw = median(wasmCore);
const mn = median(nativeCore);
console.log(`| addScan, street drive, median of ${SCANS} scans (core clock) | ${f(mw)} | ${f(mn)} | ${(mw / mn).toFixed(2)}x |`);
console.log(`| addScan, same, wasm wall time incl. the JS call | ${f(median(wasmWall))} | ${f(mn)} | ${(median(wasmWall) / mn).toFixed(2)}x |`);
const tw = wasmCore.reduce((a, b) => a + b, 0);
const tn = nativeCore.reduce((a, b) => a + b, 0);
console.log(`| addScan, same, total of ${SCANS} scans | ${f(tw)} | ${f(tn)} | ${(tw / tn).toFixed(2)}x |`);
for (const r of detectRows) {
  console.log(`| detect, ${r.file} (${r.n} points, ${r.polygons} polygons) | ${f(r.wasm)} | ${f(r.native)} | ${(r.wasm / r.native).toFixed(2)}x |`);
}
console.log("");
console.log(`same polygon counts per scan, wasm and native: ${same ? "yes" : "NO"}`);
for (const r of detectRows) {
  if (r.polygons !== r.nativeFound) console.log(`detect ${r.file}: wasm ${r.polygons} polygons, native ${r.nativeFound}`);
}
console.log(`(drive: per scan the fastest of ${REPEAT} replays, wasm and native alike, then the median; detect: median of ${REPEAT} runs each)`);
