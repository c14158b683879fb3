// The JS boundary under a fuzzer (tests/js/fuzz.mjs): 20,000 calls of every
// export and method with random and hostile arguments, from a fixed seed.
// After every throw: an Error, a working module, a working and unchanged
// Scenario; no call over 1 s. scripts/fuzz-js.mjs runs 100,000 and prints
// the counts.
import { test } from "node:test";
import assert from "node:assert/strict";
import { fuzz } from "./fuzz.mjs";

test("20,000 fuzzed calls: only Errors, nothing poisoned, nothing changed by a failed call", () => {
  const { counts, examples } = fuzz({ calls: 20_000, seed: 23 });
  const show = examples.map((e) => `${e.kind}: ${e.label}: ${e.detail}`).join("\n");
  assert.equal(counts.calls, 20_000, show);
  // The fuzzer reaches the error paths (a fuzzer whose calls all succeed tests nothing).
  assert.ok(counts.throws > 5_000, `only ${counts.throws} throws`);
  for (const kind of ["traps", "nonErrors", "unusableScenarios", "snapshotChanges", "slowCalls", "brokenModule"]) {
    assert.equal(counts[kind], 0, `${kind}:\n${show}`);
  }
});
