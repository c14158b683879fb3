#!/usr/bin/env bash
# Build the JS package with wasm-pack, release, optimised by wasm-opt (npm's
# binaryen from www/node_modules/.bin; Debian's is too old):
#   pkg/web      ES module for browsers and module workers (init() first)
#   pkg/node     CommonJS for Node (require("./pkg/node"))
# Each holds two wasm builds of the crate (Cargo features, see Cargo.toml):
#   polyscene.js, polyscene_bg.wasm          detection (default features)
#   polyscene_sim.js, polyscene_sim_bg.wasm  the simulator (polyscene/sim:
#     --no-default-features --features wasm-sim), so that the detection wasm
#     does not carry it
# (wasm-pack's bundler target is not built: its `import * from "x.wasm"` needs
# a wasm plugin in Vite and fails in esbuild; bundlers take pkg/web, whose
# `new URL("polyscene_bg.wasm", import.meta.url)` Vite and webpack follow),
# then copy pkg/web to www/pkg for the page, and print and record the
# gzipped sizes of both wasm files in pkg/wasm-size.txt. The 250,000-byte
# gzipped budget applies to polyscene_bg.wasm: above it this prints a warning,
# or fails with SIZE_BUDGET_STRICT=1 (scripts/test-js.sh sets it).
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

budget=250000
# The size check on pkg/wasm-size.txt's numbers: a warning, or with
# SIZE_BUDGET_STRICT=1 a failure.
check_budget() {
  local gz
  gz=$(sed -n 's/^polyscene_bg.wasm: [0-9]* bytes, \([0-9]*\) bytes gzipped.*/\1/p' pkg/wasm-size.txt)
  [ -n "$gz" ] || { echo "build-wasm: pkg/wasm-size.txt has no size of polyscene_bg.wasm" >&2; exit 1; }
  if [ "$gz" -gt "$budget" ]; then
    if [ "${SIZE_BUDGET_STRICT:-0}" = 1 ]; then
      echo "build-wasm: error: polyscene_bg.wasm is $gz bytes gzipped, above its budget of $budget bytes" >&2
      exit 1
    fi
    echo "build-wasm: warning: polyscene_bg.wasm is $gz bytes gzipped, above its budget of $budget bytes" >&2
  fi
}

targets=(web nodejs)
dirs=(pkg/web pkg/node)
rm -rf pkg/bundler # from builds before it was dropped
hash=$(inputs_hash)
fresh=1
for d in "${dirs[@]}" www/pkg; do
  for f in polyscene_bg.wasm polyscene_sim_bg.wasm; do
    [ -f "$d/$f" ] || fresh=0
  done
done
if [ "${FORCE:-0}" != 1 ] && [ "$fresh" = 1 ] && [ "$(cat pkg/.inputs.sha256 2>/dev/null)" = "$hash" ]; then
  echo "build-wasm: pkg/ is up to date ($(awk 'NR > 1 { printf "; " } { printf "%s", $0 }' pkg/wasm-size.txt 2>/dev/null || echo 'size unknown'))"
  check_budget
  exit 0
fi

# Panic locations in dependencies name their files by where cargo keeps
# their sources, under the builder's home
# (/root/.cargo/registry/src/index.crates.io-<hash>/spade-2.15.1/src/...):
# those prefixes are removed (spade-2.15.1/src/...), so that the wasm
# neither carries nor depends on the builder's paths (0.03 kB gzipped less).
# Cargo joins this array to .cargo/config.toml's rustflags.
flags=""
for d in "${CARGO_HOME:-$HOME/.cargo}"/registry/src/*/; do
  [ -d "$d" ] && flags+="'--remap-path-prefix=$d=',"
done
remap=(--config "target.wasm32-unknown-unknown.rustflags=[${flags%,}]")

# wasm-pack's own update check needs the internet; its warning is noise here.
quiet() { grep -v -e "failed to get wasm-pack version" -e "no LICENSE file" || true; }
# The main builds first, then the simulator's: cargo rebuilds the crate when
# its features change, so each feature set is compiled once.
for i in "${!targets[@]}"; do
  dir=${dirs[$i]}
  echo "build-wasm: wasm-pack build --release --target ${targets[$i]} -> $dir/polyscene.js"
  wasm-pack --log-level warn build --release --target "${targets[$i]}" \
    --out-dir "$dir" --out-name polyscene -- "${remap[@]}" 2>&1 | quiet
  [ -f "$dir/polyscene_bg.wasm" ] || { echo "build-wasm: ${targets[$i]} build failed" >&2; exit 1; }
done
# The simulator: built into a scratch folder (wasm-pack writes its own
# package.json there), its four files moved next to the main build's.
for i in "${!targets[@]}"; do
  dir=${dirs[$i]}
  echo "build-wasm: wasm-pack build --release --target ${targets[$i]} (wasm-sim) -> $dir/polyscene_sim.js"
  rm -rf "$dir.sim"
  wasm-pack --log-level warn build --release --target "${targets[$i]}" \
    --out-dir "$dir.sim" --out-name polyscene_sim --no-pack \
    -- --no-default-features --features wasm-sim "${remap[@]}" 2>&1 | quiet
  [ -f "$dir.sim/polyscene_sim_bg.wasm" ] || { echo "build-wasm: ${targets[$i]} wasm-sim build failed" >&2; exit 1; }
  rm -f "$dir"/polyscene_sim*
  mv "$dir.sim"/polyscene_sim* "$dir/"
  rm -rf "$dir.sim"
done

# The page imports www/pkg/polyscene.js (a copy, so that www/ is servable alone).
rm -rf www/pkg
cp -r pkg/web www/pkg
rm -f www/pkg/.gitignore

: >pkg/wasm-size.txt
for name in polyscene_bg.wasm polyscene_sim_bg.wasm; do
  wasm=pkg/web/$name
  raw=$(wc -c <"$wasm")
  gz=$(gzip -9 -c "$wasm" | wc -c)
  summary=$(printf '%s: %d bytes, %d bytes gzipped (gzip -9): %.1f kB, %.1f KiB' "$name" "$raw" "$gz" "$(awk -v b="$gz" 'BEGIN { print b / 1000 }')" "$(awk -v b="$gz" 'BEGIN { print b / 1024 }')")
  echo "$summary" >>pkg/wasm-size.txt
  echo "build-wasm: $summary"
done
echo "$hash" >pkg/.inputs.sha256
check_budget
echo "build-wasm: the npm package: scripts/pack.sh (pkg/npm, pkg/polyscene-*.tgz)"
