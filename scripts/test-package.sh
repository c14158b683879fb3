#!/usr/bin/env bash
# The npm package as a user installs it (tests/package/package.test.mjs):
# pack it (scripts/pack.sh), install the tarball into a scratch project in a
# temp dir, use it from Node (CJS, ESM), tsc --strict, Vite and esbuild builds
# in headless Chromium. Needs scripts/setup.sh all (chromium, www/node_modules,
# tests/package/tools/node_modules).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/pack.sh
timeout --kill-after=15 300 node --test --test-reporter=spec tests/package/
