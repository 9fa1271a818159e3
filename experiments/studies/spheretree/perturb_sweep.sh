#!/usr/bin/env bash
# perturb_sweep.sh BINARY LOG [sphere_tree_table options...]
# Builds the dragon tree for the mesh scaled by 1 + E, E in {0, 1, -1, 2, 3,
# -3, 5} x 1e-12 (a last-bit change of the input flips early greedy decisions
# of the build; see results/README.md, "Reproduce"),
# one build after the other, appends every run's output to LOG and prints the
# leaf-level summary (median and range over the 7 builds; summarize_sweep.py).
# EPS="0 1e-12" overrides the list of E; a later "--models bunny" in the
# options overrides the model.
set -euo pipefail
bin=$1
log=$2
shift 2
out=$(mktemp -d)
: > "$log"
for e in ${EPS:-0 1e-12 -1e-12 2e-12 3e-12 -3e-12 5e-12}; do
  echo "## perturb $e" >> "$log"
  "$bin" "$out" --models dragon --octree 0 --time-limit 600 --perturb "$e" "$@" >> "$log" 2>&1
done
rm -rf "$out"
/usr/bin/python3 "$(dirname "$0")/summarize_sweep.py" "$log"
