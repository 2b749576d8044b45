"""scipy's own tests of directed_hausdorff, run against hausdorff.directed.

scipy's test module (scipy/spatial/tests/test_hausdorff.py, which Debian's
python3-scipy installs) is loaded under another name, its global
directed_hausdorff is replaced by hausdorff.directed, and its tests are
collected here, unchanged.  Every one must pass except those listed below
with the reason, which conftest.py marks as strict expected failures: a
listed test that starts passing fails the run too (then take it off the
list), and so does a listed name that no longer exists.  docs/python.md
repeats the list.
"""
import importlib.util
import pathlib

import pytest

import hausdorff

spec = importlib.util.find_spec("scipy")
if spec is None:
    pytest.skip("scipy is not installed (scripts/deps.sh python installs it)",
                allow_module_level=True)
SCIPY_TESTS = pathlib.Path(spec.origin).parent / "spatial" / "tests" / "test_hausdorff.py"
if not SCIPY_TESTS.is_file():
    pytest.skip(f"scipy's tests are not installed ({SCIPY_TESTS})", allow_module_level=True)

_spec = importlib.util.spec_from_file_location("scipy_test_hausdorff", SCIPY_TESTS)
scipy_tests = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(scipy_tests)
scipy_tests.directed_hausdorff = hausdorff.directed

# scipy's tests, collected as if written here (their globals are scipy_tests').
TestHausdorff = scipy_tests.TestHausdorff
test_massive_arr_overflow = scipy_tests.test_massive_arr_overflow

# test id (after the file's "::") -> (the exception it fails with, why
# hausdorff.directed differs); failing with any other exception is a failure.
EXPECTED_FAILURES = {
    "TestHausdorff::test_subsets[A2-B2-77098-expected2]": (
        AssertionError,
        "a tie: both points of A lie in B, so every pair (i, nearest j) realises 0.0; "
        "scipy's expected witness (1, 1) is where its seeded shuffle stops, ours is the "
        "canonical one, the smallest i and then the smallest j: (0, 2)"),
}

# test id -> why it is not run.
SKIPPED = {
    "test_massive_arr_overflow":
        "scipy marks it xslow (its own conftest skips it unless SCIPY_XSLOW is set): "
        "it needs psutil and 80 GiB of free memory for a (3e9, 2) array",
}

collected = set()  # conftest.py records the ids it saw here


def test_the_lists_name_only_tests_that_exist():
    """Runs last in this file (pytest keeps definition order, and the
    imported tests above come first)."""
    missing = (set(EXPECTED_FAILURES) | set(SKIPPED)) - collected
    assert not missing, f"listed but not in scipy's tests any more: {sorted(missing)}"


def test_the_module_really_runs_against_hausdorff():
    assert scipy_tests.directed_hausdorff is hausdorff.directed
    assert len([k for k in collected if k.startswith("TestHausdorff::")]) >= 14
