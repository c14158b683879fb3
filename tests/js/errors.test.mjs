// Every bad input throws a plain Error whose message names the problem, and
// the module keeps working afterwards.
import { test } from "node:test";
import assert from "node:assert/strict";
import { ps, psSim, throwsError, floor } from "./common.mjs";

const VIEW = { viewpoint: [5, 5, 1.8] };

/** The module still works: a floor is detected, a scenario takes a scan. */
function stillWorks() {
  const found = ps.detect(floor(), VIEW);
  assert.equal(found.length, 1);
  assert.ok(Math.abs(found[0].area - 99) < 3, `area ${found[0].area}`);
  const s = new ps.Scenario();
  const r = s.addScan(floor(), { pose: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -5, -5, -1.8, 1] });
  assert.equal(r.polygonCount, 1);
  s.free();
}

test("point buffers: length, stride, NaN and Infinity, type", () => {
  const s = new ps.Scenario();
  throwsError(assert, () => s.addScan(new Float32Array(7), { stride: 4 }), /length 7/, /multiple of the stride 4/);
  throwsError(assert, () => ps.detect(new Float32Array(4)), /length 4/, /stride 3/, /x, y, z, intensity .* give stride 4/);
  // The hint only where four values a point would fit.
  assert.throws(() => ps.detect(new Float32Array(5)), (e) => /length 5/.test(e.message) && !/give stride 4/.test(e.message));
  throwsError(assert, () => ps.detect([[0, 0, 0], [1, 1, 1], [2, 0, 1]]), /element 0 is not a number \(got an Array\)/, /one flat list/);
  throwsError(assert, () => ps.detect(new Float32Array(6), { stride: 5 }), /'stride'/, /3 .* or 4/);
  throwsError(assert, () => s.addScan(new Float32Array(6), { stride: "3" }), /'stride'/);
  throwsError(assert, () => s.addScan(Float32Array.from([0, 0, 0, 1, NaN, 2])), /point 1/, /NaN or infinite/);
  throwsError(assert, () => ps.detect(Float32Array.from([0, 0, Infinity])), /point 0/, /NaN or infinite/);
  throwsError(assert, () => ps.detect(Float64Array.from([0, 0, 0, 1, 2, -Infinity])), /point 1/);
  throwsError(assert, () => ps.detect([0, 0, "x"]), /element 2 is not a number/);
  throwsError(assert, () => ps.detect("points"), /points must be a Float32Array/, /string/);
  throwsError(assert, () => ps.detect({ length: 3 }), /points must be a Float32Array/, /Object/);
  throwsError(assert, () => ps.detect(new Int32Array(3)), /points must be a Float32Array/, /Int32Array/);
  throwsError(assert, () => ps.detect(undefined), /points must be a Float32Array/, /undefined/);
  // Float64Array and plain arrays of numbers are accepted (converted to f32).
  assert.equal(ps.detect(Float64Array.from(floor()), VIEW).length, 1);
  assert.deepEqual(ps.detect([0, 0, 0, 1, 1, 1]), []);
  assert.equal(s.scans, 0, "failed scans leave the scenario unchanged");
  s.free();
  stillWorks();
});

