#!/usr/bin/env bash
# Serve the demo page (www/) on http://127.0.0.1:PORT (default 8080), loopback only.
#   scripts/serve.sh [PORT]
# www/node_modules (three.js, lil-gui) and www/pkg (the wasm package, made by
# scripts/build-wasm.sh) are served from inside www/, and the package's JS
# modules (js/, e.g. js/geo.mjs for the map page) under /js/, so the pages need
# no internet. Pages: / (the 3D view) and /map.html (the map dashboard).
set -euo pipefail
cd "$(dirname "$0")/.."
PORT="${1:-${PORT:-8080}}"

for f in polyscene.js polyscene_bg.wasm polyscene_sim.js polyscene_sim_bg.wasm; do
  if [ ! -f "www/pkg/$f" ]; then
    echo "serve: www/pkg/$f is missing; run scripts/build-wasm.sh (or make demo) first" >&2
    exit 1
  fi
done
if [ ! -f www/node_modules/three/build/three.module.js ] || [ ! -f www/node_modules/lil-gui/dist/lil-gui.esm.js ] ||
  [ ! -f www/node_modules/maplibre-gl/dist/maplibre-gl.mjs ] || [ ! -f www/node_modules/proj4/dist/proj4-src.js ]; then
  echo "serve: www/node_modules is incomplete; run scripts/setup.sh npm (or make demo) first" >&2
  exit 1
fi
exec node www/tools/static-server.mjs --root www --mount /js/=js --port "$PORT" --host 127.0.0.1
