#!/usr/bin/python3
"""Reads the logs of run_corpus.sh (OUT/logs/MESH.log, .rc) and writes
OUT/corpus.csv and OUT/corpus_table.md: one row per mesh.

usage: corpus_table.py [--check] OUT MESH...
--check: exit 1 when a mesh that succeeded lacks a figure of the table (the
CTest PreprocessCorpus.Subset: the log format and this parser cannot drift apart).
"""
import csv
import os
import re
import sys

TARGET_TETS = 2000
# "Enough interior nodes for the object to deform": at least this share of the
# coarse mesh's nodes lies inside (a mesh whose nodes are nearly all on the
# surface has no node to carry bending or compression through thick parts).
MIN_INTERIOR_SHARE = 0.10


def num(pattern, text, group=1, default=""):
    m = re.search(pattern, text)
    return m.group(group) if m else default


def row(out, mesh):
    log = open(os.path.join(out, "logs", mesh + ".log"), errors="replace").read()
    rc = int(open(os.path.join(out, "logs", mesh + ".rc")).read().strip() or 1)
    r = {"mesh": mesh,
         "triangles": num(r"\[read\][^\n]*?(\d+) triangles", log),
         "outcome": "ok" if rc == 0 else ("refused" if rc == 1 else f"exit {rc}")}
    err = num(r"^icd-preprocess: (.*)$", log, default="") if rc else ""
    m = re.search(r"^icd-preprocess: (.*)$", log, re.M)
    text = m.group(1) if (m and rc) else ""
    # A refusal's stated cause and fix (the part from "Cause:"), else its start.
    cause = text.find("Cause:")
    if cause > 0:
        fix = text.find(" (", text.find("The option that fixes this", cause))
        text = "... " + text[cause:fix if fix > cause else None]
    r["message"] = text[:600] + ("..." if len(text) > 600 else "")
    q = re.search(r"(\d+) vertices \((\d+) on the surface\), (\d+) tets", log)
    if q:
        nv, ns, nt = map(int, q.groups())
        r.update(tets=nt, interior_nodes=nv - ns, interior_share=f"{100.0 * (nv - ns) / nv:.1f}%",
                 tet_count_error=f"{100.0 * (nt / TARGET_TETS - 1):+.0f}%")
    d = re.search(r"dihedral angles \[([^,]+), ([^\]]+)\] deg, max radius-edge ratio ([^,]+), "
                  r"min volume [^,]+, total volume (\S+)", log)
    if d:
        r.update(min_dihedral=f"{float(d.group(1)):.1f}", max_dihedral=f"{float(d.group(2)):.1f}",
                 max_radius_edge=f"{float(d.group(3)):.2f}")
        vol_rep = num(r"component\(s\), volume (\S+)", log)
        if vol_rep:
            r["volume_change"] = f"{100.0 * (float(d.group(4)) / float(vol_rep) - 1):+.1f}%"
    ratio = num(r"near-regular tets of the same mean volume\): ratio ([\d.]+)", log)
    if ratio:
        r["step_ratio"] = ratio
    # Selective mass scaling as the runtime applies it (fem::MassScaling, the
    # scenes' default target 0.4, at most 5 % added mass).
    ms = re.search(r"with mass scaling to ([\d.]+) [^:]*: \+([\d.e+-]+) % mass on (\d+) nodes "
                   r"\(max x [^)]*\), step [^,]+, ratio ([\d.]+)( \(target not reached)?", log)
    if ms:
        r.update(scaled_ratio=ms.group(4) + (" (not reached)" if ms.group(5) else ""),
                 added_mass_pct=f"{float(ms.group(2)):.2f}",
                 scaled_nodes=ms.group(3), scaling_reached="no" if ms.group(5) else "yes")
    elif ratio and re.search(r"mass scaling to [\d.]+ \(the scenes' default\): nothing to add", log):
        r.update(scaled_ratio=ratio, added_mass_pct="0.00", scaled_nodes="0",
                 scaling_reached="yes")
    h = num(r"\(([\d.e+-]+)% of the bbox diagonal", log)
    if h:
        r["hausdorff_pct_diag"] = f"{float(h):.2f}"
    t = re.search(r"; total ([\d.]+) \(([\d.]+)\), peak (\d+) MB", log)
    if t:
        r.update(wall_s=t.group(1), cpu_s=t.group(2), peak_mb=t.group(3))
    for stage, col in (("repair", "repair_cpu_s"), ("simplify", "simplify_cpu_s"),
                       ("tetrahedralize", "tet_cpu_s"), ("sphere tree", "sphere_cpu_s"),
                       ("hausdorff", "hausdorff_cpu_s")):
        m = re.search(r"[ :]" + stage + r" ([\d.]+) \(([\d.]+)\) \[", log)
        if m:
            r[col] = m.group(2)
            r[col.replace("cpu", "wall")] = m.group(1)
    # Progress lines (printed whether the mesh succeeded or not), not the summary's notes.
    r["retries"] = len(re.findall(r"^\[\d+/\d+\] tetrahedralize: pass at cell size", log, re.M))
    r["repairs"] = "; ".join(
        s for s in [
            "autorefined" if "resolved self-intersections by autorefinement" in log else "",
            "local SI repair" if "repaired self-intersections locally" in log else "",
            "split vertices" if "split non-manifold vertices" in log else "",
            "holes %s" % num(r"filled holes: (\d+)", log) if "filled holes" in log else "",
            "WIDE HOLE" if "WARNING: filled a hole" in log else "",
            "alpha-wrapped%s (%s%% diag)" % (
                " after the mesher failed" if "the mesher failed at every size on the repaired" in log
                else " for parts in near contact" if "parts of the repaired surface in near contact"
                in log else "", num(r"lies within ([\d.e+-]+) % of the diagonal of the input", log))
            if "rebuilt the surface by alpha wrapping" in log else ""] if s)
    warn = []
    if d and float(d.group(1)) < 12.0:
        warn.append("min dihedral < 12")
    if ratio and float(ratio) < 0.4:
        warn.append("step ratio < 0.4" + (" (0.4 with mass scaling)"
                                          if r.get("scaling_reached") == "yes" else ""))
    if h and float(h) > 3.0:
        warn.append("Hausdorff > 3%")
    if "volume_change" in r and abs(float(r["volume_change"].rstrip("%"))) > 5.0:
        warn.append("volume > 5%")
    if q and abs(nt / TARGET_TETS - 1) > 0.25:
        warn.append("tets off by > 25%")
    if q and (nv - ns) < MIN_INTERIOR_SHARE * nv:
        warn.append(f"interior nodes < {100 * MIN_INTERIOR_SHARE:.0f}%")
    if t and float(t.group(2)) > 60.0:
        warn.append("CPU > 60 s")
    if t and float(t.group(3)) > 2048.0:
        warn.append("memory > 2 GB")
    r["target_misses"] = ", ".join(warn)
    return r


