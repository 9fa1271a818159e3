#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer run of the whole project
# (issue 9): configures build/asan with -DICD_SANITIZE=ON -DICD_ENABLE_ASSERTS=ON,
# builds everything, runs the whole CTest suite, then runs the runner's main
# job (icd-run experiments/scenes/two_spheres.json) with LeakSanitizer on.
# Prints the duration of each phase. Exit status 0 only when all is clean.
#
# Usage: scripts/run_sanitizers.sh [--jobs N=2] [--build DIR=build/asan]
#                                  [--no-preprocess] [--ctest-args "..."]
set -uo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build/asan"
jobs=2
preprocess=ON
ctest_args=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --jobs) jobs="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --no-preprocess) preprocess=OFF; shift ;;
    --ctest-args) ctest_args="$2"; shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "run_sanitizers.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done

# halt_on_error: the first report fails the test that triggered it.
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="${LSAN_OPTIONS:-}"

t0=$(date +%s)
phase() { echo "== $1 ($(( $(date +%s) - t0 )) s since start)"; }

phase "configure $build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DICD_SANITIZE=ON -DICD_ENABLE_ASSERTS=ON -DICD_BUILD_BENCHMARKS=OFF \
  -DICD_BUILD_PREPROCESS=$preprocess >/dev/null || exit 1
phase "build"
cmake --build "$build" -j"$jobs" || { echo "run_sanitizers.sh: build failed"; exit 1; }
t_build=$(( $(date +%s) - t0 ))

phase "ctest"
status=0
# shellcheck disable=SC2086
(cd "$build" && ctest --output-on-failure -j"$jobs" --timeout 1500 $ctest_args) || status=1
t_test=$(( $(date +%s) - t0 - t_build ))

phase "icd-run two_spheres.json with LeakSanitizer"
out="$build/asan_two_spheres"
rm -rf "$out"
if "$build/bin/icd-run" "$root/experiments/scenes/two_spheres.json" --out "$out" --quiet \
    >"$build/asan_icd_run.log" 2>&1; then
  echo "icd-run: clean (no sanitizer or leak report)"
else
  echo "icd-run: FAILED (see $build/asan_icd_run.log)"
  tail -n 40 "$build/asan_icd_run.log"
  status=1
fi
t_all=$(( $(date +%s) - t0 ))
echo "== durations: build ${t_build} s, ctest ${t_test} s, total ${t_all} s"
echo "== sanitizer run: $([[ $status == 0 ]] && echo CLEAN || echo FAILED)"
exit $status
