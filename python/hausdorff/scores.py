"""Scores of a reconstruction against a reference point set, exact.

- ``tolerance(a, b, tau)``: at each tolerance, the precision (share of A's
  points within tau of B), recall (share of B's within tau of A), F-score
  2PR/(P+R) and the per-point NSD (both shares pooled), as the Tanks and
  Temples evaluation and Open3D users' scripts compute them, with a ``<``
  (``strict=True``, theirs) or ``<=`` (default, MONAI's and DeepMind's)
  comparison made on exact distances, so that two runs and two machines
  agree on every point.  Several taus cost one pass.
- ``dtu(a, b, cap)``: DTU's accuracy (mean distance of A's points to B over
  those below the cap), completeness (likewise B to A) and overall (their
  average); the DTU MVS evaluation uses cap 20 (mm).

A is the reconstruction (prediction), B the reference.  The figures are
the C library's (hd_tolerance_scores, hd_capped_means), as the command
line's --tau and --dtu-cap report them.
"""
from __future__ import annotations

from typing import List, NamedTuple, Optional, Sequence, Union

import numpy as np

from . import _hausdorff

__all__ = ["Score", "DTU", "tolerance", "dtu"]


class Score(NamedTuple):
    tau: float
    precision: float
    recall: float
    fscore: float
    nsd: float
    within_ab: int
    within_ba: int


class DTU(NamedTuple):
    accuracy: float
    completeness: float
    overall: float
    kept_ab: int
    kept_ba: int


def _both(a, b, threads):
    d_ab, _ = _hausdorff.distances(a, b, threads=threads)
    d_ba, _ = _hausdorff.distances(b, a, threads=threads)
    return np.ascontiguousarray(d_ab, np.float64), np.ascontiguousarray(d_ba, np.float64)


def tolerance(a, b, tau: Union[float, Sequence[float]], *, strict: bool = False,
              weights_a=None, weights_b=None, threads: Optional[int] = None) -> Union[Score, List[Score]]:
    """The Score at tau, or a list of Scores for a sequence of taus.
    weights_a, weights_b: a weight per point (an area, say) instead of 1."""
    taus = np.ascontiguousarray(np.atleast_1d(np.asarray(tau, dtype=np.float64)))
    d_ab, d_ba = _both(a, b, threads)
    w = [None if v is None else np.ascontiguousarray(v, np.float64) for v in (weights_a, weights_b)]
    for v, d, name in ((w[0], d_ab, "weights_a"), (w[1], d_ba, "weights_b")):
        if v is not None and v.shape != d.shape:
            raise ValueError(f"{name} has shape {v.shape}; it needs one weight per point ({len(d)})")
    _s, _p, sc, _c = _hausdorff._figures(d_ab, d_ba, w[0], w[1], None, taus, strict, 0.0)
    out = [Score(*t) for t in sc]
    return out if np.ndim(tau) else out[0]


def dtu(a, b, cap: float = 20.0, *, threads: Optional[int] = None) -> DTU:
    """DTU accuracy / completeness / overall over the distances below cap
    (float("inf") keeps them all)."""
    if not cap > 0:
        raise ValueError(f"cap must be > 0, not {cap!r}")
    d_ab, d_ba = _both(a, b, threads)
    _s, _p, _t, c = _hausdorff._figures(d_ab, d_ba, None, None, None, None, False, float(cap))
    return DTU(*c)