test("poses: wrong length, not numbers, not rigid", () => {
  const s = new ps.Scenario();
  const pts = new Float32Array(12);
  const id = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  throwsError(assert, () => s.addScan(pts, { pose: [1, 2, 3] }), /invalid pose/, /16 numbers/, /column-major/, /got 3/);
  throwsError(assert, () => s.addScan(pts, { pose: new Float64Array(17) }), /invalid pose/, /got 17/);
  throwsError(assert, () => s.addScan(pts, { pose: "identity" }), /invalid pose/, /16 numbers/);
  throwsError(assert, () => s.addScan(pts, { pose: [...id.slice(0, 15), "1"] }), /invalid pose/, /element 15/);
  throwsError(assert, () => s.addScan(pts, { pose: id.map((v, i) => (i === 12 ? NaN : v)) }), /invalid pose/, /NaN/);
  // Scaling, shear, reflection, a projective bottom row.
  throwsError(assert, () => s.addScan(pts, { pose: id.map((v, i) => (i === 0 ? 2 : v)) }), /not orthonormal/, /scaling or shear/);
  throwsError(assert, () => s.addScan(pts, { pose: id.map((v, i) => (i === 4 ? 0.5 : v)) }), /not orthonormal/);
  throwsError(assert, () => s.addScan(pts, { pose: id.map((v, i) => (i === 10 ? -1 : v)) }), /reflection/);
  throwsError(assert, () => s.addScan(pts, { pose: id.map((v, i) => (i === 3 ? 0.1 : v)) }), /bottom row/);
  // Row-major by mistake: the translation lands in the bottom row.
  const rowMajor = [1, 0, 0, 5, 0, 1, 0, 6, 0, 0, 1, 7, 0, 0, 0, 1];
  throwsError(assert, () => s.addScan(pts, { pose: rowMajor }), /bottom row must be 0 0 0 1/);
  // Accepted forms: Array, Float64Array, Float32Array, a Matrix4-like object, none.
  for (const pose of [id, Float64Array.from(id), Float32Array.from(id), { elements: id }, undefined, null]) {
    s.addScan(pts, { stride: 3, pose });
  }
  s.addScan(pts);
  assert.equal(s.scans, 7);
  s.free();
  stillWorks();
});

