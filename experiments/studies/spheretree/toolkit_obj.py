#!/usr/bin/python3
"""Writes a closed triangle surface as the OBJ the reference toolkit's
makeTreeMedial reads (`v x y z`, faces `f a//a b//b c//c`, 1-based): from a
bundle's dense_surface.vtu (the repaired surface icd-preprocess keeps, ASCII
VTU of triangles) or a plain OFF file. Coordinates are written with 17
significant digits (the same doubles; the toolkit reads them as floats).

usage: toolkit_obj.py IN.vtu|IN.off OUT.obj
"""
import re
import sys


def fail(msg):
    print("toolkit_obj.py: " + msg, file=sys.stderr)
    sys.exit(1)


def read_vtu(path):
    text = open(path).read()
    def array(name):
        m = re.search(r'<DataArray[^>]*Name="' + name + r'"[^>]*>(.*?)</DataArray>', text, re.S)
        if not m:
            fail(f"{path}: no DataArray '{name}'")
        return m.group(1).split()
    p = [float(x) for x in array("Points")]
    c = [int(x) for x in array("connectivity")]
    off = [int(x) for x in array("offsets")]
    if len(p) % 3 or any(b - a != 3 for a, b in zip([0] + off[:-1], off)) or len(c) != 3 * len(off):
        fail(f"{path}: not a triangle surface")
    return [p[i:i + 3] for i in range(0, len(p), 3)], [c[i:i + 3] for i in range(0, len(c), 3)]


def read_off(path):
    words = []
    for line in open(path):
        line = line.split("#", 1)[0].strip()
        if line:
            words.extend(line.split())
    if not words or words[0] != "OFF":
        fail(f"{path}: not a plain OFF file")
    nv, nf = int(words[1]), int(words[2])
    v = [[float(x) for x in words[4 + 3 * i:7 + 3 * i]] for i in range(nv)]
    pos, f = 4 + 3 * nv, []
    for _ in range(nf):
        k = int(words[pos])
        if k != 3:
            fail(f"{path}: face with {k} vertices (triangles only)")
        f.append([int(x) for x in words[pos + 1:pos + 4]])
        pos += 4
    return v, f


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    src, dst = argv
    v, f = read_vtu(src) if src.lower().endswith(".vtu") else read_off(src)
    if any(i < 0 or i >= len(v) for t in f for i in t):
        fail(f"{src}: face index out of range")
    with open(dst, "w") as out:
        for p in v:
            out.write("v %.17g %.17g %.17g\n" % tuple(p))
        for t in f:
            out.write("f %d//%d %d//%d %d//%d\n" % (t[0] + 1, t[0] + 1, t[1] + 1, t[1] + 1,
                                                    t[2] + 1, t[2] + 1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
