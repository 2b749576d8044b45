"""Type stubs of the hausdorff C extension (see the docstrings for details)."""
import os
from typing import Any, Dict, List, Literal, Mapping, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

# Any (N, D) array-like of real numbers or booleans, D >= 1 coordinates
# (both sets alike; 1 and 2 are lifted to 3-D exactly, 4 and more computed
# by the module's own engine); float32 and float64 (N, 3) arrays are read in
# place (C or Fortran order, strided or reversed views).
Points = npt.ArrayLike
# What an empty set gives: an error, inf, NaN, 0, as MONAI (inf when one set
# is empty, NaN when both are) or as scikit-image (inf when one set is
# empty, 0 when both are).
Empty = Literal["error", "inf", "nan", "zero", "monai", "skimage"]
# A seed: it never changes the answer.  None, any integer (modulo 2**64), or
# a numpy random generator object (left untouched), as scipy takes them.
Seed = Union[
    None,
    int,
    np.integer,
    np.random.Generator,
    np.random.RandomState,
    np.random.BitGenerator,
    np.random.SeedSequence,
]
Matrix3 = npt.ArrayLike  # (3, 3)
Vector3 = npt.ArrayLike  # (3,)

__version__: str
algorithms: Tuple[str, ...]

class DirectedResult(Tuple[float, int, int]):
    """h(A, B) and its witness: the tuple (distance, i, j), as scipy's
    directed_hausdorff returns.  i and j are None (and algorithm None) when a
    set was empty and an empty policy gave the distance."""
    @property
    def distance(self) -> float: ...
    @property
    def i(self) -> Optional[int]: ...
    @property
    def j(self) -> Optional[int]: ...
    @property
    def algorithm(self) -> Optional[str]: ...
    @property
    def seconds(self) -> float: ...
    @property
    def distance_evals(self) -> int: ...

class HausdorffResult(Tuple[float, DirectedResult, DirectedResult]):
    """H(A, B) with both directions: the tuple (distance, ab, ba)."""
    @property
    def distance(self) -> float: ...
    @property
    def ab(self) -> DirectedResult: ...
    @property
    def ba(self) -> DirectedResult: ...
    @property
    def alpha(self) -> float: ...
    @property
    def disjoint(self) -> Optional[bool]: ...
    @property
    def seconds(self) -> float: ...

class PercentileResult(Tuple[float, float, float, float, float]):
    """Percentile Hausdorff distances: the tuple (p, ab, ba, symmetric, pooled)."""
    @property
    def p(self) -> float: ...
    @property
    def ab(self) -> float: ...
    @property
    def ba(self) -> float: ...
    @property
    def symmetric(self) -> float: ...
    @property
    def pooled(self) -> float: ...

class MeanResult(Tuple[float, float, float, float, float]):
    """Mean distances: the tuple (ab, ba, symmetric, average, pooled)."""
    @property
    def ab(self) -> float: ...
    @property
    def ba(self) -> float: ...
    @property
    def symmetric(self) -> float: ...
    @property
    def average(self) -> float: ...
    @property
    def pooled(self) -> float: ...

class Summary(Tuple[Union[int, float], ...]):
    """Sums, means and Chamfer distances of the per-point distances."""
    @property
    def n_ab(self) -> int: ...
    @property
    def n_ba(self) -> int: ...
    @property
    def max_ab(self) -> float: ...
    @property
    def max_ba(self) -> float: ...
    @property
    def sum_ab(self) -> float: ...
    @property
    def sum_ba(self) -> float: ...
    @property
    def sum2_ab(self) -> float: ...
    @property
    def sum2_ba(self) -> float: ...
    @property
    def mean_ab(self) -> float: ...
    @property
    def mean_ba(self) -> float: ...
    @property
    def mean2_ab(self) -> float: ...
    @property
    def mean2_ba(self) -> float: ...
    @property
    def mean_symmetric(self) -> float: ...
    @property
    def mean_average(self) -> float: ...
    @property
    def mean_pooled(self) -> float: ...
    @property
    def chamfer(self) -> float: ...
    @property
    def chamfer_sum2(self) -> float: ...
    @property
    def chamfer_mean(self) -> float: ...
    @property
    def chamfer_sum(self) -> float: ...

# Integers may be ints, numpy integers or anything with __index__.
def directed(
    a: Points,
    b: Points,
    seed: Seed = 0,
    *,
    rng: Seed = None,
    algorithm: str = "auto",
    threads: Optional[int] = None,
    empty: Empty = "error",
) -> DirectedResult: ...
def hausdorff(
    a: Points,
    b: Points,
    *,
    algorithm: str = "auto",
    threads: Optional[int] = None,
    seed: Seed = 0,
    rng: Seed = None,
    empty: Empty = "error",
) -> HausdorffResult: ...
def distances(
    a: Points, b: Points, *, threads: Optional[int] = None, empty: Empty = "error"
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.intp]]: ...
@overload
def percentile(
    a: Points, b: Points, p: float, *, threads: Optional[int] = None,
    empty: Empty = "error"
) -> PercentileResult: ...
@overload
def percentile(
    a: Points, b: Points, p: Union[Sequence[float], npt.NDArray[np.floating]], *,
    threads: Optional[int] = None, empty: Empty = "error"
) -> List[PercentileResult]: ...
def summary(
    a: Points, b: Points, *, directed: bool = False, threads: Optional[int] = None,
    empty: Empty = "error"
) -> Summary: ...
def mean(
    a: Points, b: Points, *, threads: Optional[int] = None, empty: Empty = "error"
) -> MeanResult: ...
def chamfer(
    a: Points, b: Points, *, threads: Optional[int] = None, empty: Empty = "error"
) -> float: ...
def read(
    path: Union[str, bytes, os.PathLike[str], os.PathLike[bytes]],
    *,
    format: Optional[str] = None,
    float32: bool = False,
    decimal_comma: bool = False,
    start: int = 0,
    count: Optional[int] = None,
) -> npt.NDArray[np.floating]: ...
def count(
    path: Union[str, bytes, os.PathLike[str], os.PathLike[bytes]],
    *,
    format: Optional[str] = None,
) -> int: ...
def formats() -> Dict[str, str]: ...
def write_field(
    in_path: Union[str, bytes, os.PathLike[str], os.PathLike[bytes]],
    out_path: Union[str, bytes, os.PathLike[str], os.PathLike[bytes]],
    values: Union[npt.ArrayLike, Mapping[str, npt.ArrayLike]],
    *,
    name: Optional[str] = None,
    farther_than: Optional[float] = None,
    nearer_than: Optional[float] = None,
    format: Optional[str] = None,
    decimal_comma: bool = False,
) -> int: ...

