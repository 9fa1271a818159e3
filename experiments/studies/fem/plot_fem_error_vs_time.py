#!/usr/bin/python3
"""Plot the CSV of fem_error_vs_time: tip-deflection error against wall time
per simulated second, one panel per reference (Timoshenko beam formula, static
solution on the finest mesh). Colour = material, marker = integrator, label =
number of tets.

Usage: /usr/bin/python3 plot_fem_error_vs_time.py fem_error_vs_time.csv [out.png]
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLORS = {"linear": "tab:blue", "corotational": "tab:orange", "stvk": "tab:green",
          "stable_neo_hookean": "tab:red"}
MARKERS = {"rk4": "o", "symplectic_euler": "s", "backward_euler": "^"}


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    src = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else src.rsplit(".", 1)[0] + ".png"
    with open(src, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{src}: no rows")
    fig, axes = plt.subplots(1, 2, figsize=(12, 5), sharex=True)
    panels = [("err_analytic", "relative error vs Timoshenko"),
              ("err_fine_static", "relative error vs static solution, 30,720-tet mesh")]
    for ax, (column, title) in zip(axes, panels):
        for row in rows:
            x = float(row["wall_per_sim_s"])
            y = max(float(row[column]), 1e-6)
            ax.scatter(x, y, color=COLORS.get(row["material"], "k"),
                       marker=MARKERS.get(row["integrator"], "x"), s=40, alpha=0.8)
            ax.annotate(row["tets"], (x, y), fontsize=6, xytext=(3, 3), textcoords="offset points")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time per simulated second [s]")
        ax.set_ylabel(column)
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    handles = [plt.Line2D([], [], color=c, marker="o", linestyle="", label=m) for m, c in COLORS.items()]
    handles += [plt.Line2D([], [], color="k", marker=mk, linestyle="", label=i) for i, mk in MARKERS.items()]
    axes[1].legend(handles=handles, fontsize=8, loc="best")
    fig.suptitle("Cantilever 1.0 x 0.1 x 0.1 m under gravity, E = 1e8 Pa, nu = 0.3: error against run time")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
