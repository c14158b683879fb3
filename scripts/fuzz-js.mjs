#!/usr/bin/env node
// Fuzz the JS boundary of pkg/node (not part of CI): `node scripts/fuzz-js.mjs [calls] [seed]`,
// default 100,000 calls from seed 23. Prints the counts the package must keep
// at 0: wasm traps, unusable Scenarios, non-Error throws, calls over 1 s,
// snapshot changes after failed calls (and a broken module), with examples.
// Needs pkg/node (scripts/build-wasm.sh) and fast-check (scripts/setup.sh npm).
import { fuzz } from "../tests/js/fuzz.mjs";

const calls = Number(process.argv[2] ?? 100_000);
const seed = Number(process.argv[3] ?? 23);
const t0 = performance.now();
const { counts, examples, maxMs } = fuzz({ calls, seed });
const s = ((performance.now() - t0) / 1000).toFixed(1);
console.log(`JS boundary fuzz: ${counts.calls} calls (seed ${seed}) in ${s} s, ${counts.throws} threw; slowest call ${maxMs.toFixed(0)} ms`);
console.log("| count | value |\n| --- | ---: |");
for (const [k, label] of [
  ["traps", "wasm traps"],
  ["unusableScenarios", "unusable Scenarios"],
  ["nonErrors", "non-Error throws"],
  ["slowCalls", "calls over 1 s"],
  ["snapshotChanges", "snapshot changes after a failed call"],
  ["brokenModule", "module broken after a throw"],
]) {
  console.log(`| ${label} | ${counts[k]} |`);
}
for (const e of examples) console.log(`${e.kind}: ${e.label}: ${e.detail}`);
const bad = counts.traps + counts.unusableScenarios + counts.nonErrors + counts.slowCalls + counts.snapshotChanges + counts.brokenModule;
process.exit(bad === 0 ? 0 : 1);
