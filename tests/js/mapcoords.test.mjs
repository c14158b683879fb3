// Map coordinates through the JS boundary: a Float64Array stays float64
// (re-centred in the core before anything becomes f32) and gives the
// polygons of the same points near the origin; a Float32Array that far
// out is refused with the fix in the message.
import { test } from "node:test";
import assert from "node:assert/strict";
import { ps, psSim, throwsError } from "./common.mjs";

const UTM = [500_000, 4_500_000, 50];

/** Scan 0 of the simulated street: sensor-frame Float32Array (stride 4) and its pose. */
function scan() {
  const sim = psSim.simulate({ layout: "street", seed: 1 });
  const s = sim.scan(0);
  sim.free();
  return s;
}

/** `points` (stride 4) moved by UTM, as a Float64Array. */
function moved(points) {
  const out = new Float64Array(points.length);
  for (let i = 0; i < points.length; i += 4) {
    for (let k = 0; k < 3; k++) out[i + k] = points[i + k] + UTM[k];
    out[i + 3] = points[i + 3];
  }
  return out;
}

test("detect: a Float64Array at UTM coordinates gives the near-origin polygons, moved", () => {
  const { points } = scan();
  const near = ps.detect(points, { stride: 4, viewpoint: [0, 0, 0] });
  const far = ps.detect(moved(points), { stride: 4, viewpoint: UTM });
  assert.ok(near.length >= 10, `${near.length} polygons`);
  assert.equal(far.length, near.length);
  for (let i = 0; i < near.length; i++) {
    const [a, b] = [near[i].vertices, far[i].vertices];
    assert.equal(b.length, a.length, `polygon ${i}`);
    for (let j = 0; j < a.length; j++) {
      assert.ok(Math.abs(b[j] - UTM[j % 3] - a[j]) <= 1e-3, `polygon ${i} vertex value ${j}`);
    }
  }
  // The same coordinates in float32: refused, naming the fix.
  throwsError(assert, () => ps.detect(new Float32Array(moved(points)), { stride: 4 }), /float32/, /Float64Array/);
});

test("addScan: a Float64Array scan equals the Float32Array one; world points far out need float64", () => {
  const { points, pose } = scan();
  const utmPose = Float64Array.from(pose);
  for (let k = 0; k < 3; k++) utmPose[12 + k] += UTM[k];
  const [a, b] = [new ps.Scenario(), new ps.Scenario()];
  a.addScan(points, { stride: 4, pose: utmPose });
  b.addScan(Float64Array.from(points), { stride: 4, pose: utmPose });
  assert.ok(a.polygons().length >= 5);
  assert.deepEqual(b.polygons(), a.polygons());
  // The scan in world coordinates with the identity pose: float64 is
  // accepted, float32 refused with the fix.
  const world = new Float64Array(points.length);
  for (let i = 0; i < points.length; i += 4) {
    const [x, y, z] = [points[i], points[i + 1], points[i + 2]];
    for (let k = 0; k < 3; k++) {
      world[i + k] = utmPose[k] * x + utmPose[4 + k] * y + utmPose[8 + k] * z + utmPose[12 + k];
    }
  }
  const c = new ps.Scenario();
  throwsError(assert, () => c.addScan(new Float32Array(world), { stride: 4 }), /float32/, /Float64Array/);
  assert.equal(c.scans, 0, "a refused scan changes nothing");
  assert.equal(c.addScan(world, { stride: 4 }).points, points.length / 4);
  for (const s of [a, b, c]) s.free();
});
