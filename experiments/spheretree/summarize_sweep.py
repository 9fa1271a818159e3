"""Leaf-level summary of a perturb_sweep.sh log: one row per build, then the
median and range of each column, and how many builds have worst42 <= 80.
The leaf level is the deepest level printed for the build (3 for the
default tree, 1 for --flat)."""
import re
import statistics
import sys

builds = []  # (E, {level: metrics})
for line in open(sys.argv[1]):
    if line.startswith("## perturb"):
        builds.append((line.split()[2], {}, {}))
        continue
    if not builds:
        continue
    _, per_level, extra = builds[-1]
    f = line.split()
    if len(f) > 10 and f[1] == "medial":
        per_level.setdefault(int(f[2]), {}).update(
            leaves=int(f[3]), worst42=float(f[4]), mean42=float(f[5]), worst162=float(f[6]),
            mean162=float(f[7]), uncovered=int(f[9]))
        if len(f) > 16:
            per_level[int(f[2])].update(redund=int(f[14]), mean42c=float(f[15]),
                                        mean162c=float(f[16]))
        if len(f) > 17:
            per_level[int(f[2])].update(shell=float(f[17]))
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
if any("shell" in r for r in rows):
    cols.insert(cols.index("mean2562") + 1, "shell")
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
