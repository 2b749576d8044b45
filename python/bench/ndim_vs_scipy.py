"""hausdorff.directed against scipy's directed_hausdorff on random sets of
more than 3 coordinates, in one run, alternating the two: the median wall
time of each over REPEATS rounds (and the median CPU time of the one-thread
runs, which a loaded machine disturbs less), and a check that both give the
same double.

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
    """(wall seconds, CPU seconds of this process, result)."""
    t, c = time.perf_counter(), time.process_time()
    r = f()
    return time.perf_counter() - t, time.process_time() - c, r


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 10_000
    dims = [int(d) for d in sys.argv[2].split(",")] if len(sys.argv) > 2 else [4, 16, 256]
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    print(f"N = {n} a set, {repeats} rounds, median seconds (wall; CPU for the one-thread runs); "
          f"scipy {__import__('scipy').__version__}")
    print(f"{'points':>8} {'dims':>5} {'scipy':>8} {'1 thread':>9} {'all cores':>10} {'x (1)':>6} "
          f"{'x (all)':>7} {'scipy cpu':>10} {'1 thr cpu':>10} {'x cpu':>6}")
    for kind in ("uniform", "normal"):
        for d in dims:
            seed = 1000 + d
            rng = np.random.default_rng(seed)
            draw = rng.random if kind == "uniform" else rng.standard_normal
            a, b = draw((n, d)), draw((n, d))
            t = {"scipy": [], "one": [], "all": [], "scipy cpu": [], "one cpu": []}
            for _ in range(repeats):
                w, c, rs = timed(lambda: directed_hausdorff(a, b))
                t["scipy"].append(w)
                t["scipy cpu"].append(c)
                w, c, r1 = timed(lambda: hausdorff.directed(a, b, threads=1))
                t["one"].append(w)
                t["one cpu"].append(c)
                w, _, ra = timed(lambda: hausdorff.directed(a, b))
                t["all"].append(w)
                assert rs[0] == r1[0] == ra[0] and tuple(r1) == tuple(ra), (kind, d, seed, rs, r1, ra)
            m = {k: statistics.median(v) for k, v in t.items()}
            print(f"{kind:>8} {d:>5} {m['scipy']:>8.4f} {m['one']:>9.4f} {m['all']:>10.4f} "
                  f"{m['scipy'] / m['one']:>5.1f}x {m['scipy'] / m['all']:>6.1f}x "
                  f"{m['scipy cpu']:>10.4f} {m['one cpu']:>10.4f} {m['scipy cpu'] / m['one cpu']:>5.1f}x"
                  f"  (seed {seed})", flush=True)


if __name__ == "__main__":
    main()
