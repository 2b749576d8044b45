"""Exact Hausdorff distance between 3D point sets.

Python bindings to libhausdorff: numpy arrays in, distances out, exact to the
last bit (identical to a brute force in double precision) and with the same
witness at any thread count.  The computation runs in C with the GIL
released.

>>> import numpy as np, hausdorff
>>> a = np.array([[0.0, 0, 0], [1, 0, 0]])
>>> b = np.array([[0.0, 0, 0], [3, 0, 0]])
>>> hausdorff.directed(a, b)           # like scipy's directed_hausdorff
hausdorff.DirectedResult(distance=1.0, i=1, j=0)
>>> hausdorff.hausdorff(a, b).distance
2.0

Functions: directed (a drop-in for scipy's directed_hausdorff), hausdorff,
distances, percentile, summary, mean, chamfer, read, count, formats,
write_field (a per-point field written back into the input's format);
the class Index (build once, query many times, optionally transformed);
the class Mesh and read_mesh (points to a triangle surface, correctly rounded).
"""
from ._hausdorff import (
    DirectedResult,
    HausdorffResult,
    Index,
    MeanResult,
    PercentileResult,
    Summary,
    __version__,
    algorithms,
    chamfer,
    count,
    directed,
    distances,
    formats,
    hausdorff,
    mean,
    percentile,
    read,
    summary,
    write_field,
)
from ._hausdorff import _mesh_distances, _read_mesh
from ._surface import (Enclosure, Mesh, SurfaceDistances, SurfaceHausdorff, SurfaceWitness, face_maxima,
                       read_mesh, surface_hausdorff, surface_within)
from . import masks, scores  # segmentation masks; reconstruction scores (masks.py, scores.py)

__all__ = [
    "DirectedResult",
    "Enclosure",
    "HausdorffResult",
    "Index",
    "Mesh",
    "MeanResult",
    "PercentileResult",
    "Summary",
    "SurfaceDistances",
    "SurfaceHausdorff",
    "SurfaceWitness",
    "__version__",
    "algorithms",
    "chamfer",
    "count",
    "directed",
    "distances",
    "face_maxima",
    "formats",
    "hausdorff",
    "mean",
    "percentile",
    "read",
    "read_mesh",
    "summary",
    "surface_hausdorff",
    "surface_within",
    "write_field",
]
