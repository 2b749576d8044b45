"""Shared by metrics_cli.py and python_metrics.py: the published cases of
MONAI's surface Dice tests, and the reference definitions the tests compare
with, written here from the libraries' documented definitions.

MONAI's cases come from tests/metrics/test_surface_dice.py of
Project-MONAI/MONAI at commit 2e4424e43b686409e5190111122ce16a0d704421
(compute_surface_dice / SurfaceDiceMetric, distance_metric="euclidean",
use_subvoxels=False): the masks are rebuilt from the test's own code
(one-hot channels of label images: channel 0 is the background), and the
expected values are the test's.
"""
import math

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

MONAI_FILE = "Project-MONAI/MONAI tests/metrics/test_surface_dice.py @ 2e4424e43b686409e5190111122ce16a0d704421"


def one_hot(labels, n_class):
    return [labels == c for c in range(n_class)]


def monai_cases():
    """(name, pred mask, gt mask, spacing or None, tau, expected NSD), every
    value the MONAI test states for one channel of one batch item.  NaN:
    both masks empty."""
    cases = []
    # test_tolerance_euclidean_distance(_with_spacing): 480 x 640, a 10-pixel shift
    p = np.zeros((480, 640), np.int64)
    g = np.zeros((480, 640), np.int64)
    p[:, 50:] = 1
    g[:, 60:] = 1
    ph, gh = one_hot(p, 2), one_hot(g, 2)
    for spacing in (None, (0.85, 1.2)):
        s = "spacing" if spacing else "no spacing"
        cases.append(("2-D shift, class 1, tau 0, " + s, ph[1], gh[1], spacing, 0.0,
                      1 - (478 + 480 + 9 * 2) / (480 * 4 + 588 * 2 + 578 * 2)))
        cases.append(("2-D shift, class 0, tau 0, " + s, ph[0], gh[0], spacing, 0.0,
                      1 - (478 + 480 + 9 * 2) / (480 * 4 + 48 * 2 + 58 * 2)))
    z = np.zeros((480, 640), np.int64)
    zh = one_hot(z, 2)
    cases.append(("2-D batch item 1 (all background), class 0", zh[0], zh[0], None, 0.0, 1.0))
    cases.append(("2-D batch item 1 (all background), class 1", zh[1], zh[1], None, 0.0, math.nan))
    # test_tolerance_euclidean_distance_3d: 200 x 110 x 80, offset by 10
    p3 = np.zeros((200, 110, 80), np.int64)
    g3 = np.zeros((200, 110, 80), np.int64)
    p3[:, :, 20:] = 1
    g3[:, :, 30:] = 1
    ph3, gh3 = one_hot(p3, 2), one_hot(g3, 2)
    cases.append(("3-D shift, class 1, tau 0", ph3[1], gh3[1], None, 0.0,
                  1 - (200 * 110 + 198 * 108 + 9 * 200 * 2 + 9 * 108 * 2) /
                  (200 * 110 * 4 + (58 + 48) * 200 * 2 + (58 + 48) * 108 * 2)))
    cases.append(("3-D shift, class 0, tau 0", ph3[0], gh3[0], None, 0.0,
                  1 - (200 * 110 + 198 * 108 + 9 * 200 * 2 + 9 * 108 * 2) /
                  (200 * 110 * 4 + (28 + 18) * 200 * 2 + (28 + 18) * 108 * 2)))
    # test_tolerance_all_distances: two 3-pixel bars in 10 x 10, Euclidean
    pa = np.zeros((10, 10), np.int64)
    ga = np.zeros((10, 10), np.int64)
    pa[1:4, 1] = 1
    ga[5:8, 6] = 1
    pah, gah = one_hot(pa, 2), one_hot(ga, 2)
    for (t0, t1), (e0, e1) in (((0, 0), (1 - (8 + 4) / (36 * 2 + 8 + 4), 0)),
                               ((2.8, 5.5), (1 - 3 / (36 * 2 + 8 + 4), 1 - (2 + 2) / (3 + 3))),
                               ((3, 6), (1 - 1 / (36 * 2 + 8 + 4), 1 - 2 / (3 + 3)))):
        cases.append(("bars, class 0, tau %g" % t0, pah[0], gah[0], None, float(t0), e0))
        cases.append(("bars, class 1, tau %g" % t1, pah[1], gah[1], None, float(t1), e1))
    # test_not_predicted_not_present: label 1 predicted where label 2 is true
    pn = np.zeros((80, 80), np.int64)
    gn = np.zeros((80, 80), np.int64)
    pn[10:20, 10:20] = 1
    gn[10:20, 10:20] = 2
    for c, e in enumerate([1.0, 0.0, 0.0, math.nan]):
        cases.append(("not predicted / not present, class %d" % c, pn == c, gn == c, None, 1.0, e))
    return cases


