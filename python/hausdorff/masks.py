"""Distances between segmentation masks (numpy arrays), exact.

The metrics MONAI, medpy and DeepMind's surface-distance compute on masks:
Hausdorff distance and its percentiles (HD95), average surface distances
(ASSD), the normalized surface Dice at a tolerance (NSD), Dice, and the
precision / recall / F-score of the surfaces at a tolerance.  A mask is any
numpy array of 1 to 3 dimensions (bool or numbers: nonzero is foreground);
``spacing`` gives the voxel size along each axis (default 1).

Surfaces are what medpy and MONAI erode them to: the foreground voxels that
binary erosion with scipy's ``generate_binary_structure(ndim,
connectivity)`` removes, the outside of the array counting as background.
The surface is found by the C library's ``hd_mask_points``, the function the
command line reads NIfTI masks with, and every figure is the library's, so
the numbers equal the command line's (``hausdorff pred.nii.gz gt.nii.gz
--percentile 95 --mean --tau 1``) to the bit.  A voxel (i, j, k) is the
point (i * spacing[0], j * spacing[1], k * spacing[2]): axis order is the
array's.

>>> import numpy as np
>>> from hausdorff import masks
>>> gt = np.zeros((20, 20, 20), bool); gt[5:15, 5:15, 5:15] = True
>>> pred = np.roll(gt, 2, axis=0)
>>> masks.hausdorff(pred, gt, spacing=(0.5, 1, 1))
1.0
>>> m = masks.metrics(pred, gt, spacing=(0.5, 1, 1), percentile=95, tau=[0.5, 1])
>>> m.nsd
[0.6639344262295082, 1.0]

Which figure is whose (docs/analysis.md has the formulas):

- ``hausdorff(..., percentile=P, definition="monai")``: max of the two
  directed P-th percentiles, MONAI's ``compute_hausdorff_distance``;
  ``definition="medpy"``: the P-th percentile of both directions' distances
  pooled, medpy's ``hd95``.  Without a percentile both are the maximum.
- ``assd(..., definition="pooled")``: the mean of both directions'
  distances together, MONAI's ``compute_average_surface_distance(
  symmetric=True)`` and medpy 0.5's ``assd``; ``"average"``: the mean of the
  two directed means (MONAI 0.x).
- ``nsd(..., definition="monai")``: MONAI's ``compute_surface_dice`` (voxel
  counts, ``use_subvoxels=False``): the surface voxels of both masks within
  tau of the other surface, over all surface voxels.
  ``definition="deepmind"`` (= ``"monai_subvoxels"``): DeepMind's
  ``compute_surface_dice_at_tolerance`` and MONAI's ``use_subvoxels=True``:
  surfels (cubes of 2 x 2 x 2 voxels the boundary crosses) weighted by
  their marching-cubes area.
- ``hausdorff(..., definition="deepmind")``, ``assd(...,
  definition="deepmind")``: DeepMind's area-weighted ``compute_robust_hausdorff``
  and the mean of its ``compute_average_surface_distance`` pair.
- ``dice``: 2 |A and B| / (|A| + |B|), NaN when both are empty.
- ``label_map(pred_labels, gt_labels, spacing)``: every label's figures
  (all of the above) in one call, a list of dicts; ``components(...)``:
  each connected component's directed distances and detection.
- ``surfels``, ``surface_distances``: DeepMind's surfels and its
  ``compute_surface_distances`` dict.

Empty masks follow ``empty`` as the rest of the module: "error" (the
default) raises ValueError; "monai" gives inf for a distance when one mask
is empty and NaN when both are, and an NSD of 0 or NaN, as MONAI does;
"inf", "nan", "zero" give that value for every distance.
"""
from __future__ import annotations

import dataclasses
import math
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _hausdorff

__all__ = ["MaskMetrics", "surface", "distances", "hausdorff", "assd", "nsd", "dice", "fscore", "metrics",
           "label_map", "components", "surfels", "surface_distances", "ROW_FIELDS", "COMPONENT_FIELDS"]

_EMPTY = ("error", "inf", "nan", "zero", "monai", "skimage")