test("options: unknown keys, wrong types and out-of-range values name the key", () => {
  const cases = [
    [{ minAreaa: 1 }, /option 'minAreaa'/, /unknown option/, /did you mean 'minArea'/],
    [{ min_area: 1 }, /option 'min_area'/, /did you mean 'minArea'/],
    [{ colour: "red" }, /option 'colour'/, /unknown option/, /minArea/],
    [{ preset: "gpp3" }, /option 'preset'/, /gpp3/, /gpp1/],
    [{ preset: 2 }, /option 'preset'/],
    [{ hull: "round" }, /option 'hull'/, /convex/],
    [{ solidity: "hard" }, /option 'solidity'/, /occupancy/],
    [{ minArea: "big" }, /option 'minArea'/, /expected a number/],
    [{ minArea: -1 }, /option 'minArea'/, />= 0/],
    [{ minArea: NaN }, /option 'minArea'/, /finite/],
    [{ distance: Infinity }, /option 'distance'/, /finite/],
    [{ distance: 0 }, /option 'distance'/, /\(0, 100\]/],
    [{ distance: null }, /option 'distance'/, /null/],
    [{ minInliers: 2.5 }, /option 'minInliers'/, /integer/],
    [{ minInliers: 2 }, /option 'minInliers'/, /\[3, /],
    [{ seed: -1 }, /option 'seed'/, /integer/],
    [{ seed: 2 ** 64 }, /option 'seed'/],
    [{ confidence: 1 }, /option 'confidence'/, /below 1/],
    [{ minOccupancy: 1.5 }, /option 'minOccupancy'/, /between 0 and 1/],
    [{ expansion: "yes" }, /option 'expansion'/, /true or false/],
    [{ viewpoint: [1, 2] }, /option 'viewpoint'/, /3/],
    [{ viewpoint: [1, 2, NaN] }, /option 'viewpoint'/, /element 2/, /finite/],
    [{ viewpoint: [1, 2, "3"] }, /option 'viewpoint'/, /element 2 is not a number/],
    [{ cell: 0.001 }, /option 'cell'/, /0\.01/],
    [{ maxWork: 0 }, /option 'maxWork'/],
    [{ mergeAngle: { deg: 3 } }, /option 'mergeAngle'/, /expected a number, string, boolean or array/],
    [{ minArea: 10n }, /option 'minArea'/, /bigint/],
  ];
  for (const [opts, ...patterns] of cases) {
    throwsError(assert, () => new ps.Scenario(opts), ...patterns);
    if (!("stride" in opts)) {
      throwsError(assert, () => ps.detect(floor(3), opts), ...patterns);
    }
  }
  throwsError(assert, () => new ps.Scenario("gpp1"), /Scenario options must be an object/, /string/);
  throwsError(assert, () => new ps.Scenario([1]), /Scenario options must be an object/, /Array/);
  throwsError(assert, () => ps.detect(floor(3), 3), /detect options must be an object/);
  throwsError(assert, () => new ps.Scenario().addScan(floor(3), { strid: 3 }), /option 'strid'/, /stride and pose/);
  throwsError(assert, () => ps.defaultOptions("gpp9"), /option 'preset'/);
  // undefined values mean "not given"; every documented key is accepted.
  const all = ps.defaultOptions("gpp1");
  const s = new ps.Scenario({ ...all, preset: "gpp2", minArea: undefined });
  assert.deepEqual(s.options(), { ...all, minArea: ps.defaultOptions().minArea });
  s.free();
  stillWorks();
});

test("use after free() says the object was freed", () => {
  const s = new ps.Scenario();
  s.free();
  for (const call of [
    () => s.addScan(floor(3)),
    () => s.polygons(),
    () => s.mesh(),
    () => s.lastLabels(),
    () => s.toJSON(),
    () => s.toJSONString(),
    () => s.options(),
    () => s.scans,
    () => s.polygonCount,
    () => JSON.stringify(s),
  ]) {
    throwsError(assert, call, /Scenario was freed/);
  }
  s.free(); // a second free() does nothing
  const sim = psSim.simulate();
  const it = sim[Symbol.iterator]();
  sim.free();
  for (const call of [() => sim.next(), () => sim.scan(0), () => sim.length, () => sim.groundTruth(), () => sim.reset(), () => [...sim]]) {
    throwsError(assert, call, /Simulation was freed/);
  }
  // An iterator taken before free() keeps its own reference to the drive.
  assert.equal(it.next().value.index, 0);
  it.free();
  stillWorks();
});

test("bad snapshots", () => {
  const cases = [
    ["{}", /not a polyscene snapshot/, /params/],
    ["not json", /not a polyscene snapshot/],
    ["", /not a polyscene snapshot/],
    [42, /not a polyscene snapshot/, /number 42/],
    [[1, 2], /not a polyscene snapshot/, /Array/],
    [null, /not a polyscene snapshot/, /null/],
    [{ params: {}, primitives: [], nextId: 0, scans: 0 }, null],
    [{ params: { minArea: -3 }, primitives: [], nextId: 0, scans: 0 }, /'minArea'/],
    [{ params: {}, primitives: [{}], nextId: 0, scans: 0 }, /not a polyscene snapshot/, /missing field/],
    [{ params: {}, primitives: [], nextId: 0, scans: 0, extra: 1 }, null],
    [{ params: {}, primitives: [], nextId: 0, scans: 0, big: 10n }, /not a polyscene snapshot/],
    // JSON.parse takes this nesting; reading it into wasm stops at 32.
    [`{"params": {}, "primitives": [], "nextId": 0, "scans": 0, "extra": ${"[".repeat(5000)}${"]".repeat(5000)}}`, /not a polyscene snapshot/, /nested more than 32 deep/],
  ];
  for (const [snap, ...patterns] of cases) {
    if (patterns[0] === null) {
      ps.Scenario.fromJSON(snap).free();
      continue;
    }
    throwsError(assert, () => ps.Scenario.fromJSON(snap), ...patterns);
  }
  // A seed above 2^53 (only Rust can give one) is refused, not rounded by JSON.parse.
  const fresh = new ps.Scenario();
  const plain = fresh.toJSONString();
  fresh.free();
  const huge = plain.replace(/"seed":\d+/, '"seed":18446744073709551615');
  assert.notEqual(huge, plain);
  throwsError(assert, () => ps.Scenario.fromJSON(huge), /not a polyscene snapshot/, /expected u64/);
  // A snapshot's strings are printable ASCII; a message quoting a long one is cut.
  const accented = plain.replace('"hull":"concave"', '"hull":"concav\u00e9"');
  assert.notEqual(accented, plain);
  throwsError(assert, () => ps.Scenario.fromJSON(accented), /not a polyscene snapshot/, /printable ASCII/);
  const long = plain.replace('"nextId":0', `"nextId":"${"a".repeat(100000)}"`);
  assert.notEqual(long, plain);
  const cut = throwsError(assert, () => ps.Scenario.fromJSON(long), /not a polyscene snapshot/, /invalid type: string/, /cut: \d+ bytes in all/);
  assert.ok(cut.message.length < 4100, `${cut.message.length} characters`);
  // A number beyond a double's range is refused (JSON.parse reads it as Infinity), not read as null.
  const infinite = plain.replace('"viewpoint":null', '"viewpoint":1e999');
  assert.notEqual(infinite, plain);
  throwsError(assert, () => ps.Scenario.fromJSON(infinite), /not a polyscene snapshot/, /out of range/, /Infinity/);
  // A real snapshot with a corrupted footprint grid is refused, not trapped on later.
  const s = new ps.Scenario();
  s.addScan(floor(), { pose: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -5, -5, -1.8, 1] });
  const snap = s.toJSON();
  s.free();
  const fp = snap.primitives[0].footprint;
  for (const [field, value] of [["bits", fp.bits.slice(16)], ["bits", "xyz"], ["w", fp.w * 2], ["h", 0], ["cell", 0]]) {
    const bad = structuredClone(snap);
    bad.primitives[0].footprint[field] = value;
    throwsError(assert, () => ps.Scenario.fromJSON(bad), /not a polyscene snapshot/, /footprint/);
  }
  stillWorks();
});

