"""read(): files through the library's readers into (N, 3) arrays."""
import doctest

import numpy as np
import pytest

import hausdorff
from conftest import brute_directed


def test_read_xyz_gives_the_parsed_doubles(tmp_path):
    pts = np.random.default_rng(131).normal(size=(57, 3))
    path = tmp_path / "cloud.xyz"
    np.savetxt(path, pts, fmt="%.17g")
    got = hausdorff.read(path)                  # os.PathLike accepted
    assert got.dtype == np.float64 and got.shape == (57, 3)
    assert np.array_equal(got, pts)
    assert got.flags.c_contiguous and got.flags.owndata is False


def test_read_float32_keeps_floats(tmp_path):
    pts = np.random.default_rng(132).normal(size=(20, 3)).astype(np.float32)
    path = tmp_path / "cloud.txt"
    np.savetxt(path, pts, fmt="%.9g")
    got = hausdorff.read(str(path), float32=True)
    assert got.dtype == np.float32 and np.array_equal(got, pts)


def test_read_with_an_explicit_format(tmp_path):
    path = tmp_path / "cloud.data"
    path.write_text("1 2 3\n4 5 6\n")
    assert hausdorff.read(path, format="xyz").tolist() == [[1, 2, 3], [4, 5, 6]]
    assert "xyz" in hausdorff.formats()


def test_read_decimal_commas_need_decimal_comma_true(tmp_path):
    path = tmp_path / "excel.csv"
    path.write_text("x;y;z\n1,5;2,5;3,5\n4,25;5,5;6,75\n")
    with pytest.raises(ValueError, match=r"excel.csv:2: '1,5' has a decimal comma.*decimal_comma=True"):
        hausdorff.read(path)
    got = hausdorff.read(path, decimal_comma=True)
    assert got.tolist() == [[1.5, 2.5, 3.5], [4.25, 5.5, 6.75]]


def test_read_a_range_and_count_from_the_header(tmp_path):
    pts = np.random.default_rng(133).normal(size=(1000, 3))
    path = tmp_path / "big.npy"
    np.save(path, pts)
    assert hausdorff.count(path) == 1000
    assert np.array_equal(hausdorff.read(path, start=250, count=500), pts[250:750])
    assert np.array_equal(hausdorff.read(path, start=990), pts[990:])
    parts = [hausdorff.read(path, start=s, count=250) for s in range(0, 1000, 250)]
    assert np.array_equal(np.concatenate(parts), pts)
    with pytest.raises(ValueError, match=r"points \[999, 1001\) asked of a file of 1000 points"):
        hausdorff.read(path, start=999, count=2)
    with pytest.raises(ValueError, match="start 1000 is not below"):
        hausdorff.read(path, start=1000)
    with pytest.raises(ValueError, match="positive"):
        hausdorff.read(path, count=0)
    text = tmp_path / "t.xyz"
    np.savetxt(text, pts[:10], fmt="%.17g")
    assert np.array_equal(hausdorff.read(text, start=3, count=4), pts[3:7])   # read whole, then cut
    assert np.array_equal(hausdorff.read(text, start=8), pts[8:10])
    with pytest.raises(ValueError, match="needs reading"):
        hausdorff.count(text)


class Indexable:
    def __init__(self, v):
        self.v = v

    def __index__(self):
        return self.v


def test_start_and_count_are_integers_of_any_kind_never_wrapped(tmp_path):
    """start was taken modulo 2**64: 2**64 + 5 read from point 5 and -1 was
    reported as 18446744073709551615.  Both are parsed as count is: any
    integer (numpy's, __index__), out of range a ValueError naming the value,
    a float a TypeError."""
    pts = np.random.default_rng(134).normal(size=(20, 3))
    path = tmp_path / "p.npy"
    np.save(path, pts)
    for make in (int, np.int64, np.uint32, Indexable):
        assert np.array_equal(hausdorff.read(path, start=make(3), count=make(4)), pts[3:7])
    for start in (2**64 + 5, 2**64, -1, np.int64(-1)):
        for count in (None, 1):
            with pytest.raises(ValueError, match=r"read: start must be a non-negative integer "
                                                 r"below 2\*\*64, not -?\d+$") as e:
                hausdorff.read(path, start=start, count=count)
            assert "18446744073709551615" not in str(e.value) and "overflows" not in str(e.value)
    for count in (2**64, -1, 0):
        with pytest.raises(ValueError, match=r"read: count must be a positive integer below 2\*\*64"):
            hausdorff.read(path, count=count)
    for bad in (1.0, "1", np.float64(2)):
        with pytest.raises(TypeError, match="start"):
            hausdorff.read(path, start=bad)
        with pytest.raises(TypeError, match="count"):
            hausdorff.read(path, count=bad)
    with pytest.raises(ValueError, match=r"start 18446744073709551615 is not below the file's 20"):
        hausdorff.read(path, start=2**64 - 1)


def test_read_errors_map_to_python_exceptions(tmp_path):
    with pytest.raises(OSError, match="cannot open"):
        hausdorff.read(tmp_path / "missing.xyz")
    empty = tmp_path / "empty.xyz"
    empty.write_text("")
    with pytest.raises(ValueError, match="no points"):
        hausdorff.read(empty)
    with pytest.raises(ValueError, match="unknown format"):
        hausdorff.read(empty, format="nonsense")


def read_ascii_ply(path):
    """The vertex block of the bundled ASCII PLY files (x y z doubles)."""
    with open(path) as f:
        n = None
        for line in f:
            if line.startswith("element vertex"):
                n = int(line.split()[2])
            if line.strip() == "end_header":
                break
        return np.loadtxt(f, max_rows=n, usecols=(0, 1, 2)).reshape(-1, 3)


@pytest.mark.parametrize("name", ["bunny_3511.ply", "cgal_lion_head.ply"])
def test_read_bundled_models_and_measure_them(data_dir, name):
    path = data_dir / name
    if "ply" not in hausdorff.formats():
        pytest.skip("this library has no PLY reader")
    pts = hausdorff.read(path)
    assert np.array_equal(pts, read_ascii_ply(path))
    other = pts[::2] + 0.001
    assert tuple(hausdorff.directed(pts, other)) == brute_directed(pts, other)


@pytest.mark.parametrize("module", [hausdorff, hausdorff._hausdorff])
def test_docstring_examples_run(module):
    failed, attempted = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert attempted > 0 and failed == 0