def _voxels(mask, name: str) -> np.ndarray:
    m = np.asarray(mask)
    if m.ndim < 1 or m.ndim > 3:
        raise ValueError(f"{name}: a mask has 1 to 3 dimensions, not {m.ndim}")
    if m.size == 0:
        raise ValueError(f"{name}: the mask has no voxels (shape {m.shape})")
    if m.dtype.kind == "f" and np.isnan(m).any():
        fg = (m != 0) & ~np.isnan(m)  # NaN is background, as the NIfTI reader has it
    else:
        fg = m != 0
    return np.asfortranarray(fg, dtype=np.uint8)


def _spacing(spacing, ndim: int) -> Tuple[float, float, float]:
    if spacing is None:
        s = [1.0] * ndim
    else:
        s = [float(v) for v in np.atleast_1d(np.asarray(spacing, dtype=np.float64))]
        if len(s) != ndim:
            raise ValueError(f"spacing has {len(s)} values; the masks have {ndim} dimensions")
        if not all(math.isfinite(v) and v > 0 for v in s):
            raise ValueError(f"spacing must be finite and positive, not {tuple(s)}")
    return tuple(s + [1.0] * (3 - ndim))  # type: ignore[return-value]


def _dims(dims) -> int:
    if dims in ("auto", 0, None):
        return 0
    if dims in (2, 3):
        return int(dims)
    raise ValueError(f"dims is 'auto', 2 or 3, not {dims!r}")


def _points(v: np.ndarray, spacing, connectivity: int, dims, all: bool) -> Tuple[np.ndarray, int]:
    """The points of the converted mask v (_voxels) and its foreground count."""
    n = list(v.shape) + [1] * (3 - v.ndim)
    s = _spacing(spacing, v.ndim)
    if connectivity not in (1, 2, 3):
        raise ValueError(f"connectivity is 1, 2 or 3, not {connectivity!r}")
    # v is Fortran-ordered (axis 0 fastest, as the library reads voxels);
    # its transpose is the same memory, C-contiguous, read without a copy
    raw, fg, _sd, _c = _hausdorff._mask_points(v.T, n[0], n[1], n[2], s[0], s[1], s[2],
                                               connectivity, _dims(dims), bool(all))
    return np.frombuffer(raw, dtype=np.float64).reshape(-1, 3).copy(), fg


def surface(mask, spacing=None, *, connectivity: int = 1, dims="auto", all: bool = False) -> np.ndarray:
    """The (n, 3) float64 points of a mask's surface voxels (every
    foreground voxel with all=True), in storage order of axis 0 fastest.
    connectivity 1, 2, 3 as medpy's; dims "auto" erodes along the axes of
    more than one voxel, 2 each slice of constant axis 2 on its own, 3 all
    three (the command line's --mask-dims)."""
    return _points(_voxels(mask, "mask"), spacing, connectivity, dims, all)[0]


def _pair(pred, gt, spacing, connectivity, dims):
    """(pred's points, gt's points, pred's voxels, gt's voxels, foreground counts)."""
    vp, vg = _voxels(pred, "pred"), _voxels(gt, "gt")
    if vp.shape != vg.shape:
        raise ValueError(f"pred and gt have different shapes: {vp.shape} and {vg.shape}")
    (a, fa), (b, fb) = (_points(v, spacing, connectivity, dims, False) for v in (vp, vg))
    return a, b, vp, vg, (fa, fb)


def distances(pred, gt, spacing=None, *, connectivity: int = 1, dims="auto",
              threads: Optional[int] = None) -> Tuple[np.ndarray, np.ndarray]:
    """(distances of pred's surface voxels to gt's surface, of gt's to
    pred's), each in storage order; empty arrays for an empty mask's side
    and inf for the other's when one mask is empty."""
    a, b = _pair(pred, gt, spacing, connectivity, dims)[:2]
    if len(a) and len(b):
        d_ab, _ = _hausdorff.distances(a, b, threads=threads)
        d_ba, _ = _hausdorff.distances(b, a, threads=threads)
        return d_ab, d_ba
    return np.full(len(a), np.inf), np.full(len(b), np.inf)


