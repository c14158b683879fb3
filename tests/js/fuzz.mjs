// A fuzzer of the JS boundary (pkg/node): random and hostile arguments for
// every export and method, built with fast-check from a fixed seed. Used by
// tests/js/boundary.test.mjs (20,000 calls) and scripts/fuzz-js.mjs
// (100,000 calls, counts printed).
//
// After every call that throws it checks: the thrown value is an Error (not
// a wasm trap, not a raw value thrown by the caller's own code), the module
// still works (detection of a small plane), the Scenario under test still
// works and its snapshot (toJSONString) is byte-identical to before the
// call. Every call is timed.
import { createRequire } from "node:module";
import path from "node:path";
import { floor, ps, psSim, repoRoot } from "./common.mjs";

const fcPath = path.join(repoRoot, "www/node_modules/fast-check");
let fc;
try {
  fc = createRequire(import.meta.url)(fcPath);
} catch {
  throw new Error(`${fcPath} is missing: install it with scripts/setup.sh npm`);
}

const ID = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
const POSE = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1.4, -1.4, -1.8, 1];

const PLANE = floor(15, 0.2); // 2.8 m x 2.8 m, 225 points
// Few hypotheses: the check runs after every throw, and a plane needs few.
const HEALTH = { viewpoint: [1.4, 1.4, 1.8], maxHypotheses: 10 };

function detached(Type, n) {
  const a = new Type(n);
  structuredClone(a.buffer, { transfer: [a.buffer] });
  return a;
}

/** Buffers one point beyond the limit at stride 3 and 4 (200 and 268 MB), made once. */
const huges = new Map();
function huge(stride) {
  if (!huges.has(stride)) huges.set(stride, new Float32Array(stride * 2 ** 24 + stride));
  return huges.get(stride);
}

function revoked() {
  const { proxy, revoke } = Proxy.revocable({}, {});
  revoke();
  return proxy;
}

/** A value thrown by "user code". */
const thrownValues = [42, undefined, null, "boom", Symbol("thrown"), 10n, { not: "an error" }, new TypeError("user TypeError")];

// ---------------------------------------------------------------------------
// Arbitraries of "makers": { label, make() } so that a fresh value (a fresh
// detached array, a fresh Proxy) is built at every call.

const maker = (label, make) => ({ label, make });
const constant = (label, value) => fc.constant(maker(label, () => value));

const number = fc.oneof(
  fc.constantFrom(0, -0, 1, -1, 3, 4, 0.5, NaN, Infinity, -Infinity, 1e9, 1.0000001e9, -1e200, 1e308, 3.4e38, 2 ** 53, 2 ** 64, 1e-320),
  fc.double(),
  fc.integer({ min: -5, max: 20 }),
);

const floats = (Type, n) =>
  fc.array(fc.oneof({ weight: 8, arbitrary: fc.double({ min: -20, max: 20, noNaN: true }) }, { weight: 1, arbitrary: number }), { maxLength: n }).map((xs) => maker(`${Type.name}(${xs.length})`, () => Type.from(xs)));

const primitive = fc.oneof(
  number.map((x) => maker(`number ${x}`, () => x)),
  fc.string({ maxLength: 12 }).map((s) => maker(`string`, () => s)),
  constant("true", true),
  constant("undefined", undefined),
  constant("null", null),
  constant("long string", "x".repeat(100_000)),
  fc.constant(maker("Symbol", () => Symbol("arg"))),
  constant("BigInt", 1n),
  constant("a function", () => 1),
);

