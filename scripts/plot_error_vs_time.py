#!/usr/bin/python3
"""Error-against-run-time plots of issue 8 from the CSV files of
bin/contact_error, bin/deformation_error and bin/sphere_update_error.

usage: /usr/bin/python3 scripts/plot_error_vs_time.py RESULTS_DIR
  RESULTS_DIR/contact_error{,_spheres}/results.csv  -> contact_error.png
  RESULTS_DIR/deformation_{links,error}/results.csv -> deformation_error/deformation_error.png
  RESULTS_DIR/sphere_update/results.csv -> sphere_update.png
The inputs are the sweeps' gathered CSVs (scripts/run_experiments.sh; only
the rows of ok cases are drawn); where a folder has no results.csv, the
program's own CSV (contact_error.csv, links.csv and resolution.csv,
sphere_update.csv) is read instead. Missing inputs are reported and skipped.
Offscreen (Agg).
"""
import csv
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return [r for r in rows if r.get("status", "ok") == "ok"]  # a sweep's failed cases have no data


def pick(d, sub, own):
    """The sweep's gathered CSV in d/sub, else the program's own CSV there."""
    p = os.path.join(d, sub, "results.csv")
    return p if os.path.exists(p) else os.path.join(d, sub, own)


def col(rows, key):
    return np.array([float(r[key]) for r in rows])


def plot_contact(path, out):
    rows = read(path)
    modes = list(dict.fromkeys(r["mode"] for r in rows))
    fig, axes = plt.subplots(2, 2, figsize=(12, 8.5))
    panels = [("force_rel_error", "relative error of the total contact force\n|F - F_full| / |F_full|"
               " (< 1e-4 drawn at 1e-4)", "log"),
              ("recall_exact", "recall of the exact contact region\n(exact triangle pairs under a reported pair)", None),
              ("false_positive", "false positives\n(reported pairs with no exact triangle pair)", None),
              ("volume_ratio", "looseness: volume of reported spheres\n/ volume for the full traversal", "log")]
    colors = plt.cm.tab10(np.arange(len(modes)))
    for ax, (key, label, yscale) in zip(axes.ravel(), panels):
        for c, mode in zip(colors, modes):
            for kind, marker, ls in (("seconds", "o", "-"), ("tests", "s", ":")):
                sel = [r for r in rows if r["mode"] == mode and r["budget_kind"] == kind]
                if not sel:
                    continue
                t = col(sel, "seconds") * 1e6
                order = np.argsort(t)
                y = col(sel, key)
                if yscale == "log":
                    y = np.maximum(y, 1e-4)
                ax.plot(t[order], y[order], marker=marker, ls=ls, color=c, ms=4,
                        label=f"{mode} ({'time' if kind == 'seconds' else 'test'} budgets)")
        full_us = float(rows[0]["full_seconds"]) * 1e6
        ax.axvline(full_us, color="k", lw=0.8, ls="--", label="uninterrupted traversal time")
        ax.set_xscale("log")
        if yscale == "log":
            ax.set_yscale("log")
        ax.set_xlabel("time spent in the collision query (µs, median of the repetitions)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].legend(fontsize=7, ncol=1)
    r0 = rows[0]
    fig.suptitle(f"Contact error vs run time, {r0['scene']} frame {r0['frame']}: "
                 f"{r0['exact_pairs']} exact triangle pairs, {r0['full_leaf_pairs']} leaf pairs in the full traversal")
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    fig.savefig(out, dpi=110)
    print(f"plot_error_vs_time: wrote {out}")


def plot_deformation(links_path, res_path, out):
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    if os.path.exists(links_path):
        rows = read(links_path)
        for k, obj in enumerate(dict.fromkeys(r["object"] for r in rows)):
            sel = [r for r in rows if r["object"] == obj]
            f = col(sel, "frame")
            c = plt.cm.tab10(k)
            axes[0].plot(f, col(sel, "rms_error_pct_bbox"), color=c, label=f"{obj}: RMS")
            axes[0].plot(f, col(sel, "max_error_pct_bbox"), color=c, ls="--", label=f"{obj}: max")
            tl, tb = np.median(col(sel, "links_seconds")) * 1e3, np.median(col(sel, "barycentric_seconds")) * 1e3
            e = np.median(col(sel, "rms_error_pct_bbox"))
            axes[1].scatter([tl], [e], marker="o", label=f"{obj}: rigid links ({sel[0]['dense_vertices']} vertices)")
            axes[1].scatter([tb], [0.0], marker="x", label=f"{obj}: barycentric reference")
        axes[0].set_xlabel("frame")
        axes[0].set_ylabel("rigid links vs barycentric (% of bbox diagonal)")
        axes[0].set_title("rigid links vs barycentric embedding, per frame")
        axes[0].legend(fontsize=7)
        axes[1].set_xscale("log")
        axes[1].set_xlabel("time to map the dense surface per frame (ms, median)")
        axes[1].set_ylabel("median RMS error (% of bbox diagonal)")
        axes[1].set_title("mapping error vs time")
        axes[1].legend(fontsize=7)
    if os.path.exists(res_path):
        rows = sorted(read(res_path), key=lambda r: float(r["cells"]))  # a sweep: sorted by case id
        t = col(rows, "frame_seconds") * 1e3
        axes[2].plot(t, col(rows, "rms_error_pct_bbox"), "o-", label="RMS over frames")
        axes[2].plot(t, col(rows, "max_error_pct_bbox"), "s--", label="max over frames")
        for r, ti in zip(rows, t):
            axes[2].annotate(f"{r['cells']} cells\n{r['coarse_tets']} tets", (ti, float(r["rms_error_pct_bbox"])),
                             fontsize=7, textcoords="offset points", xytext=(4, 4))
        axes[2].axvline(float(rows[0]["fine_frame_seconds"]) * 1e3, color="k", ls=":",
                        label=f"reference: {rows[0]['fine_cells']} cells ({rows[0]['fine_coarse_tets']} tets)")
        axes[2].set_xscale("log")
        axes[2].set_xlabel("wall time per frame (ms, median)")
        axes[2].set_ylabel("dense surface error vs fine reference (% of bbox diagonal)")
        axes[2].set_title(f"coarse resolution vs fine mesh ({rows[0]['scene']})")
        axes[2].legend(fontsize=7)
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"plot_error_vs_time: wrote {out}")


