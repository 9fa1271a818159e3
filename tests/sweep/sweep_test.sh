#!/usr/bin/env bash
# End-to-end tests of icd-sweep (CTest Sweep.*): sweep_test.sh BIN_DIR SOURCE_DIR WORK_DIR TEST
# Every path is quoted; nothing is evaluated by a shell but this script.
set -uo pipefail
bin="$1"; src="$2"; work="$3"; test="$4"
sweep="$bin/icd-sweep"
eight="$src/tests/sweep/eight_cases.json"
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fail() { echo "FAIL: $*" >&2; exit 1; }
ok_rows() { awk -F, 'NR>1 && $4=="ok"' "$1" | wc -l; }
# The number of cases icd-sweep ran (progress lines "(case K ID: status...)").
ran() { grep -c '^\[icd-sweep\] .* done, .*(case ' "$1" || true; }

case "$test" in
local_vs_mpi)
  "$sweep" "$eight" --out local -j2 2> local.log || fail "local run failed: $(cat local.log)"
  "${MPIEXEC:-mpirun}" -np 2 --oversubscribe "$sweep" "$eight" --out mpi 2> mpi.log || fail "mpi run failed: $(cat mpi.log)"
  grep -q '1 worker(s)' mpi.log || fail "mpirun -np 2 did not run the MPI backend (rank 0 + 1 worker): $(head -3 mpi.log)"
  cmp local/results.csv mpi/results.csv || fail "local and MPI CSVs differ"
  # 2 scenes x frames 1..4: 2 x (1+2+3+4) = 20 frame rows, 8 distinct cases, all ok
  [ "$(ok_rows local/results.csv)" = 20 ] || fail "expected 20 ok rows, got $(ok_rows local/results.csv)"
  [ "$(tail -n +2 local/results.csv | cut -d, -f1 | sort -u | wc -l)" = 8 ] || fail "expected 8 case ids"
  tail -n +2 local/results.csv | cut -d, -f1 | sort -c || fail "rows not sorted by case id"
  # Independent reference: icd-run run by hand for one case (two_spheres, 3 frames)
  "$bin/icd-run" "$src/experiments/scenes/two_spheres.json" --frames 3 --out ref --quiet > /dev/null ||
    fail "reference icd-run failed"
  python3 - "$work/ref/frames.csv" "$work/local/results.csv" <<'PY' || fail "sweep rows differ from the direct run"
import csv, sys
ref = list(csv.DictReader(open(sys.argv[1])))
got = [r for r in csv.DictReader(open(sys.argv[2]))
       if r["@scene"].endswith("/experiments/scenes/two_spheres.json") and r["--frames"] == "3"]
cols = ["frame", "tests", "collision_list", "max_penetration", "energy"]
assert len(got) == len(ref) == 3, (len(got), len(ref))
for a, b in zip(ref, got):
    for c in cols:
        assert a[c] == b[c], (c, a[c], b[c])
PY
  ;;
resume)
  cp "$src/experiments/scenes/two_spheres.json" scene_a.json
  cp "$src/experiments/studies/paper/scenes/two_spheres_soft.json" scene_b.json
  sed -e 's|{source_dir}/experiments/scenes/two_spheres.json|{sweep_dir}/scene_a.json|' \
      -e 's|{source_dir}/experiments/studies/paper/scenes/two_spheres_soft.json|{sweep_dir}/scene_b.json|' \
      "$eight" > sweep.json
  # with a setup command (run once before the cases, skipped when done)
  python3 - sweep.json <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["setup"] = [["icd-run", "{sweep_dir}/scene_a.json", "--frames", "1", "--out", "{out}", "--quiet"]]
