#!/usr/bin/python3
"""Do contacts hold in the main job? Runs scenes (default: the main job
bunny_dragon, bunny_bunny, dragon_dragon) with the response as it was
("before": collision.node_rate_cap false, collision.deep_step_ratio 0) and
as configured by default ("after"), and prints per run the depth ratio of
the deepest colliding leaf pair (penetration / smaller leaf radius) over the
frames with a contact (max, p99), frames with a pair deeper than its leaf
radius, frames softened, pairs weighted by the node rate cap, velocity
steps, sub-steps and cycles per frame, and the wall time per frame (median).

usage: holding.py --run ICD-RUN --work DIR [--frames N] [SCENE.json ...]
The scenes' outputs are turned off except frames.csv; mesh paths are made
absolute. No shell: every command is an argument list.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "..", "scenes")
CONFIGS = {"before": {"node_rate_cap": False, "deep_step_ratio": 0},
           "after": {}}


def quantile(v, q):
    if not v:
        return 0.0
    v = sorted(v)
    return v[min(len(v) - 1, int(q * (len(v) - 1) + 0.5))]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--run", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--frames", type=int, default=0)
    p.add_argument("--configs", default="before,after")
    p.add_argument("scenes", nargs="*")
    a = p.parse_args()
    scenes = a.scenes or [os.path.join(SCENES, f"{s}.json")
                          for s in ("bunny_dragon", "bunny_bunny", "dragon_dragon")]
    os.makedirs(a.work, exist_ok=True)
    with open("/proc/loadavg") as f:
        print("load average at start:", " ".join(f.read().split()[:3]))
    print("| scene | response | frames | contact frames | depth ratio max | p99 | deep frames "
          "| softened cycles | capped pairs | velocity steps | sub-steps/frame (median) "
          "| cycles/frame (median) | wall ms/frame (median) | energy start -> end (J) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for scene_path in scenes:
        scene = json.load(open(scene_path))
        base = os.path.dirname(os.path.abspath(scene_path))
        for o in scene["objects"]:
            if "mesh" in o and not os.path.isabs(o["mesh"]):
                cand = os.path.join(base, o["mesh"])
                o["mesh"] = cand if os.path.exists(cand) else os.path.abspath(o["mesh"])
        scene["output"] = {"csv": True, "vtu_every": 0}
        for name in a.configs.split(","):
            s = json.loads(json.dumps(scene))
            s.setdefault("collision", {}).update(CONFIGS[name])
            tag = f"{scene['name']}_{name}"
            path = os.path.join(a.work, tag + ".json")
            with open(path, "w") as f:
                json.dump(s, f, indent=1)
            out = os.path.join(a.work, tag)
            cmd = [a.run, path, "--out", out, "--quiet"]
            if a.frames:
                cmd += ["--frames", str(a.frames)]
            r = subprocess.run(cmd, capture_output=True, text=True)
            if r.returncode != 0:
                print(f"| {scene['name']} | {name} | failed: {r.stderr.strip()[-300:]} |")
                continue
            rows = list(csv.DictReader(open(os.path.join(out, "frames.csv"))))
            contact = [r for r in rows if int(r["active_pairs"]) > 0]
            ratios = [float(r["depth_ratio"]) for r in contact]
            col = lambda k: [float(r.get(k) or 0) for r in rows]
            print(f"| {scene['name']} | {name} | {len(rows)} | {len(contact)} "
                  f"| {max(ratios, default=0):.2f} | {quantile(ratios, 0.99):.2f} "
                  f"| {sum(1 for r in rows if int(r['deep_pairs']) > 0)} "
                  f"| {int(sum(col('softened')))} | {int(sum(col('capped_pairs')))} "
                  f"| {int(sum(col('deep_steps')))} | {statistics.median(col('substeps')):.0f} "
                  f"| {statistics.median(col('cycles')):.0f} "
                  f"| {1e3 * statistics.median(col('wall')):.1f} "
                  f"| {float(rows[0]['energy']):.3f} -> {float(rows[-1]['energy']):.3f} |")
            sys.stdout.flush()
    with open("/proc/loadavg") as f:
        print("load average at end:", " ".join(f.read().split()[:3]))


if __name__ == "__main__":
    main()