REQUIRED = ["tets", "tet_count_error", "interior_nodes", "interior_share", "step_ratio",
            "scaled_ratio", "added_mass_pct",
            "min_dihedral", "max_radius_edge", "hausdorff_pct_diag", "volume_change",
            "repair_cpu_s", "tet_cpu_s", "cpu_s", "wall_s", "peak_mb"]


def main():
    args = sys.argv[1:]
    check = bool(args) and args[0] == "--check"
    if check:
        args = args[1:]
    out, meshes = args[0], args[1:]
    rows = [row(out, m) for m in meshes]
    cols = ["mesh", "triangles", "outcome", "tets", "tet_count_error", "interior_nodes",
            "interior_share", "step_ratio", "scaled_ratio", "added_mass_pct", "min_dihedral", "max_dihedral", "max_radius_edge",
            "hausdorff_pct_diag", "volume_change", "repair_cpu_s", "simplify_cpu_s", "tet_cpu_s",
            "sphere_cpu_s", "hausdorff_cpu_s", "cpu_s", "wall_s", "peak_mb", "retries", "repairs",
            "target_misses", "message"]
    csv_cols = cols + ["scaled_nodes", "scaling_reached", "repair_wall_s", "simplify_wall_s", "tet_wall_s", "sphere_wall_s",
                       "hausdorff_wall_s"]
    with open(os.path.join(out, "corpus.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=csv_cols, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    ok = sum(r["outcome"] == "ok" for r in rows)
    with open(os.path.join(out, "corpus_table.md"), "w") as f:
        retried = sum(r["outcome"] == "ok" and r["retries"] > 0 for r in rows)
        wrapped = sum(r["outcome"] == "ok" and "alpha-wrapped" in r["repairs"] for r in rows)
        wrap_retried = sum(r["outcome"] == "ok" and ("after the mesher failed" in r["repairs"] or
                                                     "parts in near contact" in r["repairs"])
                           for r in rows)
        oks = [r for r in rows if r["outcome"] == "ok"]
        reached = sum(r.get("scaling_reached") == "yes" for r in oks)
        dihedral_ok = sum(r.get("min_dihedral", "") != "" and float(r["min_dihedral"]) >= 12.0
                          for r in oks)
        f.write(f"{ok} of {len(rows)} meshes succeeded ({100.0 * ok / max(1, len(rows)):.0f} %) "
                f"with defaults; {retried} of them after mesher retries at nearby cell sizes, "
                f"{wrapped} rebuilt by alpha wrapping ({wrap_retried} of them by the automatic "
                f"wrap retry: after the mesher failed, or at once for parts in near contact). Selective mass scaling (target 0.4, "
                f"<= 5 % added mass) reaches the 0.4 step ratio on {reached} of the {ok}; "
                f"min dihedral >= 12 deg on {dihedral_ok} of the {ok}.\n\n")
        f.write("| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n")
        for r in rows:
            f.write("| " + " | ".join(str(r.get(c, "")).replace("|", "/") for c in cols) + " |\n")
    print(f"[corpus] {ok}/{len(rows)} ok; table in {out}/corpus_table.md")
    if check:
        missing = [(r["mesh"], c) for r in rows if r["outcome"] == "ok" for c in REQUIRED
                   if str(r.get(c, "")) == ""]
        for m, c in missing:
            print(f"[corpus] {m}: no {c} found in its log", file=sys.stderr)
        if missing:
            sys.exit(1)


if __name__ == "__main__":
    main()