json.dump(d, open(sys.argv[1], "w"), indent=1)
PY
  "$sweep" sweep.json --out o -j2 2> r1.log || fail "first run failed"
  [ "$(ran r1.log)" = 8 ] || fail "first run: expected 8 cases run, got $(ran r1.log)"
  [ -f o/setup/0/out/frames.csv ] || fail "the setup command did not run"
  ls o/setup/0/done-* > /dev/null || fail "the setup command left no marker"
  touch -d '2001-01-01' o/setup/0/out/frames.csv
  cp o/results.csv first.csv
  "$sweep" sweep.json --out o -j2 2> r2.log || fail "second run failed"
  [ "$(ran r2.log)" = 0 ] || fail "re-run: expected 0 cases run, got $(ran r2.log)"
  [ "$(stat -c %Y o/setup/0/out/frames.csv)" = "$(date -d '2001-01-01' +%s)" ] || fail "the setup ran again"
  grep -q '8 already finished' r2.log || fail "re-run does not report 8 finished cases"
  cmp first.csv o/results.csv || fail "re-run changed the CSV"
  # one case folder lost: exactly that case runs again
  id=$(sed -n 2p first.csv | cut -d, -f1)
  rm -rf "o/cases/$id"
  "$sweep" sweep.json --out o -j2 2> r3.log || fail "third run failed"
  [ "$(ran r3.log)" = 1 ] || fail "after removing one case: expected 1 case run, got $(ran r3.log)"
  cmp first.csv o/results.csv || fail "CSV differs after re-running one case"
  # an input changed (scene_b's frame rate): its 4 cases get new ids and run, scene_a's do not
  sed -i 's/"frame_rate": 60/"frame_rate": 50/' scene_b.json
  grep -q '"frame_rate": 50' scene_b.json || fail "could not edit scene_b.json"
  "$sweep" sweep.json --out o -j2 2> r4.log || fail "fourth run failed"
  [ "$(ran r4.log)" = 4 ] || fail "after changing one input: expected 4 cases run, got $(ran r4.log)"
  cmp -s first.csv o/results.csv && fail "CSV unchanged after changing an input"
  # what is collected changed: every case runs again (same ids), the CSV has the new columns
  python3 - sweep.json <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["collect"]["columns"].remove("energy")
json.dump(d, open(sys.argv[1], "w"), indent=1)
PY
  "$sweep" sweep.json --out o -j2 2> r5.log || fail "fifth run failed"
  [ "$(ran r5.log)" = 8 ] || fail "after changing the collection: expected 8 cases run, got $(ran r5.log)"
  head -1 o/results.csv | grep -q energy && fail "the CSV still has the dropped column"
  [ "$(tail -n +2 o/results.csv | cut -d, -f1 | sort -u | wc -l)" = 8 ] || fail "expected 8 case ids after re-collection"
  ;;
failures)
  cat > sweep.json <<JSON
{"name": "failures", "program": "icd-run", "args": ["--out", "{out}", "--quiet"],
 "cases": [{"@scene": "$src/experiments/scenes/two_spheres.json", "--frames": 2},
           {"@scene": "{sweep_dir}/no_such_scene.json", "--frames": 2},
           {"@scene": "$src/experiments/scenes/two_spheres.json", "--frames": 100000}],
 "collect": {"csv": "frames.csv", "columns": ["frame", "tests"], "rows": "last"},
 "limits": {"wall_seconds": 3, "memory_mb": 4096}}
JSON
  start=$(date +%s)
  "$sweep" sweep.json --out o -j1 2> run.log; rc=$?
  took=$(( $(date +%s) - start ))
  [ "$rc" = 1 ] || fail "expected exit status 1 with failed cases, got $rc"
  python3 - "$work/o/results.csv" <<'PY' || fail "failure rows wrong: $(cat o/results.csv)"
import csv, sys
rows = {r["--frames"] + ":" + r["@scene"].rsplit("/", 1)[1]: r for r in csv.DictReader(open(sys.argv[1]))}
assert len(rows) == 3, rows.keys()
ok = rows["2:two_spheres.json"]
assert ok["status"] == "ok" and ok["exit_status"] == "0" and ok["frame"] == "1", ok
bad = rows["2:no_such_scene.json"]
assert bad["status"] == "failed" and bad["exit_status"] != "0", bad
assert "no_such_scene.json" in bad["message"], bad["message"]
slow = rows["100000:two_spheres.json"]
assert slow["status"] == "timeout" and "wall-clock limit of 3 s" in slow["message"], slow
PY
  [ "$took" -lt 60 ] || fail "the over-limit case was not stopped (run took $took s)"
  pgrep -f "$work/o/cases" > /dev/null && fail "a case process survived its time limit"
  # the markdown section lists the two failures
  [ "$(grep -c '^- `' o/results.md)" = 2 ] || fail "results.md does not list the 2 failures"
  # a re-run runs the failed cases again, not the finished one
  "$sweep" sweep.json --out o -j1 2> run2.log
  [ "$(ran run2.log)" = 2 ] || fail "re-run: expected the 2 failed cases to run again, got $(ran run2.log)"
  # SIGTERM (Slurm's time limit, Ctrl-C): the running cases are killed and recorded, exit 130
  cat > long.json <<'JSON'
{"name": "long", "program": "icd-run", "args": ["{source_dir}/experiments/scenes/two_spheres.json", "--out", "{out}", "--quiet"],
 "grid": {"--frames": [100000, 100001]}, "limits": {"wall_seconds": 600}}