class Index:
    """An index of b, built once and queried many times."""
    def __init__(self, b: Points, *, threads: Optional[int] = None) -> None: ...
    def __len__(self) -> int: ...
    @property
    def memory(self) -> int: ...
    @property
    def points(self) -> npt.NDArray[np.floating]: ...
    def directed(
        self,
        a: Points,
        *,
        rotation: Optional[Matrix3] = None,
        translation: Optional[Vector3] = None,
        threads: Optional[int] = None,
    ) -> DirectedResult: ...
    def distances(
        self,
        a: Points,
        *,
        rotation: Optional[Matrix3] = None,
        translation: Optional[Vector3] = None,
        threads: Optional[int] = None,
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.intp]]: ...

def _mesh_distances(
    points: Points, vertices: Points, faces: npt.ArrayLike, *, threads: Optional[int] = None,
    signed: bool = False
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.intp], npt.NDArray[np.float64],
           npt.NDArray[np.float64], float, int, int, int, Optional[npt.NDArray[np.int8]]]: ...
def _read_mesh(
    path: Union[str, bytes, os.PathLike[str], os.PathLike[bytes]], *, format: Optional[str] = None
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.intp], int, int, str]: ...

class SurfaceDistances(Tuple[npt.NDArray[np.float64], npt.NDArray[np.intp], npt.NDArray[np.float64],
                             npt.NDArray[np.float64], float, int, int, Optional[npt.NDArray[np.int8]]]):
    distances: npt.NDArray[np.float64]
    faces: npt.NDArray[np.intp]
    closest: npt.NDArray[np.float64]
    barycentric: npt.NDArray[np.float64]
    distance: float
    i: int
    face: int
    signs: Optional[npt.NDArray[np.int8]]

class Mesh:
    vertices: npt.NDArray[np.generic]
    faces: npt.NDArray[np.generic]
    def __init__(self, vertices: Points, faces: npt.ArrayLike) -> None: ...
    def distances(
        self, points: Points, *, threads: Optional[int] = None, signed: bool = False
    ) -> SurfaceDistances: ...

def read_mesh(
    path: Union[str, bytes, os.PathLike[str], os.PathLike[bytes]], *, format: Optional[str] = None
) -> Mesh: ...

def _surface(
    a_vertices: Points, a_faces: npt.ArrayLike, b_vertices: Points, b_faces: Optional[npt.ArrayLike], *,
    tolerance: float = 1e-9, relative: bool = True, threads: Optional[int] = None, max_splits: int = 1 << 20,
    directed: bool = False, d: float = 0.0, what: str = "hausdorff"
) -> Tuple[Any, ...]: ...

class SurfaceWitness(Tuple[int, int, Tuple[float, float, float], Tuple[float, float, float], float, float,
                           int, int, Tuple[float, float, float]]):
    face_a: int
    index_a: int
    bary_a: Tuple[float, float, float]
    point_a: Tuple[float, float, float]
    distance: float
    error: float
    face_b: int
    index_b: int
    point_b: Tuple[float, float, float]

class Enclosure(Tuple[float, float, float, bool, SurfaceWitness, int, int, int, float]):
    lower: float
    upper: float
    tolerance: float
    converged: bool
    witness: SurfaceWitness
    faces_dropped: int
    faces_split: int
    kernel_calls: int
    seconds: float

class SurfaceHausdorff(Tuple[float, float, Enclosure, Optional[Enclosure]]):
    lower: float
    upper: float
    ab: Enclosure
    ba: Optional[Enclosure]

def surface_hausdorff(
    a: Mesh, b: Union[Mesh, Points], *, tolerance: float = 1e-9, relative: bool = True,
    directed: bool = False, threads: Optional[int] = None, max_splits: int = 1 << 20
) -> SurfaceHausdorff: ...
def surface_within(
    a: Mesh, b: Mesh, d: float, *, directed: bool = False, tolerance: float = 1e-9, relative: bool = True,
    threads: Optional[int] = None, max_splits: int = 1 << 20
) -> Optional[bool]: ...
def face_maxima(
    a: Mesh, b: Mesh, *, tolerance: float = 1e-9, relative: bool = True, threads: Optional[int] = None,
    max_splits: int = 1 << 20
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], Enclosure]: ...
