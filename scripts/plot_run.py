#!/usr/bin/python3
"""Pictures of one run (a folder written by icd-main or icd-run):

  run.gif         animation of the written frames: the dense meshes (or the
                  coarse surfaces) deforming, with the contact spheres marked
                  (red: from colliding leaf pairs; grey: untested pairs)
  frames.png      frames.csv over time: energy, contact force, time per stage,
                  queries interrupted and the level they completed, and the
                  real-time deadline columns when the run has them
  tree_levels.png each object's sphere tree, level by level (circles in the
                  plane of the object's two widest axes, true radii)

usage: plot_run.py RUN_DIR [--out DIR] [--max-faces N] [--fps F]
Needs matplotlib, numpy, meshio (Debian python3-*); Pillow for the GIF.
Exits 1 naming the file when an input is missing or unreadable.
"""
import argparse
import csv
import math
import os
import sys
import xml.etree.ElementTree as ET

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.animation import PillowWriter  # noqa: E402
from matplotlib.collections import PatchCollection  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

COLOURS = ["#d9a066", "#6d9fd1", "#8fc17f", "#c98bd1", "#d1c46d"]


def fail(msg):
    print(f"plot_run.py: {msg}", file=sys.stderr)
    sys.exit(1)


def read_mesh(path):
    try:
        return meshio.read(path)
    except Exception as e:  # noqa: BLE001 - report any reader failure with the file
        fail(f"{path}: cannot read: {e}")


def read_frames(run):
    path = os.path.join(run, "frames.csv")
    try:
        with open(path) as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    if not rows:
        fail(f"{path}: no frames")
    cols = {}
    for k in rows[0]:
        try:
            cols[k] = np.array([float(r[k]) for r in rows])
        except (TypeError, ValueError):
            fail(f"{path}: column {k} is not numeric")
    return cols


def read_series(run):
    """[(time, {label: file})] from vtu/run.pvd, in time order."""
    vtu = os.path.join(run, "vtu")
    pvd = os.path.join(vtu, "run.pvd")
    try:
        root = ET.parse(pvd).getroot()
    except (OSError, ET.ParseError) as e:
        fail(f"{pvd}: {e}")
    steps = {}
    for d in root.iter("DataSet"):
        f = d.get("file")
        label = f.rsplit("_", 1)[0]
        steps.setdefault(float(d.get("timestep")), {})[label] = os.path.join(vtu, f)
    return sorted(steps.items())


def object_names(labels):
    return sorted({lab.rsplit("_", 1)[0] for lab in labels
                   if lab.endswith("_dense") or lab.endswith("_coarse")})


def surface_triangles(mesh):
    """Triangles of a dense surface, or the boundary faces of a tet mesh."""
    for c in mesh.cells:
        if c.type == "triangle":
            return c.data
    for c in mesh.cells:
        if c.type == "tetra":
            t = c.data
            faces = np.concatenate([t[:, [0, 2, 1]], t[:, [0, 1, 3]], t[:, [1, 2, 3]],
                                    t[:, [0, 3, 2]]])
            key = np.sort(faces, axis=1)
            _, idx, count = np.unique(key, axis=0, return_index=True, return_counts=True)
            return faces[idx[count == 1]]
    return np.zeros((0, 3), dtype=int)


def cluster(points, tris, max_faces):
    """Vertex-clustering decimation: vertices binned on a grid over the
    first frame's bounding box, refined until at most max_faces triangles
    remain that join three different bins. Returns (bin of each vertex,
    triangles over bins); cluster_points gives the bins' positions."""
    if len(tris) <= max_faces:
        return np.arange(len(points)), tris
    lo, hi = points.min(0), points.max(0)
    best = None
    for cells in (96, 80, 64, 48, 40, 32, 24, 16, 12, 8):
        q = np.floor((points - lo) / ((hi - lo).max() / cells + 1e-30)).astype(np.int64)
        _, label = np.unique(q, axis=0, return_inverse=True)
        label = label.ravel()
        t = label[tris]
        t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
        _, keep = np.unique(np.sort(t, axis=1), axis=0, return_index=True)
        best = (label, t[np.sort(keep)])
        if len(best[1]) <= max_faces:
            break
    return best


