#!/usr/bin/env bash
# README command 1: install the Debian packages the program needs, build the program, run the main
# example scene and draw it.
#   scripts/run_example.sh [SCENE.json] [FIELD]  (default: examples/sliding_block_heating.json, temperature)
# Leaves results/<scene>.h5 (+ .xdmf for ParaView) and results/<scene>_particles.png, _series.png.
# Installs and builds only what this needs (scripts/install_deps.sh program, scripts/build.sh --program):
# no tests, benchmarks, ParaView, clang or sanitizer runtimes; command 2 (scripts/run_tests.sh) adds them.
# (Installing the figures' packages in the background during the compile was tried for issue 33 and not
# kept: CMake's configure then raced the Python install, and whether it found Python decided whether
# command 2's reconfigure built the bindings.)
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-examples/sliding_block_heating.json}
field=${2:-temperature}
name=$(basename "$scene" .json)
build=${BUILD_DIR:-build}
scripts/install_deps.sh program
scripts/build.sh --program
mkdir -p results
"$build/coupling/frictherm" run "$scene" -o "results/$name.h5" --force  # rerunning replaces the old result
/usr/bin/python3 examples/plot_run.py "results/$name.h5" --field "$field" -o "results/$name"
echo "wrote results/$name.h5, results/$name.xdmf, results/${name}_particles.png, results/${name}_series.png"
