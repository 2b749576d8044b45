"""Label maps, surfels and components of hausdorff.masks (pytest).

- DeepMind's published values: every case of surface_distance_test.py of
  google-deepmind/surface-distance at commit
  1f805cea446805e559badc80dd27f34175e4173d, ported (their argument order is
  gt, pred; ours pred, gt).  The average surface distance of an empty side
  is not ported: DeepMind returns (inf, nan) where this module applies its
  empty policy to every distance figure.
- Random label maps against a brute-force numpy reference: MONAI's surface
  voxels (scipy's binary_erosion), every pairwise distance, the figures from
  their definitions; DeepMind's surfels from a direct 2 x 2 x 2 neighbour
  code with numpy, the area of each code taken from the library's own
  table (its values are checked by tests/internal/test_labels.c), and
  DeepMind's metric functions re-written from their definitions.
- MONAI's use_subvoxels=True values (test_compute_surface_dice_subvoxel of
  MONAI tests/metrics/test_surface_dice.py at commit
  2e4424e43b686409e5190111122ce16a0d704421).
- Components against scipy.ndimage.label.
Seeds are in the test names' parameters.
"""
import math
import os
import subprocess

import numpy as np
import pytest
from scipy import ndimage

from hausdorff import masks

DM = "surface_distance_test.py @1f805cea446805e559badc80dd27f34175e4173d"


# ---- DeepMind's definitions, for the reference ------------------------------------------

def dm_average(d, w):
    return float(np.sum(d * w) / np.sum(w)) if len(d) else math.nan


def dm_robust(d, w, percent):
    if not len(d):
        return math.inf
    o = np.argsort(d, kind="stable")
    d, w = d[o], w[o]
    cum = np.cumsum(w) / np.sum(w)
    idx = np.searchsorted(cum, percent / 100.0)
    return float(d[min(idx, len(d) - 1)])


def dm_overlap(d, w, tol):
    return float(np.sum(w[d <= tol]) / np.sum(w)) if len(d) else math.nan


def same(a, b, places=3):
    if math.isnan(b):
        return math.isnan(a)
    if math.isinf(b):
        return a == b
    return round(abs(a - b), places) == 0


def dm_case(gt, pred, spacing, asd, hd100, hd95, overlap, nsd, dice, empty_asd=False):
    r = masks.label_map(pred.astype(np.uint8), gt.astype(np.uint8), spacing, labels=[1], percentile=100,
                        empty="inf")[0]
    r95 = masks.label_map(pred.astype(np.uint8), gt.astype(np.uint8), spacing, labels=[1], percentile=95,
                          empty="inf")[0]
    if not empty_asd:
        assert same(r["asd_surfel_gt_pred"], asd[0]) and same(r["asd_surfel_pred_gt"], asd[1]), (DM, r)
    assert same(r["hd_surfel"], hd100), (DM, r)
    assert same(r95["hd_surfel"], hd95), (DM, r95)
    assert same(r["overlap_gt"], overlap[0]) and same(r["overlap_pred"], overlap[1]), (DM, r)
    assert same(r["nsd_surfel"], nsd), (DM, r)
    assert same(r["dice"], dice), (DM, r)
    assert same(masks.nsd(pred, gt, 1, spacing, definition="deepmind"), nsd)
    assert same(masks.nsd(pred, gt, 1, spacing, definition="monai_subvoxels"), nsd)


def test_deepmind_2d_two_pixels_2mm_away():
    gt, pred = np.zeros((128, 128), bool), np.zeros((128, 128), bool)
    gt[50, 70] = 1
    pred[50, 72] = 1
    sd = masks.surface_distances(pred, gt, spacing=(2, 1))
    diag = 0.5 * math.sqrt(2 ** 2 + 1 ** 2)
    np.testing.assert_allclose(sd["surfel_areas_gt"], [diag] * 4, rtol=1e-15)
    np.testing.assert_allclose(sd["surfel_areas_pred"], [diag] * 4, rtol=1e-15)
    np.testing.assert_array_equal(sd["distances_gt_to_pred"], [1., 1., 2., 2.])
    np.testing.assert_array_equal(sd["distances_pred_to_gt"], [1., 1., 2., 2.])
    dm_case(gt, pred, (2, 1), (1.5, 1.5), 2.0, 2.0, (0.5, 0.5), 0.5, 0.0)


