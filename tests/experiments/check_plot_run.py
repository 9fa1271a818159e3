#!/usr/bin/python3
"""Draws the pictures of a run folder with scripts/plot_run.py and checks
them: run.gif has one frame per time step of vtu/run.pvd and is under 5 MB,
frames.png and tree_levels.png open as images; a folder without frames.csv is
refused with a message naming the file and exit status 1.

usage: check_plot_run.py PLOT_RUN RUN_DIR SCRATCH_DIR
"""
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

from PIL import Image

plot_run, run, scratch = sys.argv[1:4]
failures = []
shutil.rmtree(scratch, ignore_errors=True)
subprocess.run(["/usr/bin/python3", plot_run, run, "--out", scratch], check=True,
               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
steps = {d.get("timestep") for d in ET.parse(os.path.join(run, "vtu", "run.pvd")).getroot().iter("DataSet")}
gif = Image.open(os.path.join(scratch, "run.gif"))
if gif.n_frames != len(steps):
    failures.append(f"run.gif has {gif.n_frames} frames, run.pvd {len(steps)} steps")
if os.path.getsize(os.path.join(scratch, "run.gif")) > 5e6:
    failures.append("run.gif is over 5 MB")
for name in ("frames.png", "tree_levels.png"):
    w, h = Image.open(os.path.join(scratch, name)).size
    if w < 200 or h < 200:
        failures.append(f"{name} is {w}x{h}")
empty = os.path.join(scratch, "empty")
os.makedirs(empty)
r = subprocess.run(["/usr/bin/python3", plot_run, empty], capture_output=True, text=True)
if r.returncode != 1 or "frames.csv" not in r.stderr:
    failures.append(f"an empty folder gave exit {r.returncode}, stderr {r.stderr!r}")
for f in failures:
    print("FAIL:", f)
print(f"checked run.gif ({len(steps)} frames), frames.png, tree_levels.png")
sys.exit(1 if failures else 0)
