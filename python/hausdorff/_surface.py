"""Points to a triangle surface: hausdorff.Mesh and hausdorff.read_mesh.

The distance from a point to a triangle is the true Euclidean distance to
the closed triangle (a degenerate one is the segment or point it collapses
to), correctly rounded to the nearest double; the distance to the mesh is
the smallest over its triangles and the face is the smallest index at that
distance: bit-identical to a loop over every triangle, at any thread count.
"""
from typing import NamedTuple, Optional

import numpy as np

from . import _hausdorff


class SurfaceDistances(NamedTuple):
    """What Mesh.distances returns."""

    distances: np.ndarray   #: (N,) float64, each point's distance to the surface
    faces: np.ndarray       #: (N,) intp, its nearest face (smallest index on ties)
    closest: np.ndarray     #: (N, 3) float64, the closest point on that face
    barycentric: np.ndarray  #: (N, 3) float64, its weights of the face's corners
    distance: float         #: h(points, surface): the largest distance
    i: int                  #: its point (smallest index on ties)
    face: int               #: that point's nearest face
    signs: Optional[np.ndarray] = None  #: (N,) int8 with signed=True: -1 inside, +1 outside, 0 on the surface


class Mesh:
    """A triangle mesh: vertices (an (V, 3) array of any real or integer
    dtype) and faces (an (M, 3) array of vertex indices).  Both are kept as
    given (numpy arrays; nothing is copied until a call needs it).
    Degenerate faces (collinear or coincident corners) are measured as
    their hull; a face index out of range, a non-finite vertex used by a
    face, or no faces at all is an error when distances are asked."""

    def __init__(self, vertices, faces):
        self.vertices = np.asarray(vertices)
        self.faces = np.asarray(faces)

    def __repr__(self):
        return "hausdorff.Mesh(%d vertices, %d faces)" % (len(self.vertices), len(self.faces))

    def distances(self, points, *, threads=None, signed=False):
        """Each point's correctly rounded distance to the surface, its
        nearest face, closest point and barycentric weights, and the
        largest distance h(points, surface) with its point and face
        (a SurfaceDistances).

        signed=True also returns `signs` (int8): -1 inside the surface, +1
        outside, 0 where the distance is 0.  Inside means a nonzero winding
        number, decided exactly; it needs a closed, consistently oriented
        mesh (every edge used as often each way once vertices with equal
        coordinates are merged) and raises ValueError naming an edge
        otherwise.  The signed distance is signs * distances."""
        d, f, c, b, h, i, face, _, s = _hausdorff._mesh_distances(points, self.vertices, self.faces,
                                                                   threads=threads, signed=bool(signed))
        return SurfaceDistances(d, f, c, b, h, i, face, s)


def read_mesh(path, *, format=None):
    """The vertices (float64) and faces of a PLY, OBJ, OFF or STL file as a
    Mesh: polygons split into fans, an STL's bit-equal corners merged."""
    vertices, faces, _, _, _ = _hausdorff._read_mesh(path, format=format)
    return Mesh(vertices, faces)
