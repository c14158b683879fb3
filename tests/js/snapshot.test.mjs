// Snapshots survive JSON.stringify / JSON.parse, and continuing from one
// gives exactly what not stopping gives.
import { test } from "node:test";
import assert from "node:assert/strict";
import { ps, psSim } from "./common.mjs";

const SCANS = 12;
const STOP = 6;
const sim = psSim.simulate({ layout: "crossing", seed: 5 });
const scans = Array.from({ length: SCANS }, (_, k) => sim.scan(k));
sim.free();

const strip = ({ timeMs, ...rest }) => rest;

function run(scenario, from, to) {
  const reports = [];
  for (let k = from; k < to; k++) {
    reports.push(strip(scenario.addScan(scans[k].points, { stride: 4, pose: scans[k].pose })));
  }
  return reports;
}

test("stop, JSON.stringify, JSON.parse, fromJSON, continue: identical to not stopping", () => {
  const options = { preset: "gpp2", hull: "concave", seed: 11 };
  const straight = new ps.Scenario(options);
  const want = run(straight, 0, SCANS);

  const first = new ps.Scenario(options);
  const got = run(first, 0, STOP);
  const text = JSON.stringify(first); // calls toJSON()
  first.free();
  const snapshot = JSON.parse(text);
  // The footprints' 64-bit words travel as hex strings: as JSON numbers,
  // words above 2^53 would be rounded by JSON.parse.
  const words = snapshot.primitives.flatMap((p) => p.footprint.bits.match(/.{16}/g) ?? []);
  assert.ok(words.some((w) => BigInt(`0x${w}`) > 2n ** 53n), "some words use the top bits");
  const resumed = ps.Scenario.fromJSON(snapshot);
  assert.equal(resumed.scans, STOP);
  assert.equal(resumed.lastLabels().length, 0, "labels of the last scan are not part of a snapshot");
  got.push(...run(resumed, STOP, SCANS));

  assert.deepEqual(got, want);
  assert.deepEqual(resumed.polygons(), straight.polygons());
  assert.deepEqual(resumed.mesh(), straight.mesh());
  assert.deepEqual(resumed.lastLabels(), straight.lastLabels());
  assert.equal(resumed.toJSONString(), straight.toJSONString());
  assert.deepEqual(resumed.options(), straight.options());
  resumed.free();
  straight.free();
});

test("toJSON() and toJSONString() restore the same state", () => {
  const s = new ps.Scenario({ preset: "gpp1", hull: "convex", expansion: false, seed: 3 });
  run(s, 0, 3);
  const fromObject = ps.Scenario.fromJSON(JSON.parse(JSON.stringify(s.toJSON())));
  const fromString = ps.Scenario.fromJSON(s.toJSONString());
  // The string is exact; the object loses only the sign of zeros (JSON.stringify(-0) is "0").
  assert.match(s.toJSONString(), /[[,:]-0\.0[,\]}]/, "the snapshot holds a negative zero");
  assert.equal(fromString.toJSONString(), s.toJSONString());
  const normalised = (x) => JSON.stringify(JSON.parse(x.toJSONString()));
  assert.equal(normalised(fromObject), normalised(s));
  assert.deepEqual(fromObject.options(), s.options());
  assert.equal(fromObject.options().hull, "convex");
  assert.equal(fromObject.options().expansion, false);
  for (const x of [s, fromObject, fromString]) x.free();
});

test("an empty scenario round-trips", () => {
  const s = new ps.Scenario();
  const again = ps.Scenario.fromJSON(JSON.parse(JSON.stringify(s)));
  assert.equal(again.polygonCount, 0);
  assert.deepEqual(again.polygons(), []);
  const m = again.mesh();
  assert.equal(m.indices.length, 0);
  assert.deepEqual(m.origin, [0, 0, 0]);
  s.free();
  again.free();
});
