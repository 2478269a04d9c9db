#!/usr/bin/env bash
# Runs the fuzzers built by scripts/run_checks.sh: the scene fuzzer (tests/fuzz/fuzz_scene.cpp) and the
# checkpoint fuzzer (tests/fuzz/fuzz_checkpoint.cpp), sharing the time: half each.
#   scripts/run_fuzzer.sh [BUILD_DIR (build-checks)] [SECONDS (60)] [extra libFuzzer flags]
# FUZZ_TARGETS="scene checkpoint" (default both) chooses them; the one that runs alone gets all the time.
# Seeds: examples/*.json and tests/fuzz/regressions/ (scene); tests/fuzz/checkpoint_regressions/
# (checkpoint: mutations of a seed checkpoint the target writes itself). New inputs go to
# BUILD_DIR/fuzz-corpus and BUILD_DIR/fuzz-corpus-checkpoint (kept between runs), findings to
# BUILD_DIR/fuzz-findings/ (crash-*, leak-*, timeout-*, oom-*; the checkpoint fuzzer's prefixed
# checkpoint-). Limits per input: FUZZ_TIMEOUT s of wall time (-timeout, default 5: the instrumented build is ~10x slower than Release and CI machines are shared; the 1 s bound of a refusal is checked on the Release program by tests/robustness) and 400 MB resident (-rss_limit_mb; ASan shadow memory and quarantine included).
# Exit code non-zero when a fuzzer found something.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-checks}
seconds=${2:-60}
shift $(( $# < 2 ? $# : 2 ))
targets=${FUZZ_TARGETS:-scene checkpoint}
count=$(echo $targets | wc -w)
share=$(( seconds / count ))
if [ "$share" -lt 1 ]; then share=1; fi
for t in $targets; do
  exe="$build/tests/fuzz/fuzz_$t"
  if [ ! -x "$exe" ]; then
    echo "run_fuzzer: $exe not built (scripts/run_checks.sh builds it with clang)" >&2
    exit 2
  fi
done
mkdir -p "$build/fuzz-findings"
# A small quarantine always (also under run_checks.sh's ASAN_OPTIONS): with the default 256 MB it alone
# fills most of the 400 MB limit once the kept corpus has grown (measured: 242 MB quarantined, an
# out-of-memory "finding" while loading 873 inputs).
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}:quarantine_size_mb=32"
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
for t in $targets; do
  case "$t" in
    scene)
      seeds="$build/fuzz-seeds"
      mkdir -p "$build/fuzz-corpus" "$seeds"
      cp examples/*.json "$seeds/"
      cp tests/fuzz/regressions/* "$seeds/" 2>/dev/null || true
      echo "run_fuzzer: scene, $share s on $(ls "$seeds" | wc -l) seeds + $(ls "$build/fuzz-corpus" | wc -l) corpus inputs"
      "$build/tests/fuzz/fuzz_scene" "$build/fuzz-corpus" "$seeds" -dict=tests/fuzz/scene.dict -max_total_time="$share" \
        -timeout="${FUZZ_TIMEOUT:-5}" -rss_limit_mb=400 -max_len=16384 -print_final_stats=1 \
        -artifact_prefix="$build/fuzz-findings/" "$@"
      ;;
    checkpoint)
      seeds="$build/fuzz-seeds-checkpoint"
      mkdir -p "$build/fuzz-corpus-checkpoint" "$seeds"
      cp tests/fuzz/checkpoint_regressions/* "$seeds/"
      echo "run_fuzzer: checkpoint, $share s on $(ls "$seeds" | wc -l) seeds + $(ls "$build/fuzz-corpus-checkpoint" | wc -l) corpus inputs"
      # 8 mutations of 12 bytes at most are read: longer inputs only cost time.
      "$build/tests/fuzz/fuzz_checkpoint" "$build/fuzz-corpus-checkpoint" "$seeds" -max_total_time="$share" \
        -timeout="${FUZZ_TIMEOUT:-5}" -rss_limit_mb=400 -max_len=96 -print_final_stats=1 \
        -artifact_prefix="$build/fuzz-findings/checkpoint-" "$@"
      ;;
    *) echo "run_fuzzer: unknown target '$t' (scene, checkpoint)" >&2; exit 2 ;;
  esac
done
