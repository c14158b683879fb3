#!/usr/bin/env bash
# Build pkg/ (scripts/build-wasm.sh, quick when unchanged), then assemble the
# npm package in pkg/npm/ and pack it: pkg/polyscene-VERSION.tgz, its size in
# pkg/npm-pack.txt (scripts/pack.mjs says what goes where and why).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-wasm.sh
node scripts/pack.mjs
