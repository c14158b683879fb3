#!/usr/bin/env bash
# Benchmarks, on demand (never part of make test): criterion natively (one
# thread), then the wasm build under Node. Prints tables; see BENCHMARKS.md.
# Not run here (hours on a shared machine): the soak of long drives,
#   cargo run --release --example soak -- new 10000   (and: loop 10000)
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; rustc $(rustc --version | awk '{print $2}')"
cargo bench --bench detect -- --noplot
cargo bench --bench scenario -- --noplot
cargo run --release --quiet --example drive -- street 100
scripts/build-wasm.sh
node benches/wasm_bench.mjs
