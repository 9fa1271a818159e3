#!/usr/bin/env python3
"""The installed programs work from the install prefix alone.

usage: run_installed.py PREFIX VERSION

Copies PREFIX to a fresh temporary folder (so nothing can come from the
build or source tree by an embedded path of the prefix) and, with the
working folder elsewhere and a private HOME / XDG_CACHE_HOME, checks that:
  - icd-run --help and --version answer (exit 0);
  - icd-main --help names the installed default scene
    (share/icd/scenes/bunny_dragon.json of the copy), which exists;
  - icd-run runs a tiny scene (a mesh named relative to the scene file, so it
    is preprocessed by the installed icd-preprocess, and a primitive) for 3
    frames: exit 0, frames.csv with 3 frames, and the preprocessed bundle in
    $XDG_CACHE_HOME/icd (the default asset cache of an installed program);
  - a second run with --cache-dir DIR puts the bundle in DIR.
"""
import math
import os
import shutil
import subprocess
import sys
import tempfile


def icosahedron_off(path):
    t = (1 + math.sqrt(5)) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    with open(path, "w", encoding="ascii") as out:
        out.write(f"OFF\n{len(v)} {len(f)} 0\n")
        for x in v:
            out.write(" ".join(str(c) for c in x) + "\n")
        for x in f:
            out.write("3 " + " ".join(str(c) for c in x) + "\n")


SCENE = """{
  "name": "installed_tiny",
  "frames": 3,
  "frame_rate": 60,
  "objects": [
    {"name": "mesh", "mesh": "ico.off", "size": 0.2,
     "preprocess": {"coarse_tets": 50, "tree_depth": 2, "tree_builder": "octree"},
     "position": [-0.12, 0, 0], "velocity": [0.5, 0, 0],
     "material": {"model": "stvk", "young": 5e5, "poisson": 0.3, "density": 1000}},
    {"name": "ball", "primitive": {"type": "sphere", "radius": 0.1, "subdivisions": 2, "cells": 3},
     "position": [0.12, 0, 0], "velocity": [-0.5, 0, 0],
     "material": {"model": "stvk", "young": 5e5, "poisson": 0.3, "density": 1000},
     "preprocess": {"tree_depth": 2}}
  ],
  "collision": {"budget_tests": 10000, "mode": "fifo", "stiffness": 2000},
  "output": {"vtu_every": 0}
}
"""


def main():
    prefix, version = sys.argv[1], sys.argv[2]
    failures = []

    def check(ok, what):
        if not ok:
            failures.append(what)
            print("FAIL", what)

    with tempfile.TemporaryDirectory(prefix="icd_installed_") as tmp:
        moved = os.path.join(tmp, "prefix")
        shutil.copytree(prefix, moved, symlinks=True)
        work = os.path.join(tmp, "work")
        scenes = os.path.join(tmp, "scenes")
        for d in (work, scenes, os.path.join(tmp, "home"), os.path.join(tmp, "xdg")):
            os.makedirs(d)
        env = {k: v for k, v in os.environ.items()
               if k not in ("ICD_CACHE_DIR", "ICD_DATA_DIR", "XDG_CACHE_HOME", "HOME")}
        env["HOME"] = os.path.join(tmp, "home")
        env["XDG_CACHE_HOME"] = os.path.join(tmp, "xdg")
        run_exe = os.path.join(moved, "bin", "icd-run")

        def run(args):
            p = subprocess.run(args, cwd=work, env=env, capture_output=True, text=True,
                               stdin=subprocess.DEVNULL, timeout=300)
            return p.returncode, p.stdout, p.stderr

        status, out, err = run([run_exe, "--help"])
        check(status == 0 and "Usage: icd-run" in out, f"icd-run --help: {status} {out!r} {err!r}")
        status, out, _ = run([run_exe, "--version"])
        check(status == 0 and out == f"icd {version}\n", f"icd-run --version: {status} {out!r}")
        status, out, err = run([os.path.join(moved, "bin", "icd-main"), "--help"])
        default_scene = os.path.join(moved, "share", "icd", "scenes", "bunny_dragon.json")
        check(status == 0 and default_scene in out and os.path.isfile(default_scene),
              f"icd-main --help does not name {default_scene}: {out!r}")

        icosahedron_off(os.path.join(scenes, "ico.off"))
        scene = os.path.join(scenes, "tiny.json")
        with open(scene, "w", encoding="ascii") as f:
            f.write(SCENE)
        status, out, err = run([run_exe, scene, "--out", "out", "--quiet"])
        check(status == 0, f"icd-run tiny scene: exit {status}\n{out}\n{err}")
        frames = os.path.join(work, "out", "frames.csv")
        if os.path.isfile(frames):
            with open(frames, encoding="utf-8") as f:
                rows = [line for line in f if line.strip()]
            check(len(rows) == 4, f"frames.csv has {len(rows)} lines, expected a header and 3")
        else:
            check(False, "no out/frames.csv")
        cache = os.path.join(tmp, "xdg", "icd")
        bundles = [d for d in os.listdir(cache)] if os.path.isdir(cache) else []
        check(any(d.startswith("ico-") for d in bundles),
              f"no ico-* bundle in $XDG_CACHE_HOME/icd: {bundles}")
        own = os.path.join(tmp, "own_cache")
        status, out, err = run([run_exe, scene, "--out", "out2", "--quiet", "--cache-dir", own])
        check(status == 0 and os.path.isdir(own) and
              any(d.startswith("ico-") for d in os.listdir(own)),
              f"--cache-dir: exit {status}, {err}")
    print(f"installed programs: {len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
