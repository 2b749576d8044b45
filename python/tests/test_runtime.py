"""Runtime behaviour: the GIL is released during computations, and repeated
calls leak neither references nor memory."""
import gc
import os
import sys
import threading
import time

import numpy as np
import pytest

import hausdorff
from conftest import gauss


def test_gil_is_released_during_a_long_computation():
    a, b = gauss(121, 12000), gauss(122, 12000, mean=(0.1, 0, 0))
    stamps = []
    stop = threading.Event()

    def spin():
        # Note the time about every millisecond, for as long as it can run.
        last = 0.0
        while not stop.is_set():
            t = time.perf_counter()
            if t - last > 0.001:
                stamps.append(t)
                last = t

    worker = threading.Thread(target=spin)
    worker.start()
    try:
        time.sleep(0.02)
        t0 = time.perf_counter()
        hausdorff.directed(a, b, algorithm="naive", threads=1)
        t1 = time.perf_counter()
    finally:
        stop.set()
        worker.join()
    # A call that kept the GIL would let the other thread run only for a
    # switch interval (5 ms) as it begins and as it returns, never in the
    # middle half of the call.
    span = t1 - t0
    assert span > 0.08, "the computation was too short to tell"
    middle = [t for t in stamps if t0 + span / 4 <= t <= t1 - span / 4]
    assert len(middle) >= 5, f"the other thread ran {len(middle)} times in {span / 2:.3f} s"


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def exercise(a, b, af32, path):
    hausdorff.directed(a, b)
    hausdorff.directed(af32, b[::-1], algorithm="naive", threads=1)
    hausdorff.hausdorff(a, b)
    hausdorff.distances(a, b)
    hausdorff.percentile(a, b, [50, 95])
    index = hausdorff.Index(b)
    index.directed(a, rotation=np.eye(3), translation=[1, 2, 3])
    index.distances(af32)
    hausdorff.read(path)
    hausdorff.directed(u=a[:, :2], v=b[:, :2], seed=np.int64(3))
    hausdorff.summary(a, b)
    hausdorff.mean(a, b, threads=np.int32(2))
    hausdorff.chamfer(a, b)
    e = b[:0]
    hausdorff.hausdorff(a, e, empty="monai")
    hausdorff.percentile(e, b, [50, 95], empty="inf")
    hausdorff.distances(a, e, empty="zero")
    hausdorff.summary(e, e, empty="nan")
    wide_a, wide_b = a[:, [0, 1, 2, 0, 1]], b[:, [2, 1, 0, 2, 1]]   # 5 coordinates: _ndim.c
    hausdorff.directed(wide_a, wide_b, rng=np.random.default_rng(1))
    hausdorff.hausdorff(wide_a, wide_b, algorithm="naive")
    hausdorff.distances(wide_a, wide_b)
    hausdorff.summary(wide_a, wide_b)
    hausdorff.directed(a[:, :1] > 0, b[:, :1] > 0)
    for bad in (np.zeros((0, 3)), np.full((2, 3), np.nan), np.zeros((2, 2)), np.zeros((2, 4)),
                np.full((2, 5), np.inf)):
        with pytest.raises(ValueError):
            hausdorff.directed(bad, b if bad.shape[1] != 5 else wide_b)
    with pytest.raises(ValueError):
        hausdorff.directed(wide_a, wide_b, algorithm="kdtree")
    with pytest.raises(ValueError):
        hausdorff.Index(wide_b)
    with pytest.raises(ValueError):
        hausdorff.read(path, start=-1)
    with pytest.raises(TypeError):
        hausdorff.directed(u=a, a=a, v=b)
    with pytest.raises(OSError):
        hausdorff.read(path + ".missing")


@pytest.mark.skipif(not os.path.exists("/proc/self/statm"), reason="needs /proc")
def test_repeated_calls_leak_neither_references_nor_memory(tmp_path):
    a, b = gauss(123, 300), gauss(124, 200)
    af32 = a.astype(np.float32)
    path = str(tmp_path / "cloud.xyz")
    np.savetxt(path, b)
    refs = [sys.getrefcount(x) for x in (a, b, af32)]
    for _ in range(50):                      # warm up caches and pools
        exercise(a, b, af32, path)
    gc.collect()
    before = rss_bytes()
    for _ in range(2000):
        exercise(a, b, af32, path)
    gc.collect()
    grown = rss_bytes() - before
    assert [sys.getrefcount(x) for x in (a, b, af32)] == refs
    # One leaked per-point array per round would be 2000 * 2.4 KB = 4.8 MB.
    assert grown < 2 * 1024 * 1024, f"RSS grew by {grown} bytes"
