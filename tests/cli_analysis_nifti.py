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


def erosion_border(m, connectivity=1):
    """medpy's border of the array as given: m ^ binary_erosion(m,
    generate_binary_structure(m.ndim, connectivity)), border value 0."""
    from scipy import ndimage
    m = m.astype(bool)
    return m ^ ndimage.binary_erosion(m, structure=ndimage.generate_binary_structure(m.ndim, connectivity))


def surface_rows(tmp, path, args):
    """The voxel indices of the points the tool made of a mask (pixdim 1,
    no transform: the coordinates are the indices), in storage order."""
    csv = os.path.join(tmp, "rows.csv")
    run(args + ["--distances", csv, path, path])
    return np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)[:, :3].astype(int)


def storage_order(mask):
    ijk = np.argwhere(mask)
    return ijk[np.lexsort((ijk[:, 0], ijk[:, 1], ijk[:, 2]))]


@test
def mask_dims_2_erodes_each_slice_on_its_own(tmp):
    """--mask-dims 2: each slice of constant k is a 2-D mask; the surface is
    the union of their in-plane borders (a stack of contours, as RT
    structures are drawn), with the in-plane connectivity asked for."""
    m = blob(14, (16, 14, 7), (8, 7, 3), (6, 5, 4))
    path = os.path.join(tmp, "m.nii")
    write_nifti(path, m)
    for c in (1, 2):
        want = np.zeros(m.shape, bool)
        for k in range(m.shape[2]):
            want[:, :, k] = erosion_border(m[:, :, k], c)
        got = surface_rows(tmp, path, ["--mask-dims", "2", "--connectivity", str(c)])
        assert np.array_equal(got, storage_order(want)), (c, len(got), int(want.sum()))
        assert len(got) != len(voxels(m, True))  # not the 3-D surface
        r = run_json(["--mask-dims", "2", "--connectivity", str(c), path, path])
        assert r["mask_dims"] == 2 and r["masks"]["a"]["surface_dims"] == 2 and r["masks"]["a"]["connectivity"] == c


@test
def mask_dims_3_keeps_an_axis_of_one_voxel_as_medpy_on_the_unsqueezed_array(tmp):
    """--mask-dims 3 on a single slice: all three axes, the empty z
    neighbours outside the image included -- every foreground voxel, what
    medpy answers for the (nx, ny, 1) array; auto gives the in-plane border."""
    m = blob(15, (20, 18, 1), (10, 9, 0), (8, 7, 1))
    path = os.path.join(tmp, "s.nii")
    write_nifti(path, m)
    assert np.array_equal(surface_rows(tmp, path, ["--mask-dims", "3"]), storage_order(erosion_border(m)))
    assert len(surface_rows(tmp, path, ["--mask-dims", "3"])) == int(m.sum())
    flat = np.zeros(m.shape, bool)
    flat[:, :, 0] = erosion_border(m[:, :, 0])
    assert np.array_equal(surface_rows(tmp, path, []), storage_order(flat))
    assert np.array_equal(surface_rows(tmp, path, ["--mask-dims", "auto"]), storage_order(flat))


@test
def connectivity_2_and_3_give_scipys_border_and_exact_distances(tmp):
    """--connectivity 2 and 3 on 3-D masks with a rotated sform: the points
    are scipy's border for that structure, the distances the brute force's
    to the bit."""
    ma = blob(16, (14, 13, 10), (7, 6, 5), (5, 5, 3))
    mb = blob(17, (14, 13, 10), (6, 7, 5), (5, 4, 3))
    m = np.zeros((3, 4))
    m[:, :3] = rotation(0.2, -0.4, 0.9) * [0.8, 1.1, 1.7]
    m[:, 3] = [3.5, -2.25, 11.0]
    ms = stored(m, 1)
    pa, pb = os.path.join(tmp, "a.nii.gz"), os.path.join(tmp, "b.nii.gz")
    write_nifti(pa, ma, sform=m)
    write_nifti(pb, mb, sform=m)
    for c in (2, 3):
        A = world(storage_order(erosion_border(ma, c)), ms)
        B = world(storage_order(erosion_border(mb, c)), ms)
        dab, _ = nearest(A, B)
        dba, _ = nearest(B, A)
        r = run_json(["--connectivity", str(c), "--percentile", "95", pa, pb])
        assert (r["n_a"], r["n_b"]) == (len(A), len(B)), (c, r["n_a"], len(A))
        same(r["hausdorff"], max(dab.max(), dba.max()), "H, connectivity %d" % c)
        same(r["percentile"]["pooled"], np.percentile(np.hstack((dab, dba)), 95), "HD95, connectivity %d" % c)


@test
def mask_options_are_checked_and_listed_in_help(tmp):
    path = os.path.join(tmp, "m.nii")
    write_nifti(path, blob(18, (6, 6, 6), (3, 3, 3), (2, 2, 2)))
    for args, words in ((["--connectivity", "4"], "1, 2 or 3"), (["--connectivity", "0"], "1, 2 or 3"),
                        (["--mask-dims", "1"], "auto, 2 or 3"), (["--mask-dims", "4"], "auto, 2 or 3")):
        _, err = run(args + [path, path], expect=1)
        assert words in err, (args, err)
    out, _ = run(["--help"])
    for words in ("--connectivity 1|2|3", "--mask-dims auto|2|3", "--units TEXT"):
        assert words in out, words


@test
def units_come_from_the_header_or_units_and_are_null_when_unknown(tmp):
    """The header's xyzt_units: mm, um and m are reported in mm; unknown (0)
    gives no unit (null), and a line that says it was taken as mm; --units
    labels any input."""
    m = blob(19, (6, 6, 6), (3, 3, 3), (2, 2, 2))
    for code, want in ((2, "mm"), (3, "mm"), (1, "mm"), (0, None)):
        path = os.path.join(tmp, "u%d.nii" % code)
        write_nifti(path, m, units=code)
        r = run_json(["--percentile", "95", path, path])
        assert r["units"] == want and r["masks"]["a"]["unit_known"] == (want is not None), (code, r["units"])
        out, _ = run(["--percentile", "95", path, path])
        assert ("(mm)" in out) == (want is not None), out
        assert ("unit not given" in out) == (want is None), out
        assert ("H(A,B) = 0 mm\n" in out) == (want is not None), out  # the distance says its unit
    r = run_json(["--units", "um", path, path])
    assert r["units"] == "um"


if __name__ == "__main__":
    main()
