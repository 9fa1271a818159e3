#!/usr/bin/env bash
# Preprocesses every corpus mesh (scripts/fetch_corpus.sh) with icd-preprocess
# at its defaults and writes one table (corpus_table.md, corpus.csv) to OUT.
#   experiments/studies/preprocess/run_corpus.sh BIN_DIR OUT [--subset] [--shard K/N] [-- EXTRA ICD-PREPROCESS ARGS]
# --subset: four small meshes only (the CTest PreprocessCorpus.Subset).
# --shard K/N: only the meshes K, K+N, K+2N, ... (0-based) of the list, to
# run N processes side by side, each with its own OUT; merge the tables with
#   corpus_table.py MERGED MESH... after copying every OUT/logs into MERGED/logs. Exit
# status 0 when every mesh succeeded or was refused with a message (no limit
# exceeded without a message, no crash), 1 when the corpus is not fetched
# (scripts/run_tests.sh fetches it).
set -uo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
bin="$1"; out="$2"; shift 2
subset=0; shard=0; shards=1; extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --subset) subset=1 ;;
    --shard)
      shift
      if ! [[ "${1:-}" =~ ^([0-9]+)/([1-9][0-9]*)$ ]] || [ "${BASH_REMATCH[1]}" -ge "${BASH_REMATCH[2]}" ]; then
        echo "run_corpus.sh: --shard needs K/N with 0 <= K < N, got '${1:-}'" >&2; exit 2
      fi
      shard=${BASH_REMATCH[1]}; shards=${BASH_REMATCH[2]} ;;
    --) shift; extra=("$@"); break ;;
    *) echo "run_corpus.sh: unknown argument $1" >&2; exit 2 ;;
  esac
  shift
done
corpus="$root/data/corpus"
if [ ! -d "$corpus" ]; then
  echo "run_corpus.sh: $corpus missing (run scripts/fetch_corpus.sh)" >&2
  exit 1
fi
mkdir -p "$out/logs"
if [ $subset = 1 ]; then
  meshes=(cross u joint dragknob)
else
  meshes=()
  k=0
  for f in "$corpus"/*.off; do
    if [ $((k % shards)) -eq "$shard" ]; then meshes+=("$(basename "$f" .off)"); fi
    k=$((k + 1))
  done
fi
status=0
for m in "${meshes[@]}"; do
  log="$out/logs/$m.log"
  # Arguments as an array: no path goes through a shell.
  "$bin/icd-preprocess" "$corpus/$m.off" -o "$out/bundles/$m" "${extra[@]}" > "$log" 2>&1
  rc=$?
  echo "$rc" > "$out/logs/$m.rc"
  echo "[corpus] $m: exit $rc"
  # 0 ok, 1 refused with a message; anything else (a crash) fails the run.
  if [ $rc -ne 0 ] && [ $rc -ne 1 ]; then status=1; fi
  if [ $rc -eq 1 ] && ! grep -q "^icd-preprocess: " "$log"; then status=1; fi
done
check=()
if [ $subset = 1 ]; then check=(--check); fi
python3 "$root/experiments/studies/preprocess/corpus_table.py" "${check[@]}" "$out" "${meshes[@]}" || status=1
rm -rf "$out/bundles"
exit $status
