"""bundle_report recomputes, from an icd-preprocess output folder's VTU files,
the quality and fidelity figures icd-preprocess printed in its summary: the
two must agree (tets, interior nodes, dihedral range, radius-edge ratio,
stable-step ratio with and without mass scaling, added mass, volume change,
Hausdorff distance), each to the summary's printed precision.
Usage: check_bundle_report.py ICD_PREPROCESS BUNDLE_REPORT WORK_DIR"""
import importlib.util
import pathlib
import shutil
import subprocess
import sys

preprocess, report, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
root = pathlib.Path(__file__).resolve().parents[2]
shutil.rmtree(work, ignore_errors=True)
(work / "logs").mkdir(parents=True)

# A closed L-shaped block (two boxes joined), outward-oriented: not convex,
# so the tets are not all alike.
pts = [(0, 0, 0), (2, 0, 0), (2, 1, 0), (1, 1, 0), (1, 2, 0), (0, 2, 0)]
verts = [(x, y, 0.0) for x, y, _ in pts] + [(x, y, 0.7) for x, y, _ in pts]
faces = [(0, 2, 1), (0, 3, 2), (0, 5, 3), (3, 5, 4),          # bottom (z = 0), facing -z
         (6, 7, 8), (6, 8, 9), (6, 9, 11), (9, 10, 11)]        # top (z = 0.7), facing +z
for i in range(6):                                              # sides
    j = (i + 1) % 6
    faces += [(i, j, j + 6), (i, j + 6, i + 6)]
mesh = work / "lblock.off"
mesh.write_text("OFF\n%d %d 0\n" % (len(verts), len(faces)) +
                "".join("%g %g %g\n" % v for v in verts) +
                "".join("3 %d %d %d\n" % f for f in faces))

out = work / "bundles" / "lblock"
log = subprocess.run([preprocess, str(mesh), "-o", str(out), "--coarse-tets", "400",
                      "--spheres", "octree"], capture_output=True, text=True, timeout=600)
(work / "logs" / "lblock.log").write_text(log.stdout + log.stderr)
(work / "logs" / "lblock.rc").write_text(str(log.returncode))
if log.returncode != 0:
    sys.exit("icd-preprocess failed:\n" + log.stdout + log.stderr)

spec = importlib.util.spec_from_file_location(
    "corpus_table", root / "experiments" / "studies" / "preprocess" / "corpus_table.py")
table = importlib.util.module_from_spec(spec)
spec.loader.exec_module(table)
summary = table.row(str(work), "lblock")

res = subprocess.run([report, str(out)], capture_output=True, text=True, timeout=600)
if res.returncode != 0:
    sys.exit("bundle_report failed:\n" + res.stdout + res.stderr)
header, row = [line.split("\t") for line in res.stdout.strip().splitlines()]
got = dict(zip(header, row))

# (summary column, bundle_report column, tolerance of the summary's rounding)
checks = [("tets", "tets", 0), ("interior_nodes", "interior_nodes", 0),
          ("min_dihedral", "min_dihedral", 0.051), ("max_dihedral", "max_dihedral", 0.051),
          ("max_radius_edge", "max_radius_edge", 0.0051), ("step_ratio", "step_ratio", 0.0011),
          ("scaled_ratio", "scaled_ratio", 0.0011), ("added_mass_pct", "added_mass_pct", 0.011),
          ("volume_change", "volume_change_pct", 0.051),
          ("hausdorff_pct_diag", "hausdorff_pct_diag", 0.011)]
bad = []
for s_col, r_col, tol in checks:
    if s_col not in summary or summary[s_col] in ("", None):
        bad.append(f"the summary has no {s_col}")
        continue
    a = float(str(summary[s_col]).rstrip("%").split()[0])
    b = float(got[r_col])
    if abs(a - b) > tol:
        bad.append(f"{s_col}: summary {a}, bundle_report {b}")
if bad:
    sys.exit("bundle_report disagrees with the summary:\n  " + "\n  ".join(bad))
print("bundle_report agrees with the summary on", len(checks), "figures:", got)
