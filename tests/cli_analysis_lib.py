"""The library's percentile and histogram functions against numpy itself,
called through ctypes on libhausdorff: hd_percentiles must give exactly
np.percentile (default method "linear") and hd_histogram exactly
np.histogram's counts, hd_histogram_edge exactly np.linspace, on seeded
arrays full of ties, edge values and awkward sizes.

usage: cli_analysis_lib.py LIBHAUSDORFF.so [NAME-FILTER]
"""
import ctypes as C
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_analysis_support import main, same, test  # noqa: E402

LIB = None
DP = C.POINTER(C.c_double)


def lib():
    global LIB
    if LIB is None:
        LIB = C.CDLL(sys.argv[1])
        LIB.hd_percentiles.argtypes = [DP, C.c_size_t, DP, C.c_size_t, DP, C.c_void_p]
        LIB.hd_histogram.argtypes = [DP, C.c_size_t, C.c_double, C.c_double, C.c_size_t,
                                     C.POINTER(C.c_uint64), C.c_void_p]
        LIB.hd_histogram_edge.argtypes = [C.c_double, C.c_double, C.c_size_t, C.c_size_t]
        LIB.hd_histogram_edge.restype = C.c_double
    return LIB


def ptr(a):
    return a.ctypes.data_as(DP)


def percentiles(v, ps):
    v = np.ascontiguousarray(v, dtype=np.float64)
    ps = np.ascontiguousarray(ps, dtype=np.float64)
    out = np.empty(len(ps))
    rc = lib().hd_percentiles(ptr(v), len(v), ptr(ps), len(ps), ptr(out), None)
    assert rc == 0, rc
    return out


def arrays():
    r = np.random.default_rng(2024)
    for n in (1, 2, 3, 10, 101, 1000, 4097):
        yield "normal n=%d" % n, r.standard_normal(n)
        yield "ties n=%d" % n, np.sqrt(r.integers(0, 5, n).astype(np.float64))
        yield "huge range n=%d" % n, r.standard_normal(n) * 10.0 ** r.integers(-200, 200, n)
    yield "all equal", np.full(77, 3.25)
    yield "with inf", np.array([1.0, np.inf, 2.0, 3.0, -np.inf])


@test
def hd_percentiles_is_numpy_percentile_to_the_bit(tmp):
    r = np.random.default_rng(7)
    ps = np.concatenate([np.arange(0, 100.25, 0.25), r.uniform(0, 100, 200), [95, 99.9999999, 1e-300]])
    for name, v in arrays():
        got = percentiles(v, ps)
        with np.errstate(invalid="ignore"):
            want = np.percentile(v, ps)
        for p, g, w in zip(ps, got, want):
            same(g, w, "%s p=%r" % (name, p))


@test
def hd_percentiles_refuses_p_outside_0_100_and_nan_values(tmp):
    v = np.array([1.0, 2.0])
    out = np.empty(1)
    for p in (-1e-9, 100.0000001, float("nan")):
        ps = np.array([p])
        assert lib().hd_percentiles(ptr(v), 2, ptr(ps), 1, ptr(out), None) == -1  # HD_EINVAL
    w = np.array([1.0, float("nan")])
    ps = np.array([50.0])
    assert lib().hd_percentiles(ptr(w), 2, ptr(ps), 1, ptr(out), None) == -4  # HD_ENONFINITE


@test
def hd_histogram_counts_and_edges_are_numpys(tmp):
    r = np.random.default_rng(11)
    for trial in range(300):
        n = int(r.integers(0, 2000))
        bins = int(r.integers(1, 60))
        kind = trial % 3
        if kind == 0:  # values on edges: multiples of a step
            v = r.integers(0, 40, n) * 0.1
            lo, hi = 0.0, float(r.integers(1, 40)) * 0.1
        elif kind == 1:
            v = r.standard_normal(n) * 3
            lo, hi = sorted(r.standard_normal(2) * 2)
        else:
            v = np.sqrt(r.integers(0, 50, n).astype(np.float64))
            lo = hi = float(r.integers(0, 7))  # numpy widens by 0.5
        v = np.ascontiguousarray(v, dtype=np.float64)
        counts = np.zeros(bins, dtype=np.uint64)
        rc = lib().hd_histogram(ptr(v), n, lo, hi, bins, counts.ctypes.data_as(C.POINTER(C.c_uint64)), None)
        assert rc == 0
        want, edges = np.histogram(v, bins, range=(lo, hi))
        assert counts.tolist() == want.tolist(), (trial, lo, hi, bins)
        for k in range(bins + 1):
            same(lib().hd_histogram_edge(lo, hi, bins, k), edges[k], "trial %d edge %d" % (trial, k))


if __name__ == "__main__":
    main()