/** Array-likes that are no plain, valid buffers. */
const hostileArray = fc.oneof(
  fc.constantFrom(Float32Array, Float64Array).chain((T) => fc.nat(12).map((n) => maker(`detached ${T.name}(${n})`, () => detached(T, n)))),
  fc.constant(maker("Proxy(Float32Array)", () => new Proxy(new Float32Array(9), {}))),
  fc.constant(maker("Proxy(Float32Array) throwing get", () => new Proxy(new Float32Array(9), { get() { throw 7; } }))),
  fc.constant(maker("Proxy throwing getPrototypeOf", () => new Proxy(new Float32Array(9), { getPrototypeOf() { throw 8; } }))),
  fc.constant(maker("Proxy(Array)", () => new Proxy([0, 0, 0], {}))),
  fc.constant(maker("Proxy(Array) throwing get", () => new Proxy([0, 0, 0], { get(t, k) { if (k === "length") return 3; throw Symbol("trap"); } }))),
  fc.constant(maker("revoked Proxy", revoked)),
  fc.constantFrom(...thrownValues).map((v) => maker("Array with throwing index getter", () => {
    const a = [0, 0, 0];
    Object.defineProperty(a, 1, { get() { throw v; } });
    return a;
  })),
  fc.constant(maker("Float32Array with throwing own length", () => {
    const a = new Float32Array(6);
    Object.defineProperty(a, "length", { get() { throw 9; } });
    return a;
  })),
  fc.constant(maker("Float32Array lying length", () => {
    const a = new Float32Array(6);
    Object.defineProperty(a, "length", { value: 3 });
    return a;
  })),
  fc.constant(maker("{length: -1}", () => ({ length: -1 }))),
  fc.constant(maker("{length: 1e9}", () => ({ length: 1e9 }))),
  fc.constant(maker("Array(1e9)", () => new Array(1e9))),
  fc.constant(maker("Array length 2^32-1", () => { const a = []; a.length = 2 ** 32 - 1; return a; })),
  fc.constant(maker("Proxy(Array) length 1e12", () => new Proxy([], { get(t, k) { return k === "length" ? 1e12 : 0; } }))),
  fc.constantFrom(3, 4).map((k) => maker(`Float32Array(2^24*${k}+${k})`, () => huge(k))),
  fc.constant(maker("Int32Array", () => new Int32Array(9))),
  fc.constant(maker("BigInt64Array", () => new BigInt64Array(3))),
  fc.constant(maker("DataView", () => new DataView(new ArrayBuffer(12)))),
  fc.constant(maker("ArrayBuffer", () => new ArrayBuffer(12))),
  fc.array(fc.oneof(number, fc.constant("1"), fc.constant(null)), { maxLength: 12 }).map((xs) => maker("Array of mixed", () => xs.slice())),
);

/** Points: mostly plausible buffers, often hostile. */
const points = fc.oneof(
  { weight: 3, arbitrary: floats(Float32Array, 30) },
  { weight: 1, arbitrary: floats(Float64Array, 12) },
  { weight: 1, arbitrary: fc.constant(maker("a 225-point plane", () => PLANE.slice())) },
  { weight: 1, arbitrary: fc.constant(maker("a plane with a NaN", () => { const p = PLANE.slice(); p[100] = NaN; return p; })) },
  { weight: 4, arbitrary: hostileArray },
  { weight: 2, arbitrary: primitive },
);

/** A getter-bearing or Proxy options object that throws. */
const throwingOptions = fc.oneof(
  fc.tuple(fc.constantFrom("stride", "pose", "minArea", "preset", "viewpoint", "seed", "layout"), fc.constantFrom(...thrownValues)).map(([key, v]) =>
    maker(`options with throwing getter ${key}`, () => Object.defineProperty({}, key, { enumerable: true, get() { throw v; } }))),
  fc.constantFrom(...thrownValues).map((v) => maker("Proxy with throwing ownKeys", () => new Proxy({}, { ownKeys() { throw v; } }))),
  fc.constantFrom(...thrownValues).map((v) => maker("Proxy with throwing getOwnPropertyDescriptor", () => new Proxy({ a: 1 }, { getOwnPropertyDescriptor() { throw v; } }))),
  fc.constant(maker("revoked Proxy", revoked)),
);

/** A pose value. */
const pose = fc.oneof(
  constant("identity", ID),
  constant("pose", POSE),
  fc.array(number, { minLength: 16, maxLength: 16 }).map((xs) => maker("16 random numbers", () => xs.slice())),
  number.map((x) => maker(`translation ${x}`, () => ID.map((v, i) => (i === 12 ? x : v)))),
  fc.constant(maker("Matrix4-like", () => ({ elements: Float64Array.from(POSE) }))),
  fc.constant(maker("Matrix4 with throwing elements", () => ({ get elements() { throw 5; } }))),
  hostileArray,
  primitive,
);