JSON
  "$sweep" long.json --out long -j2 2> long.log & pid=$!
  sleep 2; kill -TERM "$pid"; wait "$pid"; rc=$?
  [ "$rc" = 130 ] || fail "interrupted sweep: expected exit 130, got $rc"
  pgrep -f "$work/long/cases" > /dev/null && fail "a case process survived the interrupt"
  [ "$(grep -c ',killed,' long/results.csv)" = 2 ] || fail "interrupted cases not recorded: $(cat long/results.csv)"
  ;;
slurm)
  "$sweep" "$eight" --out local -j2 2> local.log || fail "local run failed"
  "$sweep" "$eight" --out "$work/slurm" --emit-slurm > emitted.txt || fail "--emit-slurm failed"
  grep -q 'sbatch --dependency=afterany:"${jid%%;\*}" .*gather.sbatch' slurm/slurm/submit.sh || fail "submit.sh does not chain the gather step"
  [ -e slurm/slurm/setup.sbatch ] && fail "setup.sbatch written for a sweep without setup"
  for f in array.sbatch gather.sbatch submit.sh; do
    [ -f "slurm/slurm/$f" ] || fail "$f not written"
    bash -n "slurm/slurm/$f" || fail "$f is not valid shell"
  done
  grep -q '^#SBATCH --array=0-7$' slurm/slurm/array.sbatch || fail "array range wrong: $(cat slurm/slurm/array.sbatch)"
  grep -q -- '--case "$SLURM_ARRAY_TASK_ID" --chunk 1' slurm/slurm/array.sbatch || fail "array task command wrong"
  grep -q -- '--gather$' slurm/slurm/gather.sbatch || fail "gather command wrong"
  # a sweep with setup commands: a setup job first, the array after it succeeded
  "$sweep" "$src/experiments/sweeps/table1_quick.json" --out "$work/t1" --emit-slurm > /dev/null || fail "--emit-slurm (setup) failed"
  grep -q -- '--setup$' t1/slurm/setup.sbatch || fail "setup.sbatch missing or wrong"
  grep -q 'dependency=afterok:' t1/slurm/submit.sh || fail "submit.sh does not wait for the setup"
  bash -n t1/slurm/submit.sh || fail "submit.sh (setup) is not valid shell"
  # what the array tasks run: --case K, then the gather step
  for k in 0 1 2 3 4 5 6 7; do
    SLURM_ARRAY_TASK_ID=$k "$sweep" "$eight" --out slurm --case "$k" 2>> cases.log || fail "--case $k failed"
  done
  "$sweep" "$eight" --out slurm --gather 2> gather.log || fail "--gather failed: $(cat gather.log)"
  cmp local/results.csv slurm/results.csv || fail "Slurm-path CSV differs from the local one"
  # chunks of 3 (3 tasks for 8 cases) into a fresh folder give the same CSV
  "$sweep" "$eight" --out chunked --gather 2> /dev/null && fail "--gather with no case run must fail (missing cases)"
  grep -c ',missing,' chunked/results.csv | grep -qx 8 || fail "missing cases not recorded"
  for k in 0 1 2; do "$sweep" "$eight" --out chunked --case "$k" --chunk 3 2>> chunks.log || fail "--case $k --chunk 3 failed"; done
  "$sweep" "$eight" --out chunked --case 3 --chunk 3 2> /dev/null; [ $? = 2 ] || fail "--case past the end must exit 2"
  "$sweep" "$eight" --out chunked --gather 2> /dev/null || fail "chunked gather failed"
  cmp local/results.csv chunked/results.csv || fail "chunked CSV differs from the local one"
  ;;
