"""empty=: what the distance functions give for an empty set, as the command
line's --empty (error, inf, nan, zero) plus MONAI's rule (inf when one set is
empty, NaN when both are) and scikit-image's (inf when one set is empty, 0
when both are)."""
import math

import numpy as np
import pytest

import hausdorff
from conftest import gauss

E = np.zeros((0, 3))
P = gauss(301, 20)

# (a, b, which) for one set empty, the other, both; `[]` is an empty set too.
SETS = [(E, P, "a"), (P, E, "b"), (E, E, "both"), ([], P, "a"), (P, [], "b"),
        (np.zeros((0, 2)), P[:, :2], "a"), (np.zeros((0, 5)), np.ones((3, 5)), "a"),
        (np.zeros((0, 1)), np.zeros((0, 1)), "both")]

POLICY = {"inf": lambda both: math.inf, "nan": lambda both: math.nan,
          "zero": lambda both: 0.0, "monai": lambda both: math.nan if both else math.inf,
          "skimage": lambda both: 0.0 if both else math.inf}


def same(x, y):
    return (math.isnan(x) and math.isnan(y)) or x == y


def figures(name, a, b, empty):
    """Every distance figure the function returns for (a, b)."""
    if name == "directed":
        r = hausdorff.directed(a, b, empty=empty)
        assert r.i is None and r.j is None and r.algorithm is None
        return [r.distance]
    if name == "hausdorff":
        r = hausdorff.hausdorff(a, b, empty=empty)
        assert r.ab.i is None and r.ba.j is None and r.disjoint is None
        return [r.distance, r.ab.distance, r.ba.distance]
    if name == "percentile":
        rs = hausdorff.percentile(a, b, [50, 95], empty=empty)
        assert [r.p for r in rs] == [50.0, 95.0]
        return [x for r in rs for x in (r.ab, r.ba, r.symmetric, r.pooled)]
    if name == "summary":
        s = hausdorff.summary(a, b, empty=empty)
        assert (s.n_ab, s.n_ba) == (len(a), len(b))
        return list(s[2:])
    if name == "mean":
        return list(hausdorff.mean(a, b, empty=empty))
    if name == "chamfer":
        return [hausdorff.chamfer(a, b, empty=empty)]
    raise AssertionError(name)


FUNCTIONS = ["directed", "hausdorff", "percentile", "summary", "mean", "chamfer"]


@pytest.mark.parametrize("name", FUNCTIONS)
@pytest.mark.parametrize("policy", sorted(POLICY))
@pytest.mark.parametrize("k", range(len(SETS)))
def test_every_figure_is_the_policys_value(name, policy, k):
    a, b, which = SETS[k]
    want = POLICY[policy](which == "both")
    got = figures(name, a, b, policy)
    assert got and all(same(x, want) for x in got), (got, want)


@pytest.mark.parametrize("name", FUNCTIONS + ["distances"])
@pytest.mark.parametrize("k", range(len(SETS)))
def test_the_default_is_an_error_that_names_the_set_and_the_option(name, k):
    a, b, which = SETS[k]
    args = (a, b, 95) if name == "percentile" else (a, b)
    with pytest.raises(ValueError, match=r"(a|b) is empty.*empty='inf'"):
        getattr(hausdorff, name)(*args)
    with pytest.raises(ValueError, match="is empty"):
        getattr(hausdorff, name)(*args, empty="error")


def test_distances_of_an_empty_b_are_the_policys_value_and_nearest_minus_1():
    for policy in POLICY:
        d, j = hausdorff.distances(P, E, empty=policy)
        assert len(d) == len(P) and all(same(x, POLICY[policy](False)) for x in d)
        assert (j == -1).all() and j.dtype == np.intp
        d, j = hausdorff.distances(E, P, empty=policy)
        assert d.shape == j.shape == (0,)


def test_a_nonempty_call_ignores_the_policy():
    a, b = gauss(302, 50), gauss(303, 40)
    for policy in POLICY:
        assert hausdorff.directed(a, b, empty=policy) == hausdorff.directed(a, b)
        assert hausdorff.summary(a, b, empty=policy) == hausdorff.summary(a, b)


def test_directed_summary_of_an_empty_set_leaves_bs_figures_nan():
    s = hausdorff.summary(P, E, directed=True, empty="zero")
    assert s.mean_ab == 0.0 and s.mean2_ab == 0.0 and s.n_ba == 0
    assert math.isnan(s.mean_ba) and math.isnan(s.chamfer)


def test_index_still_refuses_empty_sets():
    with pytest.raises(ValueError, match="b is empty"):
        hausdorff.Index(E)
    with pytest.raises(ValueError, match="a is empty"):
        hausdorff.Index(P).directed(E)


def test_skimage_rule_is_its_hausdorff_distance_of_empty_sets():
    """skimage.metrics.hausdorff_distance: 0 when both point sets are
    empty, inf when only one is."""
    assert hausdorff.hausdorff(E, E, empty="skimage").distance == 0.0
    assert hausdorff.hausdorff(E, P, empty="skimage").distance == math.inf
    assert hausdorff.hausdorff(P, E, empty="skimage").distance == math.inf
    assert tuple(hausdorff.hausdorff(P, P[:3], empty="skimage").ab) == \
        tuple(hausdorff.hausdorff(P, P[:3]).ab)                # sets with points: no effect
