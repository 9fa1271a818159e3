#!/usr/bin/python3
"""Writes RESULTS_DIR/index.md for scripts/run_experiments.sh: every table
and plot of issue 8, the definitions of the metrics, and where and why our
numbers differ from the paper's.

The parameter studies are read from the sweeps' gathered CSVs,
RESULTS_DIR/<step>/results.csv (icd-sweep: case_id, the parameters, status,
exit_status, message, then the program's columns), never from the programs'
own output folders; a case not ok is listed under its table with its message.
Fig. 9 (one run, pictures) and the main run are read from their folders.

usage: /usr/bin/python3 scripts/plot_index.py [--readme README.md] RESULTS_DIR SECONDS QUICK [STATUS_ROW...]

Sentences that state a finding (the moment of Fig. 9, identical panels,
saturated recall, a large force error) are generated from the CSVs they
describe. With --readme, the block between "<!-- results:begin -->" and
"<!-- results:end -->" in that file is replaced by the bunny-dragon rows of
Table 1 (wall clock), its scaled rows and its deterministic test-budget twin.
"""
import csv
import datetime
import os
import platform
import sys


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def read_if(d, rel):
    p = os.path.join(d, rel)
    return read(p) if os.path.exists(p) else []


def gathered_all(d, step):
    """Every row of a sweep step's gathered results.csv (ok or not)."""
    return read_if(d, f"{step}/results.csv")


def gathered(d, step):
    """The rows of the ok cases of a sweep step's gathered results.csv."""
    return [r for r in gathered_all(d, step) if r["status"] == "ok"]


def sweep_problems(d, step):
    """Generated: the cases of a sweep that are not ok, with their messages."""
    bad = {}
    for r in gathered_all(d, step):
        if r["status"] != "ok":
            bad.setdefault(r["case_id"], r)
    if not bad:
        return ""
    lines = [f"**{len(bad)} case(s) of the `{step}` sweep not ok** (their rows are missing above; "
             f"[{step}/results.csv]({step}/results.csv), case folders in `{step}/cases/`):\n"]
    for cid, r in bad.items():
        lines.append(f"- `{cid}`: {r['status']}: {r['message'].replace('|', '/')}")
    return "\n".join(lines) + "\n"


def num(v):
    try:
        return float(v)
    except ValueError:
        return float("nan")