@dataclasses.dataclass(frozen=True)
class MaskMetrics:
    """Every figure of one pred/gt pair (metrics()).  Distances in the
    spacing's unit; lists follow the order of the percentiles and taus."""
    hausdorff: float             #: max of the two directed maxima
    hausdorff_ab: float          #: pred -> gt
    hausdorff_ba: float          #: gt -> pred
    percentile: List[float]      #: MONAI's: max(P(pred->gt), P(gt->pred))
    percentile_pooled: List[float]  #: medpy's: P of both directions pooled
    percentile_ab: List[float]   #: P of pred -> gt (MONAI's directed=True)
    percentile_ba: List[float]   #: P of gt -> pred
    assd: float                  #: pooled (MONAI >= 1.0, medpy 0.5)
    assd_average: float          #: mean of the two directed means (MONAI 0.x)
    asd_ab: float                #: mean pred -> gt (medpy's asd(pred, gt))
    asd_ba: float                #: mean gt -> pred
    nsd: List[float]             #: MONAI's compute_surface_dice at each tau
    precision: List[float]       #: share of pred's surface within tau of gt's
    recall: List[float]          #: share of gt's surface within tau of pred's
    fscore: List[float]          #: 2 P R / (P + R)
    dice: float                  #: volume Dice of the masks
    points: Tuple[int, int]      #: surface voxels of pred, of gt
    foreground: Tuple[int, int]  #: foreground voxels of pred, of gt


def _empty_value(empty: str, n_a: int, n_b: int) -> float:
    if empty == "monai":
        return math.inf if n_a or n_b else math.nan
    return {"inf": math.inf, "nan": math.nan, "zero": 0.0}[empty]


def _dice(vp: np.ndarray, vg: np.ndarray, fg: Tuple[int, int]) -> float:
    total = fg[0] + fg[1]
    return 2 * int(np.count_nonzero(vp & vg)) / total if total else math.nan


def dice(pred, gt) -> float:
    """2 |pred and gt| / (|pred| + |gt|) over the foreground voxels; NaN
    when both masks are empty (DeepMind's compute_dice_coefficient)."""
    vp, vg = _voxels(pred, "pred"), _voxels(gt, "gt")
    if vp.shape != vg.shape:
        raise ValueError(f"pred and gt have different shapes: {vp.shape} and {vg.shape}")
    return _dice(vp, vg, (int(np.count_nonzero(vp)), int(np.count_nonzero(vg))))


def _floats(v) -> np.ndarray:
    return np.ascontiguousarray(np.atleast_1d(np.asarray(v, dtype=np.float64)))


def metrics(pred, gt, spacing=None, *, percentile: Union[float, Sequence[float], None] = 95,
            tau: Union[float, Sequence[float], None] = None, strict: bool = False, connectivity: int = 1,
            dims="auto", empty: str = "error", threads: Optional[int] = None) -> MaskMetrics:
    """Every figure at once, from one pass of per-point distances.
    strict: within tau means d < tau (Tanks and Temples) instead of d <= tau
    (MONAI, DeepMind)."""
    if empty not in _EMPTY:
        raise ValueError(f"empty is one of {', '.join(_EMPTY)}, not {empty!r}")
    a, b, vp, vg, fg = _pair(pred, gt, spacing, connectivity, dims)
    ps = [] if percentile is None else [float(p) for p in np.atleast_1d(percentile)]
    taus = _floats([] if tau is None else tau)
    pcts = _floats(ps) if ps else None
    if len(a) == 0 or len(b) == 0:
        if empty == "error":
            which = "pred and gt are" if not len(a) and not len(b) else "pred is" if not len(a) else "gt is"
            raise ValueError(f"{which} empty: there is no surface distance (empty='monai', 'inf', 'nan' "
                             "or 'zero' reports one)")
        v = _empty_value(empty, len(a), len(b))
        inf_a, inf_b = np.full(len(a), np.inf), np.full(len(b), np.inf)
        sc = [] if not len(taus) else _hausdorff._figures(
            inf_a if len(a) else None, inf_b if len(b) else None, None, None, None, taus, strict, 0.0)[2]
        if len(taus) and not len(a) and not len(b):
            sc = [(t, math.nan, math.nan, math.nan, math.nan, 0, 0) for t in taus]
        return MaskMetrics(v, v, v, [v] * len(ps), [v] * len(ps), [v] * len(ps), [v] * len(ps), v, v, v, v,
                           [s[4] if len(a) or len(b) else math.nan for s in sc],
                           [s[1] for s in sc], [s[2] for s in sc], [s[3] for s in sc],
                           _dice(vp, vg, fg), (len(a), len(b)), fg)
    d_ab, _ = _hausdorff.distances(a, b, threads=threads)
    d_ba, _ = _hausdorff.distances(b, a, threads=threads)
    s, pc, sc, _cap = _hausdorff._figures(d_ab, d_ba, None, None, pcts, taus, strict, 0.0)
    return MaskMetrics(max(s[0], s[1]), s[0], s[1], [p[3] for p in pc], [p[4] for p in pc], [p[1] for p in pc],
                       [p[2] for p in pc], s[6], s[5],
                       s[2], s[3], [t[4] for t in sc], [t[1] for t in sc], [t[2] for t in sc],
                       [t[3] for t in sc], _dice(vp, vg, fg), (len(a), len(b)), fg)


