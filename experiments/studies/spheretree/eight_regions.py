#!/usr/bin/python3
"""Where the leaf error of sphere trees of the corpus eight (genus 2) comes
from: per surface region, the leaves (by the region of the surface point
nearest to their centre) and the surface samples (overhang = how far the
leaves containing a sample reach along its normal), for several trees of the
same mesh side by side.

usage: eight_regions.py LABEL=LEAVES.csv,SAMPLES.csv [LABEL=...]...
         [--covered-by LABEL]

LEAVES.csv / SAMPLES.csv: `evaluate_sph data/corpus/eight.off TREE.sph
--leaf-table LEAVES.csv --sample-table SAMPLES.csv` (normalized units, origin
at the bounding-box centre; every SAMPLES.csv of one mesh and spacing lists
the same samples in the same order). --covered-by LABEL: the overhang columns
are also given over the samples that tree covers only ("restricted").

Regions (the eight lies in the x-z plane, longest side z = 2000; its holes
run along y through (0, +-HOLE_Z)): "waist" |z| < WAIST (where the two rings
meet: the outer waist and the bar between the holes), otherwise "flat" when
the normal is within 45 deg of +-y, "hole" when it points towards the axis of
the nearer hole, "outer" when away from it.
"""
import csv
import math
import sys

HOLE_Z = 512.0
WAIST = 200.0


def region(x, z, nx, ny, nz):
    if abs(z) < WAIST:
        return "waist"
    if abs(ny) > math.sqrt(0.5):
        return "flat"
    hz = HOLE_Z if z > 0 else -HOLE_Z
    return "hole" if nx * (x - 0.0) + nz * (z - hz) < 0 else "outer"


def read(path):
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def leaf_region(l):
    # The surface normal at the nearest point: from the centre to that point
    # for a centre inside, the other way for one outside.
    dx, dy, dz = l["sx"] - l["x"], l["sy"] - l["y"], l["sz"] - l["z"]
    n = math.sqrt(dx * dx + dy * dy + dz * dz) or 1.0
    sign = 1.0 if l["depth"] >= 0 else -1.0
    return region(l["sx"], l["sz"], sign * dx / n, sign * dy / n, sign * dz / n)


def main(argv):
    trees, covered_by = [], None
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--covered-by" and i + 1 < len(argv):
            covered_by = argv[i + 1]
            i += 2
            continue
        if "=" not in a or "," not in a:
            print(__doc__, file=sys.stderr)
            return 2
        label, files = a.split("=", 1)
        leaves, samples = files.split(",", 1)
        trees.append((label, read(leaves), read(samples)))
        i += 1
    if not trees:
        print(__doc__, file=sys.stderr)
        return 2
    n = len(trees[0][2])
    if any(len(t[2]) != n for t in trees):
        print("eight_regions.py: the sample tables differ in length", file=sys.stderr)
        return 1
    names = ["hole", "waist", "flat", "outer"]
    base = trees[0][2]
    sample_region = [region(s["x"], s["z"], s["nx"], s["ny"], s["nz"]) for s in base]
    mask = None
    if covered_by is not None:
        ref = next((t for t in trees if t[0] == covered_by), None)
        if ref is None:
            print(f"eight_regions.py: no tree labelled {covered_by}", file=sys.stderr)
            return 2
        mask = [s["leaves"] > 0 for s in ref[2]]
    area = {r: 0.0 for r in names}
    for s, r in zip(base, sample_region):
        area[r] += s["w"]
    total = sum(area.values())
    print("| region | area % | " + " | ".join(
        f"{t[0]} leaves | {t[0]} mean162 | {t[0]} mean2562 | {t[0]} uncovered % | "
        f"{t[0]} mean overhang" + (f" | {t[0]} overhang on {covered_by}'s covered" if mask else "")
        for t in trees) + " |")
    cols = 2 + len(trees) * (5 + (1 if mask else 0))
    print("|" + "---|" * cols)
    for r in names + ["all"]:
        cells = [r, f"{100 * (total if r == 'all' else area[r]) / total:.1f}"]
        for label, leaves, samples in trees:
            mine = [l for l in leaves if r == "all" or leaf_region(l) == r]
            cells.append(str(len(mine)))
            cells.append(f"{sum(l['e162'] for l in mine) / len(mine):.2f}" if mine else "")
            cells.append(f"{sum(l['e2562'] for l in mine) / len(mine):.2f}" if mine else "")
            a = unc = reach = 0.0
            ra = rreach = 0.0
            for k, s in enumerate(samples):
                if r != "all" and sample_region[k] != r:
                    continue
                a += s["w"]
                reach += s["w"] * s["reach"]
                if s["leaves"] == 0:
                    unc += s["w"]
                if mask and mask[k]:
                    ra += s["w"]
                    rreach += s["w"] * s["reach"]
            cells.append(f"{100 * unc / a:.2f}" if a else "")
            cells.append(f"{reach / a:.2f}" if a else "")
            if mask:
                cells.append(f"{rreach / ra:.2f}" if ra else "")
        print("| " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
