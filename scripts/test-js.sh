#!/usr/bin/env bash
# Tests of the JS package (assumes `scripts/setup.sh all` ran):
#   1. build pkg/ (scripts/build-wasm.sh; quick when nothing changed; it fails
#      here when polyscene_bg.wasm is above its 250,000-byte gzipped budget),
#      the native CLI the Node tests compare against, and examples/write_las
#      (tests/js/io.test.mjs's LAZ files: no JS library writes LAZ);
#   2. the binding layer under Node: wasm-pack test --node (tests/wasm.rs,
#      with both bindings: --features wasm-sim);
#   3. the package against pkg/node: node --test tests/js/.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$PWD/www/node_modules/.bin:$HOME/.cargo/bin:$PATH"

SIZE_BUDGET_STRICT=1 scripts/build-wasm.sh
echo "test-js: cargo build --release --bin polyscene --example write_las (the native reference; LAZ fixtures)"
cargo build --release --quiet --bin polyscene --example write_las

echo "test-js: wasm-pack test --node (tests/wasm.rs, both bindings)"
wasm-pack --log-level warn test --node -- --features wasm-sim --test wasm 2>&1 |
  grep -v -e "failed to get wasm-pack version" -e "no LICENSE file"
status=${PIPESTATUS[0]}
[ "$status" -eq 0 ] || { echo "test-js: wasm-pack test failed" >&2; exit "$status"; }

echo "test-js: node --test tests/js/"
node --test --test-reporter=spec tests/js/
