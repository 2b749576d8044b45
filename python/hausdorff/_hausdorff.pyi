"""Type stubs of the hausdorff C extension (see the docstrings for details)."""
import os
from typing import Dict, List, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

# Any (N, 3) array-like of real numbers; float32 and float64 arrays are read
# in place (C or Fortran order, strided or reversed views).
Points = npt.ArrayLike
Matrix3 = npt.ArrayLike  # (3, 3)
Vector3 = npt.ArrayLike  # (3,)

__version__: str
algorithms: Tuple[str, ...]

class DirectedResult(Tuple[float, int, int]):
    """h(A, B) and its witness: the tuple (distance, i, j)."""
    @property
    def distance(self) -> float: ...
    @property
    def i(self) -> int: ...
    @property
    def j(self) -> int: ...
    @property
    def algorithm(self) -> str: ...
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
    def disjoint(self) -> bool: ...
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

def directed(
    a: Points,
    b: Points,
    *,
    algorithm: str = "auto",
    threads: Optional[int] = None,
    seed: int = 0,
) -> DirectedResult: ...
def hausdorff(
    a: Points,
    b: Points,
    *,
    algorithm: str = "auto",
    threads: Optional[int] = None,
    seed: int = 0,
) -> HausdorffResult: ...
def distances(
    a: Points, b: Points, *, threads: Optional[int] = None
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.intp]]: ...
@overload
def percentile(
    a: Points, b: Points, p: float, *, threads: Optional[int] = None
) -> PercentileResult: ...
@overload
def percentile(
    a: Points, b: Points, p: Union[Sequence[float], npt.NDArray[np.floating]], *,
    threads: Optional[int] = None
) -> List[PercentileResult]: ...
def read(
    path: Union[str, bytes, os.PathLike[str], os.PathLike[bytes]],
    *,
    format: Optional[str] = None,
    float32: bool = False,
) -> npt.NDArray[np.floating]: ...
def formats() -> Dict[str, str]: ...

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