def hausdorff(pred, gt, spacing=None, *, percentile: Optional[float] = None, definition: str = "monai",
              connectivity: int = 1, dims="auto", empty: str = "error", threads: Optional[int] = None) -> float:
    """The Hausdorff distance between the masks' surfaces, or its
    percentile: definition "monai" = max of the directed percentiles of the
    surface voxels (compute_hausdorff_distance), "medpy" = percentile of
    both directions pooled (medpy's hd95), "deepmind" = DeepMind's
    compute_robust_hausdorff: surfels weighted by area, the smallest
    distance whose surfels hold the percentile's share of the area, the
    larger of the two directions (without a percentile: 100)."""
    if definition not in ("monai", "medpy", "deepmind"):
        raise ValueError(f"definition is 'monai', 'medpy' or 'deepmind', not {definition!r}")
    if definition == "deepmind":
        if empty == "error":
            _refuse_empty(pred, gt)
        return _binary_row(pred, gt, spacing, percentile, 1.0, connectivity, dims, empty, threads)["hd_surfel"]
    m = metrics(pred, gt, spacing, percentile=percentile, connectivity=connectivity, dims=dims, empty=empty,
                threads=threads)
    if percentile is None:
        return m.hausdorff
    return m.percentile[0] if definition == "monai" else m.percentile_pooled[0]


def _refuse_empty(pred, gt) -> None:
    e = [not np.any(_voxels(m, name)) for m, name in ((pred, "pred"), (gt, "gt"))]
    if any(e):
        which = "pred and gt are" if all(e) else "pred is" if e[0] else "gt is"
        raise ValueError(f"{which} empty: there is no surface distance (empty='monai', 'inf', 'nan' "
                         "or 'zero' reports one)")


def assd(pred, gt, spacing=None, *, definition: str = "pooled", connectivity: int = 1, dims="auto",
         empty: str = "error", threads: Optional[int] = None) -> float:
    """Average symmetric surface distance: "pooled" (MONAI >= 1.0
    symmetric=True, medpy 0.5's assd), "average" (MONAI 0.x: the mean of
    the two directed means) or "deepmind" (the mean of the two
    area-weighted directed means of DeepMind's
    compute_average_surface_distance, which returns them as a pair)."""
    if definition not in ("pooled", "average", "deepmind"):
        raise ValueError(f"definition is 'pooled', 'average' or 'deepmind', not {definition!r}")
    if definition == "deepmind":
        if empty == "error":
            _refuse_empty(pred, gt)
        r = _binary_row(pred, gt, spacing, None, 1.0, connectivity, dims, empty, threads)
        if r["empty"]:
            return r["asd_surfel_pred_gt"]
        return (r["asd_surfel_pred_gt"] + r["asd_surfel_gt_pred"]) / 2
    m = metrics(pred, gt, spacing, percentile=None, connectivity=connectivity, dims=dims, empty=empty,
                threads=threads)
    return m.assd if definition == "pooled" else m.assd_average


_NSD = ("monai", "deepmind", "monai_subvoxels")


