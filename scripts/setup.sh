#!/usr/bin/env bash
# Install what the build and the tests need, only when missing:
#   rust    - the wasm32 target, wasm-bindgen-cli (same version as Cargo.lock), wasm-pack
#   npm     - www/node_modules (three, lil-gui, playwright-core, binaryen for wasm-opt,
#             fast-check for the fuzz test of the JS boundary, maplibre-gl, proj4 and
#             @loaders.gl/las for the map page and the tests of js/);
#             tests/package/tools/node_modules (vite, esbuild, typescript: the
#             package test builds a scratch project with them)
#   browser - Debian's chromium for the end-to-end test
#   all     - everything
# Nothing is downloaded from outside the package registries.
set -euo pipefail
cd "$(dirname "$0")/.."

WASM_PACK_VERSION=0.15.1
want=("$@")
[ ${#want[@]} -eq 0 ] && want=(all)
has() { for w in "${want[@]}"; do [ "$w" = "$1" ] || [ "$w" = all ] && return 0; done; return 1; }

export PATH="$HOME/.cargo/bin:$PATH"

if has rust; then
  if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    echo "setup: adding the wasm32-unknown-unknown target"
    rustup target add wasm32-unknown-unknown
  fi
  # wasm-bindgen-cli must equal the wasm-bindgen version pinned in Cargo.toml.
  bindgen=$(sed -n 's/^wasm-bindgen = "=\([0-9.]*\)"/\1/p' Cargo.toml)
  if [ "$(wasm-bindgen --version 2>/dev/null | awk '{print $2}')" != "$bindgen" ]; then
    echo "setup: installing wasm-bindgen-cli $bindgen (a few minutes, once)"
    cargo install wasm-bindgen-cli --version "$bindgen" --force
  fi
  if [ "$(wasm-pack --version 2>/dev/null | awk '{print $2}')" != "$WASM_PACK_VERSION" ]; then
    echo "setup: installing wasm-pack $WASM_PACK_VERSION (a few minutes, once)"
    cargo install wasm-pack --version "$WASM_PACK_VERSION" --locked --force
  fi
fi

if has npm; then
  if [ ! -f www/node_modules/.package-lock.json ] || [ www/package-lock.json -nt www/node_modules/.package-lock.json ]; then
    echo "setup: installing npm packages in www/"
    (cd www && npm ci --no-audit --no-fund --loglevel=error)
  fi
  tools=tests/package/tools
  if [ ! -f $tools/node_modules/.package-lock.json ] || [ $tools/package-lock.json -nt $tools/node_modules/.package-lock.json ]; then
    echo "setup: installing vite, esbuild and typescript in $tools/"
    (cd $tools && npm ci --no-audit --no-fund --loglevel=error)
  fi
fi

if has browser; then
  if [ ! -x /usr/bin/chromium ]; then
    echo "setup: installing Debian's chromium (about 90 s, once)"
    export DEBIAN_FRONTEND=noninteractive
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
    $SUDO apt-get update -qq
    $SUDO apt-get install -y -qq chromium >/dev/null
  fi
fi
