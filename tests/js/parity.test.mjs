// The wasm build computes exactly what the native build computes: same
// simulated scans, same polygons bit for bit, same reports.
import { test } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { ps, psSim, cli, tempDir, readPoses, realScan, dataDir } from "./common.mjs";

const SCANS = 15;
const dir = tempDir("parity");
const drive = path.join(dir, "drive");
cli("simulate", "street", "--seed", "3", "--scans", String(SCANS), "--out", drive);
cli("replay", drive, "--out", path.join(dir, "ref.json"), "--report", path.join(dir, "ref.jsonl"));
const ref = JSON.parse(fs.readFileSync(path.join(dir, "ref.json"), "utf8"));
const refReports = fs
  .readFileSync(path.join(dir, "ref.jsonl"), "utf8")
  .split("\n")
  .filter((l) => l)
  .map((l) => JSON.parse(l));

function assertSamePolygons(got, want, what) {
  assert.equal(got.length, want.length, `${what}: polygon count`);
  assert.ok(want.length > 0, `${what}: the reference has polygons`);
  for (let i = 0; i < want.length; i++) {
    const [g, w] = [got[i], want[i]];
    const at = `${what}: polygon ${i} (id ${w.id})`;
    assert.equal(g.id, w.id, at);
    assert.equal(g.support, w.support, `${at} support`);
    assert.ok(Object.is(g.area, w.area), `${at} area ${g.area} != ${w.area}`);
    assert.ok(Object.is(g.offset, w.offset), `${at} offset`);
    assert.deepEqual(g.normal, w.normal, `${at} normal`);
    const flat = w.vertices.flat();
    assert.equal(g.vertices.length, flat.length, `${at} vertex count`);
    for (let k = 0; k < flat.length; k++) {
      assert.ok(Object.is(g.vertices[k], flat[k]), `${at} vertex number ${k}: ${g.vertices[k]} != ${flat[k]}`);
    }
  }
}

test("simulate() gives the native simulator's scans bit for bit", () => {
  const sim = psSim.simulate({ layout: "street", seed: 3 });
  const poses = readPoses(path.join(drive, "poses.txt"));
  assert.equal(poses.length, SCANS);
  for (let k = 0; k < SCANS; k++) {
    const s = sim.next();
    assert.equal(s.done, false);
    assert.equal(s.index, k);
    const name = String(k).padStart(6, "0");
    const bin = fs.readFileSync(path.join(drive, `${name}.bin`));
    const labels = fs.readFileSync(path.join(drive, `${name}.label`));
    assert.ok(Buffer.from(s.points.buffer).equals(bin), `scan ${k}: points differ`);
    assert.ok(Buffer.from(s.labels.buffer).equals(labels), `scan ${k}: labels differ`);
    assert.deepEqual(Array.from(s.pose), Array.from(poses[k]), `scan ${k}: pose differs`);
  }
  sim.free();
});

test("a simulated drive gives the native replay's polygons and reports exactly", () => {
  const sim = psSim.simulate({ layout: "street", seed: 3 });
  const scenario = new ps.Scenario(); // the CLI's defaults: gpp2, concave, seed 7
  for (let k = 0; k < SCANS; k++) {
    const { points, pose, stride } = sim.next();
    const report = scenario.addScan(points, { stride, pose });
    const { timeMs, ...rest } = report;
    const { timeMs: refTime, ...want } = refReports[k];
    assert.deepEqual(rest, want, `scan ${k}: report`);
    assert.deepEqual(Object.keys(timeMs).sort(), Object.keys(refTime).sort());
    assert.ok(timeMs.total > 0 && timeMs.total >= timeMs.detection, "the clock is installed");
  }
  assertSamePolygons(scenario.polygons(), ref.polygons, "replay");
  scenario.free();
  sim.free();
});

test("one-shot detect on a real Ouster scan equals the native CLI", { timeout: 120_000 }, () => {
  const file = "ouster_os1_64_legacy_f12073.bin";
  realScan(file); // a clear failure when the data is missing
  const out = path.join(dir, "detect.json");
  cli("detect", path.join(dataDir, file), "--stride", "4", "--out", out);
  const want = JSON.parse(fs.readFileSync(out, "utf8")).polygons;
  const got = ps.detect(realScan(file), { stride: 4 });
  assertSamePolygons(got, want, "detect");
});

test("one-shot detect of a map with its scans' positions (viewpoints) equals the native CLI's --viewpoints", { timeout: 120_000 }, () => {
  // Scans 5-14 of the simulated drive, moved to the world frame by their
  // poses (in f64, then float32 as the file holds them): a 1.2M-point map.
  const poses = readPoses(path.join(drive, "poses.txt"));
  const world = [];
  for (let k = 5; k < SCANS; k++) {
    const m = poses[k];
    const bin = fs.readFileSync(path.join(drive, `${String(k).padStart(6, "0")}.bin`));
    const pts = new Float32Array(bin.buffer, bin.byteOffset, bin.length / 4);
    for (let i = 0; i < pts.length; i += 4) {
      const [x, y, z] = [pts[i], pts[i + 1], pts[i + 2]];
      world.push(m[0] * x + m[4] * y + m[8] * z + m[12], m[1] * x + m[5] * y + m[9] * z + m[13], m[2] * x + m[6] * y + m[10] * z + m[14]);
    }
  }
  const cloud = Float32Array.from(world);
  const file = path.join(dir, "map.bin");
  fs.writeFileSync(file, Buffer.from(cloud.buffer));
  const positions = poses.slice(5, SCANS).flatMap((m) => [m[12], m[13], m[14]]);
  const out = path.join(dir, "map.json");
  cli("detect", file, "--stride", "3", "--viewpoints", positions.map(String).join(","), "--out", out);
  const want = JSON.parse(fs.readFileSync(out, "utf8")).polygons;
  const got = ps.detect(cloud, { viewpoints: positions });
  assertSamePolygons(got, want, "detect with viewpoints");
  // The positions drop polygons here (patches of rings at their height).
  assert.ok(ps.detect(cloud).length > got.length, "the positions change the result");
});
