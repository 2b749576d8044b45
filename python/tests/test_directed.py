"""directed() and hausdorff(): the same doubles and witnesses as a brute force
in numpy, and the same values as scipy's directed_hausdorff."""
import numpy as np
import pytest

import hausdorff
from conftest import brute_directed, brute_nearest, distance, gauss, lattice

CASES = {
    # name: (seed, A, B)
    "overlapping gaussians": lambda: (gauss(1, 700), gauss(2, 500)),
    "disjoint gaussians": lambda: (gauss(3, 400), gauss(4, 600, mean=(9, 0, 0))),
    "partly overlapping": lambda: (gauss(5, 500), gauss(6, 500, mean=(1.5, 0.5, 0))),
    "lattice ties": lambda: (lattice(7, 600, 6), lattice(8, 300, 6)),
    "perturbed copy": lambda: (lambda a: (a, a + gauss(10, len(a), sigma=1e-6)))(gauss(9, 800)),
    "huge offset": lambda: (gauss(11, 300) + 1e9, gauss(12, 300) + 1e9),
    "tiny scale": lambda: (gauss(13, 300) * 1e-9, gauss(14, 300) * 1e-9),
    "single points": lambda: (gauss(15, 1), gauss(16, 1)),
}


@pytest.mark.parametrize("case", sorted(CASES))
@pytest.mark.parametrize("algorithm", hausdorff.algorithms)
def test_directed_equals_brute_force_bit_for_bit(case, algorithm):
    a, b = CASES[case]()
    expected = brute_directed(a, b)
    got = hausdorff.directed(a, b, algorithm=algorithm)
    assert tuple(got) == expected, f"{case}, {algorithm}"


@pytest.mark.parametrize("threads", [1, 2, 3, None])
def test_witness_is_the_same_at_any_thread_count(threads):
    a, b = lattice(21, 3000, 8), lattice(22, 2000, 8)
    assert tuple(hausdorff.directed(a, b, threads=threads)) == brute_directed(a, b)


@pytest.mark.parametrize("seed", [0, 1, 12345, 2**64 - 1])
def test_seed_never_changes_the_answer(seed):
    a, b = lattice(23, 800, 5), gauss(24, 500)
    for algorithm in ("earlybreak", "ohd", "auto"):
        assert tuple(hausdorff.directed(a, b, algorithm=algorithm, seed=seed)) == \
            brute_directed(a, b)


@pytest.mark.parametrize("case", sorted(CASES))
def test_directed_agrees_with_scipy_to_the_last_bit(case):
    spatial = pytest.importorskip("scipy.spatial.distance")
    a, b = CASES[case]()
    d_scipy, i_scipy, j_scipy = spatial.directed_hausdorff(a, b)
    d, i, j = hausdorff.directed(a, b)
    assert d == d_scipy
    # Each witness realises the value: scipy's (which depends on its
    # shuffle) and ours (the canonical one).
    assert distance(a[i_scipy], b[j_scipy]) == d_scipy
    assert distance(a[i], b[j]) == d
    assert np.sqrt(brute_nearest(a[i:i + 1], b)[0][0]) == d


def test_directed_is_a_drop_in_for_scipy_tuple_unpacking():
    a, b = gauss(31, 50), gauss(32, 40)
    r = hausdorff.directed(a, b)
    d, i, j = r
    assert isinstance(r, tuple) and len(r) == 3
    assert (r.distance, r.i, r.j) == (d, i, j)
    assert isinstance(d, float) and isinstance(i, int) and isinstance(j, int)
    assert r.algorithm in hausdorff.algorithms and r.seconds >= 0


def test_hausdorff_gives_both_directions_and_the_larger():
    a, b = gauss(41, 600), gauss(42, 400, mean=(0.5, 0, 0))
    r = hausdorff.hausdorff(a, b)
    d, ab, ba = r
    assert tuple(ab) == brute_directed(a, b)
    assert tuple(ba) == brute_directed(b, a)
    assert d == max(ab.distance, ba.distance)
    assert r.disjoint is False and 0.0 < r.alpha <= 1.0


def test_hausdorff_reports_disjoint_boxes():
    a, b = gauss(43, 100), gauss(44, 100, mean=(50, 0, 0))
    r = hausdorff.hausdorff(a, b)
    assert r.disjoint is True and r.alpha == 0.0
    assert r.distance == max(brute_directed(a, b)[0], brute_directed(b, a)[0])