def test_deepmind_2d_two_squares_shifted_by_one_pixel():
    gt = np.zeros((6, 6), bool)
    gt[1:3, 1:3] = 1
    pred = np.zeros((6, 6), bool)
    pred[1:4, 1:3] = 1
    vertical, horizontal = 2, 1
    diag = 0.5 * math.sqrt(horizontal ** 2 + vertical ** 2)
    sd = masks.surface_distances(pred, gt, spacing=(vertical, horizontal))
    areas_gt = [diag, horizontal, diag, vertical, diag, horizontal, diag, vertical]
    areas_pred = [diag, horizontal, diag, vertical, vertical, diag, horizontal, diag, vertical, vertical]
    d_gt = [0] * 5 + [horizontal] + [0] * 2
    d_pred = [0] * 5 + [vertical] * 3 + [0] * 2
    # DeepMind lists them clockwise, then sorts by distance: compare as pairs
    got_gt = sorted(zip(sd["distances_gt_to_pred"], np.round(sd["surfel_areas_gt"], 12)))
    got_pred = sorted(zip(sd["distances_pred_to_gt"], np.round(sd["surfel_areas_pred"], 12)))
    assert got_gt == sorted(zip(map(float, d_gt), np.round(areas_gt, 12))), DM
    assert got_pred == sorted(zip(map(float, d_pred), np.round(areas_pred, 12))), DM
    d_gt, d_pred, a_gt, a_pred = (np.asarray(v, float) for v in (d_gt, d_pred, areas_gt, areas_pred))
    dm_case(gt, pred, (vertical, horizontal), (dm_average(d_gt, a_gt), dm_average(d_pred, a_pred)),
            max(dm_robust(d_gt, a_gt, 100), dm_robust(d_pred, a_pred, 100)),
            max(dm_robust(d_gt, a_gt, 95), dm_robust(d_pred, a_pred, 95)),
            (dm_overlap(d_gt, a_gt, 1), dm_overlap(d_pred, a_pred, 1)),
            (np.sum(a_gt[d_gt <= 1]) + np.sum(a_pred[d_pred <= 1])) / (np.sum(a_gt) + np.sum(a_pred)),
            2 * 4 / (4 + 6))


@pytest.mark.parametrize("shape,spacing,gt_at,pred_at", [
    ((128, 128), (3, 2), (50, 60), None), ((128, 128), (3, 2), None, (50, 60)),
    ((128, 128), (3, 2), None, None), ((128, 128, 128), (3, 2, 1), (50, 60, 70), None),
    ((128, 128, 128), (3, 2, 1), None, (50, 60, 72)), ((128, 128, 128), (3, 2, 1), None, None)])
def test_deepmind_empty_masks(shape, spacing, gt_at, pred_at):
    gt, pred = np.zeros(shape, bool), np.zeros(shape, bool)
    if gt_at:
        gt[gt_at] = 1
    if pred_at:
        pred[pred_at] = 1
    overlap = (0.0 if gt_at else math.nan, 0.0 if pred_at else math.nan)
    both = not gt_at and not pred_at
    dm_case(gt, pred, spacing, None, math.inf, math.inf, overlap, math.nan if both else 0.0,
            math.nan if both else 0.0, empty_asd=True)


def test_deepmind_3d_two_pixels_2mm_away():
    gt, pred = np.zeros((128, 128, 128), bool), np.zeros((128, 128, 128), bool)
    gt[50, 60, 70] = 1
    pred[50, 60, 72] = 1
    dm_case(gt, pred, (3, 2, 1), (1.5, 1.5), 2.0, 2.0, (0.5, 0.5), 0.5, 0.0)


def test_deepmind_3d_two_cubes_shifted_by_one_pixel():
    gt, pred = np.zeros((100, 100, 100), bool), np.zeros((100, 100, 100), bool)
    gt[0:50, :, :] = 1
    pred[0:51, :, :] = 1
    dm_case(gt, pred, (2, 1, 1), (0.322, 0.339), 2.0, 2.0, (0.842, 0.830), 0.836, 0.990)
    assert masks.hausdorff(pred, gt, (2, 1, 1), definition="deepmind") == 2.0
    assert round(masks.assd(pred, gt, (2, 1, 1), definition="deepmind"), 3) == round((0.322 + 0.339) / 2, 3)


# ---- brute-force references ---------------------------------------------------------------

def monai_surface(m, conn=1):
    st = ndimage.generate_binary_structure(m.ndim, conn)
    return m & ~ndimage.binary_erosion(m, st, border_value=0)


def coords(idx, spacing):
    return np.stack([idx[:, a] * spacing[a] for a in range(idx.shape[1])], axis=1).astype(np.float64)