def table1_md(rows):
    """Table 1 as the table1 program writes it (table1.md), from gathered rows."""
    rows = sorted(rows, key=lambda r: (r["scene"], r["budget_kind"], num(r["critical_time"])))
    if not rows:
        return ""
    out = ["| interaction | critical time (s) or test budget | PAIRLIST ours | paper | COLLISIONLIST ours | "
           "paper | FPS ours | paper | completed level |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        b = f"{num(r['critical_time']):g}" + (" tests" if r["budget_kind"] == "tests" else "")
        if r.get("failure"):
            out.append(f"| {r['scene']} | {b} | FAILED (first contact {r['contact_frame']}): "
                       f"{r['failure'].replace('|', '/')} | | | | | | |")
            continue
        out.append(f"| {r['scene']} | {b} | {r['pair_list']} | {r['paper_pair_list'] or '-'} | "
                   f"{r['collision_list']} | {r['paper_collision_list'] or '-'} | {num(r['fps']):.1f} | "
                   f"{r['paper_fps'] or '-'} | {r['completed_level']} |")
    return "\n".join(out) + "\n"


def table1_section(d, step, what):
    rows = gathered(d, step)
    text = table1_md(rows) if rows else f"*{what} missing ({step}/results.csv has no ok case; see run.log).*\n"
    return text + sweep_problems(d, step)


STABILITY_GROUPS = ["young", "poisson", "penalty", "velocity", "compression", "implicit"]


def stability_md(d):
    """The stability table from the icd-run sweep's gathered frames.csv rows."""
    rows = gathered_all(d, "stability")
    if not rows:
        return "*Stability table missing (stability/results.csv not produced; see run.log).*\n"
    cases = {}
    for r in rows:
        cases.setdefault(r["case_id"], []).append(r)

    def order(item):
        r = item[1][0]
        g = STABILITY_GROUPS.index(r["_group"]) if r["_group"] in STABILITY_GROUPS else len(STABILITY_GROUPS)
        first = [w for w in r["_case"].replace("=", " ").split() if w[:1].isdigit()]
        return (g, num(first[0]) if first else 0.0, r["_case"])
    out = ["| group | case | status | frames | min step (s) | energy drift | max energy gain | "
           "max penetration (m) | frames/s | message |", "|---|---|---|---|---|---|---|---|---|---|"]
    for cid, rs in sorted(cases.items(), key=order):
        r0 = rs[0]
        if r0["status"] != "ok":
            out.append(f"| {r0['_group']} | {r0['_case']} | {r0['status']} | | | | | | | "
                       f"{r0['message'].replace('|', '/')} |")
            continue
        e = [num(r["energy"]) for r in rs]
        steps = [num(r["min_step"]) for r in rs if num(r["min_step"]) > 0]
        wall = sum(num(r["wall"]) for r in rs)
        drift = (e[-1] - e[0]) / abs(e[0]) if e[0] else float("nan")
        gain = max(e) / e[0] - 1 if e[0] > 0 else float("nan")
        finite = all(x == x and abs(x) != float("inf") for x in e)
        status, msg = "stable", ""
        if not finite:
            status, msg = "unstable", "non-finite energy"
        elif gain > 1:
            status, msg = "unstable", f"energy grew to {1 + gain:.3g} x its first-frame value"
        out.append(f"| {r0['_group']} | {r0['_case']} | {status} | {len(rs)} | "
                   f"{min(steps) if steps else 0:.3g} | {drift:+.3g} | {gain:.3g} | "
                   f"{max(num(r['max_penetration']) for r in rs):.3g} | {len(rs) / max(wall, 1e-12):.1f} | {msg} |")
    return "\n".join(out) + "\n"


MODE_ORDER = ["fifo", "fifo_paper_literal", "priority", "priority_cap256", "depth_first"]


def contact_rows(d, sub):
    """The contact_error rows of a sweep, in the program's order (mode, kind, budget)."""
    rows = gathered(d, sub)
    return sorted(rows, key=lambda r: (MODE_ORDER.index(r["mode"]) if r["mode"] in MODE_ORDER else 99, r["mode"],
                                       r["budget_kind"] != "seconds", num(r["budget"])))


def fig9_moment(d, sub):
    """Generated: at which frame Fig. 9 is drawn, against Table 1's frames,
    and whether its panels differ."""
    man = read_if(d, f"{sub}/manifest.csv")
    if not man:
        return ""
    frame = man[0]["frame"]
    ref = max(man, key=lambda r: float(r["budget"]))  # fig9 takes the moment from this run
    out = [f"Drawn at frame {frame} (first contact at frame {ref['contact_frame']} in the run with the "
           f"largest budget, {float(ref['budget']):g} s)"]
    t1 = [r for r in gathered(d, "table1") if r["scene"] == man[0]["scene"]]
    frames = sorted({r["measure_frame"] for r in t1})
    if frames:
        same = frames == [frame]
        out.append(f"; Table 1's {man[0]['scene']} rows are measured at frame"
                   f"{'s' if len(frames) > 1 else ''} {', '.join(frames)}"
                   f"{': the same moment' if same else ': NOT the same moment'}")
    lists = {(r["pair_list"], r["collision_list"]) for r in man}
    if len(man) > 1 and len(lists) == 1:
        pl, cl = lists.pop()
        out.append(f". All {len(man)} panels are identical (PAIRLIST {pl}, COLLISIONLIST {cl} at every "
                   "critical time): " + ("every budget completes the traversal here, which is why the "
                                         "scaled figure exists" if pl == "0" else
                                         "the budgets give the same lists"))
    else:
        out.append(". Per panel (critical time: PAIRLIST / COLLISIONLIST): " +
                   ", ".join(f"{float(r['budget']):g} s: {r['pair_list']} / {r['collision_list']}"
                             for r in man))
    fails = [r for r in man if r.get("failure")]
    if fails:
        out.append(f". The reference run failed after the drawn frame: {fails[0]['failure']}")
    return "".join(out) + ".\n"


def contact_findings(d, sub):
    """Generated: saturated recall and large force errors, with their cause in numbers."""
    rows = contact_rows(d, sub)
    if not rows:
        return ""
    out = []
    rec = [float(r["recall_exact"]) for r in rows]
    if int(rows[0]["exact_pairs"]) == 0:
        out.append("There are no exact intersecting triangle pairs at this moment, so recall (exact) is "
                   "undefined (drawn as 1) and every reported pair counts as a false positive.")
    elif min(rec) == 1.0:
        out.append(f"Recall (exact) is 1.0 for every mode and budget ({len(rows)} queries): even the "
                   "shortest budget's answer (coarse untested pairs, which enclose their descendants) lies "
                   f"over all {rows[0]['exact_pairs']} exact triangle pairs; the budgets differ in false "
                   "positives and looseness, not in recall.")
    worst = max(rows, key=lambda r: float(r["force_rel_error"]))
    e = float(worst["force_rel_error"])
    if e > 2:
        out.append(f"The largest force error, {e:.1f}x the uninterrupted answer's force, is {worst['mode']} at "
                   f"{float(worst['budget']):g} {'s' if worst['budget_kind'] == 'seconds' else 'tests'}: "
                   f"the query stopped at level {worst['completed_level']} with {worst['reported_pairs']} "
                   f"reported pairs, {worst['colliding_pairs']} of them colliding leaves and the rest untested "
                   "coarse pairs. Eq. 11's penalty grows with the overlap depth of the two spheres, and coarse "
                   "spheres overlap by a large part of their radii where leaves barely touch, so a short "
                   "budget over-estimates the force: the price of treating untested pairs as colliding.")
    return (" ".join(out) + "\n") if out else ""


def sphere_update_findings(d):
    rows = gathered(d, "sphere_update")
    if not rows:
        return ""
    zero = [m for m in dict.fromkeys(r["method"] for r in rows)
            if all(float(r["uncovered_fraction"]) == 0 for r in rows if r["method"] == m)]
    if not zero:
        return ""
    return (f"Uncovered fraction is exactly 0 in every frame for {', '.join(zero)}: every deformed dense "
            "vertex stays inside a leaf sphere (the panels show a flat 0, not a missing curve).\n")


def main_findings(d):
    """Generated: what the main run's frames.csv says (frames run, contact, interruptions)."""
    rows = read_if(d, "main/frames.csv")
    if not rows:
        return ""
    contact = [r for r in rows if float(r["contact_force"]) > 0]
    intr = sum(int(r["interrupted"]) for r in rows)
    deep = [r for r in rows if int(r.get("deep_pairs", 0) or 0) > 0]
    s = f"The run computed all {len(rows)} frames ({float(rows[-1]['time']):.2f} s simulated)"
    if contact:
        s += (f"; contact forces in {len(contact)} frames (first at frame {contact[0]['frame']}, peak "
              f"{max(float(r['contact_force']) for r in rows):.3g} N)")
    s += f"; {intr} interrupted queries"
    if deep:
        s += (f"; in {len(deep)} frames a penetration was deeper than the penetrating leaf sphere's "
              f"radius (up to {max(float(r['depth_ratio']) for r in deep):.3g} radii: the penalty is too "
              "soft for this impact, see `frames.csv` columns `deep_pairs`, `depth_ratio`)")
    return s + ".\n"


def table1_failures(d, sub):
    """Generated: the runs of a Table 1 variant that failed, from its CSV."""
    bad = [r for r in gathered(d, sub) if r.get("failure")]
    if not bad:
        return ""
    kind = lambda r: "tests" if r.get("budget_kind") == "tests" else "s"  # noqa: E731
    return (f"**{len(bad)} run(s) failed** (the simulation stopped, so no lists): " +
            "; ".join(f"{r['scene']} at {float(r['critical_time']):g} {kind(r)}" for r in bad) +
            ". The message is in the table row. Not investigated here; a likely cause: a coarse interrupted answer treats large untested "
            "spheres as colliding, and their penalty forces can exceed what the explicit FEM step "
            "survives.\n")


def failure_banner(status):
    failed = [row.split("|")[1].strip() for row in status if "FAILED" in row]
    if not failed:
        return ""
    return (f"**{len(failed)} step(s) FAILED: {', '.join(failed)}.** Their tables and plots below are "
            "missing or from an earlier run; see [run.log](run.log).\n")


def glance(d):
    """README block: bunny-dragon Table 1 rows, wall clock and test budgets."""
    def rows_of(sub):
        rows = sorted((r for r in gathered(d, sub) if r["scene"] == "bunny_dragon"),
                      key=lambda r: num(r["critical_time"]))
        for r in rows:
            if r.get("failure"):
                r["pair_list"] = r["collision_list"] = r["tests"] = r["completed_level"] = "FAILED"
        return rows
    t1, ts, tt = rows_of("table1"), rows_of("table1_scaled"), rows_of("table1_tests")
    if not (t1 and ts and tt):
        return None
    frames = sorted({r["measure_frame"] for r in t1 + ts + tt if not r.get("failure")})
    lines = [f"<!-- generated by scripts/plot_index.py from results/experiments/ on "
             f"{datetime.datetime.utcnow():%Y-%m-%d} -->",
             f"Bunny-dragon, measured 1 frame after first contact (frame{'s' if len(frames) > 1 else ''} "
             f"{', '.join(frames)}; each run's own first contact), scene "
             "`experiments/studies/paper/scenes/bunny_dragon.json`, by `scripts/run_experiments.sh` "
             "(`table1 --after 1`). "
             "Wall-clock budgets (ours vary with the machine and its load; the paper's beside them):\n",
             "| critical time (s) | PAIRLIST ours | paper | COLLISIONLIST ours | paper |",
             "|---|---|---|---|---|"]
    for r in t1:
        lines.append(f"| {float(r['critical_time']):g} | {r['pair_list']} | {r['paper_pair_list'] or '-'} | "
                     f"{r['collision_list']} | {r['paper_collision_list'] or '-'} |")
    lines += ["", "The critical times divided by 1000 (paper's row at 1000x), still wall clock:\n",
              "| critical time (s) | PAIRLIST ours | paper (x1000) | COLLISIONLIST ours | paper (x1000) |",
              "|---|---|---|---|---|"]
    for r in ts:
        lines.append(f"| {float(r['critical_time']):g} | {r['pair_list']} | {r['paper_pair_list'] or '-'} | "
                     f"{r['collision_list']} | {r['paper_collision_list'] or '-'} |")
    lines += ["", "The deterministic twin: budgets in sphere tests, the same lists on any machine:\n",
              "| test budget per query | PAIRLIST | COLLISIONLIST | sphere tests in the frame (all cycles) "
              "| completed level |",
              "|---|---|---|---|---|"]
    for r in tt:
        lines.append(f"| {float(r['critical_time']):g} | {r['pair_list']} | {r['collision_list']} | "
                     f"{r['tests']} | {r['completed_level']} |")
    return "\n".join(lines) + "\n"


def update_readme(path, block):
    with open(path) as f:
        text = f.read()
    begin, end = "<!-- results:begin -->\n", "<!-- results:end -->"
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < i:
        raise SystemExit(f"plot_index: {path}: no '<!-- results:begin -->' ... '<!-- results:end -->' block")
    with open(path + ".part", "w") as f:
        f.write(text[: i + len(begin)] + block + text[j:])
    os.replace(path + ".part", path)
    print(f"plot_index: updated the results block of {path}")


def image(d, rel, alt):
    return f"![{alt}]({rel})\n" if os.path.exists(os.path.join(d, rel)) else f"*{alt}: {rel} missing.*\n"


def contact_summary(d, sub):
    rows = contact_rows(d, sub)
    if not rows:
        return sweep_problems(d, sub)
    lines = ["| mode | budget | time (µs) | force error | recall (exact) | false positives | PAIRLIST+COLLISIONLIST |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["budget_kind"] != "seconds":
            continue
        lines.append(f"| {r['mode']} | {float(r['budget']):g} s | {1e6 * float(r['seconds']):.1f} | "
                     f"{float(r['force_rel_error']):.3f} | {float(r['recall_exact']):.3f} | "
                     f"{float(r['false_positive']):.3f} | {r['reported_pairs']} |")
    r0 = rows[0]
    head = (f"At frame {r0['frame']} of {r0['scene']}: {r0['exact_pairs']} exact intersecting triangle pairs, "
            f"{r0['full_leaf_pairs']} colliding leaf pairs in the uninterrupted traversal, which takes "
            f"{1e6 * float(r0['full_seconds']):.1f} µs.\n\n")
    return head + "\n".join(lines) + "\n" + sweep_problems(d, sub)


def main():
    args = sys.argv[1:]
    readme = None
    if args[:1] == ["--readme"]:
        readme, args = args[1], args[2:]
    d, seconds, quick = args[0], int(args[1]), args[2] == "1"
    status = args[3:]
    md = []
    md.append("# Experiments of issue 8: results\n")
    md.append(f"Generated by `scripts/run_experiments.sh{' --quick' if quick else ''}` on "
              f"{datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, {platform.node()} "
              f"({os.cpu_count()} cores), in {seconds} s. Full log: [run.log](run.log).\n")
    if quick:
        md.append("**Quick run**: fewer budgets, frames and cases than the default; numbers are indicative.\n")
    md.append(failure_banner(status))
    md.append("| step | status | wall |\n|---|---|---|\n" + "\n".join(status) + "\n")

    md.append("## The main run: bunny and dragon colliding\n")
    md.append("`icd-main` (the default `experiments/scenes/bunny_dragon.json`) into [main/](main/), pictures by "
              "`scripts/plot_run.py`: the dense meshes deforming with the contact spheres marked (red: "
              "colliding leaves, grey: untested pairs), `frames.csv` over the run, and each object's sphere "
              "tree level by level. ParaView: `pvpython scripts/paraview_show.py main` or open "
              "[main/vtu/run.pvd](main/vtu/run.pvd).\n")
    md.append(image(d, "main/run.gif", "main run animation"))
    md.append(main_findings(d))
    md.append(image(d, "main/frames.png", "main run frames.csv"))
    md.append(image(d, "main/tree_levels.png", "sphere tree levels"))
    md.append("## Table 1: PAIRLIST, COLLISIONLIST and frame rate per critical time\n")
    md.append("Program `bin/table1`: each interaction and critical time is a fresh run from identical initial "
              "conditions, measured 1 frame after the first frame with a contact force (`--after 1`). CSV: "
              "[table1/results.csv](table1/results.csv) (sweep `table1`).\n")
    md.append(table1_section(d, "table1", "Table 1"))
    md.append(table1_failures(d, "table1"))

    md.append("The same with every critical time divided by 1000 (1e-7 .. 1e-3 s), which is roughly the speed "
              "ratio between a sphere test here and on the paper's machine: only then are our queries "
              "interrupted, and PAIRLIST (pairs left untested at the interruption) is non-zero. The paper's columns "
              "hold its row at 1000x our critical time. CSV: "
              "[table1_scaled/results.csv](table1_scaled/results.csv).\n")
    md.append(table1_section(d, "table1_scaled", "Table 1, scaled critical times"))
    md.append(table1_failures(d, "table1_scaled"))
    md.append("The deterministic twin: the same runs with budgets in sphere tests instead of seconds, "
              "so the lists do not depend on the machine or its load (the tables above do). CSV: "
              "[table1_tests/results.csv](table1_tests/results.csv).\n")
    md.append(table1_section(d, "table1_tests", "Table 1, test budgets"))
    md.append(table1_failures(d, "table1_tests"))
    md.append("**PAIRLIST in the paper and here.** The paper's PAIRLIST grows with the critical time up to "
              "1,345-1,405 pairs at 1 s, when its traversal must have finished; so it counts every pair that "
              "entered the list, not the pairs still waiting. Ours is the list at the interruption (the pairs "
              "the response treats as colliding), 0 when the traversal finishes. The CSV's `tests` column "
              "(sphere tests over the frame's detection cycles) is the nearer match to the paper's count.\n")
    md.append("## Fig. 9: spheres used for the contact response\n")
    md.append("Program `bin/fig9` + `scripts/plot_fig9.py`: bunny-dragon 1 frame after first contact, one panel "
              "per critical time; filled red: colliding leaves (COLLISIONLIST), red outlines: untested pairs "
              "(PAIRLIST at the interruption, assumed colliding). VTU files per budget in [fig9/](fig9/).\n")
    md.append(image(d, "fig9/fig9.png", "Fig. 9"))
    md.append(fig9_moment(d, "fig9"))
    md.append("The same with the critical times scaled to this machine (1e-6 .. 3e-5 s): the paper's 1e-4 s already "
              "completes our whole traversal, so only these budgets show untested pairs.\n")
    md.append(image(d, "fig9_scaled/fig9.png", "Fig. 9, scaled budgets"))
    md.append(fig9_moment(d, "fig9_scaled"))

    md.append("## Error against run time\n")
    md.append("### Contact (`bin/contact_error`)\n")
    md.append("The scene is run uninterrupted to the Table 1 moment; on those frozen sphere trees each "
              "(mode, budget) query is repeated and the median-time repetition reported. References: the "
              "uninterrupted traversal of the same trees, and the exact intersecting dense triangle pairs "
              "(AABB trees + exact triangle-triangle tests). Metrics:\n\n"
              "- **force error** = |F - F_full| / |F_full|, F the total penalty force (Eq. 11) on the first "
              "object from the reported pairs (colliding + untested), F_full the same for the uninterrupted "
              "traversal. The sphere penalty force is not defined for triangles, so the force is compared with "
              "the uninterrupted traversal only.\n"
              "- **recall (exact)**: fraction of exact intersecting triangle pairs (f, g) lying under a reported "
              "pair (a, b), i.e. sphere a meets triangle f and sphere b meets triangle g.\n"
              "- **recall (full)**: fraction of the uninterrupted traversal's colliding leaf pairs that descend from "
              "a reported pair (1 for a conservative answer).\n"
              "- **false positives**: fraction of reported pairs under which no exact triangle pair lies; "
              "**looseness**: volume of the distinct reported spheres of the first object / the same for the "
              "full traversal (the over-estimated contact region).\n\n"
              "Modes: `fifo` (paper Fig. 7, fast path: children tested when generated), `fifo_paper_literal` "
              "(Fig. 7 literally, clock read every test), `priority` (best first, largest sphere, list capped at "
              "2^14), `priority_cap256` (bounded memory: 256 pairs), `depth_first` (Fig. 4). Time budgets (circles) "
              "and deterministic test budgets (squares). CSV: [contact_error/results.csv]"
              "(contact_error/results.csv).\n")
    md.append(image(d, "contact_error/contact_error.png", "contact error vs time"))
    md.append(contact_summary(d, "contact_error"))
    md.append(contact_findings(d, "contact_error"))
    md.append("A deeper contact: two primitive spheres with a soft penalty (20 N/m), 5 frames after first contact, where the "
              "dense surfaces interpenetrate ([CSV](contact_error_spheres/results.csv)):\n")
    md.append(image(d, "contact_error_spheres/contact_error.png", "contact error vs time, two spheres"))
    md.append(contact_summary(d, "contact_error_spheres"))
    md.append(contact_findings(d, "contact_error_spheres"))
    md.append("### Deformation (`bin/deformation_error`)\n")
    md.append("Left and middle: dense surface from the rigid links (Eqs. 1, 9, 10) vs the barycentric embedding in "
              "the coarse tets (the reference mapping) on the same coarse motion of bunny-dragon, in % of the dense "
              "bounding-box diagonal, and the time of each mapping. Right: two colliding primitive spheres "
              "simulated with coarse grids of increasing resolution; dense vertices compared one to one with a "
              "fine-grid run at every frame, against the wall time per frame. CSV: "
              "[links](deformation_links/results.csv), [resolution](deformation_error/results.csv).\n")
    md.append(image(d, "deformation_error/deformation_error.png", "deformation error vs time"))
    md.append(sweep_problems(d, "deformation_error") + sweep_problems(d, "deformation_links"))
    md.append("### Sphere update (`bin/sphere_update_error`)\n")
    md.append("Two colliding primitive spheres (octree trees, so the rebuild uses the same builder). Per frame and "
              "object: the rest tree updated from the coarse nodes (paper 4.4 radius ratio, and the conservative "
              "displacement bound) vs an octree rebuilt on the deformed dense surface. Coverage: fraction of "
              "deformed dense vertices outside every leaf sphere (grid-based `measure_coverage`); tightness: total "
              "leaf-sphere volume / volume enclosed by the deformed surface (lower is tighter). CSV: "
              "[sphere_update/results.csv](sphere_update/results.csv).\n")
    md.append(image(d, "sphere_update/sphere_update.png", "sphere update vs rebuild"))
    md.append(sphere_update_findings(d))
    md.append(sweep_problems(d, "sphere_update"))

    md.append("## Stability sweep (sweep `stability`: `icd-run` with scene-field overrides)\n")
    md.append("Two colliding primitive spheres (the full loop: FEM, sphere update, interruptible detection, penalty "
              "response), `experiments/sweeps/scenes/stability_base.json` with one case per material, penalty, speed, "
              "70 % initial compression (`objects.0.initial_compression`) and integrator, as `--set` overrides. "
              "Not ok = `icd-run` stopped (a health check or a thrown error: the message); stable = it ran every "
              "frame with finite energy and the energy never exceeded twice its first-frame value. E is the "
              "`energy` column of `frames.csv` (kinetic + elastic + gravity potential + the penalty springs' energy, "
              "after each frame); energy drift = (E_last - E_first) / |E_first| (damping dissipates, so negative "
              "is expected). CSV: [stability/results.csv](stability/results.csv) (one row per case and frame).\n")
    md.append(stability_md(d))

    md.append("## Other engineers' experiments, reused\n")
    if os.path.exists(os.path.join(d, "fem/results.csv")):
        md.append("FEM error against run time (cantilever vs Timoshenko and a fine static reference), from "
                  "`experiments/studies/fem/fem_error_vs_time` (sweep `fem_error_vs_time`, one case): "
                  "[CSV](fem/results.csv)\n")
        md.append(sweep_problems(d, "fem"))
        md.append(image(d, "fem/fem_error_vs_time.png", "FEM error vs time"))
    if os.path.exists(os.path.join(d, "collision/accuracy.txt")):
        md.append("Collision accuracy/coverage experiment of the collision module: "
                  "[collision/accuracy.txt](collision/accuracy.txt); measured discussion in "
                  "`experiments/studies/collision/RESULTS.md`.\n")

    md.append("## Scenes\n")
    md.append("The bunny/dragon runs use `experiments/studies/paper/scenes/*.json`: the shipped `experiments/scenes/*.json` "
              "with the stable Neo-Hookean material (inversion-safe) and otherwise the shipped parameters.\n")
    md.append("## Where and why our numbers differ from the paper's\n")
    md.append(
        "- **Machine.** The paper ran on a 2003-era PC; we run on a shared 2-core VM with other builds running. "
        "A sphere test costs a few ns here, so a given critical time buys 10-100x more tests than in the paper: "
        "our PAIRLIST/COLLISIONLIST at a critical time correspond to the paper's at a critical time 10-100x "
        "larger. Comparing at equal *numbers of tests* (the test budgets of the contact experiment) removes the "
        "machine; comparing at equal seconds does not. Timing noise from the shared machine: medians reported.\n"
        "- **Mesh sizes and trees.** Our bunny has 37,706 vertices / 75,408 faces and the dragon 10,000 / 19,994 "
        "(two small holes), scaled to 0.3 m; coarse meshes of ~1,500 tets from our preprocessing, sphere trees "
        "3 levels below the root with branching 8 (the paper's depth). The paper's meshes, coarse resolution and "
        "tree builder differ, so the absolute list sizes differ even at completion (critical time 1 s).\n"
        "- **Frame rate.** Our FPS at the moment of contact includes explicit RK4 FEM sub-stepping for a stable "
        "step, and up to 64 detection/response cycles per frame for a stable staggered penalty (frames that "
        "start apart run one cycle, so FPS away from contact is several times higher; see `results/main`), the "
        "sphere update, response and rigid links; the paper's FPS is capped at 60 by the display "
        "and its FEM cost differs. Our list sizes saturate at smaller critical times than the paper's because "
        "the full traversal of our trees finishes in well under a millisecond.\n"
        "- **Moment of contact.** We measure Table 1 and Fig. 9 1 frame after first contact, the contact "
        "error 3 frames after (bunny-dragon) or 5 (two spheres), from identical initial conditions (the "
        "frames are stated above, from the CSVs); the paper does not define its moment precisely.\n")
    with open(os.path.join(d, "index.md"), "w") as f:
        f.write("\n".join(md))
    if readme:
        block = glance(d)
        if block is None:
            raise SystemExit("plot_index: --readme: table1, table1_scaled or table1_tests lacks bunny_dragon rows")
        update_readme(readme, block)
    print(f"plot_index: wrote {os.path.join(d, 'index.md')}")


if __name__ == "__main__":
    main()
