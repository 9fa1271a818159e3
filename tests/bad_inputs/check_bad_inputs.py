#!/usr/bin/python3
"""Feeds every bad input of manifest.tsv to the program that should refuse it
and checks the outcome (issue 9): a non-zero exit status that is not a signal
(no crash, no sanitizer abort), stderr/stdout naming the problem (the expected
substring of the manifest, case-insensitive), no hang (timeout), and, for
icd-run, no output file that looks complete (frames.csv or a .pvd series) in
the --out folder.

usage: check_bad_inputs.py --files DIR --manifest FILE --work DIR
                           --meshinfo EXE --run EXE --read-check EXE
                           [--preprocess EXE]
Rows whose program is not given (e.g. preprocess without CGAL) are skipped.
"""
import argparse
import os
import shutil
import signal
import subprocess
import sys
import time


def parse_manifest(path):
    rows = []
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            line = line.rstrip("\n")
            if not line.strip() or line.startswith("#"):
                continue
            parts = line.split("\t")
            if len(parts) != 3:
                sys.exit(f"{path}:{n}: expected 3 tab-separated fields, got {len(parts)}")
            rows.append((n, *parts))
    return rows


def looks_complete(out_dir):
    found = []
    for root, _, files in os.walk(out_dir):
        for name in files:
            if name == "frames.csv" or name.endswith(".pvd"):
                found.append(os.path.join(root, name))
    return found


def main():
    ap = argparse.ArgumentParser()
    for opt in ("files", "manifest", "work", "meshinfo", "run", "read-check"):
        ap.add_argument("--" + opt, required=True)
    ap.add_argument("--preprocess")
    ap.add_argument("--timeout", type=float, default=60)
    a = ap.parse_args()

    exe = {"meshinfo": a.meshinfo, "run": a.run, "run-dry": a.run,
           "read": a.read_check, "preprocess": a.preprocess}
    rows = parse_manifest(a.manifest)
    listed = {r[1] for r in rows}
    on_disk = {f for f in os.listdir(a.files) if not f.startswith(".")}
    failures = []
    for f in sorted(on_disk - listed):
        failures.append(f"{f}: in {a.files} but not in the manifest")
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    ran = skipped = 0
    t_all = time.monotonic()
    for n, name, program, expected in rows:
        path = os.path.join(a.files, name)
        if program not in exe:
            failures.append(f"manifest line {n}: unknown program '{program}'")
            continue
        if not exe[program]:
            skipped += 1
            continue
        if not os.path.exists(path):
            failures.append(f"{name}: listed in the manifest but missing")
            continue
        out_dir = os.path.join(a.work, name + ".out")
        if program == "meshinfo" or program == "read":
            cmd = [exe[program], path]
        elif program == "preprocess":
            cmd = [exe[program], path, "-o", out_dir, "-q"]
        else:
            cmd = [exe[program], path, "--out", out_dir, "--quiet"]
            if program == "run-dry":
                cmd.append("--dry-run")
        t0 = time.monotonic()
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, errors="replace",
                               timeout=a.timeout)
        except subprocess.TimeoutExpired:
            failures.append(f"{name}: {program} did not finish in {a.timeout} s")
            continue
        ran += 1
        dt = time.monotonic() - t0
        text = p.stdout + p.stderr
        first = (p.stderr.strip().splitlines() or ["<no stderr>"])[-1]
        problems = []
        if p.returncode < 0 or p.returncode >= 128:
            sig = -p.returncode if p.returncode < 0 else p.returncode - 128
            problems.append(f"killed by signal {sig} ({signal.Signals(sig).name})")
        elif p.returncode == 0:
            problems.append("exit status 0 (input accepted)")
        if "Sanitizer" in text or "runtime error:" in text:
            problems.append("sanitizer report")
        if expected.lower() not in text.lower():
            problems.append(f"message lacks '{expected}'")
        if program.startswith("run") or program == "preprocess":
            left = looks_complete(out_dir) if os.path.isdir(out_dir) else []
            if program == "preprocess" and os.path.isdir(out_dir):
                left += [os.path.join(out_dir, f) for f in os.listdir(out_dir)
                         if f == "bundle.icdb"]
            if left:
                problems.append("left complete-looking output: " + ", ".join(left))
        status = "FAIL" if problems else "ok"
        print(f"{status:4} {name:40} {program:10} rc={p.returncode} {dt:5.2f}s  {first[:150]}")
        if problems:
            failures.append(f"{name}: " + "; ".join(problems))
    print(f"\n{ran} bad inputs run, {skipped} skipped (program not built), "
          f"{time.monotonic() - t_all:.1f} s")
    if ran < 30:
        failures.append(f"only {ran} bad inputs were run (at least 30 expected)")
    for f in failures:
        print("FAILED:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
