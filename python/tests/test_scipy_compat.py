"""directed() as a drop-in for scipy.spatial.distance.directed_hausdorff: the
same call forms (seed positional or keyword, scipy's u= and v= names, scipy
1.15's rng= and numpy generators as seeds), the same tuple, (N, 2) points,
and integers of any kind (numpy's included) wherever an int is taken.
Points of other dimensions: test_dimensions.py."""
import numpy as np
import pytest

import hausdorff
from conftest import brute_directed, gauss, lattice


def flat(seed, n, scale=1.0):
    return np.random.default_rng(seed).normal(size=(n, 2)) * scale


def lift(p):
    """(x, y) -> (x, y, 0)."""
    p = np.asarray(p, dtype=np.float64)
    return np.column_stack([p, np.zeros(len(p))])


def test_every_call_form_of_scipy_is_accepted():
    a, b = gauss(201, 60), gauss(202, 50)
    expected = brute_directed(a, b)
    calls = [
        lambda: hausdorff.directed(a, b),
        lambda: hausdorff.directed(a, b, 0),
        lambda: hausdorff.directed(a, b, 12345),
        lambda: hausdorff.directed(a, b, None),
        lambda: hausdorff.directed(a, b, seed=7),
        lambda: hausdorff.directed(a, b, seed=None),
        lambda: hausdorff.directed(u=a, v=b),
        lambda: hausdorff.directed(u=a, v=b, seed=3),
        lambda: hausdorff.directed(a, v=b),
        lambda: hausdorff.directed(a=a, b=b),
    ]
    for call in calls:
        r = call()
        assert tuple(r) == expected


def test_scipy_names_and_ours_cannot_both_be_given():
    a, b = gauss(203, 5), gauss(204, 5)
    with pytest.raises(TypeError, match="'u'"):
        hausdorff.directed(u=a, a=a, v=b)
    with pytest.raises(TypeError):
        hausdorff.directed(a, b, 0, seed=0)        # seed twice
    with pytest.raises(TypeError):
        hausdorff.directed(a, b, 0, "naive")       # the rest is keyword-only


def test_result_is_a_tuple_like_scipys():
    spatial = pytest.importorskip("scipy.spatial.distance")
    a, b = gauss(205, 80), gauss(206, 70)
    ours, theirs = hausdorff.directed(a, b), spatial.directed_hausdorff(a, b)
    assert isinstance(ours, tuple) and len(ours) == len(theirs) == 3
    assert [type(x) for x in ours] == [type(x) for x in theirs] == [float, int, int]
    assert ours == theirs                      # unique witness here: equal tuples
    assert ours[1:] == theirs[1:] and ours[0] == theirs[0]
    d, i, j = ours
    assert (ours.distance, ours.i, ours.j) == (d, i, j)


@pytest.mark.parametrize("dtype", [np.float64, np.float32, np.int64])
@pytest.mark.parametrize("algorithm", hausdorff.algorithms)
def test_two_dimensional_points_are_points_of_the_plane_z_0(dtype, algorithm):
    a, b = (flat(207, 400, 10) ).astype(dtype), (flat(208, 300, 10) + 1).astype(dtype)
    got = hausdorff.directed(a, b, algorithm=algorithm)
    assert tuple(got) == brute_directed(lift(a), lift(b))


def test_two_dimensional_lattice_ties_give_the_canonical_witness():
    a, b = lattice(209, 500, 7)[:, :2], lattice(210, 300, 7)[:, :2]
    assert tuple(hausdorff.directed(a, b)) == brute_directed(lift(a), lift(b))


@pytest.mark.parametrize("case", ["gauss", "far", "tiny", "lattice", "layouts"])
def test_two_dimensional_distance_is_scipys_double(case):
    spatial = pytest.importorskip("scipy.spatial.distance")
    a, b = {
        "gauss": lambda: (flat(211, 700), flat(212, 500)),
        "far": lambda: (flat(213, 300) + 1e9, flat(214, 300) + 1e9),
        "tiny": lambda: (flat(215, 300) * 1e-9, flat(216, 300) * 1e-9),
        "lattice": lambda: (lattice(217, 400, 6)[:, :2], lattice(218, 400, 6)[:, :2]),
        "layouts": lambda: (np.asfortranarray(flat(219, 300)), flat(220, 600)[::-2]),
    }[case]()
    d_scipy, i_scipy, j_scipy = spatial.directed_hausdorff(a, b)
    d, i, j = hausdorff.directed(a, b)
    assert d == d_scipy
    assert np.hypot(*(a[i] - b[j])) == d or np.sqrt(((a[i] - b[j]) ** 2).sum()) == d


def test_two_dimensional_points_work_in_every_function():
    a, b = flat(221, 200), flat(222, 150)
    A, B = lift(a), lift(b)
    assert tuple(hausdorff.hausdorff(a, b).ab) == tuple(hausdorff.hausdorff(A, B).ab)
    for x, y in zip(hausdorff.distances(a, b), hausdorff.distances(A, B)):
        np.testing.assert_array_equal(x, y)
    assert hausdorff.percentile(a, b, 95) == hausdorff.percentile(A, B, 95)
    index = hausdorff.Index(b)
    assert tuple(index.directed(a)) == brute_directed(A, B)
    np.testing.assert_array_equal(index.distances(a)[0], hausdorff.distances(A, B)[0])
    with pytest.raises(ValueError, match="same number of columns"):
        index.directed(A)


@pytest.mark.parametrize("shape", [(3,), (2, 3, 1), (10, 0)])
def test_arrays_that_are_not_rows_of_points_are_refused_clearly(shape):
    with pytest.raises(ValueError, match=r"a must be an \(N, D\) array of N points of D >= 1 "
                                         r"coordinates, got shape"):
        hausdorff.directed(np.zeros(shape), np.zeros(shape))


