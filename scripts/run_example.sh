#!/usr/bin/env bash
# README command 1: install the Debian packages the program needs, build the program, run the main
# example scene and draw it.
#   scripts/run_example.sh [SCENE.json] [FIELD]  (default: examples/sliding_block_heating.json, temperature)
# Leaves results/<scene>.h5 (+ .xdmf for ParaView) and results/<scene>_particles.png, _series.png.
# Installs and builds only what this needs (scripts/install_deps.sh build and plot, scripts/build.sh
# --program): no tests, benchmarks, ParaView, clang or sanitizer runtimes; command 2
# (scripts/run_tests.sh) adds them. The figures' Python packages (`plot`) install in the background
# during the compile, after CMake's configure: that configure does not look for Python at all
# (FRICTHERM_PYTHON=OFF), so what the install has reached when cannot change the build.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-examples/sliding_block_heating.json}
field=${2:-temperature}
name=$(basename "$scene" .json)
build=${BUILD_DIR:-build}
updated=0
scripts/install_deps.sh --check build || updated=1  # then the next line updates the package lists
scripts/install_deps.sh build
scripts/build.sh --program configure
mkdir -p "$build"
plot_log=$build/install_deps_plot.log
INSTALL_DEPS_UPDATED=$updated scripts/install_deps.sh plot >"$plot_log" 2>&1 &
plot_install=$!
echo "run_example: installing the figures' Python packages during the compile (log: $plot_log)"
scripts/build.sh --program compile || { wait "$plot_install" || true; exit 1; }
mkdir -p results
"$build/coupling/frictherm" run "$scene" -o "results/$name.h5" --force  # rerunning replaces the old result
if ! wait "$plot_install"; then
  cat "$plot_log" >&2
  echo "run_example: installing the figures' packages failed (scripts/install_deps.sh plot)" >&2; exit 1
fi
echo "run_example: the figures' packages are installed ($(head -n 1 "$plot_log"))"
/usr/bin/python3 examples/plot_run.py "results/$name.h5" --field "$field" -o "results/$name"
echo "wrote results/$name.h5, results/$name.xdmf, results/${name}_particles.png, results/${name}_series.png"
