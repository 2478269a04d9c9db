#!/usr/bin/env bash
# README command 1: install the Debian packages the program needs, build the program, run the main
# example scene and draw it.
#   scripts/run_example.sh [SCENE.json] [FIELD]  (default: examples/sliding_block_heating.json, temperature)
# Leaves results/<scene>.h5 (+ .xdmf for ParaView) and results/<scene>_particles.png, _series.png.
# Installs and builds only what this needs (scripts/install_deps.sh program, scripts/build.sh --program):
# no tests, benchmarks, ParaView, clang or sanitizer runtimes; command 2 (scripts/run_tests.sh) adds them.
# The packages for the figures (install_deps.sh plot: numpy, h5py, matplotlib) are installed in the
# background while the program compiles, which needs only install_deps.sh build (issue 33).
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-examples/sliding_block_heating.json}
field=${2:-temperature}
name=$(basename "$scene" .json)
build=${BUILD_DIR:-build}
updated=0
scripts/install_deps.sh --check build || updated=1  # the install below runs apt-get update
scripts/install_deps.sh build
plot_pid=
plot_log=$(mktemp)
if ! scripts/install_deps.sh --check plot; then
  [ "$(id -u)" -eq 0 ] || sudo -v  # the background install must not ask for a password
  INSTALL_DEPS_UPDATED=$updated scripts/install_deps.sh plot > "$plot_log" 2>&1 &
  plot_pid=$!
  echo "run_example: installing the packages for the figures in the background (log: $plot_log)"
fi
scripts/build.sh --program
if [ -n "$plot_pid" ]; then
  wait "$plot_pid" || { cat "$plot_log"; echo "run_example: installing the packages for the figures failed" >&2; exit 1; }
  echo "run_example: the packages for the figures are installed"
fi
rm -f "$plot_log"
mkdir -p results
"$build/coupling/frictherm" run "$scene" -o "results/$name.h5" --force  # rerunning replaces the old result
/usr/bin/python3 examples/plot_run.py "results/$name.h5" --field "$field" -o "results/$name"
echo "wrote results/$name.h5, results/$name.xdmf, results/${name}_particles.png, results/${name}_series.png"