# scipy's test_subsets case (gh-11332): its witness depends on the seed,
# ours is the canonical one, the smallest i and then the smallest j.
SUBSET_A, SUBSET_B, SUBSET_CANONICAL = [(-5, 3), (0, 0)], [(0, 1), (0, 0), (-5, 3)], (0.0, 0, 2)

SEEDS = {  # every seed scipy 1.15+ documents for seed= and rng=, and integers of any size
    "None": lambda: None, "0": lambda: 0, "np.int64(0)": lambda: np.int64(0),
    "77098": lambda: 77098, "2**64 + 5": lambda: 2**64 + 5, "2**300": lambda: 2**300,
    "-1": lambda: -1, "Generator": lambda: np.random.default_rng(77098),
    "RandomState": lambda: np.random.RandomState(3), "BitGenerator": lambda: np.random.PCG64(5),
    "SeedSequence": lambda: np.random.SeedSequence(9),
}


@pytest.mark.parametrize("seed", sorted(SEEDS))
def test_scipy_115_seed_and_rng_forms_are_accepted(seed):
    """scipy 1.15 renamed seed to rng (directed_hausdorff(u, v, rng=0)),
    keeping seed= by keyword; both take an int, a Generator, a RandomState
    or None.  The seed never changes our answer."""
    A, B = SUBSET_A, SUBSET_B
    calls = [
        lambda s: hausdorff.directed(u=A, v=B, seed=s),
        lambda s: hausdorff.directed(u=A, v=B, rng=s),
        lambda s: hausdorff.directed(A, B, s),
        lambda s: hausdorff.directed(A, B, rng=s),
        lambda s: hausdorff.hausdorff(A, B, rng=s).ab,
        lambda s: hausdorff.hausdorff(A, B, seed=s).ab,
    ]
    for call in calls:
        assert tuple(call(SEEDS[seed]())) == SUBSET_CANONICAL
    a, b = gauss(231, 300), gauss(232, 200)
    expected = brute_directed(a, b)
    for algorithm in ("earlybreak", "ohd", "auto"):
        assert tuple(hausdorff.directed(a, b, rng=SEEDS[seed](), algorithm=algorithm)) == expected


def test_a_generator_given_as_seed_is_left_untouched():
    """Nothing is drawn from it (scipy's shuffle would advance it), and
    numpy's global state is untouched too."""
    a, b = gauss(233, 50), gauss(234, 40)
    g, rs = np.random.default_rng(5), np.random.RandomState(6)
    before = (g.bit_generator.state, rs.get_state()[1].copy(), np.random.get_state()[1].copy())
    hausdorff.directed(a, b, rng=g)
    hausdorff.directed(a, b, rs)
    hausdorff.hausdorff(a, b, seed=g)
    assert g.bit_generator.state == before[0]
    assert (rs.get_state()[1] == before[1]).all() and (np.random.get_state()[1] == before[2]).all()


def test_seed_and_rng_cannot_both_be_given():
    a, b = gauss(235, 5), gauss(236, 5)
    with pytest.raises(TypeError, match="'seed' and 'rng'"):
        hausdorff.directed(a, b, seed=1, rng=1)
    with pytest.raises(TypeError, match="'seed' and 'rng'"):
        hausdorff.hausdorff(a, b, seed=1, rng=2)
    with pytest.raises(TypeError):
        hausdorff.directed(a, b, 1, rng=1)         # positional seed and rng=


def test_different_numbers_of_columns_are_refused_as_scipy_does():
    with pytest.raises(ValueError, match="need to have the same number of columns"):
        hausdorff.directed(np.zeros((3, 2)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="need to have the same number of columns"):
        hausdorff.hausdorff(np.zeros((3, 3)), np.zeros((3, 5)))


class Indexable:
    """Any object with __index__ is an integer."""
    def __init__(self, v):
        self.v = v

    def __index__(self):
        return self.v


@pytest.mark.parametrize("make", [np.int64, np.uint64, np.int32, np.uint8, Indexable])
def test_numpy_integers_and_index_objects_are_integers(make):
    a, b = gauss(223, 300), gauss(224, 200)
    expected = brute_directed(a, b)
    assert tuple(hausdorff.directed(a, b, make(2))) == expected
    assert tuple(hausdorff.directed(a, b, seed=make(5), threads=make(2))) == expected
    assert tuple(hausdorff.hausdorff(a, b, threads=make(1), seed=make(1)).ab) == expected
    assert hausdorff.distances(a, b, threads=make(3))[0].max() == expected[0]
    assert hausdorff.percentile(a, b, 100, threads=make(1)).ab == expected[0]
    index = hausdorff.Index(b, threads=make(2))
    assert tuple(index.directed(a, threads=make(1))) == expected
    assert index.distances(a, threads=make(2))[0].max() == expected[0]


def test_non_integers_are_still_refused():
    a, b = gauss(225, 5), gauss(226, 5)
    for bad in (1.5, np.float64(2.0), "3", [1]):
        with pytest.raises(TypeError, match="threads"):
            hausdorff.directed(a, b, threads=bad)
        with pytest.raises(TypeError, match="seed must be None, an integer or a numpy random generator"):
            hausdorff.directed(a, b, seed=bad)
        with pytest.raises(TypeError, match="seed"):
            hausdorff.directed(a, b, rng=bad)
    with pytest.raises(ValueError, match="threads"):
        hausdorff.directed(a, b, threads=np.int8(-2))