/** An options object: known keys with wild values, unknown keys, or hostile. */
const optionKeys = ["stride", "pose", "preset", "minArea", "distance", "hull", "seed", "viewpoint", "maxWork", "expansion", "layout", "step", "origin", "colour"];
const optionValue = fc.oneof(primitive, pose, floats(Float64Array, 4));
const options = fc.oneof(
  { weight: 2, arbitrary: constant("no options", undefined) },
  { weight: 2, arbitrary: fc.constantFrom(3, 4).map((s) => maker(`{stride: ${s}}`, () => ({ stride: s }))) },
  { weight: 2, arbitrary: pose.map((p) => maker(`{pose: ${p.label}}`, () => ({ pose: p.make() }))) },
  {
    weight: 3,
    arbitrary: fc.array(fc.tuple(fc.constantFrom(...optionKeys), optionValue), { maxLength: 3 }).map((kv) =>
      maker(`{${kv.map(([k, v]) => `${k}: ${v.label}`).join(", ")}}`, () => Object.fromEntries(kv.map(([k, v]) => [k, v.make()])))),
  },
  { weight: 2, arbitrary: throwingOptions },
  { weight: 1, arbitrary: primitive },
  { weight: 1, arbitrary: hostileArray },
);

/** Snapshots: the Scenario's own, edited at a random place, or not snapshots at all. */
function snapshotArb(base) {
  const paths = [];
  const walk = (v, p) => {
    if (p.length) paths.push(p);
    if (v && typeof v === "object") for (const k of Object.keys(v)) walk(v[k], [...p, k]);
  };
  walk(base, []);
  const wild = fc.oneof(number, fc.constantFrom("x", null, true, [], {}, [1e200, 1e200], "0".repeat(17)));
  return fc.oneof(
    { weight: 4, arbitrary: fc.tuple(fc.constantFrom(...paths), wild).map(([p, v]) => maker(`snapshot with ${p.join(".")} = ${String(v)}`, () => {
      const s = structuredClone(base);
      let o = s;
      for (const k of p.slice(0, -1)) o = o[k];
      o[p[p.length - 1]] = structuredClone(v);
      return s;
    })) },
    { weight: 1, arbitrary: fc.nat(2000).map((n) => maker(`snapshot text cut at ${n}`, () => JSON.stringify(base).slice(0, n))) },
    { weight: 1, arbitrary: fc.constant(maker("snapshot with a BigInt", () => ({ ...structuredClone(base), big: 1n }))) },
    { weight: 1, arbitrary: fc.constant(maker("snapshot with throwing toJSON", () => ({ toJSON() { throw Symbol("toJSON"); } }))) },
    { weight: 1, arbitrary: throwingOptions },
    { weight: 1, arbitrary: primitive },
  );
}

// ---------------------------------------------------------------------------
// The calls. Each action: { name, call(ctx) } where ctx holds the Scenario
// and the Simulation under test.

function actions(base) {
  const on = (name, weight, arb, call) => ({ weight, arbitrary: arb.map((args) => ({ name, label: `${name}(${[].concat(args).map((a) => a.label).join(", ")})`, call: (ctx) => call(ctx, ...[].concat(args).map((a) => a.make())) })) });
  const none = fc.constant([]);
  return fc.oneof(
    on("detect", 6, fc.tuple(points, options), (ctx, p, o) => ps.detect(p, o)),
    on("detectFlat", 2, fc.tuple(points, options), (ctx, p, o) => ps.detectFlat(p, o)),
    on("detectWithProgress", 2, fc.tuple(points, options, primitive), (ctx, p, o, stop) =>
      ps.detectWithProgress(p, o, (at) => {
        // A callback that throws what the fuzzer made, stops, or goes on.
        if (typeof stop === "number" && at.round >= stop) throw stop;
        return stop === false ? false : undefined;
      })),
    on("scenario.addScan", 10, fc.tuple(points, options), (ctx, p, o) => ctx.scenario.addScan(p, o)),
    on("addScan re-entering", 1, fc.constant(maker("getter calling scenario.polygons()", () => null)), (ctx) =>
      ctx.scenario.addScan(PLANE.slice(0, 30), { get stride() { ctx.scenario.polygons(); ctx.scenario.toJSONString(); throw new Error("after re-entry"); } })),
    on("new Scenario", 3, options, (ctx, o) => new ps.Scenario(o).free()),
    on("defaultOptions", 3, fc.oneof(primitive, options, hostileArray), (ctx, v) => ps.defaultOptions(v)),
    on("Scenario.fromJSON", 4, snapshotArb(base), (ctx, snap) => {
      const restored = ps.Scenario.fromJSON(snap);
      // What was accepted must take a scan in bounded time (a hang showed here).
      try {
        restored.addScan(PLANE, { pose: POSE });
      } finally {
        restored.free();
      }
    }),
    on("simulate", 1, options, (ctx, o) => psSim.simulate(o).free()),
    on("simulation.scan", 2, fc.oneof(primitive, hostileArray), (ctx, i) => ctx.simulation.scan(i)),
    on("getters", 1, none, (ctx) => {
      const s = ctx.scenario;
      return [s.polygons(), s.polygonsFlat(), s.lastLabels(), s.mesh(), s.options(), s.toJSON(), s.scans, s.polygonCount, ps.version()];
    }),
  );
}

