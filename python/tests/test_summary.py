"""summary(), mean() and chamfer(): the command line's --mean and --chamfer,
and percentile() its --percentile, to the bit (the tool's --json prints every
double with 17 significant digits, which reads back exactly)."""
import json
import math
import os
import pathlib
import subprocess

import numpy as np
import pytest

import hausdorff
from conftest import SOURCE_DIR, brute_nearest, gauss, lattice


def cli():
    """The command-line tool: HD_CLI (CTest sets it), else a build's."""
    path = os.environ.get("HD_CLI")
    if path:
        assert pathlib.Path(path).is_file(), f"HD_CLI={path} does not exist"
        return path
    for build in ("build-py", "build"):
        p = SOURCE_DIR / build / "hausdorff"
        if p.is_file():
            return str(p)
    pytest.skip("no hausdorff command-line tool (set HD_CLI)")


def run_cli(tmp_path, a, b, *options):
    pa, pb = tmp_path / "a.npy", tmp_path / "b.npy"
    np.save(pa, np.asarray(a, dtype=np.float64))
    np.save(pb, np.asarray(b, dtype=np.float64))
    out = subprocess.run([cli(), "--json", *options, str(pa), str(pb)], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)


def number(x):
    """The tool writes inf and NaN as null."""
    return None if not math.isfinite(x) else x


CASES = {
    "gaussians": lambda: (gauss(401, 900), gauss(402, 700, mean=(0.3, 0, 0))),
    "lattice ties": lambda: (lattice(403, 500, 6), lattice(404, 400, 6)),
    "far apart": lambda: (gauss(405, 300) + 1e6, gauss(406, 200) + 1e6 + 5),
    "single point": lambda: (gauss(407, 1), gauss(408, 30)),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_mean_chamfer_and_percentile_are_the_command_lines_doubles(case, tmp_path):
    a, b = CASES[case]()
    j = run_cli(tmp_path, a, b, "--mean", "--chamfer", "--percentile", "95")
    m = hausdorff.mean(a, b)
    assert dict(zip(("ab", "ba", "symmetric", "average", "pooled"), m)) == j["mean"]
    s = hausdorff.summary(a, b)
    c = j["chamfer"]
    assert hausdorff.chamfer(a, b) == c["value"] == c["mean_squared"] == s.chamfer
    assert (s.chamfer_sum2, s.chamfer_mean, s.chamfer_sum, s.mean2_ab, s.mean2_ba) == \
        (c["sum_squared"], c["mean"], c["sum"], c["mean_squared_ab"], c["mean_squared_ba"])
    assert (s.mean_ab, s.mean_ba, s.mean_symmetric, s.mean_average, s.mean_pooled) == tuple(m)
    assert (s.max_ab, s.max_ba) == (j["directed_ab"], j["directed_ba"])
    p = hausdorff.percentile(a, b, 95)
    assert dict(zip(("p", "ab", "ba", "symmetric", "pooled"), p)) == j["percentile"]


def test_directed_summary_is_the_command_lines_directed_run(tmp_path):
    a, b = gauss(409, 600), gauss(410, 500)
    j = run_cli(tmp_path, a, b, "--directed", "--mean", "--chamfer")
    s = hausdorff.summary(a, b, directed=True)
    assert s.mean_ab == j["mean"]["ab"] and j["mean"]["ba"] is None
    assert s.mean2_ab == j["chamfer"]["value"] == j["chamfer"]["mean_squared_ab"]
    assert math.isnan(s.mean_ba) and math.isnan(s.chamfer) and s.n_ba == 0


@pytest.mark.parametrize("policy", ["inf", "nan", "zero"])
@pytest.mark.parametrize("which", ["a", "b", "both"])
def test_empty_sets_give_what_the_command_lines_empty_gives(policy, which, tmp_path):
    p, e = gauss(411, 30), np.zeros((0, 3))
    a, b = {"a": (e, p), "b": (p, e), "both": (e, e)}[which]
    j = run_cli(tmp_path, a, b, "--empty", policy, "--mean", "--chamfer", "--percentile", "95")
    assert j["empty"]["policy"] == policy
    assert number(hausdorff.hausdorff(a, b, empty=policy).distance) == j["hausdorff"]
    assert number(hausdorff.directed(a, b, empty=policy).distance) == j["directed_ab"]
    assert [number(x) for x in hausdorff.mean(a, b, empty=policy)] == list(j["mean"].values())
    assert number(hausdorff.chamfer(a, b, empty=policy)) == j["chamfer"]["value"]
    r = hausdorff.percentile(a, b, 95, empty=policy)
    assert [number(x) for x in r] == list(j["percentile"].values())


@pytest.mark.parametrize("case", sorted(CASES))
def test_summary_agrees_with_exact_sums_of_the_brute_force(case):
    a, b = CASES[case]()
    d_ab = np.sqrt(brute_nearest(a, b)[0])
    d_ba = np.sqrt(brute_nearest(b, a)[0])
    s = hausdorff.summary(a, b)
    assert (s.n_ab, s.n_ba, s.max_ab, s.max_ba) == (len(a), len(b), d_ab.max(), d_ba.max())
    for got, values in [(s.sum_ab, d_ab), (s.sum_ba, d_ba), (s.sum2_ab, d_ab * d_ab),
                        (s.sum2_ba, d_ba * d_ba)]:
        assert got == math.fsum(values)  # correctly rounded, whatever the order
    assert s.mean_ab == s.sum_ab / len(a) and s.mean2_ba == s.sum2_ba / len(b)
    assert s.mean_symmetric == max(s.mean_ab, s.mean_ba)
    both = np.concatenate([d_ab, d_ba])
    assert s.mean_pooled == math.fsum(both) / (len(a) + len(b))
    assert s.chamfer_sum == math.fsum(both) and s.chamfer_sum2 == math.fsum(both * both)
    assert s.chamfer == s.mean2_ab + s.mean2_ba


@pytest.mark.parametrize("threads", [1, 3, None])
def test_summary_is_the_same_at_any_thread_count(threads):
    a, b = lattice(412, 3000, 9), gauss(413, 2000) * 3
    assert hausdorff.summary(a, b, threads=threads) == hausdorff.summary(a, b, threads=1)
    assert hausdorff.mean(a, b, threads=threads) == hausdorff.mean(a, b, threads=1)


def test_two_dimensional_points_summarise_as_the_plane_z_0():
    a, b = gauss(414, 200)[:, :2], gauss(415, 150)[:, :2]
    lift = lambda p: np.column_stack([p, np.zeros(len(p))])
    assert hausdorff.summary(a, b) == hausdorff.summary(lift(a), lift(b))
