#!/usr/bin/env bash
# README command 2: install every Debian package (tests, MPI, PETSc, ParaView, clang), build everything
# and run the whole test suite with ctest.
#   scripts/run_tests.sh [extra ctest arguments, e.g. -L verification]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh all
scripts/build.sh
ctest --test-dir "${BUILD_DIR:-build}" --output-on-failure -j "$(nproc 2>/dev/null || echo 2)" "$@"
