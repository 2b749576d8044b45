"""hausdorff.masks and hausdorff.scores (the Python module) against MONAI's
published surface Dice values, the reference definitions of
metrics_support.py (MONAI's and medpy's, rebuilt from scipy), and the
command line, whose numbers they must equal to the bit.

Run by CTest `python_metrics` (pytest, with the built module on PYTHONPATH
and HD_CLI naming the tool).  Seeds are in the test names and parameters.
"""
import json
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
import pytest
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_analysis_support import nearest, write_nifti, write_pair  # noqa: E402
from metrics_support import (MONAI_FILE, close, dtu, edges, monai_cases, monai_nsd,  # noqa: E402
                             monai_orderings, surface_distances, tanks_and_temples)

from hausdorff import masks, scores  # noqa: E402

CLI = os.environ.get("HD_CLI")


def same(a, b):
    return (math.isnan(a) and math.isnan(b)) or float(a).hex() == float(b).hex()


@pytest.mark.parametrize("case", monai_cases(), ids=lambda c: c[0])
def test_monai_published_surface_dice(case):
    # each value MONAI_FILE states
    name, pred, gt, spacing, tau, expected = case
    assert close(masks.nsd(pred, gt, tau, spacing), expected, rtol=1e-7), name


def test_monai_orderings():
    for pred, gt, spacing, rising, equal in monai_orderings():
        r = masks.nsd(pred, gt, rising, spacing)
        assert all(x < y for x, y in zip(r, r[1:])), r
        e = masks.nsd(pred, gt, equal, spacing)
        assert e[0] == e[1]


def blobs(seed, shape):
    r = np.random.default_rng(seed)
    pred, gt = (ndimage.gaussian_filter(r.random(shape), 2) > 0.5 for _ in range(2))
    spacing = tuple(float(v) for v in r.choice([0.5, 0.75, 1.0, 1.25, 2.0], size=len(shape)))
    return pred, gt, spacing


@pytest.mark.parametrize("seed,shape,connectivity", [(1, (24, 20, 16), 1), (2, (40, 36), 1), (3, (18, 22, 14), 2),
                                                     (4, (30, 30), 2), (5, (16, 16, 16), 3), (6, (9, 40, 1), 1)])
def test_figures_agree_with_monai_and_medpy_definitions(seed, shape, connectivity):
    pred, gt, spacing = blobs(seed, shape)
    if len(shape) == 3 and shape[2] == 1:  # a single slice: 2-D, as the tool's --mask-dims auto
        ref_p, ref_g = pred[:, :, 0], gt[:, :, 0]
        ref_s = spacing[:2]
    else:
        ref_p, ref_g, ref_s = pred, gt, spacing
    d_pg, d_gp = surface_distances(ref_p, ref_g, ref_s, connectivity)
    m = masks.metrics(pred, gt, spacing, percentile=[95, 50], tau=[0.3, 1.1, 2.6], connectivity=connectivity)
    assert m.points == (int(edges(ref_p, connectivity).sum()), int(edges(ref_g, connectivity).sum()))
    rt = dict(rtol=1e-13)
    assert close(m.hausdorff, max(d_pg.max(), d_gp.max()), **rt)
    for k, p in enumerate([95, 50]):
        assert close(m.percentile[k], max(np.percentile(d_pg, p), np.percentile(d_gp, p)), **rt)  # MONAI
        assert close(m.percentile_pooled[k], np.percentile(np.concatenate([d_pg, d_gp]), p), **rt)  # medpy
        assert close(m.percentile_ab[k], np.percentile(d_pg, p), **rt)  # MONAI directed=True
    assert close(m.assd, np.concatenate([d_pg, d_gp]).mean(), **rt)  # MONAI >= 1.0, medpy 0.5
    assert close(m.assd_average, (d_pg.mean() + d_gp.mean()) / 2, **rt)  # MONAI 0.x
    if connectivity == 1:
        for t, v in zip([0.3, 1.1, 2.6], m.nsd):
            assert close(v, monai_nsd(ref_p, ref_g, t, ref_s), rtol=1e-15)
    dice = 2 * (pred & gt).sum() / (pred.sum() + gt.sum())
    assert same(m.dice, dice)
    assert masks.hausdorff(pred, gt, spacing, connectivity=connectivity) == m.hausdorff
    assert masks.hausdorff(pred, gt, spacing, percentile=95, definition="medpy",
                           connectivity=connectivity) == m.percentile_pooled[0]
    assert masks.assd(pred, gt, spacing, definition="average", connectivity=connectivity) == m.assd_average


