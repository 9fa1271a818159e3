#!/usr/bin/env python3
"""Writes experiments/sweeps/contact_speed.json: two balls (radius 0.1 m) and
bunny-dragon (0.3 m) thrown at each other at relative speeds 0.1-100 m/s,
with lateral offsets where their paths cross and where they miss. Every case
runs icd-run with the exact triangle reference on (frames.csv column
exact_contacts: the ground truth of whether the surfaces met).

usage: make_sweep.py [OUT.json]   (default: experiments/sweeps/contact_speed.json)
"""
import json
import math
import sys
from pathlib import Path

SPEEDS = [0.1, 1, 10, 50, 100]  # relative speed, m/s (each object moves at half)
# scene, half distance between the centres (m), closing gap (m), offsets (m):
# (lateral offset of the right object, label)
SCENES = [
    ("two_spheres.json", 0.13, 0.06,
     [(0.0, "head-on"), (0.15, "glancing (paths overlap 5 cm)"), (0.3, "miss (10 cm clear)")]),
    ("bunny_dragon.json", 0.17, 0.10,
     [(0.0, "head-on"), (0.1, "offset 0.1 m"), (0.45, "miss (0.45 m offset)")]),
]


def main():
    root = Path(__file__).resolve().parents[3]
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else root / "experiments/sweeps/contact_speed.json"
    cases = []
    for scene, half, gap, offsets in SCENES:
        for v in SPEEDS:
            # frames: the gap closes, then the objects have time to cross
            # (or be stopped): 0.5 m of relative travel at most, >= 12 frames
            frames = max(12, math.ceil(60 * (gap + min(0.5, 3 * v / 60 + 0.05)) / v) + 4)
            frames = min(frames, 120)
            if v < 1 and scene == "bunny_dragon.json":
                frames = 160  # the offset pair may need up to 0.2 m to meet
            for dy, label in offsets:
                cases.append({
                    "@scene": "{source_dir}/experiments/scenes/" + scene,
                    "_scene": scene.split(".")[0],
                    "_speed": v,
                    "_offset": dy,
                    "_case": label,
                    "frames": frames,
                    "objects.0.velocity": json.dumps([v / 2, 0, 0]),
                    "objects.1.velocity": json.dumps([-v / 2, 0, 0]),
                    "objects.1.position": json.dumps([half, dy, 0]),
                    # no Rayleigh mass damping: the objects keep their speed,
                    # so the paths are straight lines (with the scenes' 0.5 / s
                    # the bunny and dragon at 0.1 m/s stop 0.2 m later)
                    "objects.0.material.rayleigh": "[0, 0]",
                    "objects.1.material.rayleigh": "[0, 0]",
                })
                if scene == "two_spheres.json":  # StVK inverts at >= 10 m/s: the
                    # inversion-safe model, as the Tunnelling tests
                    for k in (0, 1):
                        cases[-1][f"objects.{k}.material.model"] = "stable_neo_hookean"
    sweep = {
        "name": "contact_speed",
        "title": "No contact missed, none invented: relative speeds 0.1-100 m/s, crossing and missing paths",
        "comment": "Written by experiments/studies/contact/make_sweep.py; summarised by summarise.py there. "
                   "exact_contacts (intersecting dense triangle pairs, exact predicates) is the ground truth.",
        "program": "icd-run",
        "args": ["--out", "{out}", "--quiet", "--set", "output.exact_reference=true",
                 "--set", "output.vtu_every=0"],
        "setup": [["icd-run", "{source_dir}/experiments/scenes/bunny_dragon.json", "--frames", "1",
                   "--out", "{out}", "--quiet", "--set", "output.vtu_every=0"]],
        "cases": cases,
        "collect": {"csv": "frames.csv", "rows": "all",
                    "columns": ["frame", "cycles", "subdivided", "collision_list", "pair_list",
                                "active_pairs", "max_penetration", "deep_pairs", "depth_ratio",
                                "exact_contacts"]},
        "limits": {"wall_seconds": 1800, "memory_mb": 4096},
    }
    out.write_text(json.dumps(sweep, indent=2) + "\n")
    print(f"{out}: {len(cases)} cases")


if __name__ == "__main__":
    main()
