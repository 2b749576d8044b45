#!/usr/bin/python3
"""c2m_open3d.py -- Open3D peer of the cloud-to-mesh benchmark (Debian 12's
python3-open3d 0.16): RaycastingScene.compute_distance (Embree, float32).

usage: c2m_open3d.py CASE.bin THREADS RUNS
CASE.bin is written by c2m_bench (points, the correctly rounded distances,
the mesh).  Prints the median seconds of RUNS (scene build included), the
largest difference from the correctly rounded distances and the number of
points that differ.  Times: wall and processor (all threads).
"""
import sys
import time

import numpy as np
import open3d as o3d


def load(path):
    with open(path, "rb") as f:
        n = int(np.frombuffer(f.read(8), np.uint64)[0])
        pts = np.frombuffer(f.read(24 * n), np.float64).reshape(n, 3)
        exact = np.frombuffer(f.read(8 * n), np.float64)
        nv = int(np.frombuffer(f.read(8), np.uint64)[0])
        verts = np.frombuffer(f.read(24 * nv), np.float64).reshape(nv, 3)
        nt = int(np.frombuffer(f.read(8), np.uint64)[0])
        tris = np.frombuffer(f.read(24 * nt), np.uint64).reshape(nt, 3)
    return pts, exact, verts, tris


def main():
    pts, exact, verts, tris = load(sys.argv[1])
    threads, runs = int(sys.argv[2]), int(sys.argv[3])
    q = o3d.core.Tensor(pts.astype(np.float32))
    v = o3d.core.Tensor(verts.astype(np.float32))
    t = o3d.core.Tensor(tris.astype(np.uint32))
    times, cpu = [], []
    for _ in range(runs):
        t0, c0 = time.perf_counter(), time.process_time()
        scene = o3d.t.geometry.RaycastingScene(nthreads=threads)
        scene.add_triangles(v, t)
        d = scene.compute_distance(q, nthreads=threads).numpy()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    err = np.abs(d.astype(np.float64) - exact)
    print("open3d %d threads: median %.3f s of %d (cpu %.3f s); max error %.3g (relative to the box %.3g), %d of %d points differ"
          % (threads, sorted(times)[len(times) // 2], runs, sorted(cpu)[len(cpu) // 2], err.max(),
             err.max() / np.linalg.norm(verts.max(0) - verts.min(0)), int((err > 0).sum()), len(err)))


main()
