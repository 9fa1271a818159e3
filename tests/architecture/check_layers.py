#!/usr/bin/env python3
"""Checks that module includes point one way (bottom-up layers, ARCHITECTURE.md).

Each source file of a module may include headers of its own module and of
the modules below it, never above; fem and collision know nothing of each
other; nothing outside experiments/ and tests/ includes experiments/.
Exit 1 with one line per offending include; exit 2 when a module folder is
missing (the check would otherwise pass on nothing)."""
import pathlib
import re
import sys

root = pathlib.Path(".")

# module folder -> rank; a file may include modules of lower rank or its own.
LAYERS = {
    "mesh/core": 0,
    "mesh/io": 1,
    "fem": 2,
    "collision": 2,
    "coupling": 3,
    "mesh/pipeline": 4,
    "mesh/spheres": 4,
}
# Same-rank modules that may include each other (one CGAL target, icd::mesh).
SIBLINGS = {frozenset({"mesh/pipeline", "mesh/spheres"})}

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]')


def module_of(path: str):
    for m in sorted(LAYERS, key=len, reverse=True):
        if path == m or path.startswith(m + "/"):
            return m
    return None


def check() -> int:
    missing = [m for m in LAYERS if not (root / m).is_dir()]
    if missing:
        print("missing module folders: " + ", ".join(missing))
        return 2
    errors, files = [], 0
    for m in LAYERS:
        for f in sorted((root / m).rglob("*")):
            if f.suffix not in (".hpp", ".cpp", ".h"):
                continue
            files += 1
            rel = f.relative_to(root).as_posix()
            for n, line in enumerate(f.read_text(errors="replace").splitlines(), 1):
                g = INCLUDE.match(line)
                if not g:
                    continue
                inc = g.group(1)
                if inc.startswith("experiments/") or inc.startswith("tests/"):
                    errors.append(f"{rel}:{n}: includes the application layer ({inc})")
                    continue
                if not inc.startswith("icd/"):
                    continue
                target = module_of(inc[len("icd/"):])
                if target is None or target == m:
                    continue
                if LAYERS[target] > LAYERS[m] or (
                    LAYERS[target] == LAYERS[m] and frozenset({m, target}) not in SIBLINGS
                ):
                    errors.append(f"{rel}:{n}: {m} (layer {LAYERS[m]}) includes {inc} "
                                  f"({target}, layer {LAYERS[target]})")
    if files < 50:
        print(f"only {files} source files found under {root}: wrong root?")
        return 2
    for e in errors:
        print(e)
    print(f"{files} files checked, {len(errors)} includes against the layers")
    return 1 if errors else 0


def self_test() -> int:
    """The check must fail on an upward include and on a missing folder."""
    import tempfile
    global root
    with tempfile.TemporaryDirectory() as d:
        root = pathlib.Path(d)
        for m in LAYERS:
            (root / m).mkdir(parents=True)
            for k in range(10):
                (root / m / f"f{k}.cpp").write_text("#include <icd/mesh/core/types.hpp>\n")
        if check() != 0:
            print("self-test: a clean tree failed")
            return 1
        (root / "fem" / "bad.cpp").write_text("#include <icd/coupling/world.hpp>\n")
        if check() != 1:
            print("self-test: fem including coupling was not caught")
            return 1
        (root / "fem" / "bad.cpp").write_text("#include <icd/collision/traversal.hpp>\n")
        if check() != 1:
            print("self-test: fem including collision was not caught")
            return 1
        (root / "fem" / "bad.cpp").write_text('#include "experiments/runner/run.hpp"\n')
        if check() != 1:
            print("self-test: a library including experiments/ was not caught")
            return 1
        (root / "fem" / "bad.cpp").unlink()
        (root / "coupling" / "f0.cpp").unlink()
        for f in (root / "coupling").iterdir():
            f.unlink()
        (root / "coupling").rmdir()
        if check() != 2:
            print("self-test: a missing module folder was not caught")
            return 1
    print("self-test passed")
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--self-test":
        sys.exit(self_test())
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    sys.exit(check())
