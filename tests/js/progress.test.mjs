// detectWithProgress: the core reports after each detection round through a
// JS callback (a `catch` import) and stops when the callback says so.
import { test } from "node:test";
import assert from "node:assert/strict";
import { ps, psSim } from "./common.mjs";

function scanPoints() {
  const sim = psSim.simulate({ seed: 2 });
  const { points } = sim.scan(0);
  sim.free();
  return points;
}

test("detectWithProgress reports each round and gives what detect gives", () => {
  const points = scanPoints();
  const plain = ps.detect(points, { stride: 4 });
  const seen = [];
  const watched = ps.detectWithProgress(points, { stride: 4 }, (p) => {
    seen.push(p);
  });
  assert.deepEqual(watched, plain, "watching changes nothing");
  assert.ok(seen.length > 3, `${seen.length} rounds`);
  seen.forEach((p, k) => {
    assert.deepEqual(Object.keys(p), ["round", "pointsLeft", "points", "polygons"]);
    assert.equal(p.round, k + 1);
    assert.equal(p.points, points.length / 4);
    if (k > 0) assert.ok(p.pointsLeft <= seen[k - 1].pointsLeft, "points left only fall");
  });
});

test("onProgress returning false stops the detection with an Error; the module keeps working", () => {
  const points = scanPoints();
  let calls = 0;
  assert.throws(
    () => ps.detectWithProgress(points, { stride: 4 }, () => ++calls < 2),
    (e) => e instanceof Error && /stopped by onProgress after round 2/.test(e.message),
  );
  assert.equal(calls, 2);
  assert.ok(ps.detect(points, { stride: 4 }).length > 5);
});

test("an exception thrown by onProgress is the cause of the Error thrown, and does not poison the module", () => {
  const points = scanPoints();
  class Mine extends Error {}
  const mine = new Mine("from the callback");
  for (const thrown of [mine, 42, undefined]) {
    assert.throws(
      () => ps.detectWithProgress(points, { stride: 4 }, () => { throw thrown; }),
      (e) => e instanceof Error && /onProgress after round 1 threw/.test(e.message) && "cause" in e && e.cause === thrown,
    );
  }
  const s = new ps.Scenario();
  const sim = psSim.simulate({ seed: 2 });
  const { pose } = sim.scan(0);
  assert.ok(s.addScan(points, { stride: 4, pose }).polygonCount > 5, "the module still works");
  s.free();
  sim.free();
});

test("detectWithProgress refuses bad arguments with clear errors, before any round", () => {
  let called = false;
  const cb = () => { called = true; };
  assert.throws(() => ps.detectWithProgress(new Float32Array(5), { stride: 3 }, cb), /multiple|divisible|stride/i);
  assert.throws(() => ps.detectWithProgress(scanPoints(), { stride: 4, minAreaa: 1 }, cb), /minAreaa/);
  assert.throws(() => ps.detectWithProgress(scanPoints(), { stride: 4 }, "not a function"), /onProgress must be a function/);
  assert.equal(called, false);
});
