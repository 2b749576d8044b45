"""distances() and percentile(): per-point distances equal to the brute force,
percentiles equal to numpy.percentile on them."""
import numpy as np
import pytest

import hausdorff
from conftest import brute_nearest, gauss, lattice


@pytest.mark.parametrize("threads", [1, 3])
def test_distances_equal_brute_force_with_smallest_nearest_index(threads):
    a, b = lattice(51, 2000, 7), lattice(52, 1500, 7)   # many ties
    dist, nearest = hausdorff.distances(a, b, threads=threads)
    d2, j = brute_nearest(a, b)
    assert dist.dtype == np.float64 and nearest.dtype == np.intp
    assert np.array_equal(dist, np.sqrt(d2))
    assert np.array_equal(nearest, j)


def test_distances_max_is_the_directed_distance():
    a, b = gauss(53, 1000), gauss(54, 800, mean=(0.3, 0, 0))
    dist, nearest = hausdorff.distances(a, b)
    d, i, j = hausdorff.directed(a, b)
    assert dist.max() == d and dist[i] == d and nearest[i] == j


@pytest.mark.parametrize("p", [0, 12.5, 50, 90, 95, 99, 100])
def test_percentile_matches_numpy_on_brute_force_distances(p):
    a, b = gauss(55, 900), gauss(56, 700, mean=(0.4, 0.1, 0))
    d_ab = np.sqrt(brute_nearest(a, b)[0])
    d_ba = np.sqrt(brute_nearest(b, a)[0])
    r = hausdorff.percentile(a, b, p)
    assert r.p == p
    assert r.ab == np.percentile(d_ab, p)
    assert r.ba == np.percentile(d_ba, p)
    assert r.symmetric == max(r.ab, r.ba)
    assert r.pooled == np.percentile(np.concatenate([d_ab, d_ba]), p)


def test_percentile_100_is_the_hausdorff_distance():
    a, b = lattice(57, 500, 5), gauss(58, 300, sigma=2)
    r = hausdorff.percentile(a, b, 100)
    h = hausdorff.hausdorff(a, b)
    assert (r.ab, r.ba, r.symmetric) == (h.ab.distance, h.ba.distance, h.distance)


def test_percentile_of_a_sequence_gives_one_result_per_p():
    a, b = gauss(59, 400), gauss(60, 300)
    ps = [5, 50, 95]
    many = hausdorff.percentile(a, b, np.array(ps))
    assert isinstance(many, list) and [r.p for r in many] == ps
    assert many == [hausdorff.percentile(a, b, p) for p in ps]


@pytest.mark.parametrize("p", [-1, 100.5, float("nan")])
def test_percentile_outside_0_100_is_a_value_error(p):
    with pytest.raises(ValueError, match="percentile"):
        hausdorff.percentile(gauss(61, 10), gauss(62, 10), p)
