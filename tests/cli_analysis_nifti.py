"""NIfTI masks as point sets: the tool's HD, HD95 and per-point distances in
millimetres agree bit for bit with a brute force in world coordinates, for
NIfTI-1 and NIfTI-2, .nii and .nii.gz, anisotropic spacing, a rotated sform,
a flipping qform, metres, and both --mask-points modes; the surface is the
one medpy and MONAI use (scipy's binary erosion).

usage: cli_analysis_nifti.py HAUSDORFF [NAME-FILTER]
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_analysis_support import (main, nearest, run, run_json, same, stored, test,  # noqa: E402
                                  voxels, world, write_nifti)


def blob(seed, shape, centre, radii):
    """A noisy ellipsoid mask (uint8)."""
    r = np.random.default_rng(seed)
    g = np.indices(shape).astype(np.float64)
    q = sum(((g[a] - centre[a]) / radii[a]) ** 2 for a in range(3))
    return ((q + 0.15 * r.standard_normal(shape)) < 1.0).astype(np.uint8)


def rotation(ax, ay, az):
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def check_pair(tmp, ma, mb, m_a, m_b, surface=True, ext=".nii.gz", version=1, to_mm=1.0, **kw):
    """Write two masks, run the tool, compare with the brute force."""
    pa, pb = os.path.join(tmp, "a" + ext), os.path.join(tmp, "b" + ext)
    write_nifti(pa, ma, version=version, **kw.get("a", {}))
    write_nifti(pb, mb, version=version, **kw.get("b", {}))
    A = world(voxels(ma, surface), m_a)
    B = world(voxels(mb, surface), m_b)
    if to_mm != 1.0:
        A, B = A * to_mm, B * to_mm
    dab, jab = nearest(A, B)
    dba, jba = nearest(B, A)
    csv = os.path.join(tmp, "d.csv")
    r = run_json(["--percentile", "95", "--mean", "--distances", csv,
                  "--mask-points", "surface" if surface else "all", pa, pb])
    assert r["n_a"] == len(A) and r["n_b"] == len(B), (r["n_a"], len(A), r["n_b"], len(B))
    assert r["units"] == "mm"
    same(r["directed_ab"], dab.max(), "h(A,B)")
    same(r["directed_ba"], dba.max(), "h(B,A)")
    same(r["hausdorff"], max(dab.max(), dba.max()), "H")
    p = r["percentile"]
    same(p["ab"], np.percentile(dab, 95), "HD95 ab")
    same(p["ba"], np.percentile(dba, 95), "HD95 ba")
    same(p["symmetric"], max(np.percentile(dab, 95), np.percentile(dba, 95)), "HD95 MONAI")
    same(p["pooled"], np.percentile(np.hstack((dab, dba)), 95), "HD95 medpy")
    rows = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
    assert np.array_equal(rows[:, :3], A), "points in storage order, world coordinates"
    assert np.array_equal(rows[:, 3], dab) and np.array_equal(rows[:, 4], jab)
    return r


@test
def anisotropic_spacing_with_a_rotated_sform_in_nifti1_gz(tmp):
    ma = blob(1, (18, 15, 11), (8, 7, 5), (6, 5, 4))
    mb = blob(2, (18, 15, 11), (9, 7, 5), (6, 4.5, 4))
    sp = np.array([0.7, 1.3, 2.5])
    m = np.zeros((3, 4))
    m[:, :3] = rotation(0.3, -0.5, 1.1) * sp
    m[:, 3] = [-12.25, 30.5, 7.75]
    ms = stored(m, 1)
    r = check_pair(tmp, ma, mb, ms, ms, a={"pixdim": sp, "sform": m}, b={"pixdim": sp, "sform": m})
    assert r["masks"]["a"]["transform"] == "sform" and r["masks"]["a"]["nifti"] == 1


@test
def nifti2_with_different_sforms_for_the_two_masks(tmp):
    ma = blob(3, (14, 16, 12), (7, 8, 6), (5, 6, 4))
    mb = blob(4, (20, 10, 12), (10, 5, 6), (7, 4, 4))
    m1 = np.zeros((3, 4))
    m1[:, :3] = rotation(0.1, 0.2, 0.3) * [0.9, 1.1, 2.0]
    m1[:, 3] = [1, 2, 3]
    m2 = np.zeros((3, 4))
    m2[:, :3] = rotation(-0.2, 0.1, 0.0) * [1.05, 0.8, 1.5]
    m2[:, 3] = [-1.5, 4, 2]
    r = check_pair(tmp, ma, mb, m1, m2, ext=".nii", version=2, a={"sform": m1}, b={"sform": m2})
    assert r["masks"]["b"]["nifti"] == 2


@test
def qform_with_a_flip_and_spacing_when_there_is_no_sform(tmp):
    ma = blob(5, (12, 12, 9), (6, 6, 4), (4, 5, 3))
    mb = blob(6, (12, 12, 9), (6, 5, 4), (5, 4, 3))
    q = {"b": 1.0, "c": 0.0, "d": 0.0, "qfac": -1.0, "offset": (-10.5, 20.25, 3.0)}
    sp = (0.5, 1.25, 3.0)
    # 180 degrees about x, then qfac -1 flips k: columns dx, -dy, -dz*qfac
    m = np.array([[0.5, 0, 0, -10.5], [0, -1.25, 0, 20.25], [0, 0, 3.0, 3.0]])
    r = check_pair(tmp, ma, mb, m, m, ext=".nii", a={"pixdim": sp, "qform": q}, b={"pixdim": sp, "qform": q})
    assert r["masks"]["a"]["transform"] == "qform"


@test
def all_foreground_voxels_and_pixdim_only_headers(tmp):
    ma = blob(7, (10, 9, 8), (5, 4, 4), (4, 3, 3))
    mb = blob(8, (10, 9, 8), (4, 4, 4), (3, 4, 3))
    m = np.array([[0.8, 0, 0, 0], [0, 1.6, 0, 0], [0, 0, 2.4, 0]])
    sp = (0.8, 1.6, 2.4)
    ms = stored(m, 1)
    r = check_pair(tmp, ma, mb, ms, ms, surface=False, a={"pixdim": sp}, b={"pixdim": sp})
    assert r["mask_points"] == "all" and r["masks"]["a"]["transform"] == "pixdim"


@test
def metres_are_reported_in_millimetres(tmp):
    ma = blob(9, (9, 9, 9), (4, 4, 4), (3, 3, 3))
    mb = blob(10, (9, 9, 9), (4, 5, 4), (3, 3, 3))
    m = np.array([[0.001, 0, 0, 0.01], [0, 0.002, 0, 0], [0, 0, 0.0015, 0]])
    ms = stored(m, 1)
    check_pair(tmp, ma, mb, ms, ms, to_mm=1000.0, a={"sform": m, "units": 1}, b={"sform": m, "units": 1})


@test
def surface_is_what_medpy_gets_by_binary_erosion(tmp):
    from scipy import ndimage
    m = blob(11, (16, 14, 12), (8, 7, 6), (6, 5, 4)).astype(bool)
    structure = ndimage.generate_binary_structure(3, 1)
    border = m ^ ndimage.binary_erosion(m, structure=structure, iterations=1)
    assert np.array_equal(np.sort(np.ravel_multi_index(np.argwhere(border).T, m.shape)),
                          np.sort(np.ravel_multi_index(voxels(m, True).T, m.shape)))
    path = os.path.join(tmp, "m.nii")
    write_nifti(path, m.astype(np.uint8))
    r = run_json([path, path])
    assert r["n_a"] == int(border.sum()) and r["hausdorff"] == 0


@test
def float_and_int16_masks_count_nonzero_voxels_as_foreground(tmp):
    m = blob(12, (8, 8, 8), (4, 4, 4), (3, 3, 3))
    pf, pi = os.path.join(tmp, "f.nii"), os.path.join(tmp, "i.nii")
    write_nifti(pf, (m * 0.5).astype(np.float32))
    write_nifti(pi, (m * 7).astype(np.int16))
    r = run_json(["--mask-points", "all", pf, pi])
    assert r["n_a"] == int(m.sum()) == r["n_b"] and r["hausdorff"] == 0


@test
def an_empty_mask_is_an_error_unless_empty_chooses_a_value(tmp):
    full, empty = os.path.join(tmp, "full.nii"), os.path.join(tmp, "empty.nii")
    write_nifti(full, blob(13, (6, 6, 6), (3, 3, 3), (2, 2, 2)))
    write_nifti(empty, np.zeros((6, 6, 6), np.uint8))
    _, err = run([full, empty], expect=2)
    assert "no foreground" in err and "--empty" in err, err
    r = run_json(["--empty", "inf", "--percentile", "95", full, empty])
    assert r["hausdorff"] is None and r["empty"] == {"a": False, "b": True, "policy": "inf"}
    assert r["percentile"]["symmetric"] is None
    r = run_json(["--empty", "zero", "--percentile", "95", empty, empty])
    assert r["hausdorff"] == 0 and r["percentile"]["pooled"] == 0 and r["empty"]["a"]
    out, _ = run(["--empty", "nan", full, empty])
    assert "nan" in out and "B is empty" in out, out


@test
def a_file_that_is_not_nifti_is_bad_input(tmp):
    bad = os.path.join(tmp, "bad.nii")
    with open(bad, "wb") as f:
        f.write(b"not an image at all" * 30)
    _, err = run([bad, bad], expect=2)
    assert "bad.nii" in err, err


if __name__ == "__main__":
    main()
