#!/usr/bin/env bash
# The browser tests of the demo page and the map page: headless Chromium (Debian's, through
# playwright-core) drives www/ served on a free loopback port.
#   scripts/test-e2e.sh
# Needs scripts/setup.sh all (chromium, www/node_modules); builds www/pkg if missing.
# Screenshots: target/e2e/*.png
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -f www/pkg/polyscene.js ] || [ ! -f www/pkg/polyscene_bg.wasm ]; then
  echo "test-e2e: www/pkg is missing, building it"
  scripts/build-wasm.sh
fi
if [ ! -x "${CHROMIUM:-/usr/bin/chromium}" ]; then
  echo "test-e2e: no chromium at ${CHROMIUM:-/usr/bin/chromium}; run scripts/setup.sh browser" >&2
  exit 1
fi
if [ ! -d www/node_modules/playwright-core ]; then
  echo "test-e2e: www/node_modules/playwright-core is missing; run scripts/setup.sh npm" >&2
  exit 1
fi
mkdir -p target/e2e
# Each wait inside the test has its own timeout; this bounds the whole run.
timeout --kill-after=15 360 node --test --test-reporter=spec tests/e2e/
echo "test-e2e: screenshots in target/e2e/"
