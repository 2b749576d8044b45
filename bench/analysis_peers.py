#!/usr/bin/python3
"""Per-point distances from Python: hausdorff.distances against the calls a
Python user would make for the same answer (docs/benchmarks.md, "Analysis").

    /usr/bin/python3 bench/analysis_peers.py [--size 1000000] [--runs 5]
        [--threads 1 2] [--build build]

For each case and thread count it times, median of --runs runs, the nearest
distance and nearest index of every point of A in B (one direction):
  - hausdorff.distances(a, b, threads=t) (builds a structure on both sets);
  - hausdorff.Index(b).distances(a): the index's build and then the query,
    which builds the same per-point structures (docs/analysis.md);
  - scipy.spatial.cKDTree(b).query(a, k=1, workers=t) (tree construction
    included), the usual answer in Python;
  - Open3D's PointCloud.compute_point_cloud_distance (distances only, every
    core: it has no thread setting), when Debian's python3-open3d is there.
It prints the ratio of each peer's time to ours, and whether the peer's
distances are bit-identical to ours ("=") and its indices equal.  The cases
are analysis_bench's, generated with numpy's default_rng and fixed seeds:
overlapping Gaussians, a copy perturbed by noise of 1e-3 sigma in the same
order and shuffled, and Gaussians 20 sigma apart.
"""
import argparse
import pathlib
import statistics
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]


def cases(n):
    rng = np.random.default_rng(42)
    a = rng.standard_normal((n, 3))
    b = rng.standard_normal((n, 3))
    yield "overlapping", a, b
    p = a + 1e-3 * rng.standard_normal((n, 3))
    yield "perturbed 1e-3", a, p
    yield "perturbed 1e-3, shuffled", a, p[rng.permutation(n)]
    yield "disjoint 20 sigma", a, b + np.array([20.0, 0.0, 0.0])


def median_time(f, runs):
    times, out = [], None
    for _ in range(runs):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=int, default=1000000)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--build", default=str(ROOT / "build"))
    args = ap.parse_args()
    sys.path.insert(0, str(pathlib.Path(args.build).resolve() / "python"))
    import hausdorff
    from scipy.spatial import cKDTree
    try:
        import open3d as o3d
    except ImportError:
        o3d = None

    print("| case | threads | hausdorff.distances | Index(b) + .distances(a) | scipy cKDTree | scipy / ours | "
          "scipy same | Open3D (every core) | Open3D / ours | Open3D same |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, a, b in cases(args.size):
        for t in args.threads:
            ours, (d, j) = median_time(lambda: hausdorff.distances(a, b, threads=t), args.runs)
            ix, (di, ji) = median_time(
                lambda: hausdorff.Index(b, threads=t).distances(a, threads=t), args.runs)
            if not (np.array_equal(d, di) and np.array_equal(j, ji)):
                sys.exit("%s: Index.distances differs from distances" % name)
            sp, (ds, js) = median_time(lambda: cKDTree(b).query(a, k=1, workers=t), args.runs)
            same = "=" if np.array_equal(d, ds) and np.array_equal(j, js) else \
                "distances %s, indices %s" % ("=" if np.array_equal(d, ds) else "differ",
                                              "=" if np.array_equal(j, js) else "differ")
            o3 = ("", "", "")
            if o3d is not None:
                pa = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(a))
                pb = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(b))
                to, do = median_time(lambda: np.asarray(pa.compute_point_cloud_distance(pb)), args.runs)
                o3 = ("%.3f s" % to, "%.1f" % (to / ours), "=" if np.array_equal(d, do) else "differs")
            print("| %s | %d | %.3f s | %.3f s | %.3f s | %.1f | %s | %s | %s | %s |"
                  % (name, t, ours, ix, sp, sp / ours, same, *o3), flush=True)


if __name__ == "__main__":
    main()