def cluster_points(points, label, tris):
    """Positions of the bins (mean of their vertices), as cluster() made them."""
    if len(label) == len(points) and label.max() + 1 == len(points) and tris.max() < len(points) \
            and np.array_equal(label, np.arange(len(points))):
        return points
    n = label.max() + 1
    count = np.bincount(label, minlength=n)[:, None]
    return np.stack([np.bincount(label, points[:, k], minlength=n) for k in range(3)], 1) / count


def shade(points, tris, colour):
    """Face colours: the object's colour lit from a fixed direction."""
    a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
    n = np.cross(b - a, c - a)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    light = np.array([0.4, -0.5, 0.77])
    k = 0.35 + 0.65 * np.abs(n @ (light / np.linalg.norm(light)))
    rgb = np.array(matplotlib.colors.to_rgb(colour))
    return np.clip(k[:, None] * rgb[None, :], 0, 1)


def animation(run, series, out, max_faces, fps):
    names = object_names(series[0][1])
    first = {}
    for name in names:  # which mesh to draw, and its decimation
        lab = name + "_dense" if name + "_dense" in series[0][1] else name + "_coarse"
        m = read_mesh(series[0][1][lab])
        tris = surface_triangles(m)
        first[name] = (lab,) + cluster(m.points, tris, max_faces) + (len(tris),)
    # Fixed axes: the bounding box of every drawn frame.
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    frames = []
    for t, files in series:
        meshes = {name: read_mesh(files[first[name][0]]) for name in names}
        spheres = [read_mesh(f) for lab, f in files.items() if "_contact_spheres" in lab]
        for m in meshes.values():
            lo, hi = np.minimum(lo, m.points.min(0)), np.maximum(hi, m.points.max(0))
        frames.append((t, meshes, spheres))
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2 * 1.05
    fig = plt.figure(figsize=(8, 6), dpi=80)
    ax = fig.add_subplot(projection="3d")
    ax.computed_zorder = False  # the contact spheres are drawn over the meshes: always seen
    writer = PillowWriter(fps=fps)
    with writer.saving(fig, out, dpi=80):
        for t, meshes, spheres in frames:
            ax.cla()
            for k, name in enumerate(names):
                lab, label, tris, total = first[name]
                p = cluster_points(meshes[name].points, label, tris)
                poly = Poly3DCollection(p[tris], facecolors=shade(p, tris, COLOURS[k % 5]),
                                        edgecolors="none")
                ax.add_collection3d(poly)
            n_col = n_unt = 0
            for s in spheres:
                if len(s.points) == 0:
                    continue
                flag = np.ravel(s.point_data["colliding_leaf"]) > 0.5
                r = np.ravel(s.point_data["radius"])
                n_col += int(flag.sum())
                n_unt += int((~flag).sum())
                size = (r / half * 110) ** 2  # marker area ~ radius in axes units
                for sel, colour in ((~flag, "0.45"), (flag, "red")):
                    if sel.any():
                        ax.scatter(*s.points[sel].T, s=size[sel], c=colour, alpha=0.3,
                                   depthshade=False, linewidths=0)
            for i, set_lim in enumerate((ax.set_xlim, ax.set_ylim, ax.set_zlim)):
                set_lim(centre[i] - half, centre[i] + half)
            ax.set_box_aspect((1, 1, 1), zoom=1.5)
            ax.set_axis_off()
            ax.set_title(f"t = {t:.3f} s   contact spheres: {n_col} colliding, "
                         f"{n_unt} untested", fontsize=9)
            writer.grab_frame()
    plt.close(fig)
    drawn = ", ".join(f"{n}: {len(first[n][2])} of {first[n][3]} faces" for n in names)
    return f"{len(frames)} frames ({drawn})"


