#!/usr/bin/env python3
"""The command line's scores at tolerances (--tau, --tau-rule) and DTU's
capped means (--dtu-cap), against their reference definitions, and MONAI's
published surface Dice values through NIfTI masks.

    metrics_cli.py HAUSDORFF [NAME-FILTER]

Point sets: the per-point distances of the brute force in
cli_analysis_support (bit-identical to the library's) give the reference
counts, the Tanks and Temples precision / recall / F-score (d < tau) and
DTU's means (math.fsum over the count); Open3D's
compute_point_cloud_distance is compared too when python3-open3d is
installed (skipped otherwise, with a note).  Masks: each case of MONAI's
tests/metrics/test_surface_dice.py (commit in metrics_support.MONAI_FILE)
is written as a NIfTI-2 mask (double spacing, so 0.85 and 1.2 are the test's
doubles) and the tool's "nsd" must equal the published value at MONAI's
tolerance; random masks are compared with MONAI's definition rebuilt from
scipy (metrics_support.monai_nsd).  Seeds are in the test names.
"""
import math
import os
import sys

import numpy as np
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_analysis_support import main, nearest, run, run_json, same, test, value, write_nifti, write_pair, write_xyz  # noqa: E402
from metrics_support import MONAI_FILE, close, dtu, monai_cases, monai_nsd, monai_orderings, tanks_and_temples  # noqa: E402,E501


def clouds(seed, na=700, nb=500):
    r = np.random.default_rng(seed)
    a = r.normal(size=(na, 3))
    b = r.normal(size=(nb, 3)) * 1.1 + 0.2
    # a few points exactly on a tolerance: copies of B shifted by 0.25
    a[:20] = b[:20] + np.array([0.25, 0, 0])
    return a, b


@test
def scores_at_each_tolerance_follow_their_definition_seed_7(tmp):
    a, b = clouds(7)
    pa, pb = write_pair(tmp, a, b)
    d_ab, _ = nearest(a, b)
    d_ba, _ = nearest(b, a)
    taus = [0.25, 0.1, 0.5, 0.0, 2.0]
    for rule, op in (("le", np.less_equal), ("lt", np.less)):
        j = run_json([pa, pb, "--tau", ",".join(map(repr, taus)), "--tau-rule", rule])
        assert j["tolerance"]["rule"] == ("d <= tau" if rule == "le" else "d < tau")
        for t, s in zip(taus, j["tolerance"]["scores"]):
            ca, cb = int(op(d_ab, t).sum()), int(op(d_ba, t).sum())
            assert (s["tau"], s["within_ab"], s["within_ba"]) == (t, ca, cb), (rule, t, s)
            p, r = ca / len(a), cb / len(b)
            same(s["precision"], p, "precision")
            same(s["recall"], r, "recall")
            same(value(s["fscore"]), 2 * p * r / (p + r) if p + r else 0.0, "fscore")
            same(s["nsd"], (ca + cb) / (len(a) + len(b)), "nsd")
            if rule == "lt":
                tp, tr, tf = tanks_and_temples(d_ab, d_ba, t)
                same(s["precision"], tp, "T&T precision")
                same(s["recall"], tr, "T&T recall")
                assert close(value(s["fscore"]), tf, rtol=1e-15), (s["fscore"], tf)


@test
def a_point_exactly_at_tau_is_within_by_le_and_not_by_lt(tmp):
    pa, pb = write_pair(tmp, [[0, 0, 0], [3, 0, 0]], [[0.25, 0, 0]])
    le = run_json([pa, pb, "--tau", "0.25"])["tolerance"]["scores"][0]
    lt = run_json([pa, pb, "--tau", "0.25", "--tau-rule", "lt"])["tolerance"]["scores"][0]
    assert (le["within_ab"], lt["within_ab"]) == (1, 0), (le, lt)


@test
def dtu_means_are_the_capped_means_seed_11(tmp):
    a, b = clouds(11)
    pa, pb = write_pair(tmp, a, b)
    d_ab, _ = nearest(a, b)
    d_ba, _ = nearest(b, a)
    for cap in (0.3, 1.0, float("inf")):
        j = run_json([pa, pb, "--dtu-cap", "inf" if math.isinf(cap) else repr(cap)])["dtu"]
        acc, comp, overall = dtu(d_ab, d_ba, cap)
        same(j["accuracy"], acc, "accuracy")
        same(j["completeness"], comp, "completeness")
        same(j["overall"], overall, "overall")
        assert j["kept_ab"] == int((d_ab < cap).sum()) and j["kept_ba"] == int((d_ba < cap).sum())


