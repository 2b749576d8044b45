"""What the functions accept: any (N, 3) array-like of float32 or float64 in
any layout, read in place when the layout allows; and what they refuse."""
import tracemalloc

import numpy as np
import pytest

import hausdorff
from conftest import brute_directed, gauss


def layouts(x):
    """The same points in different memory layouts (all float64)."""
    big = np.zeros((2 * len(x), 7))
    big[::2, 1:6:2] = x
    return {
        "C order": np.ascontiguousarray(x),
        "Fortran order": np.asfortranarray(x),
        "strided rows and columns": big[::2, 1:6:2],
        "reversed rows": np.ascontiguousarray(x[::-1])[::-1],
        "reversed columns": np.ascontiguousarray(x[:, ::-1])[:, ::-1],
        "list of lists": x.tolist(),
        "big-endian": x.astype(">f8"),
        "misaligned": np.frombuffer(b"\0" + x.tobytes(), dtype=np.float64,
                                    offset=1).reshape(-1, 3),
        "read-only": (lambda y: (y.setflags(write=False), y)[1])(x.copy()),
    }


@pytest.mark.parametrize("layout", sorted(layouts(np.zeros((1, 3)))))
def test_every_layout_gives_the_brute_force_answer(layout):
    a, b = gauss(101, 400), gauss(102, 300, mean=(0.2, 0, 0))
    expected = brute_directed(a, b)
    la, lb = layouts(a)[layout], layouts(b)[layout]
    assert tuple(hausdorff.directed(la, lb)) == expected
    assert tuple(hausdorff.directed(la, b)) == expected
    assert tuple(hausdorff.directed(a, lb)) == expected


def test_float32_is_widened_exactly():
    a = gauss(103, 500).astype(np.float32)
    b = np.asfortranarray(gauss(104, 400).astype(np.float32))
    expected = brute_directed(a.astype(np.float64), b.astype(np.float64))
    assert tuple(hausdorff.directed(a, b)) == expected
    assert tuple(hausdorff.directed(a[::-1], b)) == brute_directed(
        a[::-1].astype(np.float64), b.astype(np.float64))


def test_integer_and_float16_inputs_are_converted_to_float64():
    a = np.random.default_rng(105).integers(-50, 50, size=(300, 3))
    b = np.random.default_rng(106).integers(-50, 50, size=(200, 3)).astype(np.int32)
    assert tuple(hausdorff.directed(a, b)) == brute_directed(a.astype(float), b.astype(float))
    h = gauss(107, 100).astype(np.float16)
    assert tuple(hausdorff.directed(h, b)) == brute_directed(h.astype(float), b.astype(float))


def test_broadcast_rows_with_zero_stride_are_read_correctly():
    one = np.array([[3.0, 4.0, 0.0]])
    a = np.broadcast_to(one, (50, 3))
    b = gauss(108, 40)
    assert a.strides[0] == 0
    assert tuple(hausdorff.directed(a, b)) == brute_directed(np.array(a), b)
    assert tuple(hausdorff.directed(b, a)) == brute_directed(b, np.array(a))


def peak_numpy_bytes(fn):
    """Peak bytes numpy allocated (tracemalloc sees numpy's data buffers)
    while fn runs."""
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        base = tracemalloc.get_traced_memory()[0]
        fn()
        return tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()


def test_float_arrays_are_not_copied_whatever_their_layout():
    n = 200_000
    a = np.asfortranarray(gauss(109, n))[::-1]        # Fortran, reversed
    big = np.zeros((n, 6), dtype=np.float32)
    big[:, ::2] = gauss(110, n)
    b = big[:, ::2]                                     # strided float32
    size = a.nbytes                                     # 4.8 MB
    peak = peak_numpy_bytes(lambda: hausdorff.directed(a[:2000], b, threads=2))
    assert peak < size / 10
    peak = peak_numpy_bytes(lambda: hausdorff.directed(b[:2000], a, threads=2))
    assert peak < size / 10
    # The measurement does see a copy when one is needed.
    ints = np.zeros((n, 3), dtype=np.int64)
    peak = peak_numpy_bytes(lambda: hausdorff.directed(ints[:10], ints))
    assert peak >= size


