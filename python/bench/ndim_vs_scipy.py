"""hausdorff.directed against scipy's directed_hausdorff on random sets of
more than 3 coordinates, in one run, alternating the two: the median wall
time of each over REPEATS rounds, and a check that both give the same double.

usage: PYTHONPATH=build/python /usr/bin/python3 python/bench/ndim_vs_scipy.py
           [N] [DIMS,...] [REPEATS]
(defaults: 10000 points a set, dimensions 4,16,256, 5 rounds; uniform
points in the unit cube and standard normal points, seeds printed).
"""
import statistics
import sys
import time

import numpy as np
from scipy.spatial.distance import directed_hausdorff

import hausdorff


def timed(f):
    t = time.perf_counter()
    r = f()
    return time.perf_counter() - t, r


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 10_000
    dims = [int(d) for d in sys.argv[2].split(",")] if len(sys.argv) > 2 else [4, 16, 256]
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    print(f"N = {n} a set, {repeats} rounds, median seconds; scipy {__import__('scipy').__version__}")
    print(f"{'points':>8} {'dims':>5} {'scipy':>9} {'threads=1':>10} {'every core':>11} "
          f"{'ratio 1':>8} {'ratio all':>9}")
    for kind in ("uniform", "normal"):
        for d in dims:
            seed = 1000 + d
            rng = np.random.default_rng(seed)
            draw = rng.random if kind == "uniform" else rng.standard_normal
            a, b = draw((n, d)), draw((n, d))
            t_sp, t_1, t_all = [], [], []
            for _ in range(repeats):
                t, rs = timed(lambda: directed_hausdorff(a, b))
                t_sp.append(t)
                t, r1 = timed(lambda: hausdorff.directed(a, b, threads=1))
                t_1.append(t)
                t, ra = timed(lambda: hausdorff.directed(a, b))
                t_all.append(t)
                assert rs[0] == r1[0] == ra[0] and tuple(r1) == tuple(ra), (kind, d, seed, rs, r1, ra)
            m = [statistics.median(x) for x in (t_sp, t_1, t_all)]
            print(f"{kind:>8} {d:>5} {m[0]:>9.4f} {m[1]:>10.4f} {m[2]:>11.4f} "
                  f"{m[0] / m[1]:>7.1f}x {m[0] / m[2]:>8.1f}x  (seed {seed})", flush=True)


if __name__ == "__main__":
    main()
