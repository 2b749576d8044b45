#!/usr/bin/python3
"""scipy_hd.py -- SciPy peers for the engine benchmark.

usage: scipy_hd.py METHOD A.bin B.bin THREADS RUNS BUDGET_SECONDS
  METHOD directed_hausdorff: scipy.spatial.distance.directed_hausdorff
         (EARLYBREAK, Taha & Hanbury) both ways, seed 0; single-threaded.
  METHOD ckdtree: scipy.spatial.cKDTree on B, query(A, workers=THREADS),
         max; then the other direction.
The point files are raw little-endian float64 x, y, z triples (bench.c).
Prints {"distance": D, "times": [...]} like the C++ peers (reading the
files is not timed).
"""
import sys

from scipy.spatial import cKDTree
from scipy.spatial.distance import directed_hausdorff


from peercommon import load, time_runs

def main():
    method, pa, pb = sys.argv[1], sys.argv[2], sys.argv[3]
    threads, runs, budget = int(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6])
    a, b = load(pa), load(pb)
    if method == "directed_hausdorff":
        def once():
            return max(directed_hausdorff(a, b, seed=0)[0], directed_hausdorff(b, a, seed=0)[0])
    elif method == "ckdtree":
        def once():
            dab = cKDTree(b).query(a, k=1, workers=threads)[0].max()
            dba = cKDTree(a).query(b, k=1, workers=threads)[0].max()
            return max(float(dab), float(dba))
    else:
        sys.exit("unknown method " + method)
    time_runs(once, runs, budget)

if __name__ == "__main__":
    main()
