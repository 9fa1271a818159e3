#!/usr/bin/python3
"""Feeds every bad input of manifest.tsv to the program that should refuse it,
and every valid-but-unusual input of good.tsv to the program that must accept
it, and checks the outcome (issues 9 and "hostile input").

Bad inputs: a non-zero exit status that is not a signal (no crash, no
sanitizer abort), stderr/stdout naming the problem (the expected substring of
the manifest, case-insensitive), and, for icd-run and icd-preprocess, no
output file that looks complete (frames.csv, a .pvd series, bundle.icdb).
Good inputs: exit status 0 and the expected substring in the output.
Every input: at most --max-cpu-seconds of CPU time (user + system of the
child, from os.wait4: the same on a loaded machine as on an idle one;
RLIMIT_CPU stops a child that runs past it) and --max-memory-mb of memory
(RLIMIT_AS in the child, so an allocation above the bound fails, and the
child's peak resident memory is checked too); --max-wall-seconds of wall-clock
time only as a guard against a hang (a child that waits without using CPU),
generous because a loaded machine stretches wall time (load 7-10: 26 s wall
for 4 s CPU); no file written outside
its output folder (the runs start in an empty folder); no shell command of a
hostile path run (no marker file "icd_injected_marker" appears).

Rows: file<TAB>program [extra arguments]<TAB>expected substring. The file is
a name in --files, an absolute path (e.g. /dev/zero), or "gen:<name>": an
input generated at run time into the work folder by GENERATORS below (huge
files are sparse: no disk space used). Programs: meshinfo (icd-meshinfo
FILE), read (icd-read-check FILE|FOLDER), run-dry (icd-run FILE --dry-run),
run (icd-run FILE --out DIR, full run), preprocess (icd-preprocess FILE -o
DIR; skipped without CGAL).

usage: check_bad_inputs.py --files DIR --manifest FILE [--good FILE] --work DIR
                           --meshinfo EXE --run EXE --read-check EXE
                           [--preprocess EXE] [--max-cpu-seconds S] [--max-wall-seconds W]
                           [--max-memory-mb M] [--min-files N]
       check_bad_inputs.py --self-test
Rows whose program is not given (e.g. preprocess without CGAL) are skipped.
--self-test: the limits must catch fake programs (one burning CPU past the CPU
limit, one hanging without CPU) and must pass one that only waits (wall time
without CPU time, as on a loaded machine); exit 1 if they do not.
"""
import argparse
import math
import os
import resource
import shlex
import shutil
import signal
import subprocess
import sys
import time

MARKER = "icd_injected_marker"
MiB = 1 << 20


def sparse(path, size):
    with open(path, "wb") as f:
        f.truncate(size)


