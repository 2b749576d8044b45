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


# ---- surface to surface: enclosures ------------------------------------------

class SurfaceWitness(NamedTuple):
    """The point of the side measured from that proves the lower bound, and
    its nearest point on the other side."""

    face_a: int          #: its face (-1 when that side is a point set)
    index_a: int         #: its point when that side is a point set (-1 otherwise)
    bary_a: tuple        #: its weights of face_a's corners
    point_a: tuple       #: the point, as computed
    distance: float      #: the correctly rounded distance from point_a to the other side
    error: float         #: |point_a - the exact point at bary_a| <= error (0 at a vertex)
    face_b: int          #: point_a's nearest face on the other side (-1 for a point set)
    index_b: int         #: or its nearest point there (-1 for a mesh)
    point_b: tuple       #: that nearest point


class Enclosure(NamedTuple):
    """A directed distance h(X, Y) from a surface, enclosed: the correctly
    rounded h lies in [lower, upper], and the true h <= upper; lower is
    witness.distance (witness.error 0) or a bound derived from it."""

    lower: float
    upper: float
    tolerance: float     #: the absolute tolerance used
    converged: bool      #: upper - lower <= tolerance
    witness: SurfaceWitness
    faces_dropped: int   #: faces shared by both sides (distance 0)
    faces_split: int
    kernel_calls: int
    seconds: float


class SurfaceHausdorff(NamedTuple):
    """What surface_hausdorff returns: H (or h when directed) enclosed."""

    lower: float
    upper: float
    ab: Enclosure        #: h(a, b)
    ba: object           #: h(b, a) as an Enclosure, None when directed


def _enclosure(t):
    return Enclosure(t[0], t[1], t[2], t[3], SurfaceWitness(*t[4:13]), *t[13:])


def _sides(a, b):
    if not isinstance(a, Mesh):
        raise TypeError("a must be a hausdorff.Mesh (the side measured from first); got %s" % type(a).__name__)
    if isinstance(b, Mesh):
        return a.vertices, a.faces, b.vertices, b.faces
    return a.vertices, a.faces, b, None


def surface_hausdorff(a, b, *, tolerance=1e-9, relative=True, directed=False, threads=None,
                      max_splits=1 << 20):
    """The Hausdorff distance between surface a (a Mesh) and b (a Mesh, or
    an (N, 3) point set), over every point of the surfaces, as an enclosure
    [lower, upper] no wider than the tolerance (relative: times the
    diagonal of both sides' bounding box; 0: as tight as doubles allow).
    Returns a SurfaceHausdorff: lower and upper of H (of h(a, b) when
    directed), ab and ba with their witnesses.

    >>> import numpy as np, hausdorff
    >>> v = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0]], dtype=float)
    >>> r = hausdorff.surface_hausdorff(hausdorff.Mesh(v, [[0, 1, 2]]), v, tolerance=1e-12)
    >>> r.lower <= 8 ** 0.5 <= r.upper   # the hypotenuse's midpoint, far from every corner
    True
    """
    av, af, bv, bf = _sides(a, b)
    ab, ba = _hausdorff._surface(av, af, bv, bf, tolerance=tolerance, relative=bool(relative),
                                 threads=threads, max_splits=max_splits, directed=bool(directed))
    ab = _enclosure(ab)
    if ba is None:
        return SurfaceHausdorff(ab.lower, ab.upper, ab, None)
    ba = _enclosure(ba)
    return SurfaceHausdorff(max(ab.lower, ba.lower), max(ab.upper, ba.upper), ab, ba)


def surface_within(a, b, d, *, directed=False, tolerance=1e-9, relative=True, threads=None,
                   max_splits=1 << 20):
    """Is H(a, b) <= d (h(a, b) when directed)?  True or False when proven,
    None when the distance is within the tolerance of d.  Stops as soon as
    the answer is proven: far faster than surface_hausdorff."""
    if not isinstance(b, Mesh):
        raise TypeError("b must be a hausdorff.Mesh; got %s" % type(b).__name__)
    answer, _, _ = _hausdorff._surface(a.vertices, a.faces, b.vertices, b.faces, tolerance=tolerance,
                                       relative=bool(relative), threads=threads, max_splits=max_splits,
                                       directed=bool(directed), d=float(d), what="within")
    return None if answer < 0 else bool(answer)


def face_maxima(a, b, *, tolerance=1e-9, relative=True, threads=None, max_splits=1 << 20):
    """For every face k of a, the largest distance from a point of it to
    surface b, enclosed: lower[k] <= that maximum (correctly rounded) and
    the maximum <= upper[k], each pair within the tolerance.  Returns
    (lower, upper, h(a, b) as an Enclosure)."""
    if not isinstance(a, Mesh) or not isinstance(b, Mesh):
        raise TypeError("a and b must be hausdorff.Mesh objects")
    lo, hi, ab = _hausdorff._surface(a.vertices, a.faces, b.vertices, b.faces, tolerance=tolerance,
                                     relative=bool(relative), threads=threads, max_splits=max_splits,
                                     what="faces")
    return lo, hi, _enclosure(ab)
