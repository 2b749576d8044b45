"""hausdorff.surface_hausdorff, surface_within and face_maxima: the distance
between surfaces as an enclosure, checked against dense samples of A whose
distances come from Mesh.distances (exact on exactly representable samples)."""
import doctest
import math

import numpy as np
import pytest

import hausdorff

QUAD = np.array([[0, 0, 0], [4, 0, 0], [4, 4, 4], [0, 4, 0]], dtype=float)
DIAG_A = np.array([[0, 1, 2], [0, 2, 3]])
DIAG_B = np.array([[0, 1, 3], [1, 2, 3]])


def dense_max(a, b, n=32):
    """The largest distance from a grid of n steps on every face of a to b."""
    pts = []
    for f in a.faces:
        va, vb, vc = (a.vertices[k] for k in f)
        for i in range(n + 1):
            for j in range(n + 1 - i):
                pts.append(((n - i - j) * va + i * vb + j * vc) / n)
    return b.distances(np.array(pts)).distance


def test_two_triangulations_of_a_bent_quad_enclose_the_dense_maximum():
    a, b = hausdorff.Mesh(QUAD, DIAG_A), hausdorff.Mesh(QUAD, DIAG_B)
    r = hausdorff.surface_hausdorff(a, b)
    far = max(dense_max(a, b), dense_max(b, a))
    assert r.lower <= r.upper and far <= r.upper
    assert r.upper - r.lower <= r.ab.tolerance
    assert far <= r.lower + r.ab.tolerance
    assert r.lower > 1.15  # a vertex-only distance would be 0
    w = r.ab.witness
    assert 0 <= w.face_a < 2 and w.face_b in (0, 1) and w.index_b == -1
    assert w.distance == b.distances(np.array([w.point_a])).distance


def test_directed_gives_one_side_and_threads_do_not_change_it():
    a, b = hausdorff.Mesh(QUAD, DIAG_A), hausdorff.Mesh(QUAD, DIAG_B)
    one = hausdorff.surface_hausdorff(a, b, directed=True, threads=1)
    three = hausdorff.surface_hausdorff(a, b, directed=True, threads=3)
    assert one.ba is None and one.lower == one.ab.lower
    assert one == three._replace(ab=three.ab._replace(seconds=one.ab.seconds))


def test_tolerance_absolute_and_zero():
    v = np.array([[0, 0, 0], [8, 0, 0], [0, 8, 0], [0, 0, 3], [8, 0, 3], [0, 8, 3]], dtype=float)
    a, b = hausdorff.Mesh(v, [[0, 1, 2]]), hausdorff.Mesh(v, [[3, 4, 5]])
    r = hausdorff.surface_hausdorff(a, b, tolerance=0.5, relative=False, directed=True)
    assert r.ab.tolerance == 0.5 and r.lower <= 3 <= r.upper
    r = hausdorff.surface_hausdorff(a, b, tolerance=0, directed=True)
    assert r.lower == 3.0 and r.upper - 3.0 < 1e-12


def test_surface_to_points_finds_the_circumradius():
    v = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0]], dtype=float)
    r = hausdorff.surface_hausdorff(hausdorff.Mesh(v, [[0, 1, 2]]), v, tolerance=1e-12)
    assert r.ab.lower <= math.sqrt(8) <= r.ab.upper
    assert r.ba.lower == r.ba.upper == 0.0 and r.ab.witness.index_b in (0, 1, 2)


def test_within_agrees_with_the_enclosure():
    a, b = hausdorff.Mesh(QUAD, DIAG_A), hausdorff.Mesh(QUAD, DIAG_B)
    r = hausdorff.surface_hausdorff(a, b)
    assert hausdorff.surface_within(a, b, r.upper * 1.001) is True
    assert hausdorff.surface_within(a, b, r.lower * 0.999) is False


def test_face_maxima_enclose_each_face():
    a, b = hausdorff.Mesh(QUAD, DIAG_A), hausdorff.Mesh(QUAD, DIAG_B)
    lo, hi, ab = hausdorff.face_maxima(a, b)
    assert lo.shape == hi.shape == (2,)
    for k in range(2):
        far = dense_max(hausdorff.Mesh(QUAD, DIAG_A[k:k + 1]), b)
        assert lo[k] <= hi[k] and far <= hi[k] and hi[k] - lo[k] <= ab.tolerance


def test_bad_input_is_refused():
    a = hausdorff.Mesh(QUAD, DIAG_A)
    with pytest.raises(TypeError):
        hausdorff.surface_hausdorff(QUAD, a)
    with pytest.raises(ValueError):
        hausdorff.surface_hausdorff(a, hausdorff.Mesh(QUAD, [[0, 1, 7]]))
    with pytest.raises(ValueError):
        hausdorff.surface_hausdorff(a, a, tolerance=-1)


def test_docstring_examples_run():
    failed, attempted = doctest.testmod(hausdorff._surface, optionflags=doctest.ELLIPSIS)
    assert attempted > 0 and failed == 0