test("simulate: options and ranges", () => {
  throwsError(assert, () => psSim.simulate({ layout: "forest" }), /option 'layout'/, /street/);
  throwsError(assert, () => psSim.simulate({ layout: 1 }), /option 'layout'/);
  throwsError(assert, () => psSim.simulate({ seed: -2 }), /option 'seed'/);
  throwsError(assert, () => psSim.simulate({ step: 0 }), /option 'step'/, /0\.05/);
  throwsError(assert, () => psSim.simulate({ origin: [1, 2] }), /option 'origin'/, /3 numbers/);
  throwsError(assert, () => psSim.simulate({ lenght: 3 }), /option 'lenght'/, /layout, seed, step and origin/);
  const sim = psSim.simulate({ layout: "crossing", seed: 2, step: 5 });
  throwsError(assert, () => sim.scan(sim.length), /out of range/, new RegExp(`${sim.length} scans`));
  throwsError(assert, () => sim.scan(-1), /out of range/);
  throwsError(assert, () => sim.scan(0.5), /out of range/);
  assert.equal(sim.scan(sim.length - 1).index, sim.length - 1);
  sim.free();
  stillWorks();
});

test("hostile arguments: detached buffers, Proxies, throwing getters; the Scenario stays usable and unchanged", () => {
  const s = new ps.Scenario();
  const pose = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -5, -5, -1.8, 1];
  s.addScan(floor(), { pose });
  const before = s.toJSONString();
  // What a worker holds after postMessage(msg, [points.buffer]).
  const gone = new Float32Array(9);
  structuredClone(gone.buffer, { transfer: [gone.buffer] });
  const e = throwsError(assert, () => s.addScan(gone), /points/, /detached/, /postMessage/);
  assert.ok(e.cause instanceof TypeError, "the TypeError is the cause");
  throwsError(assert, () => s.addScan(new Proxy(new Float32Array(9), {})), /points must be a Float32Array/, /Proxy/);
  const arr = [0, 0, 0];
  Object.defineProperty(arr, 1, { get() { throw 42; } });
  // Values thrown by the caller's own code come back as an Error with the value as cause.
  for (const [call, pattern, cause] of [
    [() => s.addScan(arr), /reading points\[1\] threw the number 42/, 42],
    [() => s.addScan(floor(3), { get stride() { throw undefined; } }), /reading addScan options.stride threw undefined/, undefined],
    [() => s.addScan(floor(3), new Proxy({}, { ownKeys() { throw "no keys"; } })), /listing the keys of addScan options/, "no keys"],
    [() => new ps.Scenario({ get minArea() { throw 7n; } }), /Scenario options.minArea/, 7n],
    [() => ps.Scenario.fromJSON({ toJSON() { throw 3; } }), /not a polyscene snapshot/, 3],
  ]) {
    const err = throwsError(assert, call, pattern);
    assert.ok("cause" in err, `${err.message}: a cause`);
    assert.equal(err.cause, cause);
  }
  const sym = Symbol("thrown");
  const err = throwsError(assert, () => ps.detect(floor(3), { get seed() { throw sym; } }), /a symbol/);
  assert.equal(err.cause, sym);
  // A getter that re-enters the Scenario (or frees it) breaks nothing.
  throwsError(assert, () => s.addScan(floor(3), { get stride() { s.polygons(); throw new Error("mine"); } }), /Error: mine/);
  assert.equal(s.toJSONString(), before, "every failed call left the scenario byte-identical");
  assert.equal(s.addScan(floor(), { pose }).polygonCount, 1, "and it still takes scans");
  const t = new ps.Scenario();
  throwsError(assert, () => t.addScan(floor(3), { get stride() { t.free(); return 3; } }), /Scenario was freed/);
  s.free();
  // Each pass-through exception once leaked wasm stack; after ~1,000 the module trapped.
  for (let i = 0; i < 3000; i++) {
    try {
      ps.detect(new Proxy(new Float32Array(9), {}));
    } catch {}
  }
  stillWorks();
});

