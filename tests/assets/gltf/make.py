#!/usr/bin/env python3
"""Writes two-groups.gltf beside this script: the glTF 2.0 test scene of tests/tests/gltf.rs.

A box (root node "box": translation (0, 0.5, 0), scale 0.5, its cube in a child node moved by
0.2 along X) above a floor (root node "floor", a 6 x 6 quad), a perspective camera, a point and a
spot light (KHR_lights_punctual), and a linear animation of the box: translation and rotation at
0, 1 and 2 s. One buffer, embedded as a data URI. Standard library only: `python3 make.py`.
"""
import base64
import json
import pathlib
import struct

# Cube of side 1 about the origin (no normals: Kage computes them), and the floor quad.
cube_positions = [(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
cube_indices = [0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5]
floor_positions = [(-3, 0, -3), (3, 0, -3), (-3, 0, 3), (3, 0, 3)]
floor_normals = [(0, 1, 0)] * 4
floor_indices = [0, 2, 1, 1, 2, 3]
times = [0.0, 1.0, 2.0]
translations = [(0, 0.5, 0), (1, 0.5, 0), (0, 0.5, 0)]
half = 0.5 ** 0.5
rotations = [(0, 0, 0, 1), (0, half, 0, half), (0, 0, 0, 1)]

blob = bytearray()
views, accessors = [], []


def add(values, fmt, component, kind, target=None, bounds=False):
    """Appends `values` (tuples or scalars) packed with `fmt`; returns the accessor's index."""
    while len(blob) % 4:
        blob.append(0)
    start = len(blob)
    for v in values:
        blob.extend(struct.pack(fmt, *(v if isinstance(v, tuple) else (v,))))
    view = {"buffer": 0, "byteOffset": start, "byteLength": len(blob) - start}
    if target:
        view["target"] = target
    views.append(view)
    accessor = {"bufferView": len(views) - 1, "componentType": component, "count": len(values), "type": kind}
    if bounds:
        accessor["min"] = [min(v[i] for v in values) for i in range(3)]
        accessor["max"] = [max(v[i] for v in values) for i in range(3)]
    accessors.append(accessor)
    return len(accessors) - 1


FLOAT, USHORT = 5126, 5123
cube_p = add(cube_positions, "<3f", FLOAT, "VEC3", 34962, True)
cube_i = add(cube_indices, "<H", USHORT, "SCALAR", 34963)
floor_p = add(floor_positions, "<3f", FLOAT, "VEC3", 34962, True)
floor_n = add(floor_normals, "<3f", FLOAT, "VEC3", 34962)
floor_i = add(floor_indices, "<H", USHORT, "SCALAR", 34963)
times_a = add(times, "<f", FLOAT, "SCALAR")
accessors[times_a]["min"], accessors[times_a]["max"] = [times[0]], [times[-1]]
moves = add(translations, "<3f", FLOAT, "VEC3")
turns = add(rotations, "<4f", FLOAT, "VEC4")

# 90 degrees about X: the spot light's -Z points down; the camera tilted 0.3 rad down.
down = [-half, 0, 0, half]
tilt = [-0.14943813, 0, 0, 0.98877108]
gltf = {
    "asset": {"version": "2.0", "generator": "kage tests/assets/gltf/make.py"},
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [
        # Candela: 683 lm/W times the 5 and 9 W/sr Kage reads.
        {"type": "point", "color": [1, 1, 1], "intensity": 5 * 683},
        {"type": "spot", "color": [1, 0.5, 0.5], "intensity": 9 * 683, "spot": {"outerConeAngle": 0.5}},
    ]}},
    "scene": 0,
    "scenes": [{"nodes": [0, 2, 3, 4, 5]}],
    "nodes": [
        {"name": "box", "translation": [0, 0.5, 0], "scale": [0.5, 0.5, 0.5], "children": [1]},
        {"name": "cube", "mesh": 0, "translation": [0.2, 0, 0]},
        {"name": "floor", "mesh": 1},
        {"name": "camera", "camera": 0, "translation": [0, 2, 5], "rotation": tilt},
        {"name": "lamp", "translation": [0, 3, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "spot", "translation": [2, 3, 0], "rotation": down,
         "extensions": {"KHR_lights_punctual": {"light": 1}}},
    ],
    "meshes": [
        {"name": "cube", "primitives": [{"attributes": {"POSITION": cube_p}, "indices": cube_i, "material": 0}]},
        {"name": "floor", "primitives": [{"attributes": {"POSITION": floor_p, "NORMAL": floor_n},
                                          "indices": floor_i, "material": 1}]},
    ],
    "materials": [
        {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.2, 1]}},
        {"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1]}},
    ],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
    "animations": [{"name": "slide", "channels": [
        {"sampler": 0, "target": {"node": 0, "path": "translation"}},
        {"sampler": 1, "target": {"node": 0, "path": "rotation"}},
    ], "samplers": [
        {"input": times_a, "output": moves, "interpolation": "LINEAR"},
        {"input": times_a, "output": turns, "interpolation": "LINEAR"},
    ]}],
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
    "bufferViews": views,
    "accessors": accessors,
}
out = pathlib.Path(__file__).with_name("two-groups.gltf")
out.write_text(json.dumps(gltf, indent=1) + "\n")
print(f"wrote {out}")