def brute(p, q):
    """Each point of p's distance to q, summed left to right as the library does."""
    if not len(q):
        return np.full(len(p), np.inf)
    acc = np.zeros((len(p), len(q)))
    for a in range(p.shape[1]):
        diff = p[:, None, a] - q[None, :, a]
        acc = acc + diff * diff
    return np.sqrt(acc.min(axis=1))


def dm_surfels(m, spacing, table):
    """Centres and areas of the cubes of 2^ndim voxels the boundary crosses."""
    pad = np.pad(m, 1).astype(np.int64)
    nd = m.ndim
    code = np.zeros(tuple(s + 1 for s in m.shape), np.int64)
    for v in range(2 ** nd):
        sl = tuple(slice((v >> a) & 1, (v >> a & 1) + m.shape[a] + 1) for a in range(nd))
        code |= pad[sl] << v
    full = 2 ** (2 ** nd) - 1
    where = np.argwhere((code != 0) & (code != full))
    idx = where.astype(np.float64) - 0.5  # cube c covers voxels c-1 .. c
    return coords(idx, spacing), table[code[tuple(where.T)]]


def surfel_table(ndim, spacing):
    """The library's area per code, read back through single cubes."""
    size = 2 ** (2 ** ndim)
    t = np.zeros(size)
    for code in range(1, size - 1):
        cube = np.array([(code >> v) & 1 for v in range(2 ** ndim)], bool).reshape((2,) * ndim, order="F")
        pts, ar = masks.surfels(cube, spacing)
        centre = np.all(np.isclose(pts[:, :ndim], 0.5 * np.asarray(spacing[:ndim])), axis=1)
        t[code] = ar[centre][0]
    return t


@pytest.mark.parametrize("seed", range(6))
def test_label_map_matches_a_brute_force_reference(seed):
    rng = np.random.default_rng(seed)
    ndim = 2 if seed % 3 == 2 else 3
    shape = tuple(rng.integers(6, 13, ndim))
    spacing = tuple(float(s) for s in rng.choice([0.5, 1.0, 1.25, 3.0], ndim))
    pred = ndimage.median_filter(rng.integers(0, 4, shape), size=2).astype(np.int32)
    gt = ndimage.median_filter(rng.integers(0, 4, shape), size=2).astype(np.int32)
    tau = float(rng.choice([0.5, 1.0, 2.0]))
    rows = masks.label_map(pred, gt, spacing, tau=tau, percentile=90)
    table = surfel_table(ndim, spacing)
    labels = sorted((set(np.unique(pred).tolist()) | set(np.unique(gt).tolist())) - {0})
    assert [r["label"] for r in rows] == labels
    for r in rows:
        mp, mg = pred == r["label"], gt == r["label"]
        sp, sg = (coords(np.argwhere(monai_surface(m)), spacing) for m in (mp, mg))
        if not len(sp) or not len(sg):
            assert r["empty"] and math.isinf(r["hausdorff"]) and r["nsd"] == 0.0
            continue
        dp, dg = brute(sp, sg), brute(sg, sp)
        ctx = (seed, r["label"])
        assert r["hd_pred_gt"] == dp.max() and r["hd_gt_pred"] == dg.max(), ctx
        assert r["hd_p"] == max(np.percentile(dp, 90), np.percentile(dg, 90)), ctx
        assert r["hd_p_pooled"] == np.percentile(np.concatenate([dp, dg]), 90), ctx
        assert r["assd"] == math.fsum(np.concatenate([dp, dg])) / (len(dp) + len(dg)), ctx
        assert r["nsd"] == (np.sum(dp <= tau) + np.sum(dg <= tau)) / (len(dp) + len(dg)), ctx
        assert r["dice"] == 2 * np.sum(mp & mg) / (mp.sum() + mg.sum()), ctx
        (cp, wp), (cg, wg) = dm_surfels(mp, spacing, table), dm_surfels(mg, spacing, table)
        assert (r["surfels_pred"], r["surfels_gt"]) == (len(cp), len(cg)), ctx
        ep, eg = brute(cp, cg), brute(cg, cp)
        assert r["hd_surfel"] == max(dm_robust(ep, wp, 90), dm_robust(eg, wg, 90)), ctx
        assert r["asd_surfel_pred_gt"] == pytest.approx(dm_average(ep, wp), rel=1e-14), ctx
        assert r["asd_surfel_gt_pred"] == pytest.approx(dm_average(eg, wg), rel=1e-14), ctx
        want = (np.sum(wp[ep <= tau]) + np.sum(wg[eg <= tau])) / (np.sum(wp) + np.sum(wg))
        assert r["nsd_surfel"] == pytest.approx(want, rel=1e-14), ctx


