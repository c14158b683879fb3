#!/usr/bin/env bash
# Reproduce the evaluation of Oliveira et al. (2016) into REPRODUCTION.md
# (figures in docs/repro/). Called by `make repro` after `scripts/setup.sh
# rust npm`. Bounded to about half an hour on 2 cores; prints progress.
#
# Peers (Open3D in .venv, pcl.js in benches/repro/node_modules, Debian's
# pcl-tools) are installed by scripts/setup-peers.sh when missing; a peer that
# cannot be installed or fails is skipped and the report says so.
#
# Environment knobs:
#   REPRO_NO_PEERS=1     do not install or run any peer
#   SKIP_PEERS=pcl,...   leave some peers out (python, pcljs, pcl)
#   REPRO_REPEAT_SIM=3   runs per simulated location for the fast methods
#   REPRO_REPEAT_REAL=5  runs per real scan for the fast methods
#   REPRO_SCANS=200      scans of the drive replayed for Fig. 14
#   REPRO_OUT=target/repro  working directory (clouds, raw results, logs)
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
export PATH="$HOME/.cargo/bin:$PATH"

OUT=${REPRO_OUT:-target/repro}
REP_SIM=${REPRO_REPEAT_SIM:-3}
REP_REAL=${REPRO_REPEAT_REAL:-5}
# pcl.js on the real scans runs as often as polyscene (~1-2 s a run), in the
# same rounds, so that both medians come from the same stretch of time.
PCLJS_REP_REAL=${REPRO_PCLJS_REPEAT_REAL:-$REP_REAL}
SCANS=${REPRO_SCANS:-200}
DATA=${REPRO_DATA:-$ROOT/www/data}
CLOUDS=$OUT/clouds
RES=$OUT/results
LOGS=$OUT/logs
T0=$(date +%s)

step() { echo; echo "== repro [$(($(date +%s) - T0)) s] $*"; }
die() { echo "repro: $*" >&2; exit 1; }

rm -rf "$RES" "$LOGS"
mkdir -p "$CLOUDS" "$RES" "$LOGS" docs/repro
: >"$RES/status.txt"
note() { echo "$*" | tee -a "$RES/status.txt"; }

step "peers: scripts/setup-peers.sh"
if [ "${REPRO_NO_PEERS:-0}" = 1 ]; then
  note "peers: REPRO_NO_PEERS=1, no peer is installed or run"
else
  scripts/setup-peers.sh all 2>&1 | tee "$LOGS/setup-peers.log" || true
fi

step "build: cargo build --release (CLI and examples/repro_native.rs)"
if ! cargo build --release --bin polyscene --example repro_native >"$LOGS/cargo.log" 2>&1; then
  tail -n 20 "$LOGS/cargo.log"
  die "the native build failed (see $LOGS/cargo.log)"
fi
tail -n 1 "$LOGS/cargo.log"
BIN=${CARGO_TARGET_DIR:-target}/release/polyscene
NATIVE=${CARGO_TARGET_DIR:-target}/release/examples/repro_native

step "build: scripts/build-wasm.sh (pkg/node for the wasm rows)"
if scripts/build-wasm.sh >"$LOGS/build-wasm.log" 2>&1; then
  tail -n 1 "$LOGS/build-wasm.log"
  WASM=1
else
  note "wasm: scripts/build-wasm.sh failed (see $LOGS/build-wasm.log); the wasm rows are skipped"
  tail -n 5 "$LOGS/build-wasm.log"
  WASM=0
fi

step "data: five 10-scan locations of the simulated street drive + the two real scans"
"$NATIVE" export "$CLOUDS" --seed 1 --starts 0,20,40,60,80 --data "$DATA" || die "export failed"

step "timing (native): gpp1, gpp2, gpp2 convex; $REP_SIM runs per location, $REP_REAL per real scan, interleaved"
"$NATIVE" detect "$CLOUDS" "$RES" --repeat-sim "$REP_SIM" --repeat-real "$REP_REAL" \
  --variants gpp1,gpp2,gpp2-convex 2>&1 | tee "$LOGS/native.log" || die "native detection failed"

