"""Leaf-level summary of a perturb_sweep.sh log: one row per build, then the
median and range of each column, and how many builds have worst42 <= 80.
The leaf level is the deepest level printed for the build (3 for the
default tree, 1 for --flat)."""
import re
import statistics
import sys

builds = []  # (E, {level: metrics})
header = []  # the table's column names, from its header line (older logs have fewer)
names = {"spheres": "leaves", "unc.pts": "uncovered"}
kept = ["spheres", "worst42", "mean42", "worst42r", "mean42r", "worst162", "mean162", "unc.pts",
        "redund", "mean42c", "mean162c", "shell", "t50", "t90"]
counts = {"spheres", "unc.pts", "redund"}
for line in open(sys.argv[1]):
    if line.startswith("## perturb"):
        builds.append((line.split()[2], {}, {}))
        continue
    f = line.split()
    if f[:3] == ["model", "method", "level"]:
        header = f
        continue
    if not builds:
        continue
    _, per_level, extra = builds[-1]
    if len(f) == len(header) and f[1] == "medial":
        values = dict(zip(header, f))
        per_level.setdefault(int(values["level"]), {}).update(
            (names.get(c, c), (int if c in counts else float)(values[c]))
            for c in kept if c in values)
    m = re.match(r"# \w+ level (\d+): error on 2562 directions: worst ([\d.]+) mean ([\d.]+)", line)
    if m and "fit42" not in line:
        per_level.setdefault(int(m.group(1)), {}).update(
            worst2562=float(m.group(2)), mean2562=float(m.group(3)))
    m = re.search(r"build CPU time ([\d.]+) s", line)
    if m:
        extra["cpu"] = float(m.group(1))
    m = re.search(r"wall ([\d.]+) s on", line)
    if m:
        extra["wall"] = float(m.group(1))

rows = []
for e, per_level, extra in builds:
    row = {"E": e}
    if per_level:
        row.update(per_level[max(per_level)])
    row.update(extra)
    rows.append(row)

cols = ["leaves", "worst42", "mean42", "mean162", "mean2562", "worst2562", "uncovered", "cpu"]
if any("redund" in r for r in rows):
    cols[3:3] = ["redund", "mean42c", "mean162c"]
if any("mean42r" in r for r in rows):
    cols.insert(cols.index("mean42") + 1, "mean42r")
if any("shell" in r for r in rows):
    cols.insert(cols.index("mean2562") + 1, "shell")
if any("t50" in r for r in rows):
    cols[cols.index("shell") + 1:cols.index("shell") + 1] = ["t50", "t90"]
if any("wall" in extra for _, _, extra in builds):
    cols.append("wall")
print("E".ljust(8) + "".join(c.rjust(10) for c in cols))
for r in rows:
    print(r["E"].ljust(8) + "".join(str(r.get(c, "-")).rjust(10) for c in cols))
done = [r for r in rows if all(c in r for c in cols)]
if done:
    print("median".ljust(8) + "".join(str(round(statistics.median(r[c] for r in done), 2)).rjust(10) for c in cols))
    print("min".ljust(8) + "".join(str(min(r[c] for r in done)).rjust(10) for c in cols))
    print("max".ljust(8) + "".join(str(max(r[c] for r in done)).rjust(10) for c in cols))
    print(f"worst42 <= 80 in {sum(r['worst42'] <= 80 for r in done)} of {len(done)} builds")
