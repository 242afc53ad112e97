#!/usr/bin/env python3
"""Rewrites a binary STL in a canonical order so that regenerating a part gives the same
bytes. OpenSCAD 2021.01 writes the same triangles in a different order from run to run
(CGAL orders facets by address), which would show up as a spurious change in git.

Each triangle's vertex cycle is rotated to start at its smallest vertex (orientation is
kept), triangles are sorted, and the header is fixed. Coordinates and normals keep their
values (only -0.0 becomes 0.0). Standard library only:
    /usr/bin/python3 sort_stl.py IN.stl OUT.stl"""
import struct
import sys

HEADER = b"OpenSCAD Model, triangles sorted by sort_stl.py".ljust(80, b"\0")


def main(src, dst):
    data = open(src, "rb").read()
    if len(data) < 84:
        sys.exit(f"sort_stl: {src}: too short for a binary STL")
    (n,) = struct.unpack_from("<I", data, 80)
    if len(data) != 84 + 50 * n:
        sys.exit(f"sort_stl: {src}: not a binary STL ({len(data)} bytes for {n} triangles)")
    tris = []
    for i in range(n):
        f = [x + 0.0 for x in struct.unpack_from("<12f", data, 84 + 50 * i)]  # -0.0 -> 0.0
        normal, vs = f[0:3], [f[3:6], f[6:9], f[9:12]]
        k = min(range(3), key=lambda j: vs[j])
        tris.append((vs[k], vs[(k + 1) % 3], vs[(k + 2) % 3], normal))
    tris.sort()
    out = [HEADER, struct.pack("<I", n)]
    for a, b, c, normal in tris:
        out.append(struct.pack("<12fH", *normal, *a, *b, *c, 0))
    open(dst, "wb").write(b"".join(out))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: sort_stl.py IN.stl OUT.stl")
    main(sys.argv[1], sys.argv[2])
