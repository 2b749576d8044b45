#!/usr/bin/env python3
"""The command line's label maps (--labels, --components, --csv) against a
brute-force numpy reference, through NIfTI files written byte by byte.

    labels_cli.py HAUSDORFF [NAME-FILTER]

For each label of two random label maps: MONAI's surface voxels (scipy's
binary_erosion, the outside as background), every pairwise distance, and
from them HD, the directed maxima, HD_P both ways (numpy's percentile),
the pooled ASSD (math.fsum), the NSD by counts and the Dice; the surfels
are counted from the 2 x 2 x 2 neighbour codes; components from
scipy.ndimage.label.  The JSON's numbers are the shortest texts of the
doubles, so equality is to the bit.  Seeds are in the test names.
"""
import csv
import io
import math
import os
import sys

import numpy as np
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_analysis_support import main, run, run_json, test, value, write_nifti, write_pair  # noqa: E402


def surface(m):
    st = ndimage.generate_binary_structure(m.ndim, 1)
    return m & ~ndimage.binary_erosion(m, st, border_value=0)


def points(m, spacing):
    idx = np.argwhere(m).astype(np.float64)
    return np.stack([idx[:, a] * spacing[a] for a in range(3)], axis=1)


def brute(p, q):
    acc = np.zeros((len(p), len(q)))
    for a in range(3):
        d = p[:, None, a] - q[None, :, a]
        acc = acc + d * d
    return np.sqrt(acc.min(axis=1))


def surfel_count(m):
    pad = np.pad(m, 1).astype(np.int64)
    code = np.zeros(tuple(s + 1 for s in m.shape), np.int64)
    for v in range(8):
        sl = tuple(slice((v >> a) & 1, ((v >> a) & 1) + m.shape[a] + 1) for a in range(3))
        code |= pad[sl] << v
    return int(np.count_nonzero((code != 0) & (code != 255)))


def maps(seed, shape=(13, 11, 8)):
    r = np.random.default_rng(seed)
    p = ndimage.median_filter(r.integers(0, 4, shape), size=3).astype(np.int16)
    g = ndimage.median_filter(r.integers(0, 4, shape), size=3).astype(np.int16)
    return p, g


def same(a, b):
    return a == b or (math.isnan(a) and math.isnan(b))


@test
def labels_match_a_brute_force_reference_seed_1_to_3(tmp):
    sp = (0.5, 1.25, 2.0)
    for seed in (1, 2, 3):
        p, g = maps(seed)
        pa, pb = os.path.join(tmp, "p.nii"), os.path.join(tmp, "g.nii.gz")
        write_nifti(pa, p, pixdim=sp)
        write_nifti(pb, g, pixdim=sp)
        j = run_json(["--labels", "all", "--percentile", "90", "--tau", "1.5", pa, pb])
        labels = sorted((set(np.unique(p).tolist()) | set(np.unique(g).tolist())) - {0})
        assert [r["label"] for r in j["labels"]] == labels, (seed, j["labels"])
        for r in j["labels"]:
            mp, mg = p == r["label"], g == r["label"]
            a, b = points(surface(mp), sp), points(surface(mg), sp)
            da, db = brute(a, b), brute(b, a)
            ctx = (seed, r["label"])
            assert (r["points_a"], r["points_b"]) == (len(a), len(b)), ctx
            assert r["hd_ab"] == da.max() and r["hd_ba"] == db.max(), ctx
            assert r["hausdorff"] == max(da.max(), db.max()), ctx
            assert r["hd_p"] == max(np.percentile(da, 90), np.percentile(db, 90)), ctx
            assert r["hd_p_pooled"] == np.percentile(np.concatenate([da, db]), 90), ctx
            assert r["assd"] == math.fsum(np.concatenate([da, db])) / (len(da) + len(db)), ctx
            assert r["nsd"] == (np.sum(da <= 1.5) + np.sum(db <= 1.5)) / (len(da) + len(db)), ctx
            assert r["dice"] == 2 * np.sum(mp & mg) / (mp.sum() + mg.sum()), ctx
            assert (r["surfels_a"], r["surfels_b"]) == (surfel_count(mp), surfel_count(mg)), ctx


