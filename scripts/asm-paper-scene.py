#!/usr/bin/env python3
"""Writes the meshes of tests/assets/asm-paper/ (the scene shape of the Adaptive Shadow Maps
paper, Fernando et al. 2001: a 20k-triangle bunny, a robot-like articulated figure and a finely
meshed sculpture, about 31k triangles with the room):

- bunny-20k.obj: the scanned Stanford bunny (tests/assets/stanford-bunny/bunny.obj, 69,451
  triangles) reduced to 20,000 by quadric edge collapse (fast-simplification, PyPI);
- robot.obj: a figure of boxes and cylinders posed at its shoulders, elbows, hips and knees;
- sculpture.obj: a (3, 7) torus knot of thin tube on a post, fine detail for the shadow maps.

Not part of the build or CI: the outputs are committed. Needs `pip install numpy
fast-simplification`. Run from anywhere: python3 scripts/asm-paper-scene.py
"""
import math
import os

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
OUT = os.path.join(ROOT, "tests", "assets", "asm-paper")


def read_obj(path):
    vertices, faces = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                vertices.append([float(x) for x in parts[1:4]])
            elif parts[0] == "f":
                faces.append([int(p.split("/")[0]) - 1 for p in parts[1:4]])
    return np.array(vertices, dtype=np.float64), np.array(faces, dtype=np.int64)