def nsd(pred, gt, tau, spacing=None, *, definition: str = "monai", connectivity: int = 1, dims="auto",
        empty: str = "monai", threads: Optional[int] = None):
    """Normalized surface Dice at tolerance tau (a number, or a list for
    several), d <= tau.  Two definitions:

    - "monai": surface voxels counted, as MONAI's
      compute_surface_dice(use_subvoxels=False): (pred's surface voxels
      within tau of gt's surface + gt's within tau of pred's) / (all of
      both);
    - "deepmind" (the same as "monai_subvoxels"): surfels weighted by their
      marching-cubes area, as DeepMind's compute_surface_dice_at_tolerance
      and MONAI's compute_surface_dice(use_subvoxels=True): (area of the
      surfels within tau of the other side's surfels) / (all the area).

    An empty mask gives 0, two give NaN (MONAI's and DeepMind's)."""
    if definition not in _NSD:
        raise ValueError(f"definition is one of {', '.join(_NSD)}, not {definition!r}")
    if definition != "monai":
        taus = [float(t) for t in np.atleast_1d(tau)]
        out = [_binary_row(pred, gt, spacing, None, t, connectivity, dims, empty, threads)["nsd_surfel"]
               for t in taus]
        return out if np.ndim(tau) else out[0]
    m = metrics(pred, gt, spacing, percentile=None, tau=tau, connectivity=connectivity, dims=dims,
                empty=empty, threads=threads)
    return m.nsd if np.ndim(tau) else m.nsd[0]


def fscore(pred, gt, tau, spacing=None, *, strict: bool = False, connectivity: int = 1, dims="auto",
           empty: str = "monai", threads: Optional[int] = None):
    """(precision, recall, F-score) of the surfaces at tau (lists for
    several taus): precision = share of pred's surface within tau of gt's."""
    m = metrics(pred, gt, spacing, percentile=None, tau=tau, strict=strict, connectivity=connectivity,
                dims=dims, empty=empty, threads=threads)
    if np.ndim(tau):
        return m.precision, m.recall, m.fscore
    return m.precision[0], m.recall[0], m.fscore[0]


# ---- label maps (hd_label_map) -------------------------------------------------------

#: The keys of a label_map row, in the C struct's order (hd_label_row_t).
ROW_FIELDS = ("label", "empty", "voxels_pred", "voxels_gt", "overlap", "dice", "points_pred", "points_gt",
              "hausdorff", "hd_pred_gt", "hd_gt_pred", "hd_p", "hd_p_pooled", "assd", "asd_pred_gt", "asd_gt_pred",
              "nsd", "surfels_pred", "surfels_gt", "area_pred", "area_gt", "nsd_surfel", "overlap_pred",
              "overlap_gt", "hd_surfel", "asd_surfel_pred_gt", "asd_surfel_gt_pred", "components_pred",
              "components_gt")
#: The keys of a components() row (hd_label_component_t); side is "pred" or "gt".
COMPONENT_FIELDS = ("label", "side", "index", "voxels", "overlap", "points", "hausdorff", "hd_p", "nearest",
                    "detected")

# numpy dtype -> hd_label_type_t
_LABEL_TYPES = {np.dtype(np.uint8): 0, np.dtype(np.int8): 1, np.dtype(np.uint16): 2, np.dtype(np.int16): 3,
                np.dtype(np.uint32): 4, np.dtype(np.int32): 5, np.dtype(np.int64): 6, np.dtype(np.uint64): 7}


def _label_array(v, name: str) -> np.ndarray:
    m = np.asarray(v)
    if m.ndim < 1 or m.ndim > 3:
        raise ValueError(f"{name}: a label map has 1 to 3 dimensions, not {m.ndim}")
    if m.size == 0:
        raise ValueError(f"{name}: the label map has no voxels (shape {m.shape})")
    if m.dtype == np.bool_:
        m = m.astype(np.uint8)
    elif m.dtype.kind == "f":
        if not np.all(np.isfinite(m)) or not np.all(m == np.round(m)):
            raise ValueError(f"{name}: a label map of floats holds whole numbers only")
        m = m.astype(np.int64)
    elif m.dtype.kind not in "iu":
        raise ValueError(f"{name}: labels are integers or booleans, not {m.dtype}")
    return m


