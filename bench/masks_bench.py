"""Time hausdorff.masks.metrics (HD95 and NSD of two masks) against the same
figures computed as MONAI does them, with scipy's Euclidean distance
transform (tests/metrics_support.surface_distances).  Two ellipsoids in
256 x 256 x 160 voxels, spacing (0.8, 0.8, 1.5); medians of 5 (scipy: 3).

    PYTHONPATH=build/python /usr/bin/python3 bench/masks_bench.py
"""
import os
import sys
import time

import numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from hausdorff import masks
from metrics_support import surface_distances
shape = (256, 256, 160)
x, y, z = np.ogrid[:shape[0], :shape[1], :shape[2]]
gt = ((x - 128) ** 2 / 80 ** 2 + (y - 120) ** 2 / 70 ** 2 + (z - 80) ** 2 / 50 ** 2) <= 1
pred = ((x - 131) ** 2 / 78 ** 2 + (y - 121) ** 2 / 72 ** 2 + (z - 79) ** 2 / 49 ** 2) <= 1
sp = (0.8, 0.8, 1.5)
def med(f, k=5):
    t = []
    for _ in range(k):
        t0 = time.perf_counter(); v = f(); t.append(time.perf_counter() - t0)
    return sorted(t)[k // 2], v
for th in (1, 2):
    t, m = med(lambda: masks.metrics(pred, gt, sp, percentile=95, tau=[1, 2], threads=th))
    print("masks.metrics threads=%d: %.3f s, points %s" % (th, t, m.points))
def ref():
    dp, dg = surface_distances(pred, gt, sp)
    return max(np.percentile(dp, 95), np.percentile(dg, 95)), ((dp <= 1).sum() + (dg <= 1).sum()) / (len(dp) + len(dg))
t, v = med(ref, 3)
print("scipy EDT (MONAI's algorithm): %.3f s" % t, v, (m.percentile[0], m.nsd[0]))
t, _ = med(lambda: masks.surface(gt, sp))
print("masks.surface: %.3f s" % t)
