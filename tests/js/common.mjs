// Shared helpers of the Node tests of the JS package (pkg/node, CommonJS).
import { createRequire } from "node:module";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";

export const repoRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../..");
// The real scans ship with the page (www/data, with their licences), so a
// fresh clone has them.
export const dataDir = path.resolve(repoRoot, "www/data");

const pkgDir = path.join(repoRoot, "pkg/node");
if (!fs.existsSync(path.join(pkgDir, "polyscene_bg.wasm"))) {
  throw new Error(`${pkgDir} is missing: build it with scripts/build-wasm.sh (or make build)`);
}
/** The package under test. */
export const ps = createRequire(import.meta.url)(pkgDir);
/** The simulator's module of the package (polyscene/sim: a wasm of its own). */
export const psSim = createRequire(import.meta.url)(path.join(pkgDir, "polyscene_sim.js"));

/** The native CLI (built by scripts/test-js.sh with cargo build --release). */
export function cli(...args) {
  const target = process.env.CARGO_TARGET_DIR ?? path.join(repoRoot, "target");
  const bin = path.join(target, "release", "polyscene");
  if (!fs.existsSync(bin)) {
    throw new Error(`${bin} is missing: build it with cargo build --release --bin polyscene`);
  }
  return execFileSync(bin, args, { encoding: "utf8", maxBuffer: 1 << 28 });
}

/** A fresh temporary directory, removed when the process exits. */
export function tempDir(name) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), `polyscene-${name}-`));
  process.on("exit", () => fs.rmSync(dir, { recursive: true, force: true }));
  return dir;
}

/** A real scan of www/data (little-endian f32, stride 4), or a clear failure. */
export function realScan(file) {
  const p = path.join(dataDir, file);
  if (!fs.existsSync(p)) {
    throw new Error(`real scan ${p} is missing: the tests read the scans bundled in www/data`);
  }
  const bytes = fs.readFileSync(p);
  return new Float32Array(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength));
}

/** Read a KITTI poses.txt into column-major Float64Array(16)s. */
export function readPoses(file) {
  return fs
    .readFileSync(file, "utf8")
    .split("\n")
    .filter((l) => l.trim())
    .map((line) => {
      const r = line.trim().split(/\s+/).map(Number); // row-major 3x4
      return Float64Array.from([r[0], r[4], r[8], 0, r[1], r[5], r[9], 0, r[2], r[6], r[10], 0, r[3], r[7], r[11], 1]);
    });
}

/** Assert that `fn` throws a plain `Error` (not a wasm trap) whose message matches every pattern. */
export function throwsError(assert, fn, ...patterns) {
  let caught;
  try {
    fn();
  } catch (e) {
    caught = e;
  }
  assert.ok(caught, `expected an Error matching ${patterns.join(", ")}; nothing was thrown`);
  assert.ok(caught instanceof Error, `expected an Error, got ${caught}`);
  assert.ok(!(caught instanceof WebAssembly.RuntimeError), `the instance trapped: ${caught.message}`);
  for (const p of patterns) {
    assert.match(caught.message, p);
  }
  return caught;
}

/** Polygon area (m^2) of interleaved 3D vertices. */
export function polygonArea(v, normal) {
  let sx = 0, sy = 0, sz = 0;
  const n = v.length / 3;
  for (let i = 0; i < n; i++) {
    const j = (i + 1) % n;
    const [ax, ay, az] = [v[3 * i], v[3 * i + 1], v[3 * i + 2]];
    const [bx, by, bz] = [v[3 * j], v[3 * j + 1], v[3 * j + 2]];
    sx += ay * bz - az * by;
    sy += az * bx - ax * bz;
    sz += ax * by - ay * bx;
  }
  return 0.5 * (sx * normal[0] + sy * normal[1] + sz * normal[2]);
}

/** A flat grid of points: `n` x `n` with spacing `step` on z = `z` (stride 3). */
export function floor(n = 100, step = 0.1, z = 0) {
  const pts = new Float32Array(n * n * 3);
  let k = 0;
  for (let i = 0; i < n; i++) {
    for (let j = 0; j < n; j++) {
      pts[k++] = i * step;
      pts[k++] = j * step;
      pts[k++] = z;
    }
  }
  return pts;
}
