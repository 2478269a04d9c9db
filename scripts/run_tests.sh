#!/usr/bin/env bash
# README command 2: install every Debian package (tests, MPI, PETSc, ParaView, clang), build everything
# and run the whole test suite with ctest.
#   scripts/run_tests.sh [extra ctest arguments, e.g. -L verification]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh all
scripts/build.sh
# A new build folder has no test costs yet, so ctest would start the tests in the order they were
# declared, the longest (the PBX convergence studies, the decomposed output read by VTK) among the
# last (measured: 847 s against 793 s of work per core). tests/ctest_cost_data.txt holds the seconds each test over 2 s took on the
# 2-core machine (ctest's own CTestCostData.txt of a full run); seeded once, ctest keeps it up to date.
costs="${BUILD_DIR:-build}/Testing/Temporary/CTestCostData.txt"
if [ ! -f "$costs" ]; then mkdir -p "$(dirname "$costs")" && cp tests/ctest_cost_data.txt "$costs"; fi
ctest --test-dir "${BUILD_DIR:-build}" --output-on-failure -j "$(nproc 2>/dev/null || echo 2)" "$@"
