#!/usr/bin/env python3
"""Names two source files of one unity batch would share: every entity
declared outside a class in each file (functions, variables, types, aliases,
in named or anonymous namespaces; found with Universal Ctags), reported when
another file of the same list declares the same name. Two such files must
not share a unity batch (a redefinition fails to compile; two overloads of
one helper would compile and might call the other file's helper).

    scripts/unity_clashes.py FILE.cpp FILE.cpp ...     (one target's sources)

Exit 1 when a clash is found."""
import collections
import subprocess
import sys

SKIP_KINDS = {"namespace", "macro", "member", "enumerator", "local", "parameter", "prototype",
              "externvar", "label", "header"}
SKIP_NAMES = {"TEST", "TEST_F", "TEST_P", "INSTANTIATE_TEST_SUITE_P", "TYPED_TEST", "main"}


def names(path):
    out = subprocess.run(["ctags", "-x", "--language-force=c++", "--c++-kinds=+p-m",
                          "--_xformat=%N\t%K\t%s\t%S", path],
                         check=True, capture_output=True, text=True).stdout
    found = set()
    for line in out.splitlines():
        name, kind, scope, *_ = (line.split("\t") + ["", ""])[:4]
        if kind in SKIP_KINDS or name in SKIP_NAMES or name.startswith("__anon"):
            continue
        # Class members: their scope is a class, struct or union (ctags prints
        # its name; namespaces' names are in the namespace tags).
        if scope and not is_namespace(scope, out):
            continue
        found.add(name)
    return found


def is_namespace(scope, tags):
    last = scope.split("::")[-1]
    if last.startswith("__anon"):
        return True
    for line in tags.splitlines():
        f = line.split("\t")
        if len(f) >= 2 and f[0] == last and f[1] == "namespace":
            return True
    return False


def main():
    files = sys.argv[1:]
    if not files:
        sys.exit(__doc__)
    where = collections.defaultdict(list)
    for f in files:
        for n in names(f):
            where[n].append(f)
    clashes = {n: fs for n, fs in where.items() if len(fs) > 1}
    for n, fs in sorted(clashes.items()):
        print(f"{n}: {' '.join(fs)}")
    sys.exit(1 if clashes else 0)


if __name__ == "__main__":
    main()
