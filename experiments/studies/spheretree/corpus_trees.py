#!/usr/bin/python3
"""The corpus sphere-tree table (issue 30 item 8): the tree each corpus mesh's
asset bundle carries (icd-preprocess at its defaults: the tree the runtime
loads), evaluated by corpus_trees against the bundle's dense surface.

usage: corpus_trees.py BIN OUT [--from RUN]... [--meshes A,B,...] [--permuted A,B,...]
                       [--subset] [-- EXTRA ICD-PREPROCESS ARGS]

BIN   folder with icd-preprocess and corpus_trees (a build's bin/).
OUT   output folder: corpus_trees.md, corpus_trees.csv, trees/<mesh>.sph, and,
      for meshes it preprocesses itself, bundles/<mesh>/ and logs/<mesh>.log.
--from RUN  take the bundle and log of a mesh from RUN/bundles/<mesh>/ and
      RUN/logs/<mesh>.log (the layout of run_corpus.sh's OUT, bundles kept)
      when they are there, instead of preprocessing it (repeatable; the first
      RUN holding a mesh wins; a mesh without a bundle whose RUN/logs/<mesh>.rc
      is not 0 is listed as refused).
--meshes  only these corpus meshes (default: every data/corpus/*.off).
--permuted  also preprocess these meshes with their vertices and faces
      shuffled (fixed seed, each face rotated, orientation kept) and report
      whether the tree is the same file (.sph bytes) and, if not, how its
      leaves and mean162 differ (target: within 2 % and 5 %).
--cached-only  do not preprocess or evaluate: rows come from OUT/rows/ only
      (meshes without one are listed as not evaluated). Every evaluated mesh
      leaves its row in OUT/rows/<mesh>.json, and a later run with the same OUT
      reuses it, so runs over parts of the corpus (--meshes) can share OUT and
      a last run writes the whole table.
--subset  the CTest SphereTreeCorpus.Subset (about 7 s CPU): mesh cross and
      its permuted copy, EXTRA = --coarse-tets 150 --no-hausdorff
      --sphere-depth 2 (the tree depends on the repaired surface, not on the
      tet mesh; depth 2 halves the build), coverage evaluated at spacing
      SUBSET_SPACING units instead of 1. Fails (exit 1) when the mesh is
      missing or refused, a figure is missing, the leaf level leaves a surface
      sample or vertex uncovered, or the permuted tree differs.
A permuted copy is evaluated only when its tree file differs from the
original's (icd-preprocess --sph of both; with --from, the original's tree as
corpus_trees writes it).
Exit status: 0 when the table was written (and, with --subset, every check
passed), 1 otherwise; 2 for bad arguments.
"""
import csv
import json
import os
import random
import re
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
CORPUS = os.path.join(ROOT, "data", "corpus")
COLUMNS = ["mesh", "outcome", "triangles", "levels", "leaves", "worst42", "mean42", "worst162",
           "mean162", "mean2562", "worst2562", "uncovered_pct", "uncovered_vertices",
           "build_cpu_s", "build_wall_s", "eval_cpu_s", "permuted"]
# The subset's coverage spacing (normalized units): the cross at spacing 1 has
# about 8 million coverage samples (1.4 s CPU per evaluation), at 4 16 times
# fewer, still 20 per leaf and edge-on spacing far below the leaves' radii.
SUBSET_SPACING = 4.0


def fail(msg):
    print("corpus_trees.py: " + msg, file=sys.stderr)
    sys.exit(1)


def read_off(path):
    """Vertices (text of the 3 coordinates) and faces (index lists) of an OFF file."""
    words = []
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                words.extend(line.split())
    if not words or not words[0].endswith("OFF"):
        fail(f"{path}: not an OFF file")
    if words[0] != "OFF":
        fail(f"{path}: only plain OFF is supported for --permuted")
    nv, nf = int(words[1]), int(words[2])
    pos = 4
    verts = []
    for _ in range(nv):
        verts.append(words[pos:pos + 3])
        pos += 3
    faces = []
    for _ in range(nf):
        k = int(words[pos])
        faces.append(words[pos + 1:pos + 1 + k])
        pos += 1 + k
    return verts, faces