bad_input)
  "$sweep" --version | grep -q . || fail "--version prints nothing"
  "$sweep" --help | grep -q -- '--emit-slurm' || fail "--help lacks --emit-slurm"
  "$sweep" "$eight" --no-such-option > /dev/null 2>&1; [ $? = 2 ] || fail "unknown option must exit 2"
  "$sweep" > /dev/null 2>&1; [ $? = 2 ] || fail "missing sweep file must exit 2"
  printf '{"name": "x", "program": "icd-run", "grid": {"--frames": []}}' > empty.json
  "$sweep" empty.json --out o1 2> e1.log; [ $? = 1 ] || fail "empty value list must exit 1"
  grep -q 'empty.json: "grid".--frames: empty list' e1.log || fail "message does not name file and field: $(cat e1.log)"
  printf '{"name": "x", "program": "../bin/icd-run"}' > path.json
  "$sweep" path.json --out o2 2> e2.log; [ $? = 1 ] || fail "a program path must be refused"
  grep -q '"program"' e2.log || fail "message does not name the field: $(cat e2.log)"
  printf '{"name": "x", "program": "icd-run", "colect": {}}' > typo.json
  "$sweep" typo.json --out o3 2> e3.log; [ $? = 1 ] || fail "an unknown field must be refused"
  grep -q 'unknown field "colect"' e3.log || fail "message does not name the unknown field: $(cat e3.log)"
  printf '{"name": "x", "program": "icd-run", "args": ["{out}"], "collect": {"csv": "f.csv"}, "grid": {"--frames": [1' > cut.json
  "$sweep" cut.json --out o4 2> e4.log; [ $? = 1 ] || fail "truncated JSON must be refused"
  grep -q 'cut.json: not valid JSON' e4.log || fail "message: $(cat e4.log)"
  for d in o1 o2 o3 o4; do [ -e "$d" ] && fail "output folder $d written for a bad sweep file"; done
  # the log collector: a regex group from the case's stdout (icd-run prints its frame count)
  cat > log.json <<'JSON'
{"name": "l", "program": "icd-run", "args": ["{source_dir}/experiments/scenes/two_spheres.json", "--out", "{out}", "--quiet"],
 "grid": {"--frames": [1, 2]},
 "collect": {"log": {"frames": "^scene \"two_spheres\": 2 objects, (\\d+) frames", "absent": "no such (line)"}}}
JSON
  "$sweep" log.json --out l -j1 2> l.log || fail "log sweep failed: $(cat l.log)"
  python3 - "$work/l/results.csv" <<'PY' || fail "log collector wrong: $(cat l/results.csv)"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 2 and all(r["frames"] == r["--frames"] and r["absent"] == "" for r in rows), rows
PY
  # scene fields become --set key=value (the scene-reading programs' override option)
  printf '{"name": "s", "program": "icd-run", "args": ["x.json"], "cases": [{"collision.stiffness": 3000, "_label": "a", "--quiet": true, "--dry-run": false}]}' > set.json
  "$sweep" set.json --out s -j1 2> /dev/null
  python3 - "$work/s" <<'PY' || fail "argument list of a --set case wrong"
import glob, json, sys
cases = glob.glob(sys.argv[1] + "/cases/*/case.json")
assert len(cases) == 1, cases
argv = json.load(open(cases[0]))["argv"]
assert argv[1:] == ["x.json", "--set", "collision.stiffness=3000", "--quiet"], argv
PY
  ;;
set_fields)
  # Scene fields through --set KEY=VALUE: the sweep's case equals icd-run on a
  # scene file edited by hand (an independent reference).
  if ! "$bin/icd-run" --help 2>&1 | grep -q -- '--set KEY=VALUE'; then
    echo "SKIP: this icd-run has no --set KEY=VALUE (the scene override option is not merged)"
    exit 77
  fi
  python3 - "$src/experiments/scenes/two_spheres.json" edited.json <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["collision"]["stiffness"] = 5000
d["objects"][0]["material"]["young"] = 1e6
json.dump(d, open(sys.argv[2], "w"), indent=1)
PY
  cat > set.json <<'JSON'
{"name": "set", "program": "icd-run",
 "args": ["{source_dir}/experiments/scenes/two_spheres.json", "--out", "{out}", "--quiet", "--frames", "4"],
 "cases": [{"_which": "edited", "collision.stiffness": 5000, "objects.0.material.young": 1e6},
           {"_which": "base", "collision.stiffness": 2000}],
 "collect": {"csv": "frames.csv", "columns": ["frame", "tests", "max_penetration", "contact_force", "energy"]}}
