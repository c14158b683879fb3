#!/usr/bin/env bash
# Every test of the project, in order of cost. Assumes `scripts/setup.sh all`
# ran (make test does that first).
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
# The wasm's size budget is a test: above it scripts/build-wasm.sh fails (the
# demo build only warns).
export SIZE_BUDGET_STRICT=1
step() { printf '\n==> %s\n' "$*"; }

step "format"
cargo fmt --check
step "lint (native, all targets)"
cargo clippy --all-targets -- -D warnings
step "lint (wasm32 library: the main binding, the simulator's, both)"
cargo clippy --lib --target wasm32-unknown-unknown -- -D warnings
cargo clippy --lib --target wasm32-unknown-unknown --no-default-features --features wasm-sim -- -D warnings
cargo clippy --lib --target wasm32-unknown-unknown --all-features -- -D warnings
step "the library compiles for wasm32-unknown-unknown"
cargo build --lib --target wasm32-unknown-unknown
step "docs"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --lib --quiet
step "Rust tests (release: they run detection on clouds of 10^5-10^7 points)"
cargo test --release
step "JS package: wasm-pack test --node and node --test against pkg/node"
scripts/test-js.sh
step "browser end-to-end test of the page"
scripts/test-e2e.sh
step "the npm package: installed from its tarball, in Node, tsc, Vite and esbuild (Chromium)"
scripts/test-package.sh