def write_permuted_off(src, dst, seed=7):
    """`src` with its vertices and faces shuffled, each face rotated (orientation
    kept); the coordinate texts are copied unchanged (same doubles)."""
    verts, faces = read_off(src)
    rng = random.Random(seed)
    order = list(range(len(verts)))
    rng.shuffle(order)
    new_of_old = [0] * len(verts)
    for new, old in enumerate(order):
        new_of_old[old] = new
    out_faces = []
    for f in faces:
        idx = [new_of_old[int(i)] for i in f]
        k = rng.randrange(len(idx))
        out_faces.append(idx[k:] + idx[:k])
    rng.shuffle(out_faces)
    with open(dst, "w") as f:
        f.write(f"OFF\n{len(verts)} {len(out_faces)} 0\n")
        for old in order:
            f.write(" ".join(verts[old]) + "\n")
        for idx in out_faces:
            f.write(f"{len(idx)} " + " ".join(map(str, idx)) + "\n")


def stage_times(log):
    """(wall, cpu) seconds of the sphere-tree stage from an icd-preprocess log."""
    m = re.search(r"[ :]sphere tree ([\d.]+) \(([\d.]+)\) \[", log)
    return (m.group(1), m.group(2)) if m else ("", "")


def read_rc(run, mesh):
    try:
        return int(open(os.path.join(run, "logs", mesh + ".rc")).read().strip())
    except (OSError, ValueError):
        return None


def run_holds(run, mesh):
    """RUN has the mesh's log and either its bundle or an exit status that says
    it was refused (a bundle removed after a successful run does not count)."""
    if not os.path.isfile(os.path.join(run, "logs", mesh + ".log")):
        return False
    if os.path.isfile(os.path.join(run, "bundles", mesh, "bundle.icdb")):
        return True
    rc = read_rc(run, mesh)
    return rc is not None and rc != 0


def preprocess(bin_dir, src, bundle, log_path, sph, extra):
    os.makedirs(os.path.dirname(log_path), exist_ok=True)
    with open(log_path, "w") as log:
        # Arguments as a list: no path goes through a shell.
        rc = subprocess.call([os.path.join(bin_dir, "icd-preprocess"), src, "-o", bundle,
                              "--sph", sph] + extra, stdout=log, stderr=subprocess.STDOUT)
    return rc


def evaluate(bin_dir, bundle, sph_dir, spacing=None):
    extra = ["--coverage-spacing", str(spacing)] if spacing else []
    p = subprocess.run([os.path.join(bin_dir, "corpus_trees"), bundle, "--sph-dir", sph_dir] + extra,
                       capture_output=True, text=True)
    if p.returncode != 0:
        fail(f"corpus_trees failed on {bundle}: {p.stderr.strip()}")
    lines = p.stdout.strip().split("\n")
    head, row = lines[0].split("\t"), lines[1].split("\t")
    return dict(zip(head, row))


def median(rows, key):
    vals = [float(r[key]) for r in rows if r.get(key, "") != ""]
    return statistics.median(vals) if vals else float("nan")