test("defaultOptions refuses non-strings; huge inputs are refused before they are allocated", () => {
  for (const v of [{}, 5, true, Symbol(), 1n, { length: -1 }, { length: 1e9 }, [], "x".repeat(1e6)]) {
    throwsError(assert, () => ps.defaultOptions(v), /option 'preset'/, /gpp1/);
  }
  assert.equal(ps.defaultOptions(null).minArea, ps.defaultOptions("gpp2").minArea);
  // 2^24 points at most (stride 3: 50,331,648 numbers), checked from the length alone.
  throwsError(assert, () => ps.detect(new Float32Array(3 * 2 ** 24 + 3)), /points/, /50331651 numbers is more than the 50331648/);
  const big = [];
  big.length = 2 ** 32 - 1;
  throwsError(assert, () => ps.detect(big), /points/, /more than/);
  throwsError(assert, () => ps.Scenario.fromJSON("x".repeat(2 ** 28 + 1)), /not a polyscene snapshot/, /268435456/);
  // 2^20 objects at most (the root and its params are two), counted before JSON.parse builds them.
  const objects = (n) => `{"params": {}, "primitives": [], "nextId": 0, "scans": 0, "extra": [${"{},".repeat(n - 3)}{}]}`;
  ps.Scenario.fromJSON(objects(2 ** 20)).free();
  throwsError(assert, () => ps.Scenario.fromJSON(objects(2 ** 20 + 1)), /not a polyscene snapshot/, /more than the 1048576 objects/);
  // 2^24 values at most, counted before JSON.parse builds them.
  const many = `{"params": {}, "primitives": [], "nextId": 0, "scans": 0, "extra": [${"0,".repeat(2 ** 24)}0]}`;
  throwsError(assert, () => ps.Scenario.fromJSON(many), /not a polyscene snapshot/, /more than the 16777216 values/);
  stillWorks();
});

test("a snapshot with a vertex at -1e200 m is refused", () => {
  const s = new ps.Scenario();
  s.addScan(floor(), { pose: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -5, -5, -1.8, 1] });
  const snap = s.toJSON();
  s.free();
  snap.primitives[0].outline[0][0] = -1e200;
  throwsError(assert, () => ps.Scenario.fromJSON(snap), /not a polyscene snapshot/, /polygon 0/, /outline vertex 0/);
});