@pytest.mark.parametrize("shape", [(3,), (2, 3, 1), (10, 0)])
def test_wrong_shapes_are_value_errors(shape):
    with pytest.raises(ValueError, match=r"a must be an \(N, D\) array of N points"):
        hausdorff.directed(np.zeros(shape), np.zeros(shape))
    with pytest.raises(ValueError, match=r"b must be an \(N, D\) array of N points|"
                                         r"need to have the same number of columns"):
        hausdorff.hausdorff(gauss(111, 5), np.zeros(shape))


@pytest.mark.parametrize("fn", ["directed", "hausdorff", "distances", "percentile", "Index"])
def test_empty_sets_are_value_errors(fn):
    empty = np.zeros((0, 3))
    args = {"directed": (empty, gauss(112, 5)), "hausdorff": (gauss(112, 5), empty),
            "distances": (empty, gauss(112, 5)), "percentile": (gauss(112, 5), empty, 95),
            "Index": (empty,)}[fn]
    with pytest.raises(ValueError, match="empty"):
        getattr(hausdorff, fn)(*args)


@pytest.mark.parametrize("bad, what", [(np.nan, "NaN"), (np.inf, "infinite"),
                                       (-np.inf, "infinite"), (1e200, "limit")])
def test_non_finite_or_huge_coordinates_are_value_errors(bad, what):
    a = gauss(113, 20)
    a[7, 1] = bad
    with pytest.raises(ValueError, match=what) as e:
        hausdorff.directed(a, gauss(114, 10))
    assert "point 7" in str(e.value)
    with pytest.raises(ValueError, match=what):
        hausdorff.hausdorff(gauss(114, 10), a)
    with pytest.raises(ValueError, match=what):
        hausdorff.distances(gauss(114, 10), a)
    with pytest.raises(ValueError, match=what):
        hausdorff.Index(a)
    with pytest.raises(ValueError, match=what):
        hausdorff.Index(gauss(114, 10)).directed(a)


def test_non_numeric_dtypes_are_type_errors():
    with pytest.raises(TypeError, match=r"a must hold real numbers \(float32, float64, integers or "
                                        r"booleans\), got complex128$"):
        hausdorff.directed(np.zeros((4, 3), dtype=complex), gauss(115, 3))
    with pytest.raises((TypeError, ValueError)):
        hausdorff.directed([["a", "b", "c"]], gauss(115, 3))


@pytest.mark.parametrize("dims", [1, 2, 3, 5])
def test_booleans_are_zero_and_one_as_scipy_computes_with_them(dims):
    rng = np.random.default_rng(118 + dims)
    a, b = rng.random((40, dims)) < 0.5, rng.random((30, dims)) < 0.5
    want = brute_directed(a.astype(float), b.astype(float))
    assert tuple(hausdorff.directed(a, b)) == want
    assert tuple(hausdorff.directed(a, b.astype(float))) == want
    spatial = pytest.importorskip("scipy.spatial.distance")
    assert spatial.directed_hausdorff(a, b)[0] == want[0]


def test_a_non_finite_coordinate_is_named_with_its_article():
    a = gauss(119, 5)
    a[2, 0] = np.inf
    with pytest.raises(ValueError, match="point set A: point 2 has an infinite coordinate"):
        hausdorff.directed(a, gauss(120, 5))


def test_bad_options_are_rejected_clearly():
    a, b = gauss(116, 5), gauss(117, 5)
    with pytest.raises(ValueError, match="unknown algorithm 'fastest'"):
        hausdorff.directed(a, b, algorithm="fastest")
    with pytest.raises(ValueError, match="threads"):
        hausdorff.directed(a, b, threads=-1)
    with pytest.raises(TypeError, match="threads"):
        hausdorff.directed(a, b, threads=1.5)
    with pytest.raises(TypeError, match="seed"):
        hausdorff.directed(a, b, seed="1")
    with pytest.raises(ValueError, match="empty must be"):
        hausdorff.directed(a, b, empty="skip")
    with pytest.raises(TypeError):
        hausdorff.directed(a, b, 0, "naive")   # after seed, keyword-only (as scipy's)
    with pytest.raises(TypeError):
        hausdorff.hausdorff(a, b, 0)           # hausdorff() options are keyword-only
