#!/usr/bin/python3
"""Compares two gathered results.csv of the same sweep (e.g. the local pool's
and MPI's) and says whether they are equal except for what the programs
measure themselves.

usage: /usr/bin/python3 experiments/sweep/compare_results.py SWEEP.json A.csv B.csv

What is a measurement comes from the sweep file's "measured" field:
  "columns": columns never compared (wall times, frames per second);
  "rows": {"column": "value"}: rows whose every cell depends on the clock
          (a wall-clock critical time cuts the traversal), compared only on
          case_id, the parameter columns and the "stable" columns;
  "stable": columns compared even in those rows.
Everything else must be equal byte for byte: case ids, parameters, status,
exit status, message, every other collected column, and the row count.
Exit status 0 when equal, 1 when they differ (the first differences are
printed), 2 for a bad command line or unreadable file.
"""
import csv
import json
import sys


def read(path):
    with open(path, newline="") as f:
        r = csv.reader(f)
        rows = list(r)
    if not rows:
        raise ValueError(f"{path}: empty (no header)")
    return rows[0], rows[1:]


def main(argv):
    if len(argv) != 4 or argv[1] in ("-h", "--help"):
        print(__doc__, file=sys.stderr if len(argv) != 2 else sys.stdout)
        return 0 if len(argv) == 2 else 2
    try:
        with open(argv[1]) as f:
            sweep = json.load(f)
        measured = sweep.get("measured", {})
        skip = set(measured.get("columns", []))
        row_filter = measured.get("rows", {})
        stable = set(measured.get("stable", []))
        (ha, ra), (hb, rb) = read(argv[2]), read(argv[3])
    except (OSError, ValueError) as e:
        print(f"compare_results: {e}", file=sys.stderr)
        return 2
    name = sweep.get("name", argv[1])
    if ha != hb:
        print(f"{name}: the headers differ:\n  {','.join(ha)}\n  {','.join(hb)}")
        return 1
    if "status" not in ha:
        print(f"{name}: {argv[2]} is not a gathered results.csv (no status column)", file=sys.stderr)
        return 2
    params = ha[1:ha.index("status")]
    key_cols = {"case_id", *params, *stable}
    diffs = []
    if len(ra) != len(rb):
        diffs.append(f"row count {len(ra)} != {len(rb)}")
    timed_rows = 0
    for k, (a, b) in enumerate(zip(ra, rb)):
        da, db = dict(zip(ha, a)), dict(zip(hb, b))
        timed = bool(row_filter) and all(da.get(c) == v for c, v in row_filter.items())
        timed_rows += timed
        for c in ha:
            if c in skip or (timed and c not in key_cols):
                continue
            if da.get(c) != db.get(c):
                diffs.append(f"row {k + 2} (case {da.get('case_id')}), column {c}: {da.get(c)!r} != {db.get(c)!r}")
    ignored = sorted(skip & set(ha))
    what = (f"{len(ra)} rows; not compared: columns {', '.join(ignored) or '(none)'}"
            + (f"; {timed_rows} clock-dependent rows ({', '.join(f'{c}={v}' for c, v in row_filter.items())}) "
               f"on case_id, parameters and {', '.join(sorted(stable)) or 'nothing else'} only" if row_filter else ""))
    if diffs:
        print(f"{name}: DIFFERENT ({len(diffs)} differences; {what})")
        for d in diffs[:20]:
            print("  " + d)
        return 1
    print(f"{name}: equal ({what})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