def write_table(out, rows, command, load):
    with open(os.path.join(out, "corpus_trees.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    ok = [r for r in rows if r["outcome"] == "ok"]
    lines = [
        "# Sphere trees of the corpus bundles",
        "",
        "The tree each corpus mesh's asset bundle carries (`icd-preprocess` defaults: medial axis,",
        "fit light, branching 8, depth 3, up to 512 leaves; the tree the runtime loads), leaf level,",
        "evaluated by `corpus_trees` against the bundle's dense (repaired) surface. Units: longest",
        "bounding-box side 2000. Error of a sphere = largest distance to the surface of its probes",
        "outside the mesh, 42 / 162 probes (our frame) or 2562 directions (close to the true",
        "protrusion). Uncovered: share of the dense samples (spacing 1 unit) outside every leaf, and",
        "the vertices outside every leaf. Build: the sphere-tree stage of `icd-preprocess`, CPU (wall)",
        "seconds. Permuted: the same mesh with shuffled vertices and faces gives the same `.sph` file.",
        "",
        f"Command: `{command}`; load average when the table was written: {load}.",
        "",
        "| mesh | triangles | leaves | worst42 | mean42 | worst162 | mean162 | mean2562 | worst2562 | uncovered % (vertices) | build CPU (wall) s | permuted |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if r["outcome"] != "ok":
            lines.append(f"| {r['mesh']} | {r.get('triangles', '')} | {r['outcome']} | | | | | | | | | |")
            continue
        lines.append(
            f"| {r['mesh']} | {r['triangles']} | {r['leaves']} | {r['worst42']} | {r['mean42']} | "
            f"{r['worst162']} | {r['mean162']} | {r['mean2562']} | {r['worst2562']} | "
            f"{float(r['uncovered_pct']):.3f} ({r['uncovered_vertices']}) | "
            f"{r['build_cpu_s']} ({r['build_wall_s']}) | {r.get('permuted', '')} |")
    if ok:
        lines += [
            "",
            f"{len(ok)} of {len(rows)} meshes have a tree. Medians over them: leaves "
            f"{median(ok, 'leaves'):.0f}, worst42 {median(ok, 'worst42'):.1f}, mean42 "
            f"{median(ok, 'mean42'):.2f}, mean162 {median(ok, 'mean162'):.2f}, mean2562 "
            f"{median(ok, 'mean2562'):.2f}, worst2562 {median(ok, 'worst2562'):.1f}, build CPU "
            f"{median(ok, 'build_cpu_s'):.1f} s (largest "
            f"{max(float(r['build_cpu_s']) for r in ok if r['build_cpu_s']):.1f} s). Uncovered "
            f"samples on {sum(1 for r in ok if float(r['uncovered_pct']) > 0)} of them, "
            f"uncovered vertices on {sum(1 for r in ok if int(r['uncovered_vertices']) > 0)}.",
        ]
    with open(os.path.join(out, "corpus_trees.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def main(argv):
    args, extra = argv, []
    if "--" in argv:
        k = argv.index("--")
        args, extra = argv[:k], argv[k + 1:]
    if len(args) < 2 or args[0].startswith("-") or args[1].startswith("-"):
        print(__doc__, file=sys.stderr)
        return 2
    bin_dir, out = args[0], args[1]
    runs, meshes, permuted, subset, cached_only = [], None, [], False, False
    i = 2
    while i < len(args):
        a = args[i]
        if a in ("--from", "--meshes", "--permuted") and i + 1 >= len(args):
            print(f"corpus_trees.py: {a} needs a value", file=sys.stderr)
            return 2
        if a == "--from":
            runs.append(args[i + 1]); i += 2
        elif a == "--meshes":
            meshes = [m for m in args[i + 1].split(",") if m]; i += 2
        elif a == "--permuted":
            permuted = [m for m in args[i + 1].split(",") if m]; i += 2
        elif a == "--subset":
            subset = True; i += 1
        elif a == "--cached-only":
            cached_only = True; i += 1
        else:
            print(f"corpus_trees.py: unknown argument {a}", file=sys.stderr)
            return 2
    if subset:
        meshes, permuted = ["cross"], ["cross"]
        extra = extra or ["--coarse-tets", "150", "--no-hausdorff", "--sphere-depth", "2"]
    if not os.path.isdir(CORPUS):
        fail(f"{CORPUS} missing (run scripts/fetch_corpus.sh)")
    if meshes is None:
        meshes = sorted(f[:-4] for f in os.listdir(CORPUS) if f.endswith(".off"))
    for m in meshes + permuted:
        if not os.path.isfile(os.path.join(CORPUS, m + ".off")):
            fail(f"{os.path.join(CORPUS, m + '.off')} missing (run scripts/fetch_corpus.sh)")
    os.makedirs(out, exist_ok=True)
    sph_dir = os.path.join(out, "trees")
    rows, problems = [], []
    preprocessed_sph = {}  # mesh -> the tree icd-preprocess wrote in this run
    rows_dir = os.path.join(out, "rows")
    os.makedirs(rows_dir, exist_ok=True)
    for m in meshes:
        r = {"mesh": m}
        cached = os.path.join(rows_dir, m + ".json")
        if os.path.isfile(cached) and not subset:
            r = json.load(open(cached))
            rows.append(r)
            if r["outcome"] != "ok":
                problems.append(f"{m}: {r['outcome']}")
            continue
        if cached_only:
            r["outcome"] = "not evaluated"
            rows.append(r)
            continue
        src = os.path.join(CORPUS, m + ".off")
        found = next((run for run in runs if run_holds(run, m)), None)
        if found:
            bundle = os.path.join(found, "bundles", m)
            log = open(os.path.join(found, "logs", m + ".log"), errors="replace").read()
            rc = 0 if os.path.isfile(os.path.join(bundle, "bundle.icdb")) else read_rc(found, m)
        else:
            bundle = os.path.join(out, "bundles", m)
            log_path = os.path.join(out, "logs", m + ".log")
            preprocessed_sph[m] = os.path.join(out, "logs", m + ".sph")
            rc = preprocess(bin_dir, src, bundle, log_path, preprocessed_sph[m], extra)
            log = open(log_path, errors="replace").read()
        if rc != 0:
            r["outcome"] = "refused" if rc == 1 else f"exit {rc}"
            t = re.search(r"\[read\][^\n]*?(\d+) triangles", log)
            r["triangles"] = t.group(1) if t else ""
            rows.append(r)
            json.dump(r, open(cached, "w"))
            problems.append(f"{m}: {r['outcome']}")
            print(f"[trees] {m}: {r['outcome']}", flush=True)
            continue
        e = evaluate(bin_dir, bundle, sph_dir, SUBSET_SPACING if subset else None)
        r.update(e)
        r["outcome"] = "ok"
        r["build_wall_s"], r["build_cpu_s"] = stage_times(log)
        rows.append(r)
        json.dump(r, open(cached, "w"))
        print(f"[trees] {m}: {r['leaves']} leaves, mean162 {r['mean162']}, mean2562 "
              f"{r['mean2562']}, uncovered {r['uncovered_pct']} %, build {r['build_cpu_s']} s CPU",
              flush=True)
    for m in permuted:
        r = next((x for x in rows if x["mesh"] == m and x["outcome"] == "ok"), None)
        if r is None:
            problems.append(f"{m}: no tree to compare the permuted one with")
            continue
        pdir = os.path.join(out, "permuted")
        os.makedirs(pdir, exist_ok=True)
        src = os.path.join(pdir, m + ".off")
        write_permuted_off(os.path.join(CORPUS, m + ".off"), src)
        bundle = os.path.join(pdir, "bundles", m)
        rc = preprocess(bin_dir, src, bundle, os.path.join(pdir, m + ".log"),
                        os.path.join(pdir, m + ".sph"), extra)
        if rc != 0:
            r["permuted"] = "refused"
            problems.append(f"{m}: permuted copy refused")
            continue
        # Compared: both trees as icd-preprocess wrote them when this run
        # preprocessed the original, else both as corpus_trees writes them.
        mine, theirs = preprocessed_sph.get(m), os.path.join(pdir, m + ".sph")
        e = None
        if mine is None:
            e = evaluate(bin_dir, bundle, os.path.join(pdir, "trees"),
                         SUBSET_SPACING if subset else None)
            mine, theirs = os.path.join(sph_dir, m + ".sph"), os.path.join(pdir, "trees", m + ".sph")
        if open(mine, "rb").read() == open(theirs, "rb").read():
            r["permuted"] = "same tree"
        else:
            e = e or evaluate(bin_dir, bundle, os.path.join(pdir, "trees"),
                              SUBSET_SPACING if subset else None)
            dl = 100.0 * (int(e["leaves"]) / int(r["leaves"]) - 1)
            dm = 100.0 * (float(e["mean162"]) / float(r["mean162"]) - 1)
            r["permuted"] = f"differs: leaves {dl:+.1f} %, mean162 {dm:+.1f} %"
            problems.append(f"{m}: permuted input gives another tree ({r['permuted']})")
        json.dump(r, open(os.path.join(rows_dir, m + ".json"), "w"))
        print(f"[trees] {m} permuted: {r['permuted']}", flush=True)
    if subset:
        for r in rows:
            if r["outcome"] != "ok":
                continue
            for c in COLUMNS[2:-2]:
                if r.get(c, "") == "":
                    problems.append(f"{r['mesh']}: figure '{c}' missing")
            if r.get("uncovered_pct") and float(r["uncovered_pct"]) > 0:
                problems.append(f"{r['mesh']}: {r['uncovered_pct']} % of the surface uncovered")
            if r.get("uncovered_vertices") and int(r["uncovered_vertices"]) > 0:
                problems.append(f"{r['mesh']}: {r['uncovered_vertices']} vertices uncovered")
    load = open("/proc/loadavg").read().split()[:3] if os.path.exists("/proc/loadavg") else ["?"]
    command = "experiments/studies/spheretree/corpus_trees.py " + " ".join(argv)
    write_table(out, rows, command, " ".join(load))
    if subset and problems:
        for p in problems:
            print("corpus_trees.py: " + p, file=sys.stderr)
        return 1
    for p in problems:
        print("[trees] note: " + p)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