def frames_plot(cols, out):
    t = cols["time"]
    extra = sorted(k for k in cols if "deadline" in k or k in ("late", "missed"))
    rows = 3 if not extra else 4
    fig, axes = plt.subplots(rows, 2, figsize=(11, 3 * rows), sharex=True)
    axes = axes.ravel()
    axes[0].plot(t, cols["energy"], lw=1)
    axes[0].set_ylabel("energy (J)")
    axes[0].set_title("total energy of the deformable objects")
    axes[1].plot(t, cols["contact_force"], lw=1, color="C3")
    axes[1].set_ylabel("contact force (N)")
    axes[1].set_title("|contact force| on the first object of each pair")
    stages = ["fem", "links", "sphere_update", "collision", "response"]
    axes[2].stackplot(t, *[1e3 * cols[s] for s in stages], labels=stages)
    axes[2].set_ylabel("ms per frame")
    axes[2].set_title("wall-clock time per stage (this machine, this load)")
    axes[2].legend(fontsize=7, loc="upper left")
    axes[3].plot(t, 1e3 * cols["wall"], lw=1, color="k")
    axes[3].set_ylabel("ms per frame")
    axes[3].set_title("wall-clock time per frame")
    axes[4].step(t, cols["interrupted"], where="mid", lw=1, color="C0")
    axes[4].set_ylabel("interrupted queries per frame", color="C0")
    twin = axes[4].twinx()  # own scale: contact pairs outnumber interruptions
    twin.step(t, cols["active_pairs"], where="mid", lw=0.8, color="C1")
    twin.set_ylabel("sphere pairs in contact", color="C1")
    axes[4].set_title(f"interrupted queries ({int(cols['interrupted'].sum())} in the run)")
    # A query that reports no pair has completed every level (frames.csv
    # holds INT_MAX there): left blank rather than drawn at 2e9.
    level = np.where(cols["completed_level"] < 1e6, cols["completed_level"], np.nan)
    axes[5].step(t, level, where="mid", lw=1, color="C2")
    axes[5].set_ylabel("level")
    axes[5].set_title("level every reported pair reached (blank: none reported)")
    for k, name in enumerate(extra[:2]):
        axes[6 + k].step(t, cols[name], where="mid", lw=1)
        axes[6 + k].set_title(name)
    for ax in axes[2 * (rows - 1):]:
        ax.set_xlabel("simulated time (s)")
    for ax in axes[len(extra) + 6:] if extra else []:
        ax.set_visible(False)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)


def tree_levels(run, out):
    vtu = os.path.join(run, "vtu")
    trees = sorted(f for f in os.listdir(vtu) if f.endswith("_tree.vtu"))
    if not trees:
        fail(f"{vtu}: no <object>_tree.vtu")
    data = []
    for f in trees:
        m = read_mesh(os.path.join(vtu, f))
        data.append((f[: -len("_tree.vtu")], m.points, np.ravel(m.point_data["radius"]),
                     np.ravel(m.point_data["level"]).astype(int)))
    levels = max(int(lv.max()) for _, _, _, lv in data) + 1
    fig, axes = plt.subplots(len(data), levels, figsize=(2.4 * levels, 2.6 * len(data)),
                             squeeze=False)
    for row, (name, c, r, lv) in enumerate(data):
        ext = c.max(0) - c.min(0)
        ax_i = np.argsort(ext)[::-1][:2]  # the two widest axes
        lo = (c - r[:, None]).min(0)[ax_i]
        hi = (c + r[:, None]).max(0)[ax_i]
        for level in range(levels):
            ax = axes[row, level]
            sel = lv == level
            patches = [Circle((x, y), rr) for (x, y), rr in zip(c[sel][:, ax_i], r[sel])]
            ax.add_collection(PatchCollection(patches, facecolor=COLOURS[row % 5], alpha=0.25,
                                              edgecolor="k", linewidth=0.3))
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(f"{name} level {level}: {int(sel.sum())}", fontsize=8)
    fig.suptitle("sphere trees by level (projected on each object's two widest axes)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run")
    ap.add_argument("--out", help="folder of the pictures (default: RUN_DIR)")
    ap.add_argument("--max-faces", type=int, default=4000,
                    help="faces per object in the animation (vertex-clustering decimation)")
    ap.add_argument("--fps", type=float, default=6)
    a = ap.parse_args()
    out = a.out or a.run
    os.makedirs(out, exist_ok=True)
    cols = read_frames(a.run)
    frames_plot(cols, os.path.join(out, "frames.png"))
    series = read_series(a.run)
    if not series:
        fail(f"{a.run}/vtu/run.pvd: no time steps")
    tree_levels(a.run, os.path.join(out, "tree_levels.png"))
    what = animation(a.run, series, os.path.join(out, "run.gif"), a.max_faces, a.fps)
    size = os.path.getsize(os.path.join(out, "run.gif"))
    print(f"plot_run.py: {out}/run.gif ({what}, {size / 1e6:.1f} MB), frames.png, "
          f"tree_levels.png")


if __name__ == "__main__":
    main()