step "timing (one Node process): polyscene wasm (pkg/node) and pcl.js RANSAC x15"
node_args=("$CLOUDS" "$RES" --repeat-sim "$REP_SIM" --repeat-real "$REP_REAL" --pcljs-repeat-sim 1 --pcljs-repeat-real "$PCLJS_REP_REAL")
[ "$WASM" = 1 ] || node_args+=(--no-wasm)
if [ "${REPRO_NO_PEERS:-0}" = 1 ] || [[ ",${SKIP_PEERS:-}," == *",pcljs,"* ]]; then node_args+=(--no-pcljs); fi
node benches/repro/wasm_peers.cjs "${node_args[@]}" 2>&1 | tee "$LOGS/node.log" ||
  note "node: benches/repro/wasm_peers.cjs failed (see $LOGS/node.log)"

if [ "${REPRO_NO_PEERS:-0}" != 1 ]; then
  step "timing (peers): Open3D BPA, Poisson, segment_plane+DBSCAN, planar patches; PCL greedy triangulation"
  PY=.venv/bin/python
  if [ -x "$PY" ] && "$PY" -c "import numpy" 2>/dev/null; then
    "$PY" benches/repro/peers.py "$CLOUDS" "$RES" --voxel 0.1 --repeat-real 3 2>&1 | tee "$LOGS/peers.log" ||
      note "peers: benches/repro/peers.py failed (see $LOGS/peers.log)"
  else
    note "peers: .venv with numpy is missing (scripts/setup-peers.sh python): the Open3D and PCL rows are skipped"
  fi
fi

step "Fig. 14: replay $SCANS scans of the drive with and without expansion"
"$BIN" simulate street --seed 1 --scans "$SCANS" --out "$OUT/drive" || die "simulate failed"
for mode in exp noexp; do
  flag=(); [ "$mode" = noexp ] && flag=(--no-expansion)
  "$BIN" replay "$OUT/drive" "${flag[@]}" --report "$RES/replay_$mode.jsonl" --out "$RES/replay_$mode.json" ||
    die "replay $mode failed"
  echo "  replay ($mode): $(tail -n 1 "$RES/replay_$mode.jsonl" | cut -c1-160)..."
  "$BIN" eval "$RES/replay_$mode.json" "$OUT/drive" >"$RES/replay_${mode}_eval.txt" 2>&1 ||
    note "eval of the $mode map failed"
done

step "accuracy: one-sided Hausdorff, completeness, precision/recall of every output"
PYR=python3
[ -x .venv/bin/python ] && PYR=.venv/bin/python
"$PYR" benches/repro/report.py jobs "$CLOUDS" "$RES" >"$RES/jobs.json" || die "cannot list the evaluation jobs"
"$NATIVE" eval "$CLOUDS" "$RES/jobs.json" "$RES/eval.json" 2>&1 | tee "$LOGS/eval.log" || die "evaluation failed"

step "report: REPRODUCTION.md and docs/repro/"
{
  echo "cpu=$(lscpu | sed -n 's/^Model name:[[:space:]]*//p' | head -n 1)"
  echo "cores=$(nproc)"
  echo "mem=$(free -g | awk '/^Mem:/ {print $2 " GiB"}')"
  echo "rustc=$(rustc --version)"
  echo "node=$(node --version)"
  rev=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
  [ -n "$(git status --porcelain -- src Cargo.toml Cargo.lock 2>/dev/null)" ] && rev="$rev (with uncommitted changes in src/)"
  echo "rev=$rev"
  echo "os=$(. /etc/os-release && echo "$PRETTY_NAME")"
  echo "seconds=$(($(date +%s) - T0))"
  echo "date=$(date -u +%Y-%m-%d)"
  echo "rep_sim=$REP_SIM"
  echo "rep_real=$REP_REAL"
  echo "pcljs_rep_real=$PCLJS_REP_REAL"
  echo "scans=$SCANS"
} >"$RES/env.txt"
"$PYR" benches/repro/report.py render "$CLOUDS" "$RES" REPRODUCTION.md docs/repro || die "report failed"
step "done in $(($(date +%s) - T0)) s: REPRODUCTION.md, docs/repro/"