def plot_sphere_update(path, out):
    rows = read(path)
    methods = list(dict.fromkeys(r["method"] for r in rows))
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    for m in methods:
        sel = [r for r in rows if r["method"] == m]
        t = col(sel, "seconds") * 1e6
        for ax, key in ((axes[0], "uncovered_fraction"), (axes[1], "tightness")):
            y = col(sel, key)
            ax.errorbar([np.median(t)], [np.median(y)], yerr=[[np.median(y) - y.min()], [y.max() - np.median(y)]],
                        xerr=[[np.median(t) - t.min()], [t.max() - np.median(t)]], fmt="o", capsize=3, label=m)
        frames = sorted(set(int(r["frame"]) for r in sel))
        worst = [max(float(r["uncovered_fraction"]) for r in sel if int(r["frame"]) == f) for f in frames]
        axes[2].plot(frames, worst, label=m)
    axes[0].set_ylabel("uncovered fraction of dense vertices (leaves)")
    axes[1].set_ylabel("tightness: leaf sphere volume / enclosed volume")
    for ax in axes[:2]:
        ax.set_xscale("log")
        ax.set_xlabel("time per object per frame (µs; median, bars: min-max over frames)")
    axes[2].set_xlabel("frame")
    axes[2].set_ylabel("uncovered fraction (worst object)")
    # Fractions are >= 0: no negative axis; an all-zero panel says so.
    for ax in (axes[0], axes[2]):
        top = max(float(r["uncovered_fraction"]) for r in rows)
        ax.set_ylim(0, top * 1.1 if top > 0 else 1e-3)
        if top == 0:
            ax.text(0.5, 0.5, "0 in every frame: every deformed vertex\ninside a leaf sphere",
                    transform=ax.transAxes, ha="center", va="center", fontsize=8)
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"Sphere update vs rebuild on the deformed surface ({rows[0]['scene']})")
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    fig.savefig(out, dpi=110)
    print(f"plot_error_vs_time: wrote {out}")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    d = sys.argv[1]
    done = 0
    for sub in ("contact_error", "contact_error_spheres"):
        p = pick(d, sub, "contact_error.csv")
        if os.path.exists(p):
            plot_contact(p, os.path.join(d, sub, "contact_error.png"))
            done += 1
        else:
            print(f"plot_error_vs_time: {p} missing, skipped")
    links = os.path.join(d, "deformation_links", "results.csv")
    if not os.path.exists(links):
        links = os.path.join(d, "deformation_error", "links.csv")
    res = pick(d, "deformation_error", "resolution.csv")
    if os.path.exists(links) or os.path.exists(res):
        plot_deformation(links, res, os.path.join(d, "deformation_error", "deformation_error.png"))
        done += 1
    else:
        print(f"plot_error_vs_time: {links} missing, skipped")
    p = pick(d, "sphere_update", "sphere_update.csv")
    if os.path.exists(p):
        plot_sphere_update(p, os.path.join(d, "sphere_update", "sphere_update.png"))
        done += 1
    else:
        print(f"plot_error_vs_time: {p} missing, skipped")
    if done == 0:
        sys.exit("plot_error_vs_time: nothing to plot")


if __name__ == "__main__":
    main()
