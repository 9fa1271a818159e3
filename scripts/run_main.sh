#!/usr/bin/env bash
# Command 1 of the README: installs what is missing, builds every program in
# Release, fetches the real meshes and runs the main job (the default
# bunny-dragon scene).
# Extra arguments are passed to the main job.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install_deps.sh"
"$root/scripts/fetch_meshes.sh"
build="$root/build/release"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DICD_BUILD_TESTS=OFF -DICD_BUILD_BENCHMARKS=ON >/dev/null
# Every program the README names (all land in build/release/bin).
cmake --build "$build" -j2
results="$root/results/main"
"$build/bin/icd-main" --out "$results" "$@"