def write_obj(path, header, vertices, faces):
    with open(path, "w") as f:
        for line in header:
            f.write(f"# {line}\n")
        for v in vertices:
            f.write("v " + " ".join(f"{x:.5f}".rstrip("0").rstrip(".") for x in v) + "\n")
        for t in faces:
            f.write(f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n")


class Mesh:
    def __init__(self):
        self.vertices, self.faces = [], []

    def add(self, vertices, faces):
        base = len(self.vertices)
        self.vertices += [list(v) for v in vertices]
        self.faces += [[base + i for i in t] for t in faces]


def box(lo, hi):
    """A box's 8 corners and 12 outward-facing triangles (counter-clockwise seen from outside)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return v, [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def cylinder(radius, length, segments):
    """A closed cylinder along +Y from y = 0 to y = length."""
    v = []
    for y in (0.0, length):
        for k in range(segments):
            a = 2 * math.pi * k / segments
            v.append((radius * math.cos(a), y, radius * math.sin(a)))
    v += [(0.0, 0.0, 0.0), (0.0, length, 0.0)]
    bottom, top = 2 * segments, 2 * segments + 1
    f = []
    for k in range(segments):
        n = (k + 1) % segments
        f += [(k, segments + k, segments + n), (k, segments + n, n)]
        f += [(bottom, k, n), (top, segments + n, segments + k)]
    return v, f


def rotate_x(v, angle):
    c, s = math.cos(angle), math.sin(angle)
    return [(x, c * y - s * z, s * y + c * z) for x, y, z in v]


def rotate_z(v, angle):
    c, s = math.cos(angle), math.sin(angle)
    return [(c * x - s * y, s * x + c * y, z) for x, y, z in v]


def move(v, offset):
    return [(x + offset[0], y + offset[1], z + offset[2]) for x, y, z in v]


def limb(mesh, joint, angles, lengths, radius, segments):
    """Two cylinders hanging from `joint`, the first turned by angles[0] (about X, then Z),
    the second by angles[1] further at the end of the first."""
    at = joint
    turn = (0.0, 0.0)
    for (ax, az), length in zip(angles, lengths):
        turn = (turn[0] + ax, turn[1] + az)
        v, f = cylinder(radius, length, segments)
        v = [(x, -y, z) for x, y, z in v]  # hanging down
        f = [(a, c, b) for a, b, c in f]  # the mirror flips the winding back
        v = rotate_z(rotate_x(v, turn[0]), turn[1])
        mesh.add(move(v, at), f)
        end = rotate_z(rotate_x([(0.0, -length, 0.0)], turn[0]), turn[1])[0]
        at = (at[0] + end[0], at[1] + end[1], at[2] + end[2])
        radius *= 0.85
    return at


def robot():
    """A figure about 1.7 tall standing on y = 0: a torso, a head with eyes, arms and legs of
    two cylinders each (one arm raised and bent, one leg stepping forward), boxy hands and feet."""
    m = Mesh()
    m.add(*box((-0.22, 0.85, -0.12), (0.22, 1.35, 0.12)))  # torso
    m.add(*box((-0.08, 1.35, -0.06), (0.08, 1.42, 0.06)))  # neck
    m.add(*box((-0.12, 1.42, -0.11), (0.12, 1.64, 0.11)))  # head
    m.add(*box((-0.07, 1.52, 0.11), (-0.03, 1.56, 0.14)))  # eyes
    m.add(*box((0.03, 1.52, 0.11), (0.07, 1.56, 0.14)))
    m.add(*box((-0.03, 1.64, -0.01), (0.03, 1.74, 0.01)))  # antenna
    m.add(*box((-0.2, 0.75, -0.1), (0.2, 0.85, 0.1)))  # hips
    segments = 64
    # Arms from the shoulders: the right raised forward and bent, the left hanging out a little.
    for side, angles in ((1, ((-1.9, 0.3), (-0.9, 0.0))), (-1, ((0.2, -0.25), (0.5, 0.0)))):
        hand = limb(m, (side * 0.27, 1.3, 0.0), angles, (0.3, 0.28), 0.05, segments)
        m.add(*box((hand[0] - 0.04, hand[1] - 0.04, hand[2] - 0.04), (hand[0] + 0.04, hand[1] + 0.04, hand[2] + 0.04)))
    # Legs from the hips: the right stepping forward with its knee bent, the left straight.
    for side, angles in ((1, ((0.35, 0.0), (-0.35, 0.0))), (-1, ((0.0, 0.0), (0.0, 0.0)))):
        ankle = limb(m, (side * 0.11, 0.78, 0.0), angles, (0.38, 0.36), 0.07, segments)
        m.add(*box((ankle[0] - 0.06, 0.0, ankle[2] - 0.06), (ankle[0] + 0.06, 0.05, ankle[2] + 0.14)))
    return m


def sculpture():
    """A (3, 7) torus knot of a 1.5 cm tube, 0.7 across, centred 1.15 up, on a post 0.95 tall and
    a base: 300 rings of 14."""
    m = Mesh()
    p_turns, q_turns, rings, around, tube = 3, 7, 300, 14, 0.015

    def knot(t):
        r = 0.25 + 0.1 * math.cos(q_turns * t)
        return np.array([r * math.cos(p_turns * t), 0.1 * math.sin(q_turns * t), r * math.sin(p_turns * t)])

    v = []
    for i in range(rings):
        t = 2 * math.pi * i / rings
        c = knot(t)
        tangent = knot(t + 1e-3) - knot(t - 1e-3)
        tangent /= np.linalg.norm(tangent)
        normal = np.cross(tangent, [0.0, 1.0, 0.0])
        normal /= np.linalg.norm(normal)
        binormal = np.cross(tangent, normal)
        for k in range(around):
            a = 2 * math.pi * k / around
            p = c + tube * (math.cos(a) * normal + math.sin(a) * binormal)
            v.append((p[0], p[1] + 1.15, p[2]))
    f = []
    for i in range(rings):
        j = (i + 1) % rings
        for k in range(around):
            n = (k + 1) % around
            a, b, c, d = i * around + k, i * around + n, j * around + n, j * around + k
            f += [(a, b, c), (a, c, d)]
    m.add(v, f)
    post_v, post_f = cylinder(0.02, 0.95, 16)
    m.add(post_v, post_f)
    m.add(*box((-0.15, 0.0, -0.15), (0.15, 0.04, 0.15)))  # base
    return m


def main():
    import fast_simplification

    os.makedirs(OUT, exist_ok=True)
    points, faces = read_obj(os.path.join(ROOT, "tests", "assets", "stanford-bunny", "bunny.obj"))
    target = 20000
    reduced_points, reduced_faces = fast_simplification.simplify(points, faces, 1.0 - target / len(faces))
    write_obj(os.path.join(OUT, "bunny-20k.obj"),
              ["The Stanford bunny (Stanford Computer Graphics Laboratory; tests/assets/stanford-bunny)",
               f"reduced from {len(faces)} to {len(reduced_faces)} triangles by scripts/asm-paper-scene.py"],
              reduced_points, reduced_faces)
    for name, mesh, what in (("robot", robot(), "a posed figure of boxes and cylinders"),
                             ("sculpture", sculpture(), "a (3, 7) torus knot of thin tube on a post")):
        write_obj(os.path.join(OUT, f"{name}.obj"), [f"{what}; written by scripts/asm-paper-scene.py"],
                  mesh.vertices, mesh.faces)
    for name in ("bunny-20k", "robot", "sculpture"):
        with open(os.path.join(OUT, f"{name}.obj")) as f:
            print(name, sum(1 for line in f if line.startswith("f ")), "triangles")


if __name__ == "__main__":
    main()