@test
def open3d_distances_give_the_same_scores_seed_5(tmp):
    try:
        import open3d as o3d
    except ImportError:
        print("     (python3-open3d is not installed: the comparison with Open3D is skipped)")
        return
    a, b = clouds(5, 3000, 2000)
    pa, pb = write_pair(tmp, a, b)
    ca, cb = o3d.geometry.PointCloud(), o3d.geometry.PointCloud()
    ca.points = o3d.utility.Vector3dVector(a)
    cb.points = o3d.utility.Vector3dVector(b)
    d_ab = np.asarray(ca.compute_point_cloud_distance(cb))
    d_ba = np.asarray(cb.compute_point_cloud_distance(ca))
    taus = [0.05, 0.1, 0.2]
    j = run_json([pa, pb, "--tau", "0.05,0.1,0.2", "--tau-rule", "lt", "--dtu-cap", "0.5"])
    for t, s in zip(taus, j["tolerance"]["scores"]):
        p, r, f = tanks_and_temples(d_ab, d_ba, t)
        assert close(s["precision"], p, 1e-15) and close(s["recall"], r, 1e-15) and close(s["fscore"], f, 1e-15), \
            (t, s, p, r, f)
    acc, comp, _ = dtu(d_ab, d_ba, 0.5)
    assert close(j["dtu"]["accuracy"], acc, 1e-12) and close(j["dtu"]["completeness"], comp, 1e-12)


def mask_file(tmp, name, mask, spacing):
    m = np.asarray(mask, np.uint8)
    if m.ndim == 2:
        m = m[:, :, None]
    s = list(spacing) if spacing is not None else [1.0] * 3
    s = (s + [1.0] * 3)[:3]
    path = os.path.join(tmp, name + ".nii")
    write_nifti(path, m, pixdim=s, version=2)
    return path


NIFTI = os.environ.get("HD_NIFTI", "1") != "0"


def masks_test(fn):
    """A @test that needs NIfTI masks: skipped, with a note, without libnifti2."""
    def run_or_skip(tmp):
        if not NIFTI:
            print("     (the tool was built without libnifti2: %s skipped)" % fn.__name__)
            return
        fn(tmp)
    run_or_skip.__name__ = fn.__name__
    return test(run_or_skip)


def nsd_of_tool(tmp, pred, gt, spacing, taus):
    pp, pg = mask_file(tmp, "pred", pred, spacing), mask_file(tmp, "gt", gt, spacing)
    j = run_json([pp, pg, "--tau", ",".join(repr(float(t)) for t in taus), "--empty", "monai"])
    return [value(s["nsd"]) for s in j["tolerance"]["scores"]]


@masks_test
def monai_surface_dice_published_values(tmp):
    print("     cases of " + MONAI_FILE)
    for name, pred, gt, spacing, tau, expected in monai_cases():
        got = nsd_of_tool(tmp, pred, gt, spacing, [tau])[0]
        assert close(got, expected, rtol=1e-7), (name, got, expected)


@masks_test
def monai_surface_dice_orderings(tmp):
    for pred, gt, spacing, rising, equal in monai_orderings():
        r = nsd_of_tool(tmp, pred, gt, spacing, rising)
        assert all(x < y for x, y in zip(r, r[1:])), (spacing, rising, r)
        e = nsd_of_tool(tmp, pred, gt, spacing, equal)
        assert e[0] == e[1], (spacing, equal, e)


@masks_test
def random_masks_agree_with_monais_definition_seeds_1_to_6(tmp):
    for seed in range(1, 7):
        r = np.random.default_rng(seed)
        shape = (24, 20, 16) if seed % 2 else (40, 36)
        pred, gt = (ndimage.gaussian_filter(r.random(shape), 2) > 0.5 for _ in range(2))
        spacing = tuple(r.choice([0.5, 0.75, 1.0, 1.25, 2.0], size=len(shape)))
        taus = [0.3, 1.1, 2.6, 4.1]  # no distance of these spacings lies within 1e-9 of them
        got = nsd_of_tool(tmp, pred, gt, spacing, taus)
        for t, g in zip(taus, got):
            want = monai_nsd(pred, gt, t, spacing)
            assert close(g, want, rtol=1e-15), (seed, t, g, want)


@masks_test
def empty_masks_give_nsd_0_or_nan_as_monai(tmp):
    gt = np.zeros((12, 12, 6), bool)
    gt[3:8, 3:8, 2:4] = True
    assert nsd_of_tool(tmp, np.zeros_like(gt), gt, None, [1.0]) == [0.0]
    assert math.isnan(nsd_of_tool(tmp, np.zeros_like(gt), np.zeros_like(gt), None, [1.0])[0])


@test
def bad_values_are_usage_errors(tmp):
    pa = os.path.join(tmp, "a.xyz")
    write_xyz(pa, [[0, 0, 0]])
    for args, words in ((["--tau", "x"], "--tau needs numbers"), (["--tau", "-1"], "--tau needs numbers"),
                        (["--tau", ""], "--tau needs numbers"), (["--tau", ",".join(["1"] * 65)], "at most 64"),
                        (["--tau-rule", "ge"], "--tau-rule is le"), (["--dtu-cap", "0"], "--dtu-cap needs"),
                        (["--dtu-cap", "nan"], "--dtu-cap needs")):
        _, err = run([pa, pa] + args, expect=1)
        assert words in err, (args, err)


if __name__ == "__main__":
    main()
