#!/usr/bin/env python3
"""Casts the rays of `kage bench rays --export DIR` with Embree 4 on one thread: the CPU ray
tracer Kage's ray casting is measured against (benchmark only; not part of CI).

Needs embreex from PyPI (`pip install embreex numpy`). Prints one line per query and ray set:
Mrays/s (median of RUNS timed casts after one warm-up) and how many rays hit, so that the
results can be checked against Kage's. The process is pinned to one CPU: Embree casts each
ray on the calling thread (rtcIntersect1 / rtcOccluded1), and the pin keeps its build threads
off the other core too. The scene is built with Embree's defaults plus the robust flag
(watertight, as Kage's test is).

The last line casts the PRT precomputation's rays of every 16th vertex (`prt.f32`), closest
hits against each ray's own group, as `kage precompute` casts them: its Mrays/s against the
precomputation's.

Usage: python3 scripts/embree-rays.py DIR [RUNS] [--rays-only | --prt-only]
(--rays-only: all lines but the last; --prt-only: the last line alone; for the paired rounds of
scripts/embree-compare.sh)
"""
import os
import sys
import time

import numpy as np
from embreex import mesh_construction, rtcore_scene


def main():
    prt_only = "--prt-only" in sys.argv[1:]
    rays_only = "--rays-only" in sys.argv[1:]
    args = [a for a in sys.argv[1:] if a not in ("--prt-only", "--rays-only")]
    folder = args[0]
    runs = int(args[1]) if len(args) > 1 else 5
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    triangles = np.fromfile(os.path.join(folder, "triangles.f32"), dtype="<f4").reshape(-1, 3, 3)
    build = time.perf_counter()
    scene = rtcore_scene.EmbreeScene()
    mesh_construction.TriangleMesh(scene, triangles)
    # Embree commits the scene (builds its BVH) at the first cast: an untimed warm-up casts one.
    scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32), query="OCCLUDED")
    build_ms = (time.perf_counter() - build) * 1e3
    print(f"embree: {len(triangles)} triangles, scene built in {build_ms:.1f} ms (one CPU)")
    print(f"{'query':<12} {'set':<11} {'ms':>9} {'Mrays/s':>9} {'hits':>9}")
    def median_seconds(cast):
        times = []
        for run in range(runs + 1):
            start = time.perf_counter()
            result = cast()
            if run > 0:
                times.append(time.perf_counter() - start)
        return sorted(times)[len(times) // 2], result

    for query, name in [] if prt_only else [("INTERSECT", "closest hit"), ("OCCLUDED", "any hit")]:
        for ray_set in ["coherent", "incoherent"]:
            rays = np.fromfile(os.path.join(folder, ray_set + ".f32"), dtype="<f4").reshape(-1, 7)
            origins = np.ascontiguousarray(rays[:, 0:3])
            directions = np.ascontiguousarray(rays[:, 3:6])
            tmax = np.ascontiguousarray(rays[:, 6])
            seconds, result = median_seconds(lambda: scene.run(origins, directions, dists=tmax, query=query))
            hits = int(np.count_nonzero(np.asarray(result) != -1))
            print(f"{name:<12} {ray_set:<11} {seconds * 1e3:9.2f} {len(rays) / seconds * 1e-6:9.3f} {hits:9d}")

    if rays_only:
        return
    # The PRT rays: closest hits (the precomputation tells front from back hits), each against
    # its own group's triangles only, one Embree scene per group.
    groups = np.fromfile(os.path.join(folder, "triangle-groups.u32"), dtype="<u4")
    rays = np.fromfile(os.path.join(folder, "prt.f32"), dtype="<f4").reshape(-1, 8)
    ray_groups = rays[:, 7].astype(np.uint32)
    casts = []
    for group in np.unique(ray_groups):
        group_scene = rtcore_scene.EmbreeScene()
        mesh_construction.TriangleMesh(group_scene, np.ascontiguousarray(triangles[groups == group]))
        mine = rays[ray_groups == group]
        casts.append((group_scene, np.ascontiguousarray(mine[:, 0:3]), np.ascontiguousarray(mine[:, 3:6]),
                      np.ascontiguousarray(mine[:, 6])))
    for group_scene, origins, directions, tmax in casts:
        group_scene.run(origins[:1], directions[:1], dists=tmax[:1], query="OCCLUDED")
    seconds, hits = median_seconds(lambda: sum(int(np.count_nonzero(c[0].run(*c[1:3], dists=c[3], query="INTERSECT") != -1))
                                              for c in casts))
    print(f"{'closest hit':<12} {'prt':<11} {seconds * 1e3:9.2f} {len(rays) / seconds * 1e-6:9.3f} {hits:9d}"
          "   (PRT rays of every 16th vertex, each against its own group)")


if __name__ == "__main__":
    main()