@test
def components_are_scipy_labels_seed_4(tmp):
    p, g = maps(4)
    pa, pb = write_pair(tmp, p, g, ("p.nii", "g.nii"))
    for conn, rank in ((6, 1), (18, 2), (26, 3)):
        j = run_json(["--labels", "all", "--components", str(conn), pa, pb])
        st = ndimage.generate_binary_structure(3, rank)
        for r in j["labels"]:
            na = ndimage.label(p == r["label"], st)[1]
            nb = ndimage.label(g == r["label"], st)[1]
            assert (r["components_a"], r["components_b"]) == (na, nb), (conn, r["label"])
        mine = [c for c in j["components"]]
        assert len(mine) == sum(r["components_a"] + r["components_b"] for r in j["labels"])
        for c in mine:  # a component's figures are its surface voxels' distances
            assert c["nearest"] <= c["hd_p"] <= c["hausdorff"]
            assert c["detected"] == (c["overlap"] > 0 or c["nearest"] <= 1)


@test
def csv_and_text_carry_the_json_figures_seed_5(tmp):
    p, g = maps(5)
    pa, pb = write_pair(tmp, p, g, ("p.nii", "g.nii"), pixdim=(0.8, 0.8, 2.5))
    j = run_json(["--labels", "all", pa, pb])
    out, _ = run(["--labels", "all", "--csv", pa, pb])
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == len(j["labels"])
    for r, c in zip(j["labels"], rows):
        for k, v in r.items():
            assert same(float(c[k]), value(v)), (k, c[k], v)
    text, _ = run(["--labels", "all", pa, pb])
    lines = text.splitlines()
    assert lines[0].startswith("labels: %d " % len(j["labels"])), lines[0]
    assert "NSD_surfel" in lines[1] and len(lines) == 2 + len(j["labels"])


@test
def absent_labels_follow_empty(tmp):
    p, g = maps(6)
    g[g == 3] = 1  # label 3 only in the prediction
    pa, pb = write_pair(tmp, p, g, ("p.nii", "g.nii"))
    _, err = run(["--labels", "all", pa, pb], expect=2)
    assert "label 3 is absent from B" in err, err
    j = run_json(["--labels", "3,7", "--empty", "monai", pa, pb])
    r3, r7 = j["labels"]
    assert r3["empty"] == 2 and r3["hausdorff"] is None and r3["nsd"] == 0 and r3["nsd_surfel"] == 0
    assert r7["empty"] == 3 and r7["nsd"] is None and r7["dice"] is None
    j = run_json(["--labels", "3", "--empty", "zero", pa, pb])
    assert j["labels"][0]["hausdorff"] == 0 and j["labels"][0]["hd_surfel"] == 0


@test
def float_label_maps_hold_whole_numbers(tmp):
    p, g = maps(7)
    pa, pb, pc = (os.path.join(tmp, n) for n in ("p.nii", "g.nii", "bad.nii"))
    write_nifti(pa, p.astype(np.float32))
    write_nifti(pb, g)
    want = run_json(["--labels", "all", os.path.join(tmp, "p.nii"), pb])
    write_nifti(os.path.join(tmp, "pi.nii"), p)
    assert run_json(["--labels", "all", os.path.join(tmp, "pi.nii"), pb]) == want
    bad = p.astype(np.float32)
    bad[0, 0, 0] = 0.5
    write_nifti(pc, bad)
    _, err = run(["--labels", "all", pc, pb], expect=2)
    assert "whole numbers" in err, err


@test
def bad_label_options_are_usage_errors(tmp):
    p, g = maps(8)
    pa, pb = write_pair(tmp, p, g, ("p.nii", "g.nii"))
    for args in (["--labels", "1,x"], ["--labels", ""], ["--labels", "all", "--components", "5"],
                 ["--labels", "all", "--csv", "--json"], ["--labels", "all", "--mean"],
                 ["--labels", "all", "--tau", "1,2"], ["--labels", "all", "--directed"]):
        _, err = run(args + [pa, pb], expect=1)
        assert "--labels" in err or "--components" in err, (args, err)
    small = os.path.join(tmp, "small.nii")
    write_nifti(small, p[:5])
    _, err = run(["--labels", "all", small, pb], expect=2)
    assert "compared voxel by voxel" in err, err


if __name__ == "__main__":
    main()
