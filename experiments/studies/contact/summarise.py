#!/usr/bin/env python3
"""Summarises the contact_speed sweep (experiments/sweeps/contact_speed.json):
one row per case from its results.csv (every frame collected).

usage: summarise.py RESULTS.csv
Columns: paths cross (by the geometry: offset under the objects' extent),
frames whose end state has intersecting dense triangles (exact reference),
frames with reported sphere pairs (colliding leaves or untested pairs),
frames with exact contacts but no reported pair (missed), the largest sphere
penetration (mm) and depth ratio (penetration / smaller leaf radius), frames
with a penetration deeper than a leaf radius (deep_pairs > 0), most cycles
and subdivided cycles in a frame.
"""
import csv
import sys
from collections import OrderedDict

CROSS = {"two_spheres": 0.2, "bunny_dragon": 0.3}  # offsets below this: the paths cross


def main():
    rows = list(csv.DictReader(open(sys.argv[1])))
    cases = OrderedDict()
    for r in rows:
        key = (r["_scene"], float(r["_speed"]), float(r["_offset"]))
        cases.setdefault(key, []).append(r)
    print("| scene | speed (m/s) | offset (m) | paths cross | status | frames | exact-contact frames "
          "| reported frames | missed frames | found | max penetration (mm) | max depth ratio "
          "| deep frames | max cycles |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    bad = 0
    for key in sorted(cases, key=lambda k: (k[0] != "two_spheres", k[0], k[2], k[1])):
        fr = cases[key]
        scene, v, dy = key
        status = fr[0]["status"]
        cross = dy < CROSS[scene]
        if status != "ok" or not fr[0]["frame"]:
            print(f"| {scene} | {v:g} | {dy:g} | {'yes' if cross else 'no'} | {status} "
                  f"({fr[0]['message']}) | | | | | | | | | |")
            bad += 1
            continue
        num = lambda r, c: float(r[c]) if r[c] not in ("", "nan") else 0.0
        exact = sum(1 for r in fr if num(r, "exact_contacts") > 0)
        reported = sum(1 for r in fr if num(r, "collision_list") + num(r, "pair_list") > 0 or
                       num(r, "max_penetration") > 0)
        missed = sum(1 for r in fr if num(r, "exact_contacts") > 0 and
                     num(r, "collision_list") + num(r, "pair_list") == 0)
        found = any(num(r, "max_penetration") > 0 for r in fr)
        pen = max(num(r, "max_penetration") for r in fr)
        ratio = max(num(r, "depth_ratio") for r in fr)
        deep = sum(1 for r in fr if num(r, "deep_pairs") > 0)
        cyc = max(int(num(r, "cycles")) for r in fr)
        ok = (found == cross) and missed == 0
        bad += not ok
        print(f"| {scene} | {v:g} | {dy:g} | {'yes' if cross else 'no'} | {status} | {len(fr)} | "
              f"{exact} | {reported} | {missed} | {'yes' if found else 'no'}{'' if ok else ' **(wrong)**'} | "
              f"{1e3 * pen:.1f} | {ratio:.2f} | {deep} | {cyc} |")
    print(f"\n{len(cases)} cases, {bad} wrong (contact found where paths miss, none where they cross, "
          "or a frame with exact contacts and no reported pair)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
