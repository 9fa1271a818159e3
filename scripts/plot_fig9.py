#!/usr/bin/python3
"""Renders the paper's Fig. 9 from the files written by bin/fig9.

One panel per critical time: the two dense meshes (orthographic projection,
Lambert-shaded, faces sorted back to front) and the spheres used for the
contact response drawn as their exact orthographic outlines (circles):
colliding leaves (COLLISIONLIST) filled red, untested pairs (PAIRLIST at the
interruption, assumed colliding) as red outlines. Offscreen (Agg).

usage: /usr/bin/python3 scripts/plot_fig9.py FIG9_DIR [--out fig9.png] [--max-faces N]
"""
import argparse
import csv
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import PatchCollection, PolyCollection
from matplotlib.patches import Circle
import meshio
import numpy as np


def view_basis(azimuth_deg, elevation_deg):
    """Orthonormal screen axes (right, up) and the direction towards the viewer."""
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    toward = np.array([np.sin(az) * np.cos(el), np.sin(el), np.cos(az) * np.cos(el)])
    right = np.cross([0.0, 1.0, 0.0], toward)
    right /= np.linalg.norm(right)
    up = np.cross(toward, right)
    return right, up, toward


def draw_mesh(ax, path, basis, color, max_faces, rng):
    mesh = meshio.read(path)
    V = mesh.points
    F = mesh.cells_dict["triangle"]
    if len(F) > max_faces:  # decimate for plotting: a random subset of the faces
        F = F[rng.choice(len(F), max_faces, replace=False)]
    right, up, toward = basis
    tri = V[F]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    facing = n @ toward
    keep = facing > 0  # back-face culling (closed meshes)
    tri, facing = tri[keep], facing[keep]
    depth = (tri.mean(axis=1) @ toward)
    order = np.argsort(depth)
    xy = np.stack([tri @ right, tri @ up], axis=-1)[order]
    shade = 0.35 + 0.65 * facing[order]
    colors = np.clip(np.outer(shade, color), 0, 1)
    ax.add_collection(PolyCollection(xy, facecolors=colors, edgecolors="none", alpha=0.55))
    return xy.reshape(-1, 2)


def draw_spheres(ax, path, basis):
    with open(path) as f:
        if 'NumberOfPoints="0"' in f.read(4096):
            return 0, 0  # no sphere pair reported (meshio cannot read an empty VTU)
    s = meshio.read(path)
    right, up, _ = basis
    r = s.point_data["radius"].ravel()
    leaf = s.point_data["colliding_leaf"].ravel() > 0.5
    c = np.stack([s.points @ right, s.points @ up], axis=-1)
    untested = [Circle(c[k], r[k]) for k in np.flatnonzero(~leaf)]
    colliding = [Circle(c[k], r[k]) for k in np.flatnonzero(leaf)]
    ax.add_collection(PatchCollection(untested, facecolor=(1, 0, 0, 0.08), edgecolor=(0.8, 0, 0, 0.9),
                                      linewidths=0.6, linestyle="--"))
    ax.add_collection(PatchCollection(colliding, facecolor=(1, 0, 0, 0.75), edgecolor=(0.5, 0, 0, 1),
                                      linewidths=0.4))
    return int(leaf.sum()), int((~leaf).sum())


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("fig9_dir")
    ap.add_argument("--out", default=None, help="PNG path (default FIG9_DIR/fig9.png)")
    ap.add_argument("--max-faces", type=int, default=100000, help="faces drawn per mesh (random subset above)")
    ap.add_argument("--azimuth", type=float, default=20.0, help="view azimuth about +y, degrees")
    ap.add_argument("--elevation", type=float, default=15.0, help="view elevation, degrees")
    args = ap.parse_args()
    manifest = os.path.join(args.fig9_dir, "manifest.csv")
    if not os.path.exists(manifest):
        sys.exit(f"plot_fig9: {manifest} not found (run bin/fig9 first)")
    with open(manifest) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_fig9: {manifest} has no rows")
    basis = view_basis(args.azimuth, args.elevation)
    rng = np.random.default_rng(0)
    mesh_colors = [np.array([0.55, 0.65, 0.85]), np.array([0.75, 0.75, 0.6])]
    fig, axes = plt.subplots(1, len(rows), figsize=(4.2 * len(rows), 4.6), squeeze=False)
    for ax, row in zip(axes[0], rows):
        d = os.path.join(args.fig9_dir, row["dir"])
        pts = [draw_mesh(ax, os.path.join(d, name), basis, mesh_colors[k % 2], args.max_faces, rng)
               for k, name in enumerate(row["objects"].split(";"))]
        nleaf = nunt = 0
        for name in row["spheres"].split(";"):
            a, b = draw_spheres(ax, os.path.join(d, name), basis)
            nleaf, nunt = nleaf + a, nunt + b
        allp = np.vstack(pts)
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        pad = 0.05 * (hi - lo).max()
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(f"critical time {float(row['budget']):g} s\n"
                     f"PAIRLIST {row['pair_list']}, COLLISIONLIST {row['collision_list']}\n"
                     f"(frame {row['frame']}, completed level {row['completed_level']})"
                     + ("\nFEM FAILED after this frame (see manifest.csv)" if row.get("failure") else ""),
                     fontsize=9, color="darkred" if row.get("failure") else "black")
    handles = [plt.Rectangle((0, 0), 1, 1, facecolor=(1, 0, 0, 0.75), edgecolor=(0.5, 0, 0)),
               plt.Rectangle((0, 0), 1, 1, facecolor=(1, 0, 0, 0.08), edgecolor=(0.8, 0, 0), linestyle="--")]
    fig.legend(handles, ["colliding leaf spheres (COLLISIONLIST)",
                         "untested sphere pairs (PAIRLIST, assumed colliding)"],
               loc="lower center", ncol=2, fontsize=9, frameon=False)
    fig.suptitle(f"Spheres used for the contact response, {rows[0]['scene']} (orthographic view)", fontsize=11)
    fig.tight_layout(rect=(0, 0.06, 1, 0.95))
    out = args.out or os.path.join(args.fig9_dir, "fig9.png")
    fig.savefig(out, dpi=130)
    print(f"plot_fig9: wrote {out}")


if __name__ == "__main__":
    main()
