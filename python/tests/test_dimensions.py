"""Points of any number of coordinates: 1 and 2 are lifted to 3-D exactly,
4 and more go to the module's own engine (python/hausdorff/_ndim.c).  Every
answer is the brute force's to the bit (squared differences summed over the
coordinates left to right, one sqrt), witness included (smallest indices),
and scipy's double."""
import math

import numpy as np
import pytest

import hausdorff
from conftest import brute_directed, brute_nearest, distance


def normal(seed, n, dims, scale=1.0):
    return np.random.default_rng(seed).normal(size=(n, dims)) * scale


def grid(seed, n, dims, side=3):
    """Small integers: ties everywhere."""
    return np.random.default_rng(seed).integers(0, side, size=(n, dims)).astype(np.float64)


CASES = {  # name: (A, B), every one with its seeds in the name's data
    "normal 4-D": (normal(501, 300, 4), normal(502, 250, 4)),
    "normal 5-D, shifted": (normal(503, 200, 5) + 0.7, normal(504, 260, 5)),
    "uniform 16-D": (np.random.default_rng(505).random((240, 16)),
                     np.random.default_rng(506).random((200, 16))),
    "normal 33-D (blocks of 8 and a remainder)": (normal(507, 150, 33), normal(508, 170, 33)),
    "normal 256-D": (normal(509, 60, 256), normal(510, 70, 256)),
    "grid 4-D, ties": (grid(511, 300, 4), grid(512, 200, 4)),
    "grid 6-D, ties": (grid(513, 200, 6, 2), grid(514, 150, 6, 2)),
    "1e9 offsets 4-D": (normal(515, 200, 4) + 1e9, normal(516, 200, 4) + 1e9),
    "1e-9 scale 7-D": (normal(517, 200, 7, 1e-9), normal(518, 180, 7, 1e-9)),
    "single points 9-D": (normal(519, 1, 9), normal(520, 1, 9)),
    "one point against many 4-D": (normal(521, 1, 4), normal(522, 500, 4)),
    "B of 9 points (a block and one) 12-D": (normal(523, 100, 12), normal(524, 9, 12)),
    # enough rows of B for the early break to try the central ones first
    "normal 64-D, 300 x 260": (normal(525, 300, 64), normal(526, 260, 64)),
    "grid 40-D, ties, 250 x 200": (grid(527, 250, 40, 2), grid(528, 200, 40, 2)),
    "two clusters 24-D": (normal(529, 200, 24),
                          np.vstack((normal(530, 120, 24) + 3, normal(531, 120, 24) - 3))),
}


@pytest.mark.parametrize("name", sorted(CASES))
@pytest.mark.parametrize("algorithm", ["auto", "earlybreak", "naive"])
def test_more_than_three_coordinates_equal_the_brute_force(name, algorithm):
    a, b = CASES[name]
    want = brute_directed(a, b)
    for threads in (1, 2, 3):
        r = hausdorff.directed(a, b, algorithm=algorithm, threads=threads)
        assert tuple(r) == want, (name, algorithm, threads)
        assert r.algorithm == ("naive" if algorithm == "naive" else "earlybreak")
    assert distance(a[want[1]], b[want[2]]) == want[0]


@pytest.mark.parametrize("seed", [0, 1, 7, 2**64 - 1, 2**200, -3])
def test_the_seed_never_changes_the_answer_in_any_dimension(seed):
    for name in ("grid 4-D, ties", "normal 33-D (blocks of 8 and a remainder)"):
        a, b = CASES[name]
        assert tuple(hausdorff.directed(a, b, seed)) == brute_directed(a, b), (name, seed)


def test_one_coordinate_is_exact_as_a_lift_to_3d():
    a = np.random.default_rng(531).normal(size=(400, 1))
    b = np.random.default_rng(532).normal(size=(300, 1))
    want = brute_directed(a, b)
    for algorithm in hausdorff.algorithms:
        assert tuple(hausdorff.directed(a, b, algorithm=algorithm)) == want, algorithm
    ties = np.arange(10.0)[:, None]
    assert tuple(hausdorff.directed(ties, ties[::3])) == brute_directed(ties, ties[::3])
    index = hausdorff.Index(b)
    assert tuple(index.directed(a)) == want and index.points.shape == (300, 3)


def test_scipy_gives_the_same_double_in_every_dimension():
    spatial = pytest.importorskip("scipy.spatial.distance")
    for dims in (1, 2, 3, 4, 5, 8, 16, 64):
        a, b = normal(540 + dims, 200, dims), normal(640 + dims, 150, dims)
        ours, theirs = hausdorff.directed(a, b), spatial.directed_hausdorff(a, b)
        assert ours[0] == theirs[0], dims
        assert distance(a[theirs[1]], b[theirs[2]]) == ours[0]   # scipy's witness realises it


def test_trajectories_as_mdanalysis_flattens_them():
    """MDAnalysis's hausdorff(P, Q) calls directed_hausdorff on frames
    flattened to 3N coordinates: (frames, atoms, 3) -> (frames, 3 * atoms)."""
    rng = np.random.default_rng(550)
    walk = np.cumsum(rng.normal(size=(40, 25, 3)) * 0.1, axis=0)
    P = walk.reshape(40, -1)
    Q = (walk + rng.normal(size=walk.shape) * 0.05)[::2].reshape(20, -1)
    assert P.shape[1] == 75
    want_pq, want_qp = brute_directed(P, Q), brute_directed(Q, P)
    h = hausdorff.hausdorff(P, Q)
    assert (tuple(h.ab), tuple(h.ba)) == (want_pq, want_qp)
    assert h.distance == max(want_pq[0], want_qp[0])


