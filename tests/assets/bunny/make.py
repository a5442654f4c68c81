#!/usr/bin/env python3
"""Writes bunny.obj beside this script: the low-resolution Stanford bunny Kage embeds
(engine/assets/bunny.obj: positions and triangles, no normals) with vertex normals added and one
of them zeroed, as scanned meshes users bring have (a `vn 0 0 0`).

- `v` lines: copied from engine/assets/bunny.obj unchanged, in the same order.
- `vn` lines: one per vertex, the area-weighted vertex normal (the sum of the unnormalized face
  normals of the triangles using it, normalized), written with 6 decimals; vertex ZERO (1-based,
  as OBJ counts) gets `vn 0 0 0` instead.
- `f` lines: the same triangles as `f a//a b//b c//c` (each vertex with its own normal).

Standard library only: `python3 tests/assets/bunny/make.py`.
"""
import math
import pathlib

ZERO = 1  # the vertex whose normal is written as 0 0 0 (1-based)

here = pathlib.Path(__file__).resolve().parent
source = here.parent.parent.parent / "engine" / "assets" / "bunny.obj"

vertex_lines, positions, faces = [], [], []
for line in source.read_text().splitlines():
    words = line.split()
    if words[:1] == ["v"]:
        vertex_lines.append(line)
        positions.append(tuple(float(w) for w in words[1:4]))
    elif words[:1] == ["f"]:
        faces.append(tuple(int(w.split("/")[0]) - 1 for w in words[1:4]))

sums = [[0.0, 0.0, 0.0] for _ in positions]
for a, b, c in faces:
    pa, pb, pc = positions[a], positions[b], positions[c]
    u = [pb[i] - pa[i] for i in range(3)]
    v = [pc[i] - pa[i] for i in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    for i in (a, b, c):
        for k in range(3):
            sums[i][k] += n[k]

normal_lines = []
for at, s in enumerate(sums):
    length = math.sqrt(sum(x * x for x in s))
    if at + 1 == ZERO:
        normal_lines.append("vn 0 0 0")
    else:
        normal_lines.append("vn %.6f %.6f %.6f" % tuple(x / length for x in s))

out = [
    "# Stanford bunny, low resolution (1839 vertices), public domain (Stanford 3D Scanning Repository,",
    "# via the npm package bunny 1.0.1); area-weighted vertex normals added and vertex %d's zeroed" % ZERO,
    "# by tests/assets/bunny/make.py",
    *vertex_lines,
    *normal_lines,
    *("f %d//%d %d//%d %d//%d" % (a + 1, a + 1, b + 1, b + 1, c + 1, c + 1) for a, b, c in faces),
]
(here / "bunny.obj").write_text("\n".join(out) + "\n")
