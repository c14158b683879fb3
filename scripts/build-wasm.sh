#!/usr/bin/env bash
# Build the JS package with wasm-pack, release, optimised by wasm-opt (npm's
# binaryen from www/node_modules/.bin; Debian's is too old):
#   pkg/web      ES module for browsers and module workers (init() first)
#   pkg/node     CommonJS for Node (require("./pkg/node"))
# (wasm-pack's bundler target is not built: its `import * from "x.wasm"` needs
# a wasm plugin in Vite and fails in esbuild; bundlers take pkg/web, whose
# `new URL("polyscene_bg.wasm", import.meta.url)` Vite and webpack follow),
# then copy pkg/web to www/pkg for the page, and print and record the
# gzipped size of the wasm in pkg/wasm-size.txt.
# Quick when nothing changed: the inputs' hash is kept in pkg/.inputs.sha256
# (FORCE=1 rebuilds anyway). Assumes `scripts/setup.sh rust npm` ran.
set -euo pipefail
cd "$(dirname "$0")/.."

export PATH="$PWD/www/node_modules/.bin:$HOME/.cargo/bin:$PATH"
for tool in wasm-pack wasm-bindgen wasm-opt; do
  if ! command -v "$tool" >/dev/null; then
    echo "build-wasm: $tool not found; run scripts/setup.sh rust npm" >&2
    exit 1
  fi
done

# One build at a time (make test, make demo and people may run this at once).
mkdir -p pkg
exec 9>pkg/.build.lock
if ! flock -n 9; then
  echo "build-wasm: waiting for another build-wasm.sh to finish"
  flock 9
fi

inputs_hash() {
  find src build build.rs Cargo.toml Cargo.lock .cargo scripts/build-wasm.sh -type f -print0 | sort -z |
    xargs -0 sha256sum | sha256sum | cut -d' ' -f1
}

targets=(web nodejs)
dirs=(pkg/web pkg/node)
rm -rf pkg/bundler # from builds before it was dropped
hash=$(inputs_hash)
fresh=1
for d in "${dirs[@]}" www/pkg; do
  [ -f "$d/polyscene_bg.wasm" ] || fresh=0
done
if [ "${FORCE:-0}" != 1 ] && [ "$fresh" = 1 ] && [ "$(cat pkg/.inputs.sha256 2>/dev/null)" = "$hash" ]; then
  echo "build-wasm: pkg/ is up to date ($(cat pkg/wasm-size.txt 2>/dev/null || echo 'size unknown'))"
  exit 0
fi

for i in "${!targets[@]}"; do
  echo "build-wasm: wasm-pack build --release --target ${targets[$i]} -> ${dirs[$i]}"
  # wasm-pack's own update check needs the internet; its warning is noise here.
  wasm-pack --log-level warn build --release --target "${targets[$i]}" \
    --out-dir "${dirs[$i]}" --out-name polyscene 2>&1 |
    grep -v -e "failed to get wasm-pack version" -e "no LICENSE file" || true
  [ -f "${dirs[$i]}/polyscene_bg.wasm" ] || { echo "build-wasm: ${targets[$i]} build failed" >&2; exit 1; }
done

# The page imports www/pkg/polyscene.js (a copy, so that www/ is servable alone).
rm -rf www/pkg
cp -r pkg/web www/pkg
rm -f www/pkg/.gitignore

wasm=pkg/web/polyscene_bg.wasm
raw=$(wc -c <"$wasm")
gz=$(gzip -9 -c "$wasm" | wc -c)
summary=$(printf 'polyscene_bg.wasm: %d bytes, %d bytes gzipped (gzip -9): %.1f kB, %.1f KiB' "$raw" "$gz" "$(awk -v b="$gz" 'BEGIN { print b / 1000 }')" "$(awk -v b="$gz" 'BEGIN { print b / 1024 }')")
echo "$summary" >pkg/wasm-size.txt
echo "build-wasm: $summary"
if [ "$gz" -gt 250000 ]; then
  echo "build-wasm: warning: the gzipped wasm is above the 250 kB (250,000 bytes) budget" >&2
fi
echo "$hash" >pkg/.inputs.sha256
echo "build-wasm: the npm package: scripts/pack.sh (pkg/npm, pkg/polyscene-*.tgz)"