def lines_file(path, header, line, count, footer=b""):
    with open(path, "wb") as f:
        f.write(header)
        chunk = line * 65536
        for _ in range(count // 65536):
            f.write(chunk)
        f.write(line * (count % 65536))
        f.write(footer)


def gen_scene_values(path, count):
    # {"objects": [0, 0, ...]}: `count` values in all.
    with open(path, "wb") as f:
        f.write(b'{"objects": [0')
        f.write(b",0" * (count - 3))
        f.write(b"]}\n")


def gen_stl_distinct(path, size_limit):
    # Binary STL of distinct corners (no welding), just below the size limit.
    import struct
    n = (size_limit - 84) // 50
    with open(path, "wb") as f:
        f.write(b"worst case".ljust(80, b" ") + struct.pack("<I", n))
        rec = bytearray(50)
        for t in range(n):
            struct.pack_into("<12f", rec, 0, 0, 0, 1, t, 0, 0, t, 1, 0, t, 0, 1)
            f.write(rec)


def gen_vtu_points(path, size):
    # A VTU of "0 0 0" points (the shortest tokens) and one triangle.
    n = (size - 2000) // 6
    head = ('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0">\n'
            '<UnstructuredGrid>\n<Piece NumberOfPoints="%d" NumberOfCells="1">\n<Points>\n'
            '<DataArray type="Float64" NumberOfComponents="3" format="ascii">\n' % n).encode()
    tail = (b'</DataArray>\n</Points>\n<Cells>\n'
            b'<DataArray type="Int64" Name="connectivity" format="ascii">0 1 2</DataArray>\n'
            b'<DataArray type="Int64" Name="offsets" format="ascii">3</DataArray>\n'
            b'<DataArray type="UInt8" Name="types" format="ascii">5</DataArray>\n'
            b'</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n')
    lines_file(path, head, b"0 0 0\n", n, tail)


def gen_hostile_named_mesh(work):
    # A scene whose mesh path holds a shell command; the mesh (an open surface:
    # one triangle) is refused by icd-preprocess, which must get the path as
    # one argument: no shell may run the `touch`.
    folder = os.path.join(work, "hostile_names")
    os.makedirs(folder, exist_ok=True)
    mesh = f"x$(touch {MARKER}).off"
    with open(os.path.join(folder, mesh), "w") as f:
        f.write("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    scene = os.path.join(folder, "scene_shell_injection.json")
    with open(scene, "w") as f:
        f.write('{"name": "shell", "frames": 1, "objects": [{"name": "evil", "mesh": %s,'
                ' "size": 0.2, "preprocess": {"coarse_tets": 10}}]}\n' % json_string(mesh))
    return scene


def json_string(s):
    import json
    return json.dumps(s)


# gen:<name> -> function(path in the work folder) writing the input, or
# returning another path to use.
GENERATORS = {
    # Far above the limits: refused by their size before a byte is read.
    "scene_nul_1536mib.json": lambda p: sparse(p, 1536 * MiB),
    "mesh_nul_1536mib.off": lambda p: sparse(p, 1536 * MiB),
    "mesh_nul_1536mib.stl": lambda p: sparse(p, 1536 * MiB),
    "sph_nul_1536mib.sph": lambda p: sparse(p, 1536 * MiB),
    "vtu_nul_1536mib.vtu": lambda p: sparse(p, 1536 * MiB),
    "bundle_huge_icdb": lambda p: (os.makedirs(p), sparse(os.path.join(p, "bundle.icdb"), 1536 * MiB)),
    # Just within the limits: read (and refused by their content) in bounded
    # time and memory.
    "scene_nul_63mib.json": lambda p: sparse(p, 63 * MiB),
    "scene_too_many_values.json": lambda p: gen_scene_values(p, (1 << 20) + 1),
    "scene_most_values.json": lambda p: gen_scene_values(p, 1 << 20),
    # (A quarter to a third of the limits, so that they stay well within 10 s
    # of CPU time: about 1 s each; the at-limit files take 3-7 s on an idle
    # machine; the reliability README gives the at-limit figures.)
    "off_worst_vertices.off": lambda p: lines_file(
        p, b"OFF\n4000000 1 0\n", b"0 0 0\n", 4000000, b"3 0 1 2\n"),
    "off_worst_faces.off": lambda p: lines_file(
        p, b"OFF\n3 3000000 0\n0 0 0\n1 0 0\n0 1 0\n", b"3 0 1 2\n", 3000000),
    "stl_worst_distinct.stl": lambda p: gen_stl_distinct(p, 20 * MiB),
    "vtu_worst_points.vtu": lambda p: gen_vtu_points(p, 16 * MiB),
    "sph_worst_lines.sph": lambda p: lines_file(
        p, b"7 10\n", b"0 0 0 1 0\n", (10 ** 7 - 1) // 9),
    "scene_shell_injection.json": None,  # gen_hostile_named_mesh (needs the work folder)
}


def parse_manifest(path):
    rows = []
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            line = line.rstrip("\n")
            if not line.strip() or line.startswith("#"):
                continue
            parts = line.split("\t")
            if len(parts) != 3:
                sys.exit(f"{path}:{n}: expected 3 tab-separated fields, got {len(parts)}")
            rows.append((os.path.basename(path), n, *parts))
    return rows


def looks_complete(out_dir):
    found = []
    for root, _, files in os.walk(out_dir):
        for name in files:
            if name == "frames.csv" or name.endswith(".pvd") or name == "bundle.icdb":
                found.append(os.path.join(root, name))
    return found


def tree(folder):
    out = set()
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            out.add(os.path.relpath(os.path.join(root, name), folder))
    return out


def run_limited(cmd, cwd, max_cpu, max_wall, max_memory, env=None):
    """Runs cmd in cwd (environment env, None: this one) under RLIMIT_AS = max_memory (0: none)
    and RLIMIT_CPU (SIGXCPU a second past max_cpu), killed after max_wall seconds of wall time;
    returns (returncode, stdout, stderr, CPU seconds (user + system), wall seconds, peak RSS bytes
    of this child, timed out)."""
    def limit():
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        cpu = math.ceil(max_cpu) + 1
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 2))
        if max_memory:
            resource.setrlimit(resource.RLIMIT_AS, (max_memory, max_memory))
    out_path, err_path = os.path.join(cwd, ".stdout"), os.path.join(cwd, ".stderr")
    t0 = time.monotonic()
    with open(out_path, "wb") as out_f, open(err_path, "wb") as err_f:
        p = subprocess.Popen(cmd, cwd=cwd, stdout=out_f, stderr=err_f, preexec_fn=limit, env=env)
    timed_out = False
    while True:  # os.wait4: the rusage of this child alone
        pid, status, usage = os.wait4(p.pid, os.WNOHANG)
        if pid == p.pid:
            break
        if time.monotonic() - t0 > max_wall and not timed_out:
            p.kill()
            timed_out = True
        time.sleep(0.01)
    p.returncode = os.waitstatus_to_exitcode(status)
    wall = time.monotonic() - t0
    with open(out_path, "rb") as f:
        out = f.read().decode("utf-8", "replace")
    with open(err_path, "rb") as f:
        err = f.read().decode("utf-8", "replace")
    os.remove(out_path)
    os.remove(err_path)
    cpu = usage.ru_utime + usage.ru_stime
    return p.returncode, out, err, cpu, wall, usage.ru_maxrss * 1024, timed_out


def limit_problems(rc, cpu, wall, timed_out, max_cpu, max_wall):
    """What the time limits say of a run: CPU time above max_cpu (stopped by SIGXCPU or not), a
    hang past the wall-clock guard, a crash (any other signal). Empty when the run is within."""
    problems = []
    xcpu = rc in (-signal.SIGXCPU, 128 + signal.SIGXCPU)
    if cpu > max_cpu or xcpu:
        problems.append(f"used {cpu:.1f} s of CPU time, above the limit of {max_cpu:g} s"
                        + (" (stopped by SIGXCPU)" if xcpu else ""))
    elif timed_out:
        problems.append(f"still running after {max_wall:g} s of wall time ({cpu:.1f} s CPU): hung?")
    elif rc < 0 or rc >= 128:
        sig = -rc if rc < 0 else rc - 128
        problems.append(f"killed by signal {sig} ({signal.Signals(sig).name})")
    return problems


def self_test():
    """The limits catch a CPU burner and a hang, and pass a program that only waits."""
    import tempfile
    failures = []
    with tempfile.TemporaryDirectory(prefix="icd_bad_inputs_self_test_") as cwd:
        def judge(name, code, max_cpu, max_wall, expect):
            cmd = [sys.executable, "-c", code]
            rc, _, err, cpu, wall, _, timed_out = run_limited(cmd, cwd, max_cpu, max_wall, 0)
            problems = limit_problems(rc, cpu, wall, timed_out, max_cpu, max_wall)
            print(f"self-test {name}: rc={rc} cpu {cpu:.2f} s wall {wall:.2f} s: "
                  f"{'; '.join(problems) or 'within the limits'}")
            if expect is None and problems:
                failures.append(f"{name}: flagged ({'; '.join(problems)}), expected within limits")
            if expect is not None and not any(expect in p for p in problems):
                failures.append(f"{name}: not flagged with '{expect}': {problems}; {err[-300:]}")
        # Burns CPU forever: stopped by RLIMIT_CPU (SIGXCPU) near 2 s of CPU.
        judge("cpu burner", "while True: pass", 1, 60, "of CPU time, above the limit of 1 s")
        # Burns 1.3 s of CPU, then exits 0: the CPU figure alone flags it.
        judge("cpu burner that exits", "import signal, time\n"
              "signal.signal(signal.SIGXCPU, signal.SIG_IGN)\n"
              "t = time.process_time()\nwhile time.process_time() - t < 1.3: pass",
              1, 60, "of CPU time, above the limit of 1 s")
        # Sleeps 1.5 s (wall time without CPU time, as on a loaded machine): within a 1 s CPU limit.
        judge("sleeper", "import time; time.sleep(1.5)", 1, 60, None)
        # Hangs without CPU: the wall-clock guard.
        judge("hang", "import time; time.sleep(600)", 1, 1.5, "wall time")
    for f in failures:
        print("FAILED:", f)
    return 1 if failures else 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    ap = argparse.ArgumentParser()
    for opt in ("files", "manifest", "work", "meshinfo", "run", "read-check"):
        ap.add_argument("--" + opt, required=True)
    ap.add_argument("--good")
    ap.add_argument("--preprocess")
    ap.add_argument("--max-cpu-seconds", type=float, default=10)
    ap.add_argument("--max-wall-seconds", type=float, default=120,
                    help="hang guard only: wall time stretches with the machine's load")
    ap.add_argument("--max-memory-mb", type=float, default=1024,
                    help="0: no memory bound (sanitizer builds reserve terabytes of address space)")
    ap.add_argument("--min-files", type=int, default=110)
    a = ap.parse_args()

    absolute = lambda p: os.path.abspath(p) if p else p  # the inputs run in folders of their own
    exe = {"meshinfo": absolute(a.meshinfo), "run": absolute(a.run), "run-dry": absolute(a.run),
           "read": absolute(a.read_check), "preprocess": absolute(a.preprocess)}
    a.files, a.work = absolute(a.files), absolute(a.work)
    bad_rows = parse_manifest(a.manifest)
    good_rows = parse_manifest(a.good) if a.good else []
    rows = [(r, False) for r in bad_rows] + [(r, True) for r in good_rows]
    listed = {r[2] for r in bad_rows + good_rows}
    on_disk = {f for f in os.listdir(a.files) if not f.startswith(".")}
    failures = []
    for f in sorted(on_disk - listed):
        failures.append(f"{f}: in {a.files} but in no manifest")
    bad_files = {r[2] for r in bad_rows}
    if len(bad_files) < a.min_files:
        failures.append(f"the bad-input corpus holds {len(bad_files)} inputs, "
                        f"fewer than {a.min_files}")
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    max_memory = int(a.max_memory_mb * MiB)
    ran = skipped = 0
    slowest = (0.0, 0.0, "")
    t_all = time.monotonic()
    # The runner's asset cache (a scene's raw mesh is preprocessed into it,
    # with a lock file named after the mesh, hostile names included) is a
    # private folder of the work folder, never the source tree's assets/.
    child_env = dict(os.environ, ICD_CACHE_DIR=os.path.join(a.work, "cache"))
    for (manifest, n, name, program_args, expected), good in rows:
        words = program_args.split(" ")
        program, extra = words[0], words[1:]
        where = f"{manifest}:{n}: {name} ({program_args})"
        if program not in exe:
            failures.append(f"{where}: unknown program '{program}'")
            continue
        if not exe[program]:
            skipped += 1
            continue
        # Each input runs in an empty folder of its own: anything written
        # outside its output folder shows up there.
        cwd = os.path.join(a.work, f"{manifest}.{n}")
        os.makedirs(cwd)
        if name.startswith("gen:"):
            gen = name[4:]
            if gen not in GENERATORS:
                failures.append(f"{where}: no generator '{gen}'")
                continue
            path = os.path.join(a.work, "gen", gen)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            if gen == "scene_shell_injection.json":
                path = gen_hostile_named_mesh(os.path.join(a.work, "gen"))
            elif not os.path.exists(path):
                GENERATORS[gen](path)
        elif os.path.isabs(name):
            path = name
        else:
            path = os.path.join(a.files, name)
        if not os.path.exists(path):
            failures.append(f"{where}: listed in the manifest but missing")
            continue
        out_dir = os.path.join(cwd, "out")
        if program in ("meshinfo", "read"):
            cmd = [exe[program], path]
        elif program == "preprocess":
            cmd = [exe[program], path, "-o", out_dir, "-q"]
        else:
            cmd = [exe[program], path, "--out", out_dir, "--quiet"]
            if program == "run-dry":
                cmd.append("--dry-run")
        cmd += extra
        before = tree(cwd) | {".stdout", ".stderr"}
        rc, out, err, cpu, wall, rss, timed_out = run_limited(
            cmd, cwd, a.max_cpu_seconds, a.max_wall_seconds, max_memory, child_env)
        ran += 1
        slowest = max(slowest, (cpu, wall, name))
        text = out + err
        last = (err.strip().splitlines() or out.strip().splitlines() or ["<no output>"])[-1]
        problems = limit_problems(rc, cpu, wall, timed_out, a.max_cpu_seconds, a.max_wall_seconds)
        if problems:
            pass  # a crash, a hang or too much CPU: the exit status says nothing more
        elif good and rc != 0:
            problems.append(f"exit status {rc} (a valid input refused)")
        elif not good and rc == 0:
            problems.append("exit status 0 (input accepted)")
        if max_memory and rss > max_memory:
            problems.append(f"peak memory {rss / MiB:.0f} MiB above {a.max_memory_mb:.0f} MiB")
        if "Sanitizer" in text or "runtime error:" in text:
            problems.append("sanitizer report")
        if "bad_alloc" in text:
            problems.append("std::bad_alloc (an allocation above the memory bound?)")
        if expected.lower() not in text.lower():
            problems.append(f"message lacks '{expected}'")
        if not good and (program.startswith("run") or program == "preprocess"):
            left = looks_complete(out_dir) if os.path.isdir(out_dir) else []
            if left:
                problems.append("left complete-looking output: " + ", ".join(left))
        outside = sorted(p for p in tree(cwd) - before
                         if p != "out" and not p.startswith("out" + os.sep))
        if outside:
            problems.append("wrote outside its output folder: " + ", ".join(outside[:5]))
        for root in (cwd, a.work, os.path.dirname(path)):
            if os.path.exists(os.path.join(root, MARKER)):
                problems.append(f"a shell ran a command from a path ({MARKER} created in {root})")
                os.remove(os.path.join(root, MARKER))
        status = "FAIL" if problems else ("good" if good else "ok")
        print(f"{status:4} {name:40} {program_args:16} rc={rc} {cpu:5.2f}s cpu {wall:5.2f}s wall "
              f"{rss / MiB:5.0f}MiB  "
              f"{last[:150]}")
        if problems:
            failures.append(f"{where}: " + "; ".join(problems) +
                            f"\n    command: {shlex.join(cmd)}\n    output: {text.strip()[-600:]}")
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024  # MiB
    print(f"\n{ran} inputs run ({len(bad_files)} bad, {len({r[2] for r in good_rows})} good), "
          f"{skipped} skipped (program not built), {time.monotonic() - t_all:.1f} s wall; "
          f"most CPU {slowest[0]:.2f} s ({slowest[2]}, {slowest[1]:.2f} s wall; limit "
          f"{a.max_cpu_seconds:g} s CPU, {a.max_wall_seconds:g} s wall), "
          f"largest peak memory {peak:.0f} MiB")
    if ran < 30:
        failures.append(f"only {ran} inputs were run (at least 30 expected)")
    # The hostile-named mesh was preprocessed through the private cache: its
    # lock file is there (and so not in the source tree's assets/).
    cache = os.path.join(a.work, "cache")
    if exe.get("run") and not any(
            e.startswith("x$(touch") for e in (os.listdir(cache) if os.path.isdir(cache) else [])):
        failures.append(f"the hostile-named mesh left no lock in the private cache {cache}")
    for f in failures:
        print("FAILED:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
