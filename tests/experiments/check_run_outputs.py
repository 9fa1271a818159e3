#!/usr/bin/python3
"""Runs a short scene with icd-run and reads EVERY output file back with
meshio (an independent reader) and Python's XML parser (run.pvd, which meshio
cannot open). Fails when the output folder is empty, a file does not read, a
file is missing from or extra to run.pvd, an array is missing or has the wrong
shape, or the arrays disagree with each other and with frames.csv.

usage: check_run_outputs.py ICD_RUN SCENE OUT_DIR [FRAMES]
"""
import csv
import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
    return cond


def main():
    icd_run, scene, out = sys.argv[1], sys.argv[2], sys.argv[3]
    frames = int(sys.argv[4]) if len(sys.argv) > 4 else 21
    shutil.rmtree(out, ignore_errors=True)
    subprocess.run([icd_run, scene, "--out", out, "--frames", str(frames), "--quiet"],
                   check=True, stdout=subprocess.DEVNULL)
    vtu = os.path.join(out, "vtu")
    files = sorted(os.listdir(vtu)) if os.path.isdir(vtu) else []
    if not check(files, f"{vtu}: no output files"):
        return

    # frames.csv, scene copy and version.
    with open(os.path.join(out, "frames.csv")) as f:
        rows = list(csv.DictReader(f))
    check(len(rows) == frames, f"frames.csv has {len(rows)} rows, expected {frames}")
    with open(os.path.join(out, "scene.json"), "rb") as a, open(scene, "rb") as b:
        check(a.read() == b.read(), "scene.json is not a copy of the scene run")
    with open(os.path.join(out, "version.txt")) as f:
        check(f.read().startswith("icd "), "version.txt does not start with 'icd '")

    # The one collection: every file exists, every step holds the same parts.
    root = ET.parse(os.path.join(vtu, "run.pvd")).getroot()
    entries = [(float(d.get("timestep")), int(d.get("part")), d.get("file"))
               for d in root.iter("DataSet")]
    steps = sorted({t for t, _, _ in entries})
    parts = sorted({p for _, p, _ in entries})
    check(len(entries) == len(steps) * len(parts), "a time step lacks a part in run.pvd")
    with open(scene) as f:
        every = json.load(f)["output"]["vtu_every"]
    written = [f for f in range(frames) if f % every == 0 or f == frames - 1]
    expected_times = [float(rows[f]["time"]) for f in written]
    check(np.allclose(steps, expected_times, rtol=0, atol=1e-8),  # csv: 9 digits
          f"run.pvd times {steps} are not frames.csv's times of the written frames {expected_times}")
    listed = {file for _, _, file in entries}
    for name in files:
        if name == "run.pvd":
            continue
        check(name in listed or name.endswith("_tree.vtu"), f"{name} is not listed in run.pvd")
    for file in listed:
        check(os.path.isfile(os.path.join(vtu, file)), f"run.pvd lists {file}, which is missing")

    # Every VTU reads; its arrays are there with the right shapes.
    rest = {}
    read = 0
    for name in files:
        if not name.endswith(".vtu"):
            continue
        path = os.path.join(vtu, name)
        try:
            m = meshio.read(path)
        except Exception as e:  # noqa: BLE001 - any failure to read is the finding
            check(False, f"meshio cannot read {name}: {e!r}")
            continue
        read += 1
        n = len(m.points)
        pd = m.point_data
        time = [t for t, _, f in entries if f == name]
        if time:
            check(np.isclose(float(np.ravel(m.field_data["TimeValue"])[0]), time[0], rtol=0,
                             atol=1e-12), f"{name}: TimeValue differs from run.pvd's time")
        stem = name.rsplit("_", 1)[0]
        if "_coarse" in name:
            for a in ("displacement", "velocity", "contact_force", "external_force"):
                if check(a in pd, f"{name}: no point array {a}"):
                    check(pd[a].shape == (n, 3), f"{name}: {a} is {pd[a].shape}, not ({n}, 3)")
            vr = m.cell_data.get("volume_ratio")
            if check(vr is not None, f"{name}: no cell array volume_ratio"):
                check(np.all(np.ravel(vr[0]) > 0), f"{name}: an inverted or flat tet")
        elif "_dense" in name:
            if check("displacement" in pd, f"{name}: no point array displacement"):
                check(pd["displacement"].shape == (n, 3), f"{name}: displacement shape")
        else:
            for a in ("radius", "level") + (("leaf",) if name.endswith("_tree.vtu")
                                              else ("colliding_leaf",)):
                check(a in pd, f"{name}: no point array {a}")
            if "radius" in pd:
                check(np.all(pd["radius"] >= 0), f"{name}: a negative radius")
        if "displacement" in pd:
            # points - displacement is the rest shape: the same in every frame.
            r = m.points - pd["displacement"]
            if stem in rest:
                check(np.allclose(r, rest[stem], rtol=0, atol=1e-9),
                      f"{name}: points - displacement differs from the first frame's")
            else:
                rest[stem] = r
    check(read == sum(1 for f in files if f.endswith(".vtu")), "not every VTU was read")
    check(any(f.endswith("_tree.vtu") for f in files), "no sphere tree file")
    moved = False
    for name in files:  # the objects approach each other: displacements grow from zero
        if "_coarse" in name and not name.endswith("_000000.vtu"):
            moved |= np.abs(meshio.read(os.path.join(vtu, name)).point_data["displacement"]).max() > 0
    check(moved, "no coarse node moved")
    print(f"{read} VTU files and run.pvd ({len(steps)} steps x {len(parts)} parts) read back")


if __name__ == "__main__":
    main()
    for f in failures:
        print("FAIL:", f)
    sys.exit(1 if failures else 0)
