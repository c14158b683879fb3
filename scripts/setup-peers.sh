#!/usr/bin/env bash
# Install the peers of the reproduction report (scripts/repro.sh), only when
# missing; every step may fail without failing the script (the report then
# skips that peer and says so):
#   python - .venv with open3d 0.20.0 (peer) plus numpy and matplotlib (figures)
#   pcljs  - benches/repro/node_modules/pcl.js 1.16.0 (PCL compiled to wasm)
#   pcl    - Debian's pcl-tools (pcl_gp3_surface: greedy projection triangulation)
#   all    - everything (default)
# Only the package registries are used (PyPI, npm, Debian). `make test` never
# needs any of this. Set SKIP_PEERS=pcl,pcljs,... to leave some out.
set -uo pipefail
cd "$(dirname "$0")/.."

OPEN3D_VERSION=0.20.0
PCLJS_VERSION=1.16.0
want=("$@")
[ ${#want[@]} -eq 0 ] && want=(all)
has() {
  case ",${SKIP_PEERS:-}," in *",$1,"*) return 1 ;; esac
  for w in "${want[@]}"; do [ "$w" = "$1" ] || [ "$w" = all ] && return 0; done
  return 1
}
say() { echo "setup-peers: $*"; }

if has python; then
  py=.venv/bin/python
  if [ ! -x "$py" ]; then
    say "creating .venv"
    python3 -m venv .venv || say "cannot create .venv (python3 -m venv failed): Open3D rows and PNG figures will be skipped"
  fi
  if [ -x "$py" ]; then
    if ! "$py" -c "import numpy, matplotlib" 2>/dev/null; then
      say "installing numpy and matplotlib into .venv"
      "$py" -m pip install -q --disable-pip-version-check numpy matplotlib ||
        say "pip could not install matplotlib: figures fall back to SVG"
    fi
    have=$("$py" -c "import importlib.metadata as m; print(m.version('open3d'))" 2>/dev/null || true)
    if [ "$have" != "$OPEN3D_VERSION" ]; then
      say "installing open3d $OPEN3D_VERSION into .venv (about a minute, once)"
      "$py" -m pip install -q --disable-pip-version-check "open3d==$OPEN3D_VERSION" ||
        say "pip could not install open3d $OPEN3D_VERSION: the Open3D rows will be skipped"
    fi
    # open3d's wheel links libGL, libEGL, libgomp, TBB and libusb; a headless
    # machine may lack them (a fresh one here lacked TBB and libusb).
    if "$py" -c "import importlib.metadata as m; m.version('open3d')" 2>/dev/null &&
       ! "$py" -c "import open3d" 2>/dev/null; then
      say "open3d does not import; installing the shared libraries it needs (libgl1, libegl1, libgomp1, libtbb12, libusb-1.0-0)"
      SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
      { $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libgl1 libegl1 libgomp1 libtbb12 libusb-1.0-0 >/dev/null; } ||
        say "apt-get failed"
      "$py" -c "import open3d" 2>/dev/null || say "open3d still does not import: the Open3D rows will be skipped"
    fi
  fi
fi

if has pcljs; then
  pj=benches/repro/node_modules/pcl.js/package.json
  if [ "$(node -p "require('./$pj').version" 2>/dev/null)" != "$PCLJS_VERSION" ]; then
    say "installing pcl.js $PCLJS_VERSION into benches/repro/node_modules"
    (cd benches/repro && npm install --no-audit --no-fund --loglevel=error --no-save "pcl.js@$PCLJS_VERSION") ||
      say "npm could not install pcl.js: the pcl.js row will be skipped"
  fi
fi

if has pcl; then
  if ! command -v pcl_gp3_surface >/dev/null; then
    say "installing Debian's pcl-tools (pcl_gp3_surface; a few minutes, once)"
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
    export DEBIAN_FRONTEND=noninteractive
    { $SUDO apt-get update -qq && timeout 900 $SUDO apt-get install -y -qq --no-install-recommends pcl-tools >/dev/null; } ||
      say "apt-get could not install pcl-tools: the PCL greedy triangulation row will be skipped"
  fi
fi
exit 0
