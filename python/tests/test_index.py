"""Index: built once, queried many times, optionally with a transform; the
answers equal a brute force on the transformed points."""
import threading

import numpy as np
import pytest

import hausdorff
from conftest import brute_directed, brute_nearest, brute_transform, gauss, lattice


def rotation(seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q


def test_index_directed_equals_brute_force():
    b = gauss(71, 1200)
    index = hausdorff.Index(b)
    assert len(index) == 1200
    for seed in range(3):
        a = gauss(72 + seed, 500, mean=(seed * 0.5, 0, 0))
        assert tuple(index.directed(a)) == brute_directed(a, b)


@pytest.mark.parametrize("threads", [1, 3])
def test_index_with_rotation_and_translation_equals_brute_force(threads):
    b, a = gauss(81, 1000), gauss(82, 700)
    R, t = rotation(83), np.array([0.25, -1.5, 3.0])
    index = hausdorff.Index(b)
    moved = brute_transform(R, t, a)
    r = index.directed(a, rotation=R, translation=t, threads=threads)
    assert tuple(r) == brute_directed(moved, b)
    dist, nearest = index.distances(a, rotation=R, translation=t, threads=threads)
    d2, j = brute_nearest(moved, b)
    assert np.array_equal(dist, np.sqrt(d2)) and np.array_equal(nearest, j)


def test_index_translation_alone_and_rotation_alone():
    b, a = lattice(84, 800, 6), lattice(85, 400, 6)
    index = hausdorff.Index(b)
    t = [0.5, 0.0, -0.5]
    assert tuple(index.directed(a, translation=t)) == \
        brute_directed(brute_transform(np.eye(3), t, a), b)
    R = rotation(86)
    assert tuple(index.directed(a, rotation=R)) == \
        brute_directed(brute_transform(R, [0, 0, 0], a), b)


def test_index_keeps_its_own_copy_of_the_points():
    b = gauss(87, 300)
    a = gauss(88, 200)
    expected = brute_directed(a, b)
    index = hausdorff.Index(b)
    b[:] = 1e6                        # the caller reuses its buffer
    assert tuple(index.directed(a)) == expected
    assert not index.points.flags.writeable
    with pytest.raises(ValueError):
        index.points[0, 0] = 1.0


def test_index_points_can_never_be_made_writable():
    """setflags(write=True) succeeded on the index's own array, and writing
    then changed the index's answers; its owner is now read-only."""
    b, a = gauss(89, 100), gauss(90, 50)
    expected = brute_directed(a, b)
    for pts in (b, b[:, :2], b[:, :1], b.astype(np.float32)):
        index = hausdorff.Index(pts)
        for view in (index.points, index.points[::2], index.points.view()):
            with pytest.raises(ValueError, match="WRITEABLE"):
                view.setflags(write=True)
            assert not view.flags.writeable
        with pytest.raises(ValueError):
            np.copyto(index.points, 0.0)
    index = hausdorff.Index(b)
    assert tuple(index.directed(a)) == expected
    assert np.array_equal(index.points, b)


def test_index_float32_points_stay_float32():
    b = gauss(89, 500).astype(np.float32)
    index = hausdorff.Index(b)
    assert index.points.dtype == np.float32 and "float32" in repr(index)
    a = gauss(90, 300)
    assert tuple(index.directed(a)) == brute_directed(a, b)
    assert index.memory > 0


def test_index_queried_from_many_python_threads_at_once():
    b = gauss(91, 3000)
    index = hausdorff.Index(b)
    queries = [gauss(92 + k, 800, mean=(k * 0.1, 0, 0)) for k in range(6)]
    expected = [brute_directed(q, b) for q in queries]
    got = [None] * len(queries)

    def work(k):
        got[k] = tuple(index.directed(queries[k], threads=1))

    workers = [threading.Thread(target=work, args=(k,)) for k in range(len(queries))]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    assert got == expected


@pytest.mark.parametrize("kw, message", [
    ({"rotation": np.eye(2)}, "rotation must have shape"),
    ({"translation": [1, 2]}, "translation must have shape"),
    ({"rotation": np.full((3, 3), np.nan)}, "rotation must be finite"),
    ({"translation": [0, np.inf, 0]}, "translation must be finite"),
])
def test_index_rejects_bad_transforms(kw, message):
    index = hausdorff.Index(gauss(93, 10))
    with pytest.raises(ValueError, match=message):
        index.directed(gauss(94, 10), **kw)
