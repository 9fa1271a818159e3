#!/usr/bin/env python3
"""Summary of a Ninja build log (.ninja_log, format v5): the longest steps,
totals per folder and per kind (compile, precompiled header, link), and the
steps running at the end of the build (what serialises it).

    scripts/ninja_log_summary.py build/cold/.ninja_log [--top 30]

Times are each step's wall time as Ninja recorded it (ms); on an idle
machine with -jN <= cores their sum approximates the build's CPU time."""
import argparse
import collections
import sys


def read_log(path):
    steps = {}
    with open(path, encoding="utf-8") as f:
        header = f.readline()
        if not header.startswith("# ninja log v"):
            sys.exit(f"{path}: not a ninja log (first line: {header.strip()!r})")
        for n, line in enumerate(f, start=2):
            parts = line.rstrip("\n").split("\t")
            if len(parts) != 5:
                sys.exit(f"{path}:{n}: expected 5 tab-separated fields")
            start, end, _, out, cmdhash = parts
            steps[out] = (int(start), int(end), cmdhash)  # the last run of each output
    # One command with several outputs appears once per output: keep one.
    seen, unique = set(), []
    for out, (s, e, h) in steps.items():
        if (s, e, h) in seen:
            continue
        seen.add((s, e, h))
        unique.append((out, s, e))
    return unique


def kind(out):
    if out.endswith(".gch") or out.endswith(".pch"):
        return "pch"
    if out.endswith(".o"):
        return "compile"
    if out.endswith(".a"):
        return "archive"
    return "link"


def folder(out):
    # CMake object paths: <dir>/CMakeFiles/<target>.dir/<source>.o
    if "/CMakeFiles/" in out:
        d = out.split("/CMakeFiles/")[0]
    else:
        d = out.rsplit("/", 1)[0] if "/" in out else "."
    parts = d.split("/")
    if parts[0] in ("experiments", "tests", "mesh") and len(parts) > 1:
        return "/".join(parts[:2])
    return parts[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("log")
    ap.add_argument("--top", type=int, default=30)
    a = ap.parse_args()
    steps = read_log(a.log)
    if not steps:
        sys.exit(f"{a.log}: no steps")
    dur = lambda s: (s[2] - s[1]) / 1000.0
    total = sum(dur(s) for s in steps)
    t0 = min(s[1] for s in steps)
    t1 = max(s[2] for s in steps)
    print(f"steps {len(steps)}, sum of step times {total:.0f} s, span {(t1 - t0) / 1000:.0f} s")
    by_kind = collections.Counter()
    for s in steps:
        by_kind[kind(s[0])] += dur(s)
    print("per kind: " + ", ".join(f"{k} {v:.0f} s" for k, v in by_kind.most_common()))
    print(f"\ntop {a.top} steps (s):")
    for s in sorted(steps, key=dur, reverse=True)[: a.top]:
        print(f"{dur(s):7.1f}  {s[0]}")
    by_dir = collections.defaultdict(lambda: [0.0, 0])
    for s in steps:
        v = by_dir[folder(s[0])]
        v[0] += dur(s)
        v[1] += 1
    print("\nper folder (s, steps):")
    for d, (t, n) in sorted(by_dir.items(), key=lambda kv: -kv[1][0]):
        print(f"{t:7.1f} {n:4d}  {d}")
    print("\nlast 10 steps to finish (start..end, s from the build start):")
    for s in sorted(steps, key=lambda s: s[2])[-10:]:
        print(f"{(s[1] - t0) / 1000:7.1f} .. {(s[2] - t0) / 1000:7.1f}  {s[0]}")


if __name__ == "__main__":
    main()