def monai_orderings():
    """The test's orderings between tolerances: (pred, gt, spacing, taus
    increasing strictly in NSD, taus giving one NSD)."""
    p = np.zeros((480, 640), bool)
    g = np.zeros((480, 640), bool)
    p[:, 50:] = True
    g[:, 60:] = True
    return [(p, g, (0.85, 1.2), [0, 1, 9, 10, 11], [12, 13]),
            (~p, ~g, (0.85, 1.2), [0, 1, 9, 10, 11], [12, 13]),
            (p, g, None, [0, 1, 9, 10], [10, 11])]


def close(a, b, rtol=1e-7, atol=1e-12):
    a, b = float(a), float(b)
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return abs(a - b) <= atol + rtol * abs(b)


# ---- reference definitions ---------------------------------------------------------


def edges(mask, connectivity=1):
    """medpy's and MONAI's border: mask ^ binary_erosion(mask, structure),
    the outside being background."""
    m = np.asarray(mask, bool)
    st = ndimage.generate_binary_structure(m.ndim, connectivity)
    return m & ~ndimage.binary_erosion(m, st, border_value=0)


def surface_distances(pred, gt, spacing=None, connectivity=1):
    """MONAI's get_surface_distance both ways: the Euclidean distance
    transform of the other border (scipy, with sampling), read at this
    border; inf when the other border is empty."""
    ep, eg = edges(pred, connectivity), edges(gt, connectivity)
    s = spacing if spacing is not None else [1.0] * ep.ndim

    def at(src, dst):
        if not dst.any():
            return np.full(int(src.sum()), np.inf)
        return ndimage.distance_transform_edt(~dst, sampling=s)[src]
    return at(ep, eg), at(eg, ep)


def monai_nsd(pred, gt, tau, spacing=None):
    """MONAI's compute_surface_dice (use_subvoxels=False)."""
    d_pg, d_gp = surface_distances(pred, gt, spacing)
    n = len(d_pg) + len(d_gp)
    return math.nan if n == 0 else (np.sum(d_pg <= tau) + np.sum(d_gp <= tau)) / n


def tanks_and_temples(d_rec_to_ref, d_ref_to_rec, tau):
    """The Tanks and Temples evaluation's precision, recall, F-score: d < tau."""
    p = float(np.mean(d_rec_to_ref < tau))
    r = float(np.mean(d_ref_to_rec < tau))
    return p, r, (2 * p * r / (p + r) if p + r > 0 else 0.0)


def dtu(d_rec_to_ref, d_ref_to_rec, cap):
    """DTU's accuracy and completeness: mean of the distances below the cap,
    exactly summed (math.fsum) so that the mean is the correctly rounded
    sum over the count."""
    a = d_rec_to_ref[d_rec_to_ref < cap]
    c = d_ref_to_rec[d_ref_to_rec < cap]
    acc, comp = math.fsum(a) / len(a), math.fsum(c) / len(c)
    return acc, comp, (acc + comp) / 2


def kdtree_distances(a, b):
    return cKDTree(b).query(a)[0]
