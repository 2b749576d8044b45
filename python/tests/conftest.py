"""Shared helpers of the Python tests: an independent brute force in numpy,
seeded point sets, and the repository's data directory.

The brute force evaluates squared distances as dx*dx + dy*dy + dz*dz, left to
right (as many terms as the points have coordinates), one numpy operation at
a time (numpy never fuses a multiply into an add), takes the first index of
each minimum and maximum (numpy's argmin and argmax return the first), and
one sqrt at the end: the definition the library promises to match to the bit.
"""
import os
import pathlib

import numpy as np
import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("HD_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
DATA_DIR = SOURCE_DIR / "data"


def as_f64(x):
    return np.asarray(x, dtype=np.float64)


def brute_nearest(a, b, chunk=2048):
    """Squared nearest distance of every point of a to b, and the smallest
    index attaining it; points of any number of coordinates."""
    a, b = as_f64(a), as_f64(b)
    d2 = np.empty(len(a))
    j = np.empty(len(a), dtype=np.intp)
    for s in range(0, len(a), chunk):
        p = a[s:s + chunk]
        m = None
        for c in range(a.shape[1]):   # columns summed left to right
            d = p[:, None, c] - b[None, :, c]
            m = d * d if m is None else m + d * d
        k = np.argmin(m, axis=1)
        j[s:s + chunk] = k
        d2[s:s + chunk] = m[np.arange(len(p)), k]
    return d2, j


def distance(p, q):
    """|p - q| evaluated as the library does (any number of coordinates)."""
    p, q = as_f64(p), as_f64(q)
    d = p - q
    s = d[0] * d[0]
    for c in range(1, len(d)):
        s = s + d[c] * d[c]
    return float(np.sqrt(s))


def brute_directed(a, b):
    """(distance, i, j) of h(a, b) with the canonical witness."""
    d2, j = brute_nearest(a, b)
    i = int(np.argmax(d2))
    return float(np.sqrt(d2[i])), i, int(j[i])


def brute_transform(rotation, translation, points):
    """The header's transform, in its order: ((r0*x + r1*y) + r2*z) + t0."""
    r = as_f64(rotation).reshape(9)
    t = as_f64(translation)
    p = as_f64(points)
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    out = np.empty_like(p)
    for row in range(3):
        out[:, row] = ((r[3 * row] * x + r[3 * row + 1] * y) + r[3 * row + 2] * z) + t[row]
    return out


def gauss(seed, n, mean=(0.0, 0.0, 0.0), sigma=1.0):
    return np.random.default_rng(seed).normal(mean, sigma, size=(n, 3))


def lattice(seed, n, side):
    """Integer lattice points: ties everywhere."""
    return np.random.default_rng(seed).integers(0, side, size=(n, 3)).astype(np.float64)


@pytest.fixture
def data_dir():
    if not DATA_DIR.is_dir():
        pytest.skip(f"no data directory at {DATA_DIR}")
    return DATA_DIR


def pytest_configure(config):
    # scipy's test module (run by test_scipy_suite.py) uses its own marker.
    config.addinivalue_line("markers", "xslow: scipy's very slow tests")


def pytest_collection_modifyitems(config, items):
    """test_scipy_suite.py: strict expected failures and skips, each with its
    reason, from the module's EXPECTED_FAILURES and SKIPPED."""
    for item in items:
        module = getattr(item, "module", None)
        expected = getattr(module, "EXPECTED_FAILURES", None)
        if expected is None:
            continue
        key = item.nodeid.split("::", 1)[1]
        module.collected.add(key)
        if key in expected:
            raises, reason = expected[key]
            item.add_marker(pytest.mark.xfail(raises=raises, reason=reason, strict=True))
        if key in module.SKIPPED:
            item.add_marker(pytest.mark.skip(reason=module.SKIPPED[key]))
