#!/usr/bin/python3
"""Summarises a bench_coupling JSON run (with --benchmark_repetitions) into a
Markdown table: median ns per dense vertex of each link mapping on each object,
and ratios against the reference (per-link) code and the barycentric embedding,
all from the same run.

Usage: summarise_bench.py bench.json > table.md
"""
import json
import statistics
import sys
from collections import defaultdict

MAPPINGS = ["reference", "evaluator", "apply_wrapper", "origin_sparse", "barycentric"]


def main(path):
    with open(path) as f:
        run = json.load(f)
    samples = defaultdict(list)  # (mapping, object) -> ns per vertex, one per repetition
    info = {}
    for b in run["benchmarks"]:
        if b.get("run_type") != "iteration" or not b["name"].startswith("Links/"):
            continue
        _, mapping, obj = b["run_name"].split("/")
        samples[(mapping, obj)].append(1e9 * b["ns_per_vertex"])  # stored in seconds
        info.setdefault(obj, {})["dense_vertices"] = int(b["dense_vertices"])
        if "triples" in b:
            info[obj]["triples"] = int(b["triples"])
    objects = sorted(info, key=lambda o: info[o]["dense_vertices"])
    median = {k: statistics.median(v) for k, v in samples.items()}
    reps = min(len(v) for v in samples.values())

    ctx = run["context"]
    print(f"Machine: {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, "
          f"load average {', '.join(f'{x:.1f}' for x in ctx.get('load_avg', []))}; "
          f"{reps} repetitions, medians (ns per dense vertex, CPU time).\n")
    print("| object | dense vertices | distinct triples | " +
          " | ".join(MAPPINGS) + " | reference / evaluator | evaluator / barycentric | evaluator min-max |")
    print("|---" * (6 + len(MAPPINGS)) + "|")
    for o in objects:
        row = [o, str(info[o]["dense_vertices"]), str(info[o].get("triples", "?"))]
        row += [f"{median[(m, o)]:.2f}" if (m, o) in median else "-" for m in MAPPINGS]
        ev = median.get(("evaluator", o))
        row.append(f"{median[('reference', o)] / ev:.2f}" if ev else "-")
        row.append(f"{ev / median[('barycentric', o)]:.2f}" if ev else "-")
        ev_samples = samples.get(("evaluator", o), [])
        row.append(f"{min(ev_samples):.2f}-{max(ev_samples):.2f}" if ev_samples else "-")
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main(sys.argv[1])