@pytest.mark.parametrize("dims, make", [(6, normal), (12, normal), (4, grid), (9, grid)])
def test_every_distance_function_takes_more_coordinates(dims, make):
    """Nearest distances: a tree of boxes up to 8 coordinates, a scan above."""
    a, b = make(561, 120, dims), make(562, 90, dims) + 0.3
    d2_ab, j_ab = brute_nearest(a, b)
    d2_ba, _ = brute_nearest(b, a)
    d_ab, d_ba = np.sqrt(d2_ab), np.sqrt(d2_ba)
    for threads in (1, 2, 3):
        dist, nearest = hausdorff.distances(a, b, threads=threads)
        np.testing.assert_array_equal(dist, d_ab)
        np.testing.assert_array_equal(nearest, j_ab)
    p = hausdorff.percentile(a, b, [50, 95])
    assert [r.ab for r in p] == [np.percentile(d_ab, 50), np.percentile(d_ab, 95)]
    assert p[1].pooled == np.percentile(np.hstack((d_ab, d_ba)), 95)
    m = hausdorff.mean(a, b)
    assert abs(m.ab - math.fsum(d_ab) / len(d_ab)) <= 4e-16 * m.ab
    assert abs(m.pooled - math.fsum(np.hstack((d_ab, d_ba))) / 210) <= 4e-16 * m.pooled
    c = hausdorff.chamfer(a, b)
    assert abs(c - (math.fsum(d2_ab) / 120 + math.fsum(d2_ba) / 90)) <= 1e-15 * c
    s = hausdorff.summary(a, b, directed=True)
    assert s.max_ab == d_ab.max() and s.n_ba == 0 and math.isnan(s.max_ba)


def test_boxes_in_more_coordinates():
    a = np.zeros((2, 4))
    a[1] = 1.0
    b = a + [0.5, 0, 0, 0]                   # half the extent along the first axis
    h = hausdorff.hausdorff(a, b)
    assert h.alpha == 0.5 and h.disjoint is False
    far = hausdorff.hausdorff(a, a + [0, 0, 0, 2])
    assert far.alpha == 0.0 and far.disjoint is True


def test_layouts_and_types_in_more_coordinates_are_read_as_doubles():
    a, b = normal(571, 200, 5), normal(572, 150, 5)
    want = brute_directed(a, b)
    for x, y in ((np.asfortranarray(a), b), (a[::-1][::-1], b), (a.astype(">f8"), b)):
        assert tuple(hausdorff.directed(x, y)) == want
    f32a, f32b = a.astype(np.float32), b.astype(np.float32)
    assert tuple(hausdorff.directed(f32a, f32b)) == brute_directed(f32a, f32b)
    ints = (a * 10).astype(np.int64)
    assert tuple(hausdorff.directed(ints, b)) == brute_directed(ints.astype(float), b)
    strided = normal(573, 300, 10)[::3, ::2]
    assert tuple(hausdorff.directed(strided, b)) == brute_directed(strided, b)


def test_more_coordinates_check_values_as_the_library_does():
    a = normal(581, 20, 4)
    a[7, 3] = np.nan
    with pytest.raises(ValueError, match=r"point set A: point 7 has a NaN coordinate"):
        hausdorff.directed(a, normal(582, 5, 4))
    a[7, 3] = -np.inf
    with pytest.raises(ValueError, match=r"point set B: point 7 has an infinite coordinate"):
        hausdorff.hausdorff(normal(582, 5, 4), a)
    # dims * (2 * limit)^2 must stay finite: 1e153 for up to 44 coordinates, less above
    big = np.zeros((3, 256))
    big[2, 100] = 5e152
    with pytest.raises(ValueError, match=r"point 2 has coordinate 5e\+152, beyond the limit .* 256"):
        hausdorff.distances(big, big)
    big[2, 100] = 4e152
    assert hausdorff.directed(big, big[:1]).distance == 4e152
    with pytest.raises(ValueError, match="computes in 3 dimensions"):
        hausdorff.directed(normal(583, 5, 4), normal(584, 5, 4), algorithm="kdtree")
    with pytest.raises(ValueError, match="Index takes points of 1, 2 or 3 coordinates"):
        hausdorff.Index(normal(585, 5, 4))


def test_a_coordinate_just_beyond_the_limit_prints_unlike_the_limit():
    a = np.zeros((2, 4))
    a[1, 2] = np.nextafter(1e153, np.inf)
    with pytest.raises(ValueError, match=r"coordinate 1\.0000000000000002e\+153, beyond the limit 1e\+153 "):
        hausdorff.directed(a, a[:1])


def test_a_line_whose_gaps_grow_is_exact_in_any_visiting_order():
    """Nearest distances increase along the line: an order that met the
    points in that order would scan all of B for each of them."""
    x = np.cumsum(np.arange(1.0, 400.0))
    a = np.zeros((len(x), 5))
    a[:, 0] = x
    b = a[::2] + [0, 0, 0, 0, 0.5]
    want = brute_directed(a, b)
    for seed in range(5):
        assert tuple(hausdorff.directed(a, b, seed, threads=2)) == want