@pytest.mark.skipif(not CLI, reason="HD_CLI names no tool")
@pytest.mark.parametrize("seed,shape", [(11, (24, 20, 16)), (12, (40, 36))])
def test_masks_equal_the_command_line_to_the_bit(seed, shape):
    pred, gt, spacing = blobs(seed, shape)
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for name, m in (("pred", pred), ("gt", gt)):
            v = np.asarray(m, np.uint8)
            v = v[:, :, None] if v.ndim == 2 else v
            paths.append(os.path.join(tmp, name + ".nii"))
            write_nifti(paths[-1], v, pixdim=(list(spacing) + [1.0])[:3], version=2)
        out = subprocess.run([CLI, *paths, "--json", "--percentile", "95", "--mean", "--tau", "0.3,1.1,2.6"],
                             capture_output=True, text=True, check=True).stdout
    j = json.loads(out)
    m = masks.metrics(pred, gt, spacing, percentile=95, tau=[0.3, 1.1, 2.6])
    pairs = [(j["hausdorff"], m.hausdorff), (j["directed_ab"], m.hausdorff_ab), (j["directed_ba"], m.hausdorff_ba),
             (j["percentile"]["symmetric"], m.percentile[0]), (j["percentile"]["pooled"], m.percentile_pooled[0]),
             (j["mean"]["pooled"], m.assd), (j["mean"]["average"], m.assd_average), (j["mean"]["ab"], m.asd_ab)]
    for k, s in enumerate(j["tolerance"]["scores"]):
        pairs += [(s["nsd"], m.nsd[k]), (s["precision"], m.precision[k]), (s["recall"], m.recall[k]),
                  (s["fscore"], m.fscore[k])]
    for a, b in pairs:
        assert same(a, b), (a, b)
    assert (j["masks"]["a"]["points"], j["masks"]["b"]["points"]) == m.points


def test_empty_masks_follow_the_policy():
    gt = np.zeros((10, 10, 5), bool)
    gt[2:6, 2:6, 1:3] = True
    none = np.zeros_like(gt)
    with pytest.raises(ValueError, match="pred is empty"):
        masks.metrics(none, gt)
    m = masks.metrics(none, gt, empty="monai", tau=1)
    assert math.isinf(m.hausdorff) and m.nsd == [0.0] and m.dice == 0.0
    m = masks.metrics(none, none, empty="monai", tau=1)
    assert math.isnan(m.hausdorff) and math.isnan(m.nsd[0]) and math.isnan(m.dice)
    assert masks.nsd(none, gt, 1.0) == 0.0


def test_bad_masks_are_refused():
    a = np.zeros((4, 4), bool)
    with pytest.raises(ValueError, match="different shapes"):
        masks.metrics(a, np.zeros((4, 5), bool))
    with pytest.raises(ValueError, match="spacing has 3 values"):
        masks.surface(a, (1, 1, 1))
    with pytest.raises(ValueError, match="spacing must be finite and positive"):
        masks.surface(a, (1, 0))
    with pytest.raises(ValueError, match="1 to 3 dimensions"):
        masks.surface(np.zeros((2, 2, 2, 2)))
    with pytest.raises(ValueError, match="connectivity"):
        masks.surface(a, connectivity=4)


def test_surface_points_are_voxel_centres_times_spacing_in_array_order():
    m = np.zeros((5, 4, 3), np.int16)
    m[1:4, 1:3, :] = 7
    pts = masks.surface(m, (0.5, 2.0, 3.0))
    idx = np.argwhere(edges(m != 0))
    want = idx[np.lexsort((idx[:, 0], idx[:, 1], idx[:, 2]))] * np.array([0.5, 2.0, 3.0])
    assert np.array_equal(pts, want)


@pytest.mark.parametrize("seed", [21, 22])
def test_point_set_scores_follow_their_definitions(seed):
    r = np.random.default_rng(seed)
    a, b = r.normal(size=(600, 3)), r.normal(size=(450, 3)) + 0.1
    d_ab, _ = nearest(a, b)
    d_ba, _ = nearest(b, a)
    taus = [0.05, 0.2, 0.4]
    for s, t in zip(scores.tolerance(a, b, taus, strict=True), taus):
        p, rc, f = tanks_and_temples(d_ab, d_ba, t)
        assert same(s.precision, p) and same(s.recall, rc) and close(s.fscore, f, rtol=1e-15)
    w_a, w_b = r.random(600), r.random(450)
    s = scores.tolerance(a, b, 0.2, weights_a=w_a, weights_b=w_b)
    assert same(s.precision, math.fsum(w_a[d_ab <= 0.2]) / math.fsum(w_a))
    assert same(s.nsd, math.fsum(np.concatenate([w_a[d_ab <= 0.2], w_b[d_ba <= 0.2]])) /
                math.fsum(np.concatenate([w_a, w_b])))
    got = scores.dtu(a, b, 0.3)
    assert got[:3] == dtu(d_ab, d_ba, 0.3)


@pytest.mark.skipif(not CLI, reason="HD_CLI names no tool")
def test_point_set_scores_equal_the_command_line():
    r = np.random.default_rng(31)
    a, b = r.normal(size=(300, 3)), r.normal(size=(200, 3))
    with tempfile.TemporaryDirectory() as tmp:
        pa, pb = write_pair(tmp, a, b)
        j = json.loads(subprocess.run([CLI, pa, pb, "--json", "--tau", "0.1,0.3", "--dtu-cap", "0.5"],
                                      capture_output=True, text=True, check=True).stdout)
    for s, t in zip(j["tolerance"]["scores"], scores.tolerance(a, b, [0.1, 0.3])):
        assert (s["precision"], s["recall"], s["fscore"], s["nsd"]) == t[1:5]
    d = scores.dtu(a, b, 0.5)
    assert (j["dtu"]["accuracy"], j["dtu"]["completeness"], j["dtu"]["overall"]) == d[:3]


def test_docstring_examples_run():
    import doctest
    for module in (masks, scores):
        failed, _ = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert failed == 0, module.__name__
