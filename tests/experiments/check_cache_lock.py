"""Two icd-run processes that need the same raw mesh preprocessed into the
same empty asset cache at once (a sweep's parallel cases): both succeed,
icd-preprocess runs once, and the cache holds one complete bundle and no
half-written folder.  Usage: check_cache_lock.py ICD_RUN WORK_DIR

The mesh is preprocessed with the octree sphere tree (0.2 s of CPU: the lock
is what is checked, not the medial tree, which takes ~36 s of CPU even for
this ball). So that the runs surely overlapped, one of them must have waited
on the lock ("[icd] waiting for another process"); an attempt in which
neither waited (the first finished before the second reached the lock) is
repeated with an empty cache, up to ATTEMPTS times."""
import math
import pathlib
import shutil
import subprocess
import sys

icd_run, work = sys.argv[1], pathlib.Path(sys.argv[2])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)

# A closed icosphere (subdivided icosahedron, 162 vertices) as a raw mesh.
t = (1 + 5 ** 0.5) / 2
verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
         (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
verts = [tuple(c / math.sqrt(sum(x * x for x in v)) for c in v) for v in verts]
for _ in range(2):
    mid, out = {}, []
    def midpoint(a, b):
        key = (min(a, b), max(a, b))
        if key not in mid:
            m = [(p + q) / 2 for p, q in zip(verts[a], verts[b])]
            n = math.sqrt(sum(c * c for c in m))
            verts.append(tuple(c / n for c in m))
            mid[key] = len(verts) - 1
        return mid[key]
    for a, b, c in faces:
        ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
        out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
    faces = out
with open(work / "ball.off", "w") as f:
    f.write(f"OFF\n{len(verts)} {len(faces)} 0\n")
    f.writelines(f"{x} {y} {z}\n" for x, y, z in verts)
    f.writelines(f"3 {a} {b} {c}\n" for a, b, c in faces)
(work / "scene.json").write_text("""{
  "name": "cache_lock", "frames": 2, "frame_rate": 60,
  "objects": [{"name": "ball", "mesh": "ball.off", "size": 0.2,
               "preprocess": {"coarse_tets": 200, "tree_depth": 2, "tree_branching": 8,
                              "tree_builder": "octree"},
               "material": {"model": "stvk", "young": 1e5, "poisson": 0.3, "density": 1000}}],
  "output": {"csv": true, "vtu_every": 0}
}
""")
ATTEMPTS = 5


def attempt(n):
    """One attempt: (errors, whether a run waited on the lock, the bundle's name)."""
    cache, out = work / f"cache{n}", work / f"out{n}"
    procs = [subprocess.Popen([icd_run, str(work / "scene.json"), "--quiet", "--cache-dir",
                               str(cache), "--out", str(out / str(k))], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for k in range(2)]
    outs = [p.communicate(timeout=600) for p in procs]
    errors = []
    for k, (p, (_, err)) in enumerate(zip(procs, outs)):
        if p.returncode != 0:
            errors.append(f"run {k} exited {p.returncode}: {err.strip()}")
    preprocessed = sum(err.count("[icd] preprocessing") for _, err in outs)
    if preprocessed != 1:
        errors.append(f"icd-preprocess ran {preprocessed} times, expected once")
    bundles = [d for d in cache.iterdir() if d.is_dir()]
    if len(bundles) != 1 or bundles[0].name.endswith(".part"):
        errors.append(f"cache folders: {[d.name for d in bundles]}, expected one complete bundle")
    for k in range(2):
        if not (out / str(k) / "frames.csv").exists():
            errors.append(f"run {k} wrote no frames.csv")
    waited = sum(err.count("[icd] waiting for another process") for _, err in outs)
    return errors, waited > 0, bundles[0].name if bundles else ""


for n in range(ATTEMPTS):
    errors, waited, bundle = attempt(n)
    if errors:
        sys.exit(f"attempt {n + 1}: " + "\n".join(errors))
    if waited:
        print(f"two concurrent runs, one waited on the lock, one preprocessing, one bundle "
              f"(attempt {n + 1}): {bundle}")
        sys.exit(0)
sys.exit(f"in {ATTEMPTS} attempts the two runs never overlapped (neither waited on the lock)")
