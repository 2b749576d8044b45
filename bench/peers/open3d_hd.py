#!/usr/bin/python3
"""open3d_hd.py -- Open3D peer for the engine benchmark (Debian 12's
python3-open3d 0.16): PointCloud.compute_point_cloud_distance both ways
(a KD-tree nearest-neighbour loop, FLANN/nanoflann inside), max.

usage: open3d_hd.py A.bin B.bin THREADS RUNS BUDGET_SECONDS
Open3D picks its own thread count (OpenMP); THREADS is passed to it through
OMP_NUM_THREADS by bench.c.  Prints {"distance": D, "times": [...]}.
"""
import sys

import numpy as np
import open3d as o3d


from peercommon import load, time_runs

def main():
    pa, pb = sys.argv[1], sys.argv[2]
    runs, budget = int(sys.argv[4]), float(sys.argv[5])
    a, b = load(pa), load(pb)

    def once():
        ca = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(a))
        cb = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(b))
        dab = np.asarray(ca.compute_point_cloud_distance(cb)).max()
        dba = np.asarray(cb.compute_point_cloud_distance(ca)).max()
        return max(float(dab), float(dba))

    time_runs(once, runs, budget)

if __name__ == "__main__":
    main()