def _table(pred, gt, spacing, spacing_gt, labels, percentile, tau, strict, connectivity, dims, empty, comps,
           threads):
    if empty not in _EMPTY:
        raise ValueError(f"empty is one of {', '.join(_EMPTY)}, not {empty!r}")
    a, b = _label_array(pred, "pred"), _label_array(gt, "gt")
    if a.shape != b.shape:
        raise ValueError(f"pred and gt have different shapes: {a.shape} and {b.shape}")
    t = np.promote_types(a.dtype, b.dtype)
    if t not in _LABEL_TYPES:
        t = np.dtype(np.int64)
    # The library reads the arrays where they are: Fortran order (nibabel's)
    # as axis 0 fastest, C order as the last axis fastest with the axes'
    # spacings placed accordingly (the coordinates are the same doubles);
    # anything else is copied to C order.
    # (dims=2 and the 2-D surfels of a 3-D array whose axis 2 has one voxel
    # name the array's axis 2: those go through Fortran order.)
    a, b = a.astype(t, copy=False), b.astype(t, copy=False)
    ndim = a.ndim
    corder = not (a.flags.f_contiguous and b.flags.f_contiguous)
    if corder and ndim == 3 and (_dims(dims) == 2 or a.shape[0] == 1 or a.shape[2] == 1):
        a, b, corder = np.asfortranarray(a), np.asfortranarray(b), False
    if corder:
        a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
        n = list(a.shape[::-1]) + [1] * (3 - ndim)
    else:
        a, b = a.T, b.T  # C-contiguous views of the same memory
        n = list(a.shape[::-1]) + [1] * (3 - ndim)
    sa = _spacing(spacing, a.ndim)
    sb = sa if spacing_gt is None else _spacing(spacing_gt, a.ndim)
    lab = None if labels is None else np.ascontiguousarray(np.atleast_1d(np.asarray(labels, dtype=np.int64)))
    if comps not in (None, 0, 4, 8, 6, 18, 26):
        raise ValueError(f"components is 6, 18, 26 (3-D) or 4, 8 (2-D), not {comps!r}")
    if connectivity not in (1, 2, 3):
        raise ValueError(f"connectivity is 1, 2 or 3, not {connectivity!r}")
    return _hausdorff._label_map(a, b, _LABEL_TYPES[t], n[0], n[1], n[2], sa, sb, lab, float(percentile),
                                 float(tau), bool(strict), connectivity, _dims(dims), empty, int(comps or 0),
                                 0 if threads is None else int(threads), ndim, corder)


def label_map(pred, gt, spacing=None, *, labels=None, percentile: float = 95, tau: float = 1.0,
              strict: bool = False, connectivity: int = 1, dims="auto", empty: str = "monai",
              components=None, spacing_gt=None, threads: Optional[int] = None) -> List[dict]:
    """Every label's figures in one call: a list of dicts, one per label
    (every nonzero label present in pred or gt, ascending, or the given
    ``labels`` in their order), keys ROW_FIELDS.  pred and gt are integer
    (or bool) arrays of one shape; each label's masks are cut to its box,
    so memory follows the largest label, not their number.

    Voxel-surface figures (MONAI, medpy): hausdorff, hd_pred_gt,
    hd_gt_pred, hd_p (MONAI's max of the directed P-th percentiles), hd_p_pooled
    (medpy's), assd (pooled), asd_pred_gt, asd_gt_pred, nsd (MONAI's
    compute_surface_dice).  Surfel figures (DeepMind's surface-distance;
    MONAI's use_subvoxels=True): nsd_surfel, overlap_pred / overlap_gt (the
    surface overlaps at tau), hd_surfel (compute_robust_hausdorff at
    ``percentile``), asd_surfel_pred_gt / asd_surfel_gt_pred
    (compute_average_surface_distance).  dice is the volume Dice.

    A label absent from one side (or both) follows ``empty`` (default
    "monai": inf for a distance when one side is empty, NaN when both; NSD
    0 and NaN; "error" raises ValueError).  components=6/18/26 (4/8 in 2-D)
    counts each side's connected components into components_pred /
    components_gt (components() lists them)."""
    rows, _ = _table(pred, gt, spacing, spacing_gt, labels, percentile, tau, strict, connectivity, dims, empty,
                     components, threads)
    return [dict(zip(ROW_FIELDS, r)) for r in rows]


def components(pred, gt, spacing=None, *, connectivity: int = 26, labels=None, percentile: float = 95,
               tau: float = 1.0, strict: bool = False, surface_connectivity: int = 1, dims="auto",
               empty: str = "monai", spacing_gt=None, threads: Optional[int] = None) -> List[dict]:
    """Each connected component (connectivity 6, 18, 26 in 3-D; 4, 8 in 2-D)
    of each label of each side: a list of dicts, keys COMPONENT_FIELDS:
    hausdorff / hd_p / nearest are the largest, P-th percentile and
    smallest distance of its surface voxels to the other side's surface
    (inf when the other side has no such label), overlap its voxels that
    the other side also labels so, detected whether it overlaps or comes
    within tau.  Order: per label, pred's components, then gt's, each
    numbered 1.. by its first voxel in the arrays' memory order (axis 0
    fastest for Fortran-ordered arrays such as nibabel's, the last axis
    fastest otherwise).  A bool array is one label (1)."""
    _, comps = _table(pred, gt, spacing, spacing_gt, labels, percentile, tau, strict, surface_connectivity, dims,
                      empty, connectivity, threads)
    out = []
    for c in comps:
        d = dict(zip(COMPONENT_FIELDS, c))
        d["side"] = ("pred", "gt")[d["side"]]
        d["detected"] = bool(d["detected"])
        out.append(d)
    return out


