"""peercommon.py -- what the Python peers of the engine benchmark share:
reading the raw little-endian float64 point files that bench.c writes, and
the timing loop (at most RUNS runs, no new run once BUDGET seconds are
spent; reading is not timed) that prints {"distance": D, "times": [...]}
like the C++ peers."""
import json
import time

import numpy as np


def load(path):
    return np.fromfile(path, dtype="<f8").reshape(-1, 3)


def time_runs(once, runs, budget):
    times, spent, d = [], 0.0, 0.0
    for r in range(runs):
        if r and spent >= budget:
            break
        t0 = time.perf_counter()
        d = once()
        t = time.perf_counter() - t0
        times.append(t)
        spent += t
    print(json.dumps({"distance": float(d), "times": times}))