@pytest.mark.parametrize("seed,conn", [(0, 6), (1, 18), (2, 26), (3, 4), (4, 8)])
def test_components_match_scipy_label(seed, conn):
    rng = np.random.default_rng(seed)
    ndim = 2 if conn in (4, 8) else 3
    shape = tuple(rng.integers(8, 14, ndim))
    spacing = tuple(float(s) for s in rng.choice([0.5, 1.0, 2.0], ndim))
    pred = (rng.random(shape) < 0.12).astype(np.uint8) * 2
    gt = (rng.random(shape) < 0.12).astype(np.uint8) * 2
    tau = 1.0
    comps = masks.components(pred, gt, spacing, connectivity=conn, tau=tau, percentile=95)
    structure = ndimage.generate_binary_structure(ndim, {4: 1, 8: 2, 6: 1, 18: 2, 26: 3}[conn])
    want = []
    for side, (m, o) in enumerate(((pred == 2, gt == 2), (gt == 2, pred == 2))):
        lab, n = ndimage.label(m, structure)
        # components are numbered by their first voxel in memory order (C here)
        flat = lab.ravel(order="C")
        firsts = list(dict.fromkeys(flat[flat != 0]))
        so, su = monai_surface(o), monai_surface(m)
        oc = coords(np.argwhere(so), spacing)
        for c in firsts:
            cm = lab == c
            pts = coords(np.argwhere(su & cm), spacing)
            d = brute(pts, oc)
            want.append((("pred", "gt")[side], int(cm.sum()), int((cm & o).sum()), len(pts), d.max(),
                         np.percentile(d, 95), d.min(), bool((cm & o).any() or d.min() <= tau)))
    got = [(c["side"], c["voxels"], c["overlap"], c["points"], c["hausdorff"], c["hd_p"], c["nearest"],
            c["detected"]) for c in comps]
    assert got == want, (seed, conn)


def test_empty_labels_and_chosen_lists():
    pred = np.zeros((5, 6, 7), np.uint16)
    gt = np.zeros_like(pred)
    pred[1:3, 1:3, 1:3] = 4
    gt[2:4, 2:4, 2:4] = 4
    gt[0, 0, 0] = 9
    rows = masks.label_map(pred, gt, (1, 2, 3), labels=[9, 4, 5])
    assert [r["label"] for r in rows] == [9, 4, 5]
    assert rows[0]["empty"] == 1 and math.isinf(rows[0]["hausdorff"]) and rows[0]["nsd"] == 0.0
    assert rows[0]["nsd_surfel"] == 0.0
    assert rows[2]["empty"] == 3 and math.isnan(rows[2]["hausdorff"]) and math.isnan(rows[2]["dice"])
    assert rows[1]["empty"] == 0 and rows[1]["dice"] == 2 * 1 / 16
    with pytest.raises(ValueError, match="label 9 is absent from A"):
        masks.label_map(pred, gt, (1, 2, 3), empty="error")
    zero = masks.label_map(pred, gt, (1, 2, 3), labels=[9], empty="zero")[0]
    assert zero["hausdorff"] == 0.0 and zero["hd_surfel"] == 0.0


def test_a_binary_row_equals_the_mask_functions():
    rng = np.random.default_rng(7)
    pred = ndimage.binary_dilation(rng.random((20, 18, 9)) < 0.02, iterations=2)
    gt = ndimage.binary_dilation(rng.random((20, 18, 9)) < 0.02, iterations=2)
    sp = (0.7, 0.7, 2.5)
    m = masks.metrics(pred, gt, sp, percentile=95, tau=1.5)
    r = masks.label_map(pred, gt, sp, percentile=95, tau=1.5)[0]
    assert (r["hausdorff"], r["hd_p"], r["hd_p_pooled"], r["assd"], r["nsd"]) == \
           (m.hausdorff, m.percentile[0], m.percentile_pooled[0], m.assd, m.nsd[0])
    assert masks.hausdorff(pred, gt, sp, percentile=95, definition="deepmind") == \
        masks.label_map(pred, gt, sp, percentile=95)[0]["hd_surfel"]


