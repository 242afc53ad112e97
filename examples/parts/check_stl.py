#!/usr/bin/env python3
"""Checks an STL (binary or ASCII): triangles, bounding box, signed-tetrahedra volume,
boundary and non-manifold edges. Exits 1 when the mesh is open or its volume is not
positive. Standard library only: /usr/bin/python3 check_stl.py PART.stl"""
import struct
import sys
from collections import Counter


def read(path):
    data = open(path, "rb").read()
    if len(data) >= 84:
        (n,) = struct.unpack_from("<I", data, 80)
        if 84 + 50 * n == len(data):
            tris = []
            for i in range(n):
                v = struct.unpack_from("<12f", data, 84 + 50 * i)
                tris.append((v[3:6], v[6:9], v[9:12]))
            return tris
    words = data.decode("ascii").split()
    tris, cur = [], []
    for i, w in enumerate(words):
        if w == "vertex":
            cur.append(tuple(float(x) for x in words[i + 1:i + 4]))
            if len(cur) == 3:
                tris.append(tuple(cur))
                cur = []
    return tris


def main(path):
    tris = read(path)
    lo = [min(v[k] for t in tris for v in t) for k in range(3)]
    hi = [max(v[k] for t in tris for v in t) for k in range(3)]
    vol = 0.0
    for a, b, c in tris:
        vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0
    edges = Counter()
    for t in tris:
        for i in range(3):
            p, q = t[i], t[(i + 1) % 3]
            edges[(min(p, q), max(p, q))] += 1
    boundary = sum(1 for c in edges.values() if c % 2 == 1)
    nonmanifold = sum(1 for c in edges.values() if c > 2)
    print(f"{path}: {len(tris)} triangles, bounds {lo} .. {hi}, volume {vol:.3f} mm^3, "
          f"{boundary} boundary edges, {nonmanifold} non-manifold edges")
    return 0 if boundary == 0 and vol > 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
