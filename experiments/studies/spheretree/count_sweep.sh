#!/usr/bin/env bash
# count_sweep.sh BINARY LOGDIR [sphere_tree_table options...]
# Error against sphere count: builds the tree with each list of per-level
# caps in CAPS (default: depth 3 with 256, 350, 445 and 512 leaves, depth 4
# with 600, 700 and 800) for the perturbations in EPS (default "0 1e-12
# -1e-12"; perturb_sweep.sh), writes LOGDIR/caps_<list>.log and prints the
# leaf-level summary of each (median and range over the builds). A trailing
# "--models bunny" picks the bunny.
set -euo pipefail
bin=$1
logdir=$2
shift 2
here=$(dirname "$0")
mkdir -p "$logdir"
export EPS=${EPS:-0 1e-12 -1e-12}
for caps in ${CAPS:-1,8,64,256 1,8,64,350 1,8,64,445 1,8,64,512 1,8,64,512,600 1,8,64,512,700 1,8,64,512,800}; do
  echo "## caps $caps"
  "$here/perturb_sweep.sh" "$bin" "$logdir/caps_${caps//,/_}.log" --caps "$caps" "$@"
done