def test_label_types_and_float_labels():
    rng = np.random.default_rng(3)
    base = rng.integers(0, 3, (7, 8, 9))
    want = masks.label_map(base.astype(np.int64), base[::-1].astype(np.int64))
    for t in (np.uint8, np.int8, np.uint16, np.int16, np.uint32, np.int32, np.uint64, np.float32):
        got = masks.label_map(base.astype(t), base[::-1].astype(t))
        assert got == want, t
    with pytest.raises(ValueError, match="whole numbers"):
        masks.label_map(base + 0.5, base)
    with pytest.raises(ValueError, match="different shapes"):
        masks.label_map(base, base[1:])


def test_monai_compute_surface_dice_subvoxel():
    """MONAI tests/metrics/test_surface_dice.py @2e4424e43b686409e5190111122ce16a0d704421,
    test_compute_surface_dice_subvoxel (use_subvoxels=True)."""
    gt, pred = np.zeros((128, 128, 128), bool), np.zeros((128, 128, 128), bool)
    gt[50, 60, 70] = 1
    assert masks.nsd(pred, gt, 1.0, (3, 2, 1), definition="monai_subvoxels") == 0.0
    gt[50, 60, 70] = 0
    pred[50, 60, 72] = 1
    assert masks.nsd(pred, gt, 1.0, (3, 2, 1), definition="monai_subvoxels") == 0.0
    gt[50, 60, 70] = 1
    assert masks.nsd(pred, gt, 1.0, (3, 2, 1), definition="monai_subvoxels") == 0.5
    gt, pred = np.zeros((100, 100, 100), bool), np.zeros((100, 100, 100), bool)
    gt[0:50] = 1
    pred[0:51] = 1
    got = masks.nsd(pred, gt, 1.0, (2, 1, 1), definition="monai_subvoxels")
    assert abs(got - 0.836145) <= 1e-3 + 1e-3 * 0.836145


def test_c_and_fortran_order_give_the_same_rows():
    rng = np.random.default_rng(11)
    c = ndimage.median_filter(rng.integers(0, 4, (9, 11, 7)), size=2).astype(np.uint8)
    g = ndimage.median_filter(rng.integers(0, 4, (9, 11, 7)), size=2).astype(np.uint8)
    sp = (0.7, 1.1, 2.3)
    a = masks.label_map(c, g, sp, components=18)
    b = masks.label_map(np.asfortranarray(c), np.asfortranarray(g), sp, components=18)
    assert a == b  # every figure to the bit (no label is empty here: no NaN)
    assert len(masks.components(c, g, sp, connectivity=18)) == sum(r["components_pred"] + r["components_gt"]
                                                                   for r in a)


@pytest.mark.skipif(not os.environ.get("HD_CLI"), reason="the command line is built without libnifti2")
def test_label_map_equals_the_command_line(tmp_path):
    """The same label maps as NIfTI files: every figure of every row and
    component of `hausdorff --labels all --json --components 18` equals
    label_map's and components' to the bit."""
    import json
    import sys
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from cli_analysis_support import write_nifti
    rng = np.random.default_rng(12)
    p = ndimage.median_filter(rng.integers(0, 4, (12, 10, 7)), size=3).astype(np.int16)
    g = ndimage.median_filter(rng.integers(0, 4, (12, 10, 7)), size=3).astype(np.int16)
    sp = (0.5, 1.25, 2.0)
    write_nifti(str(tmp_path / "p.nii"), p, pixdim=sp)
    write_nifti(str(tmp_path / "g.nii.gz"), g, pixdim=sp)
    out = subprocess.run([os.environ["HD_CLI"], "--labels", "all", "--json", "--components", "18", "--percentile",
                          "90", "--tau", "1.5", str(tmp_path / "p.nii"), str(tmp_path / "g.nii.gz")],
                         capture_output=True, text=True, check=True).stdout
    j = json.loads(out)
    rows = masks.label_map(p, g, sp, percentile=90, tau=1.5, components=18)
    # NIfTI stores i fastest: Fortran order numbers the components as the tool does
    comps = masks.components(np.asfortranarray(p), np.asfortranarray(g), sp, connectivity=18, percentile=90,
                             tau=1.5)
    assert len(rows) == len(j["labels"])
    for r, c in zip(rows, j["labels"]):
        assert [r[k] for k in masks.ROW_FIELDS] == [math.nan if v is None else v for v in c.values()], r["label"]
    key = ("label", "side", "index", "voxels", "overlap", "points", "hausdorff", "hd_p", "nearest", "detected")
    assert [tuple(c[k] for k in key) for c in comps] == \
        [(c["label"], {"A": "pred", "B": "gt"}[c["side"]]) + tuple(c[k] for k in key[2:]) for c in j["components"]]