JSON
  "$sweep" set.json --out o -j2 2> run.log || fail "--set sweep failed: $(cat run.log)"
  "$bin/icd-run" edited.json --frames 4 --out ref --quiet > /dev/null || fail "reference icd-run failed"
  python3 - "$work/ref/frames.csv" "$work/o/results.csv" <<'PY' || fail "the --set case differs from the edited scene"
import csv, sys
ref = list(csv.DictReader(open(sys.argv[1])))
rows = list(csv.DictReader(open(sys.argv[2])))
edited = [r for r in rows if r["_which"] == "edited"]
base = [r for r in rows if r["_which"] == "base"]
cols = ["frame", "tests", "max_penetration", "contact_force", "energy"]
assert len(edited) == len(ref) == 4 and len(base) == 4
assert all(a[c] == b[c] for a, b in zip(ref, edited) for c in cols), "edited case != edited scene"
assert any(a["energy"] != b["energy"] for a, b in zip(edited, base)), "--set changed nothing"
PY
  ;;
json_collect)
  # The JSON collector: fields picked by JSON pointer from a file the case
  # writes, against the values read back by Python (an independent reader).
  # Programs are looked up beside icd-sweep, so the test runs a copy of it in a
  # folder with a small writer program.
  mkdir -p jbin
  cp "$sweep" jbin/icd-sweep
  cat > jbin/writer <<'PY'
#!/usr/bin/python3
import json, sys
out, v, kind = sys.argv[1], float(sys.argv[2]), sys.argv[3]
d = {"name": kind, "value": v, "nested": {"list": [v, 2 * v, {"deep": "x,\"y\""}]}, "flag": v > 1,
     "count": int(10 * v), "none": None}
with open(out + "/r.json", "w") as f:
    if kind == "broken":
        f.write('{"name": ')          # not valid JSON
    else:
        if kind == "partial":
            del d["nested"]
        json.dump(d, f)
PY
  chmod +x jbin/writer
  cat > json.json <<'JSON'
{"name": "j", "program": "writer", "args": ["{out}"],
 "grid": {"@value": [0.5, 1.25, 3], "@kind": ["full", "partial", "broken"]},
 "collect": {"json": "r.json", "fields": ["/name", "/value", "/nested/list/1", "/nested/list/2/deep", "/flag", "/count", "/none"]}}
JSON
  jbin/icd-sweep json.json --out j -j2 2> j.log; rc=$?
  [ "$rc" = 1 ] || fail "json sweep with broken cases: expected exit 1, got $rc: $(cat j.log)"
  python3 - "$work/j/results.csv" "$work/j/cases" <<'PY' || fail "json collector wrong: $(cat j/results.csv)"
import csv, glob, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 9, len(rows)
cols = ["name", "value", "nested/list/1", "nested/list/2/deep", "flag", "count", "none"]
for r in rows:
    if r["@kind"] == "full":
        assert r["status"] == "ok", r
        # the reference: the case's own r.json read by Python
        ref = json.load(open(glob.glob(f"{sys.argv[2]}/{r['case_id']}/out/r.json")[0]))
        want = [ref["name"], ref["value"], ref["nested"]["list"][1], ref["nested"]["list"][2]["deep"],
                ref["flag"], ref["count"], ref["none"]]
        for c, w in zip(cols, want):
            got = r[c]
            if isinstance(w, str):
                assert got == w, (c, got, w)          # strings verbatim (commas and quotes survive the CSV)
            else:
                assert json.loads(got) == w, (c, got, w)  # numbers, booleans, null as JSON text
        assert float(r["nested/list/1"]) == 2 * float(r["@value"]), r
    elif r["@kind"] == "partial":
        assert r["status"] == "failed" and "no field /nested/list/1" in r["message"], r
        assert all(r[c] == "" for c in cols), r
    else:
        assert r["status"] == "failed" and "r.json: not valid JSON" in r["message"], r
PY
  # a field that is not a JSON pointer is refused when the sweep file is read
  sed 's|"/none"|"none"|' json.json > badptr.json
  jbin/icd-sweep badptr.json --out jb 2> jb.log; [ $? = 1 ] || fail "a field without / must be refused"
  grep -q 'badptr.json: "collect".fields: a JSON pointer' jb.log || fail "message: $(cat jb.log)"
  [ -e jb ] && fail "output folder written for a bad sweep file"
  ;;
*) fail "unknown test $test" ;;
esac
echo "PASS $test"
