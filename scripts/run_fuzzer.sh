#!/usr/bin/env bash
# Runs the scene fuzzer (tests/fuzz/fuzz_scene.cpp) built by scripts/run_checks.sh.
#   scripts/run_fuzzer.sh [BUILD_DIR (build-checks)] [SECONDS (60)] [extra libFuzzer flags]
# Seeds: examples/*.json and tests/fuzz/regressions/; new inputs go to BUILD_DIR/fuzz-corpus (kept
# between runs), findings to BUILD_DIR/fuzz-findings/ (crash-*, leak-*, timeout-*, oom-*). Limits per
# input: FUZZ_TIMEOUT s of wall time (-timeout, default 5: the instrumented build is ~10x slower than Release and CI machines are shared; the 1 s bound of a refusal is checked on the Release program by tests/robustness) and 400 MB resident (-rss_limit_mb; ASan shadow memory and quarantine included).
# Exit code non-zero when the fuzzer found something.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-checks}
seconds=${2:-60}
shift $(( $# < 2 ? $# : 2 ))
exe="$build/tests/fuzz/fuzz_scene"
if [ ! -x "$exe" ]; then
  echo "run_fuzzer: $exe not built (scripts/run_checks.sh builds it with clang)" >&2
  exit 2
fi
seeds="$build/fuzz-seeds"
mkdir -p "$build/fuzz-corpus" "$build/fuzz-findings" "$seeds"
cp examples/*.json "$seeds/"
cp tests/fuzz/regressions/* "$seeds/" 2>/dev/null || true
# A small quarantine always (also under run_checks.sh's ASAN_OPTIONS): with the default 256 MB it alone
# fills most of the 400 MB limit once the kept corpus has grown (measured: 242 MB quarantined, an
# out-of-memory "finding" while loading 873 inputs).
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}:quarantine_size_mb=32"
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
echo "run_fuzzer: $seconds s on $(ls "$seeds" | wc -l) seeds + $(ls "$build/fuzz-corpus" | wc -l) corpus inputs"
"$exe" "$build/fuzz-corpus" "$seeds" -dict=tests/fuzz/scene.dict -max_total_time="$seconds" -timeout="${FUZZ_TIMEOUT:-5}" \
       -rss_limit_mb=400 -max_len=16384 -print_final_stats=1 -artifact_prefix="$build/fuzz-findings/" "$@"
