#!/usr/bin/env bash
# Command 1 of the README: installs what is missing, builds every program in
# Release, fetches the real meshes, runs the main job (the default
# bunny-dragon scene) into results/main and draws its pictures there
# (scripts/plot_run.py: run.gif, frames.png, tree_levels.png).
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
# The source the programs were built from, beside icd-main's version.txt.
if describe=$(git -C "$root" describe --always --dirty 2>/dev/null); then
  echo "git describe: $describe" >> "$results/version.txt"
fi
/usr/bin/python3 "$root/scripts/plot_run.py" "$results"
