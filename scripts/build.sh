#!/usr/bin/env bash
# Configures and builds frictherm (Release) into ./build (through ccache when it is installed; without
# ccache, as on a fresh machine, a new build folder compiles the libraries against precompiled headers:
# FRICTHERM_PRECOMPILED_HEADERS in CMakeLists.txt, about a third less compile CPU).
#   scripts/build.sh            everything: library, program, tests, benchmarks, MPI parts when found
#                               (README command 2; turns tests, benchmarks and MPI on in an existing build)
#   scripts/build.sh --program  the `frictherm` program and what it links, nothing else (README command 1):
#                               a new build folder is configured without tests, benchmarks, the MPI
#                               parts and the Python package (so without looking for Python); an existing
#                               one keeps its configuration and builds the program only.
#   scripts/build.sh --program configure | compile   only that half (scripts/run_example.sh installs the
#                               figures' Python packages in between, during the compile)
# BUILD_DIR (default build) names the folder.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
mode=${1:-all}
step=${2:-both}
case "$mode" in all|--program) ;; *) echo "build.sh: the argument is --program or nothing, not '$mode'" >&2; exit 2;; esac
case "$step" in both|configure|compile) ;; *) echo "build.sh: after --program comes configure, compile or nothing, not '$step'" >&2; exit 2;; esac
jobs=$(nproc 2>/dev/null || echo 2)
launcher=()
if command -v ccache >/dev/null 2>&1; then
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$(dirname "$(pwd)")}
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
# SUNDIALS: the system's (libsundials-dev) when installed, else the Debian packages that
# scripts/install_deps.sh program unpacked into .deps/sundials (it says why). Named on every configure,
# so a build folder configured against the unpacked copy moves to the system's once command 2 installs it.
sundials_config=$(compgen -G "/usr/lib/*/cmake/sundials/SUNDIALSConfig.cmake" ||
                  compgen -G "$(pwd)/.deps/sundials/usr/lib/*/cmake/sundials/SUNDIALSConfig.cmake" || true)
sundials=()
if [ -n "$sundials_config" ]; then sundials=(-DSUNDIALS_DIR="$(dirname "$(echo "$sundials_config" | head -1)")"); fi
# FRICTHERM_ARCH=portable|auto|x86-64-v3|native scripts/build.sh: the instruction set (cmake/Arch.cmake;
# default portable: SSE2, the same bits on every machine; auto: AVX2 + FMA when this machine runs them,
# 9-15 % faster, outputs equal to round-off; docs/performance.md "Instruction sets").
arch=()
if [ -n "${FRICTHERM_ARCH:-}" ]; then arch=(-DFRICTHERM_ARCH="$FRICTHERM_ARCH"); fi
# A new build folder uses Ninja when installed (scripts/install_deps.sh installs ninja-build): unlike
# CMake's Makefiles, it compiles a library's sources while the libraries it links are still compiling,
# so both cores stay busy to the end (an existing folder keeps its generator).
generator=()
if [ ! -f "$build/CMakeCache.txt" ] && command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
if [ "$mode" = --program ]; then
  options=()
  if [ ! -f "$build/CMakeCache.txt" ]; then
    options=(-DFRICTHERM_BUILD_TESTS=OFF -DFRICTHERM_BUILD_BENCH=OFF -DFRICTHERM_WITH_MPI=OFF -DFRICTHERM_PYTHON=OFF)
  fi
  if [ "$step" != compile ]; then
    cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "${sundials[@]}" "${arch[@]}" "${options[@]}"
  fi
  if [ "$step" != configure ]; then cmake --build "$build" -j "$jobs" --target frictherm; fi
else
  cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "${sundials[@]}" "${arch[@]}" \
        -DFRICTHERM_BUILD_TESTS=ON -DFRICTHERM_BUILD_BENCH=ON -DFRICTHERM_WITH_MPI=ON -DFRICTHERM_PYTHON=ON
  cmake --build "$build" -j "$jobs"
fi
