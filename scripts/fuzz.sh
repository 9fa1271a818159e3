#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz/) with clang-14 in build-fuzz and
# runs each for a bounded time, starting from the seed corpus in
# tests/fuzz/corpus/<target>/. Crashing inputs are kept in
# build-fuzz/fuzz-out/crashes/<target>/ (copy them to tests/fuzz/regressions/
# once fixed). Prints executions and coverage (libFuzzer cov/ft) per target.
#
# Usage: scripts/fuzz.sh [--seconds N] [--targets "off obj ..."] [--no-build]
#                        [--parallel K] [--keep-going]
#   --seconds N    run time per target (default 60)
#   --parallel K   run K targets at the same time (default 1)
#   --keep-going   libFuzzer fork mode: record a finding and go on fuzzing
#                  (default: a target stops at its first finding)
# Exit status: 0 when no target found anything, 1 otherwise.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${ICD_FUZZ_BUILD:-$root/build-fuzz}"
seconds=60
targets="off obj ply stl vtu sph bundle scene"
do_build=1
parallel=1
mode=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --targets) targets="$2"; shift 2 ;;
    --no-build) do_build=0; shift ;;
    --parallel) parallel="$2"; shift 2 ;;
    --keep-going) mode=(-fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1); shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "fuzz.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done

if [[ $do_build == 1 ]]; then
  flags="-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer -g"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_CXX_COMPILER=clang++-14 -DICD_BUILD_PREPROCESS=OFF -DICD_FUZZ=ON \
    -DICD_ENABLE_ASSERTS=ON -DICD_BUILD_BENCHMARKS=OFF \
    -DCMAKE_CXX_FLAGS="$flags" >/dev/null
  cmake --build "$build" -j2 --target $(for t in $targets; do echo "fuzz_$t"; done)
fi

out="$build/fuzz-out"
mkdir -p "$out"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}"

run_one() {
  local t="$1"
  local corpus="$out/corpus/$t" crashes="$out/crashes/$t" log="$out/$t.log"
  mkdir -p "$corpus" "$crashes"
  if [[ "$t" == bundle && ! -e "$root/tests/fuzz/corpus/bundle/valid.icdb" ]]; then
    ICD_FUZZ_SEED_OUT="$root/tests/fuzz/corpus/bundle" "$build/tests/fuzz/fuzz_bundle" -runs=0 \
      >/dev/null 2>&1 || true
  fi
  "$build/tests/fuzz/fuzz_$t" "${mode[@]}" "$corpus" "$root/tests/fuzz/corpus/$t" \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="$crashes/" \
    >"$log" 2>&1 || true
}

pids=()
for t in $targets; do
  run_one "$t" &
  pids+=($!)
  if (( ${#pids[@]} >= parallel )); then wait "${pids[0]}"; pids=("${pids[@]:1}"); fi
done
for p in "${pids[@]}"; do wait "$p"; done

status=0
printf '%-8s %12s %8s %8s %8s %s\n' target execs cov ft corpus findings
for t in $targets; do
  log="$out/$t.log"
  # (no stat lines in fork mode or after a crash: never let a missing match stop the summary)
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1 || true)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)
  [[ -z "$execs" ]] && execs=$(grep -oE '^#[0-9]+' <<<"$last" | tr -d '#' || true)
  cov=$(grep -o 'cov: [0-9]*' <<<"$last" | grep -o '[0-9]*' || true)
  ft=$(grep -o 'ft: [0-9]*' <<<"$last" | grep -o '[0-9]*' || true)
  files=$(find "$out/corpus/$t" -type f | wc -l)
  found=$(find "$out/crashes/$t" -type f | wc -l)
  printf '%-8s %12s %8s %8s %8s %s\n' "$t" "${execs:-?}" "${cov:-?}" "${ft:-?}" "$files" "$found"
  if (( found > 0 )) || grep -q 'ERROR: libFuzzer\|SUMMARY: .*Sanitizer\|FUZZ FINDING' "$log"; then
    status=1
    echo "  findings in $out/crashes/$t (log: $log)"
  fi
done
exit $status
