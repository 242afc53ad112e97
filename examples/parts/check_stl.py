#!/usr/bin/env python3
"""Checks an STL mesh (binary or ASCII) and prints its triangle count, bounding box,
signed-tetrahedra volume, boundary edges (used by exactly one triangle), non-manifold
edges (used by more than two) and misoriented edges (two triangles running the edge the
same way). Vertices are welded when their coordinates are identical.

Exits 1 when the mesh is open, non-manifold, inconsistently oriented or its volume is not
positive; 2 when the file cannot be read. Standard library only:
    /usr/bin/python3 check_stl.py PART.stl [PART.stl ...]"""
import struct
import sys
from collections import Counter


def read(path):
    """Returns a list of triangles, each a tuple of three (x, y, z) tuples."""
    data = open(path, "rb").read()
    if len(data) >= 84:
        (n,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + 50 * n:  # binary, even when the header starts with "solid"
            tris = []
            for i in range(n):
                v = [x + 0.0 for x in struct.unpack_from("<12f", data, 84 + 50 * i)]  # -0.0 -> 0.0
                tris.append((tuple(v[3:6]), tuple(v[6:9]), tuple(v[9:12])))
            return tris
    if not data.lstrip().startswith(b"solid"):
        raise ValueError("neither a binary STL (size does not match its triangle count) "
                         "nor an ASCII STL (no 'solid')")
    words = data.decode("ascii").split()
    tris, cur = [], []
    for i, w in enumerate(words):
        if w == "vertex":
            cur.append(tuple(float(x) + 0.0 for x in words[i + 1:i + 4]))
            if len(cur) == 3:
                tris.append(tuple(cur))
                cur = []
    if cur:
        raise ValueError("ASCII STL ends inside a facet")
    return tris


def check(path):
    try:
        tris = read(path)
    except (OSError, ValueError, UnicodeDecodeError) as e:
        print(f"{path}: cannot read: {e}")
        return 2
    if not tris:
        print(f"{path}: no triangles")
        return 1
    lo = [min(v[k] for t in tris for v in t) for k in range(3)]
    hi = [max(v[k] for t in tris for v in t) for k in range(3)]
    vol = 0.0
    for a, b, c in tris:
        vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
    vol /= 6.0
    directed = Counter()
    degenerate = 0
    for t in tris:
        if t[0] == t[1] or t[1] == t[2] or t[2] == t[0]:
            degenerate += 1
        for i in range(3):
            directed[(t[i], t[(i + 1) % 3])] += 1
    undirected = Counter()
    for (p, q), n in directed.items():
        undirected[(min(p, q), max(p, q))] += n
    boundary = sum(1 for n in undirected.values() if n == 1)
    nonmanifold = sum(1 for n in undirected.values() if n > 2)
    misoriented = sum(1 for (p, q), n in undirected.items()
                      if n == 2 and directed[(p, q)] != 1)
    fmt = lambda p: "(" + ", ".join(f"{x:g}" for x in p) + ")"
    print(f"{path}: {len(tris)} triangles, bounds {fmt(lo)} .. {fmt(hi)}, "
          f"volume {vol:.6f} mm^3, {boundary} boundary edges, {nonmanifold} non-manifold edges, "
          f"{misoriented} misoriented edges, {degenerate} degenerate triangles")
    problems = []
    if boundary:
        problems.append("open (boundary edges)")
    if nonmanifold:
        problems.append("non-manifold edges")
    if misoriented:
        problems.append("inconsistent orientation")
    if not vol > 0:
        problems.append("volume not positive")
    if problems:
        print(f"{path}: FAIL: " + ", ".join(problems))
        return 1
    return 0


def main(paths):
    if not paths:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    return max(check(p) for p in paths)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