/** The module still works: the 225-point plane gives its one polygon. */
function moduleWorks() {
  const found = ps.detect(PLANE, HEALTH);
  return found.length === 1 && Math.abs(found[0].area - 7.36) < 0.01;
}

/**
 * Run `calls` fuzzed calls from `seed`. Returns the counts and up to
 * `keep` examples of each kind of failure.
 */
export function fuzz({ calls, seed, keep = 5, slowMs = 1000 }) {
  const counts = { calls: 0, throws: 0, traps: 0, nonErrors: 0, unusableScenarios: 0, snapshotChanges: 0, slowCalls: 0, brokenModule: 0 };
  const examples = [];
  const note = (kind, label, detail) => {
    counts[kind]++;
    if (examples.filter((e) => e.kind === kind).length < keep) examples.push({ kind, label, detail: String(detail) });
  };
  const ctx = { scenario: new ps.Scenario(), simulation: psSim.simulate({ layout: "crossing", step: 10 }) };
  ctx.scenario.addScan(PLANE, { pose: POSE });
  const base = JSON.parse(ctx.scenario.toJSONString());
  const arb = actions(base);
  const batch = 500;
  let maxMs = 0;
  for (let b = 0; counts.calls < calls; b++) {
    const todo = fc.sample(arb, { seed: seed + b, numRuns: Math.min(batch, calls - counts.calls) });
    for (const action of todo) {
      counts.calls++;
      let before;
      try {
        before = ctx.scenario.toJSONString();
      } catch (e) {
        note("unusableScenarios", action.label, `before: ${e?.message}`);
        ctx.scenario = new ps.Scenario();
        before = ctx.scenario.toJSONString();
      }
      let thrown;
      let threw = false;
      const t0 = performance.now();
      try {
        action.call(ctx);
      } catch (e) {
        threw = true;
        thrown = e;
      }
      const ms = performance.now() - t0;
      maxMs = Math.max(maxMs, ms);
      if (ms > slowMs) note("slowCalls", action.label, `${ms.toFixed(0)} ms`);
      if (!threw) continue;
      counts.throws++;
      if (thrown instanceof WebAssembly.RuntimeError) note("traps", action.label, thrown.message);
      else if (!(thrown instanceof Error)) note("nonErrors", action.label, typeof thrown === "symbol" ? "a Symbol" : thrown);
      try {
        if (!moduleWorks()) note("brokenModule", action.label, "detection of the health plane changed");
      } catch (e) {
        note("brokenModule", action.label, e?.message ?? e);
      }
      let after;
      try {
        after = ctx.scenario.toJSONString();
        void ctx.scenario.scans;
      } catch (e) {
        note("unusableScenarios", action.label, e?.message ?? e);
        ctx.scenario = new ps.Scenario();
        continue;
      }
      if (after !== before) note("snapshotChanges", action.label, `${before.length} -> ${after.length} bytes`);
      if (counts.traps + counts.brokenModule > 20) break; // the instance is gone
    }
    if (counts.traps + counts.brokenModule > 20) break;
  }
  ctx.scenario.free();
  ctx.simulation.free();
  return { counts, examples, maxMs };
}
