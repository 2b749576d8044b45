"""NIfTI masks against the values MONAI's and medpy's own test suites
publish: the masks of those tests are rebuilt here from their definitions,
written with nibabel (as a user's masks are), and the tool's answers are
compared with the published numbers at the published tolerance.

Sources (the numbers below are quoted from them; the masks are rebuilt from
their descriptions, no code is copied):
  MONAI  tests/test_hausdorff_distance.py   (commit 06b28e5b, Apache-2.0)
  MONAI  tests/metrics/test_surface_distance.py (commit a34ca8ae, Apache-2.0)
  MONAI  tests/test_surface_distance.py     (commit 08c00907, MONAI 0.x)
  medpy  tests/metric_/surface.py           (commit 919d2f83, GPL-3.0)
  medpy  tests/metric_/binary.py            (commit 3fbdf6c9, GPL-3.0)
How each library's figure maps onto the tool's JSON is in docs/analysis.md,
"Against MONAI and medpy".  For medpy's `connectivity` the expected values
are computed here from medpy's definition with scipy.ndimage (border =
mask ^ binary_erosion(mask, generate_binary_structure(ndim, c)), distances
from distance_transform_edt), since its suite has no case for it.

usage: cli_nifti_reference.py HAUSDORFF [NAME-FILTER]
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_analysis_support import main, nearest, run, run_json, test  # noqa: E402

import nibabel as nib  # noqa: E402  (Debian: python3-nibabel, scripts/deps.sh test)
from scipy import ndimage  # noqa: E402


def save(path, vol, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), version=1, units="mm"):
    """A mask as nibabel writes it: sform and qform = diag(spacing) + origin."""
    vol = np.asarray(vol)
    n = vol.ndim
    aff = np.eye(4)
    for a in range(min(n, 3)):
        aff[a, a] = spacing[a]
    aff[:3, 3] = origin
    img = (nib.Nifti1Image if version == 1 else nib.Nifti2Image)(vol, aff)
    if units:
        img.header.set_xyzt_units(units)
    nib.save(img, path)
    return path


def close(got, want, rtol, what):
    if want == 0:
        assert got == 0, (what, got)
    else:
        assert abs(got - want) <= rtol * abs(want), "%s: %r, published %r" % (what, got, want)


# ---- MONAI ------------------------------------------------------------------

def sphere(radius=20.0, centre=(49, 49, 49), shape=(99, 99, 99), spacing=(1.0, 1.0, 1.0)):
    """MONAI's create_spherical_seg_3d: voxel (i, j, k) is 1 when
    (i*s0 - c0)^2 + (j*s1 - c1)^2 + (k*s2 - c2)^2 <= radius^2."""
    g = [np.arange(shape[a], dtype=float)[tuple(slice(None) if b == a else None for b in range(3))] * spacing[a]
         - centre[a] for a in range(3)]
    return ((g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) <= radius * radius).astype(np.int32)


SP = (0.85, 1.2, 0.9)
# (seg_1 = y_pred, seg_2 = y, spacing, percentile,
#  published euclidean (directed = h(pred, gt), undirected))
MONAI_HD = [
    ("identical spheres", dict(), dict(), None, None, (0, 0)),
    ("spheres shifted by (1,1,1)", dict(centre=(20, 20, 20)), dict(centre=(19, 19, 19)), None, None,
     (1.7320508075688772, 1.7320508075688772)),
    ("large spheres shifted by 1", dict(radius=33, centre=(19, 33, 22)), dict(radius=33, centre=(20, 33, 22)),
     None, None, (1, 1)),
    ("radius 20 inside radius 40", dict(centre=(20, 33, 22)), dict(radius=40, centre=(20, 33, 22)), None, None,
     (20.09975124224178, 20.223748416156685)),
    ("HD95, radius 20 inside radius 40", dict(centre=(20, 33, 22)), dict(radius=40, centre=(20, 33, 22)), None,
     95, (19.924858845171276, 20.09975124224178)),
    ("anisotropic spacing, shifted", dict(centre=(20, 20, 20), spacing=SP), dict(centre=(19, 19, 19), spacing=SP),
     SP, None, (2.0808651447296143, 2.2671568)),
    ("anisotropic spacing, radius 15 inside 30", dict(radius=15, centre=(20, 33, 22), spacing=SP),
     dict(radius=30, centre=(20, 33, 22), spacing=SP), SP, None, (15.439640998840332, 15.62594)),
]


@test
def monai_hausdorff_distance_published_values(tmp):
    """MONAI HausdorffDistanceMetric (euclidean), rtol 1e-6 as its test:
    directed is h(pred, gt) = our directed_ab, undirected max(h, h') = our
    hausdorff; with percentile=95 our percentile.ab and .symmetric.  Spacing
    goes into the header (NIfTI-2 here: float64, as MONAI's spacing)."""
    for k, (name, a, b, spacing, pct, (directed, undirected)) in enumerate(MONAI_HD):
        version = 2 if spacing else 1
        ext = ".nii" if spacing else ".nii.gz"
        pa = save(os.path.join(tmp, "pred%d%s" % (k, ext)), sphere(**a), spacing or (1, 1, 1), version=version)
        pb = save(os.path.join(tmp, "gt%d%s" % (k, ext)), sphere(**b), spacing or (1, 1, 1), version=version)
        args = ["--percentile", str(pct)] if pct else []
        r = run_json(args + [pa, pb])
        if pct:
            close(r["percentile"]["ab"], directed, 1e-6, name + " directed")
            close(r["percentile"]["symmetric"], undirected, 1e-6, name + " undirected")
        else:
            close(r["directed_ab"], directed, 1e-6, name + " directed")
            close(r["hausdorff"], undirected, 1e-6, name + " undirected")
            d = run_json(["--directed", pa, pb])
            close(d["directed_ab"], directed, 1e-6, name + " --directed")


# (seg_1 = y_pred, seg_2 = y, spacing, published (symmetric, not symmetric)),
# MONAI 1.x (tests/metrics/test_surface_distance.py, commit a34ca8ae, rtol 1e-5)
MONAI_ASD = [
    ("identical spheres", dict(), dict(), None, (0, 0)),
    ("large spheres shifted by 1", dict(radius=33, centre=(19, 33, 22)), dict(radius=33, centre=(20, 33, 22)),
     None, (0.350217, 0.3483278807706289)),
    ("radius 20 inside radius 40", dict(centre=(20, 33, 22)), dict(radius=40, centre=(20, 33, 22)), None,
     (15.117741, 12.040033513150455)),
    ("anisotropic spacing, shifted by 1", dict(radius=33, centre=(42, 45, 52), spacing=SP),
     dict(radius=33, centre=(43, 45, 52), spacing=SP), SP, (0.4951, 0.4951)),
]
# MONAI 0.x (tests/test_surface_distance.py, commit 08c00907, rtol 1e-7): then
# symmetric was the average of the two one-way means, our mean.average
MONAI_ASD_OLD = [
    ("large spheres shifted by 1", dict(radius=33, centre=(19, 33, 22)), dict(radius=33, centre=(20, 33, 22)),
     0.35021200688332677),
    ("radius 20 inside radius 40", dict(centre=(20, 33, 22)), dict(radius=40, centre=(20, 33, 22)),
     13.975673696300824),
]


@test
def monai_average_surface_distance_published_values(tmp):
    """MONAI SurfaceDistanceMetric (euclidean): symmetric=True is, since
    MONAI 1.0, the mean over both surfaces together = our mean.pooled;
    symmetric=False the mean of pred's surface to gt = our mean.ab.  MONAI
    0.x's symmetric figure was (mean.ab + mean.ba) / 2 = our mean.average."""
    for k, (name, a, b, spacing, (symmetric, one_way)) in enumerate(MONAI_ASD):
        pa = save(os.path.join(tmp, "pred%d.nii.gz" % k), sphere(**a), spacing or (1, 1, 1), version=2)
        pb = save(os.path.join(tmp, "gt%d.nii.gz" % k), sphere(**b), spacing or (1, 1, 1), version=2)
        r = run_json(["--mean", pa, pb])
        close(r["mean"]["pooled"], symmetric, 1e-5, name + " symmetric")
        close(r["mean"]["ab"], one_way, 1e-5, name + " not symmetric")
    for k, (name, a, b, average) in enumerate(MONAI_ASD_OLD):
        pa = save(os.path.join(tmp, "old_pred%d.nii" % k), sphere(**a))
        pb = save(os.path.join(tmp, "old_gt%d.nii" % k), sphere(**b))
        close(run_json(["--mean", pa, pb])["mean"]["average"], average, 1e-7, name + " (MONAI 0.x) symmetric")


@test
def monai_empty_masks_with_empty_monai(tmp):
    """MONAI: inf when pred or gt has no foreground, NaN when neither has
    (its test_nans): --empty monai, inf and NaN being null in JSON."""
    full = save(os.path.join(tmp, "full.nii.gz"), sphere())
    empty = save(os.path.join(tmp, "empty.nii.gz"), np.zeros((99, 99, 99), np.int32))
    for a, b, which in ((empty, full, {"a": True, "b": False}), (full, empty, {"a": False, "b": True})):
        r = run_json(["--empty", "monai", "--percentile", "95", "--mean", a, b])
        assert r["hausdorff"] is None and r["empty"] == dict(which, policy="monai"), r
        out, _ = run(["--empty", "monai", a, b])
        assert "= inf" in out, out
    out, _ = run(["--empty", "monai", empty, empty])
    assert "= nan" in out and "A and B are empty" in out, out


# ---- medpy ------------------------------------------------------------------

def medpy_images():
    """medpy's tests/metric_/surface.py images (bool)."""
    d1 = np.zeros((2, 2, 2), bool)
    d1[0, 0, 0] = True
    d2 = np.zeros((2, 2, 2), bool)
    d2[1, 1, 1] = True
    d4 = np.zeros((4, 4, 4), bool)
    for k in range(4):
        d4[k, k, k] = True
    cube = np.zeros((5, 5, 5), bool)
    cube[1:4, 1:4, 1:4] = True
    cube[2, 2, 2] = False
    centre = np.zeros((5, 5, 5), bool)
    centre[2, 2, 2] = True
    return d1, d2, d4, cube, centre


@test
def medpy_surface_class_published_values(tmp):
    """medpy.metric.surface.Surface: maximum, average and root-mean-square
    symmetric surface distance to 7 places (assertAlmostEqual).  Its
    'average symmetric' is the mean over both surfaces together (our
    mean.pooled); RMS is sqrt(chamfer.sum_squared / (n_a + n_b)).  Its
    offsets are in voxels: the header's origin is offset x spacing."""
    d1, d2, d4, cube, centre = medpy_images()
    r3 = math.sqrt(3)
    cases = [  # (name, A, B, spacing, offset of B, (max, average, rms))
        ("same image", d1, d1, 1, 0, (0, 0, 0)),
        ("similar image", d1, d2, 1, 0, (1.732050808, 1.732050808, 1.732050808)),
        ("shifted image", d1, d1, 1, 1, (1.732050808, 1.732050808, 1.732050808)),
        ("shifted, spacing 2", d1, d1, 2, 1, (3.464101615, 3.464101615, 3.464101615)),
        ("different image", d1, d4, 1, 0, (5.196152423, 2.078460969, 2.898275349)),
        ("cube A->B", cube, centre, 1, 0, (1.73205080757, 1.40099885959, 1.4272480643)),
        ("cube B->A", centre, cube, 1, 0, (1.73205080757, 1.40099885959, 1.4272480643)),
    ]
    assert abs(5.196152423 - 3 * r3) < 1e-9  # the published numbers are what they seem
    for k, (name, a, b, sp, off, (hd, avg, rms)) in enumerate(cases):
        pa = save(os.path.join(tmp, "a%d.nii" % k), a.astype(np.uint8), (sp,) * 3)
        pb = save(os.path.join(tmp, "b%d.nii" % k), b.astype(np.uint8), (sp,) * 3, origin=(off * sp,) * 3)
        r = run_json(["--mean", "--chamfer", pa, pb])
        got_rms = math.sqrt(r["chamfer"]["sum_squared"] / (r["n_a"] + r["n_b"]))
        for got, want, what in ((r["hausdorff"], hd, "max"), (r["mean"]["pooled"], avg, "average"),
                                (got_rms, rms, "rms")):
            assert round(got - want, 7) == 0, "%s %s: %r, published %r" % (name, what, got, want)
    # medpy's contour test: a 3x3x3 cube in a 4x4x4 image loses only its centre
    c = np.zeros((4, 4, 4), np.uint8)
    c[:3, :3, :3] = 1
    pc = save(os.path.join(tmp, "contour.nii"), c)
    assert run_json([pc, pc])["n_a"] == 26


MIN_RESULT, MIN_REFERENCE = np.array([1, 0], np.uint8), np.array([0, 1], np.uint8)
SYM_RESULT = np.array([[1, 0, 0, 0], [1, 0, 0, 0], [1, 0, 0, 0], [1, 1, 0, 0]], np.uint8)
SYM_REFERENCE = np.array([[1, 1, 0, 0], [1, 0, 0, 0], [1, 0, 0, 0], [0, 0, 0, 0]], np.uint8)


def medpy_surface_distances(result, reference, spacing, connectivity=1):
    """medpy.metric.binary.__surface_distances, from its definition."""
    result, reference = result.astype(bool), reference.astype(bool)
    fp = ndimage.generate_binary_structure(result.ndim, connectivity)
    rb = result ^ ndimage.binary_erosion(result, structure=fp, iterations=1)
    fb = reference ^ ndimage.binary_erosion(reference, structure=fp, iterations=1)
    return ndimage.distance_transform_edt(~fb, sampling=spacing)[rb]


@test
def medpy_binary_published_values_on_1d_and_2d_masks(tmp):
    """medpy.metric.binary: asd([1,0], [0,1]) == 1, == 2 with spacing 2, assd
    the same (a 1-D mask, dim[0] = 1); asd is not symmetric on its 4x4 pair
    (the values from its definition), assd is.  asd(result, reference) is
    our mean.ab; assd, the mean of both directions' distances together
    (medpy 0.5 averages the two lists, not the two asd), our mean.pooled,
    which differs from mean.average = (asd + asd') / 2 on that pair."""
    for sp, want in ((1.0, 1.0), (2.0, 2.0)):
        pa = save(os.path.join(tmp, "r.nii"), MIN_RESULT, (sp, 1, 1))
        pb = save(os.path.join(tmp, "f.nii"), MIN_REFERENCE, (sp, 1, 1))
        r = run_json(["--mean", pa, pb])
        assert r["masks"]["a"]["dim"] == [2, 1, 1]
        assert r["mean"]["ab"] == want and r["mean"]["pooled"] == want, r["mean"]
    pa = save(os.path.join(tmp, "rs.nii"), SYM_RESULT)
    pb = save(os.path.join(tmp, "fs.nii"), SYM_REFERENCE)
    m1 = run_json(["--mean", pa, pb])["mean"]
    m2 = run_json(["--mean", pb, pa])["mean"]
    sd1 = medpy_surface_distances(SYM_RESULT, SYM_REFERENCE, (1, 1))
    sd2 = medpy_surface_distances(SYM_REFERENCE, SYM_RESULT, (1, 1))
    asd1, asd2, assd = sd1.mean(), sd2.mean(), np.hstack((sd1, sd2)).mean()
    assert asd1 != asd2 and len(sd1) != len(sd2)
    assert abs(m1["ab"] - asd1) < 1e-15 and abs(m2["ab"] - asd2) < 1e-15, (m1, asd1, m2, asd2)
    assert m1["ab"] != m2["ab"] and m1["pooled"] == m2["pooled"]
    assert abs(m1["pooled"] - assd) < 1e-15, (m1, assd)
    assert abs(m1["average"] - assd) > 1e-3, (m1, assd)   # the two-means formula is not medpy's


def blob(seed, shape, centre, radii):
    r = np.random.default_rng(seed)
    g = np.indices(shape).astype(np.float64)
    q = sum(((g[a] - centre[a]) / radii[a]) ** 2 for a in range(len(shape)))
    return ((q + 0.25 * r.standard_normal(shape)) < 1.0).astype(np.uint8)


@test
def connectivity_is_medpys_on_3d_and_2d_masks(tmp):
    """--connectivity c: the border medpy computes with connectivity=c
    (generate_binary_structure(ndim, c); in 2-D, 3 acts as 2, as scipy's
    structure does), and its hd, hd95 and assd (both directions' distances
    averaged together: our mean.pooled) on it."""
    sp3 = (0.75, 1.25, 2.0)
    cases = [(blob(1, (20, 17, 13), (10, 8, 6), (7, 6, 4)), blob(2, (20, 17, 13), (9, 9, 6), (7, 5, 4)), sp3),
             (blob(3, (30, 26), (15, 12), (11, 8)), blob(4, (30, 26), (14, 13), (10, 9)), (0.75, 1.25))]
    for k, (a, b, sp) in enumerate(cases):
        pa = save(os.path.join(tmp, "a%d.nii.gz" % k), a, sp + (1.0,) * (3 - len(sp)))
        pb = save(os.path.join(tmp, "b%d.nii.gz" % k), b, sp + (1.0,) * (3 - len(sp)))
        counts = set()
        for c in (1, 2, 3):
            fp = ndimage.generate_binary_structure(a.ndim, c)
            border = a.astype(bool) ^ ndimage.binary_erosion(a.astype(bool), structure=fp)
            r = run_json(["--connectivity", str(c), "--percentile", "95", "--mean", pa, pb])
            assert r["n_a"] == int(border.sum()), (a.ndim, c, r["n_a"], int(border.sum()))
            assert r["masks"]["a"]["connectivity"] == min(c, a.ndim) and r["masks"]["a"]["surface_dims"] == a.ndim
            counts.add(r["n_a"])
            h1 = medpy_surface_distances(a, b, sp, c)
            h2 = medpy_surface_distances(b, a, sp, c)
            hd = max(h1.max(), h2.max())
            hd95 = np.percentile(np.hstack((h1, h2)), 95)
            assd = np.hstack((h1, h2)).mean()
            close(r["hausdorff"], hd, 1e-13, "hd, connectivity %d" % c)
            close(r["percentile"]["pooled"], hd95, 1e-13, "hd95, connectivity %d" % c)
            close(r["mean"]["pooled"], assd, 1e-13, "assd, connectivity %d" % c)
        assert len(counts) == (3 if a.ndim == 3 else 2), counts  # each neighbourhood its own border


if __name__ == "__main__":
    main()
