#!/usr/bin/env bash
# A/B of the fem code of a previous commit against the working tree, in one
# process, frame-interleaved (ab_main.cpp). The previous commit's fem/ and
# mesh/core/ sources are compiled with the namespace icd renamed to icd_old;
# the working tree's libraries come from an existing build directory. The
# commit must have the layered layout (mesh/core, <icd/...> includes).
# Usage: experiments/studies/fem/ab_previous/run_ab.sh <commit> [build dir] [mesh 0|1] [repetitions] [check interval]
# (run from the repository root; compiles with 2 jobs into /tmp/icd_fem_ab_<commit>).
set -euo pipefail
commit=${1:?usage: run_ab.sh <commit> [build dir] [mesh] [repetitions] [check interval]}
build=$(realpath "${2:-build-fem}")
shift $(( $# < 2 ? $# : 2 ))
here=$(cd "$(dirname "$0")" && pwd)
root=$(git rev-parse --show-toplevel)
work=/tmp/icd_fem_ab_$(git rev-parse --short "$commit")
flags="-O3 -DNDEBUG -UNDEBUG -fopenmp -std=c++20 -isystem /usr/include/eigen3 -isystem /usr/include/suitesparse"
mkdir -p "$work/src" "$work/obj"
if [ ! -f "$work/obj/done" ]; then
  git -C "$root" archive "$commit" fem mesh/core | tar x -C "$work/src"
  mkdir -p "$work/inc/icd" && ln -sfn "$work/src/fem" "$work/inc/icd/fem" &&
    ln -sfn "$work/src/mesh" "$work/inc/icd/mesh" && cp "$build/generated/icd/config.hpp" "$work/inc/icd/"
  ls "$work"/src/fem/*.cpp "$work"/src/mesh/core/*.cpp |
    xargs -P2 -I{} sh -c "g++ $flags -Dicd=icd_old -I$work/inc -c {} -o $work/obj/\$(basename {} .cpp).o"
  touch "$work/obj/done"
fi
# ab_variant.cpp lives outside both trees, so that its quoted includes find the -I tree only.
g++ $flags -Dicd=icd_old -DVARIANT=old -I"$work/inc" -c "$here/ab_variant.cpp" -o "$work/ab_old.o"
g++ $flags -DVARIANT=new -I"$build/generated" -c "$here/ab_variant.cpp" -o "$work/ab_new.o"
g++ $flags -c "$here/ab_main.cpp" -o "$work/ab_main.o"
g++ -fopenmp "$work/ab_main.o" "$work/ab_old.o" "$work/ab_new.o" "$work"/obj/*.o \
  "$build/fem/libicd_fem.a" "$build/mesh/core/libicd_mesh_core.a" \
  -lcholmod -lsuitesparseconfig -lmetis -o "$work/ab_main"
"$work/ab_main" "$@"