def _binary_row(pred, gt, spacing, percentile, tau, connectivity, dims, empty, threads) -> dict:
    """The label-map row of two masks (foreground = label 1)."""
    vp, vg = (_voxels(m, name) for m, name in ((pred, "pred"), (gt, "gt")))
    if vp.shape != vg.shape:
        raise ValueError(f"pred and gt have different shapes: {vp.shape} and {vg.shape}")
    return label_map(vp, vg, spacing, labels=[1], percentile=100 if percentile is None else percentile, tau=tau,
                     connectivity=connectivity, dims=dims, empty=empty, threads=threads)[0]


# ---- surfels (hd_mask_surfels): DeepMind's surface-distance ----------------------------

def _surfel_dims(dims, ndim: int) -> int:
    if dims in ("auto", 0, None):
        return 2 if ndim <= 2 else 3
    if dims in (2, 3):
        return int(dims)
    raise ValueError(f"dims is 'auto', 2 or 3, not {dims!r}")


def surfels(mask, spacing=None, *, dims="auto") -> Tuple[np.ndarray, np.ndarray]:
    """(centres (n, 3), areas (n,)) of the mask's surfels: the cubes of
    2 x 2 x 2 voxels (2 x 2 pixels for a 2-D mask) that the boundary
    crosses, each weighted by the area (length in 2-D) of its
    marching-cubes surface, as DeepMind's surface-distance and MONAI's
    use_subvoxels=True weigh them.  Cube (i, j, k) holds voxels i..i+1,
    j..j+1, k..k+1 (i from -1), its centre (i + 0.5) * spacing[0], ...;
    storage order, axis 0 fastest."""
    v = _voxels(mask, "mask")
    n = list(v.shape) + [1] * (3 - v.ndim)
    s = _spacing(spacing, v.ndim)
    raw, ar = _hausdorff._mask_surfels(v.T, n[0], n[1], n[2], s[0], s[1], s[2], _surfel_dims(dims, v.ndim))
    return np.frombuffer(raw, dtype=np.float64).reshape(-1, 3).copy(), np.frombuffer(ar, dtype=np.float64).copy()


def surface_distances(pred, gt, spacing=None, *, dims="auto", threads: Optional[int] = None) -> dict:
    """DeepMind's compute_surface_distances(mask_gt, mask_pred, spacing)
    dict: distances_gt_to_pred, distances_pred_to_gt (each sorted
    ascending) and surfel_areas_gt, surfel_areas_pred (in the same order:
    ties keep the storage order).  A side with no surfel gives empty arrays
    and the other side's distances are inf.  Distances are exact
    nearest-surfel distances (DeepMind's distance transform gives the
    same); note the argument order: pred first, as everywhere in this
    module."""
    vp, vg = _voxels(pred, "pred"), _voxels(gt, "gt")
    if vp.shape != vg.shape:
        raise ValueError(f"pred and gt have different shapes: {vp.shape} and {vg.shape}")
    (pa, wa), (pb, wb) = surfels(pred, spacing, dims=dims), surfels(gt, spacing, dims=dims)
    if len(pa) and len(pb):
        d_pg, _ = _hausdorff.distances(pa, pb, threads=threads)
        d_gp, _ = _hausdorff.distances(pb, pa, threads=threads)
    else:
        d_pg, d_gp = np.full(len(pa), np.inf), np.full(len(pb), np.inf)
    o_p, o_g = np.argsort(d_pg, kind="stable"), np.argsort(d_gp, kind="stable")
    return {"distances_gt_to_pred": np.asarray(d_gp)[o_g], "distances_pred_to_gt": np.asarray(d_pg)[o_p],
            "surfel_areas_gt": wb[o_g], "surfel_areas_pred": wa[o_p]}
