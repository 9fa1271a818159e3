#!/usr/bin/env bash
# Command 2 of the README: installs what is missing, builds the test
# configuration (Release with asserts on) and runs the whole suite with CTest.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install_deps.sh"
"$root/scripts/fetch_meshes.sh"
"$root/scripts/fetch_corpus.sh"
build="$root/build/test"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DICD_ENABLE_ASSERTS=ON -DICD_BUILD_TESTS=ON -DICD_BUILD_BENCHMARKS=ON >/dev/null
cmake --build "$build" -j2
cd "$build" && ctest --output-on-failure -j2 "$@"
