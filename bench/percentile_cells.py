#!/usr/bin/env python3
"""percentile_cells.py -- how many points a uniform grid's cell bounds decide
against the band of a percentile (docs/journal/benchmarks.md, "Percentiles
from cell bounds").

For each case written by `percentile_bench N 1 1 95 --write DIR` and each
direction P -> Q: the exact nearest distances (scipy's cKDTree), the band
percentile.c would take from a sample of 4096 (ranks r1 - w .. r2 + w,
w = 6 n sqrt(q (1 - q) / 4096)), and, for a grid of g cubic cells along the
longest axis of both sets' box, the share of P's points whose cell is
decided: [d(c) - h, d(c) + h] (c the cell's centre, h its half diagonal,
which contain every distance of the cell's points) lies below or above the
band.  Figures only: nothing here takes part in an answer.

usage: /usr/bin/python3 bench/percentile_cells.py DIR [g ...]   (default 32 64 256 1024)
"""
import sys

import numpy as np
from scipy.spatial import cKDTree

CASES = ["a_overlapping", "b_disjoint", "c_partial", "d_small_B", "e_shuffled"]


def band(d, p=95.0, m=4096, spread=6.0):
    n = len(d)
    s = np.sort(d)
    r = (n - 1) * p / 100.0
    r1, r2 = int(np.floor(r)), int(np.ceil(r))
    q = (r1 + 0.5) / n
    w = int(spread * n * np.sqrt(q * (1 - q) / m))
    return s[max(r1 - w, 0)], s[min(r2 + w, n - 1)]


def main():
    d = sys.argv[1]
    grids = [int(g) for g in sys.argv[2:]] or [32, 64, 256, 1024]
    print("| case | direction | P95 | band | " + " | ".join("g = %d: points per cell, undecided" % g for g in grids)
          + " |")
    print("|---|---|---|---|" + "---|" * len(grids))
    for c in CASES:
        A = np.fromfile("%s/%s_A.bin" % (d, c)).reshape(-1, 3)
        B = np.fromfile("%s/%s_B.bin" % (d, c)).reshape(-1, 3)
        lo = np.minimum(A.min(0), B.min(0))
        ext = (np.maximum(A.max(0), B.max(0)) - lo).max()
        for P, Q, name in ((A, B, "A->B"), (B, A, "B->A")):
            tq = cKDTree(Q)
            dist, _ = tq.query(P)
            blo, bhi = band(dist)
            row = []
            for g in grids:
                s = ext / g
                cell = np.minimum(np.floor((P - lo) / s).astype(np.int64), g - 1)
                key = (cell[:, 0] * g + cell[:, 1]) * g + cell[:, 2]
                u, inv = np.unique(key, return_inverse=True)
                centre = np.stack([u // (g * g), (u // g) % g, u % g], 1) * s + lo + s / 2
                dc, _ = tq.query(centre)
                h = s * np.sqrt(3) / 2
                decided = (dc + h < blo) | (dc - h > bhi)
                row.append("%.1f, %.3f" % (len(P) / len(u), 1 - decided[inv].mean()))
            print("| %s | %s | %.4g | %.4g .. %.4g | %s |" % (c, name, np.percentile(dist, 95), blo, bhi,
                                                              " | ".join(row)))


if __name__ == "__main__":
    main()
