"""The report a person reads: distances as the shortest text that reads back
as the same double; a coordinate of float32 data (a binary STL, --float32,
a NIfTI-1 mask) as the shortest text of its float; ratios and times for a
person; counts singular for one; --sample leaving a point side as its
points; hausdorff-mpi with its own --help and the same report.  The
functions behind the numbers are tests/cli_numtext_unit.c's.

Usage: cli_report.py HAUSDORFF [NAME-FILTER] (hausdorff-mpi from
HD_MPI_TOOL; the NIfTI cases when HD_CLI_NIFTI is ON).
"""
import json
import math
import os
import re
import struct
import subprocess

import numpy as np

from cli_analysis_support import main, run, run_json, test, write_nifti, write_xyz

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(os.path.dirname(HERE), "data")
MPI_TOOL = os.environ.get("HD_MPI_TOOL") or None
MPI_ENV = dict(os.environ, ASAN_OPTIONS="detect_leaks=0")  # Open MPI's own leaks, in a sanitizer build


def f32(v):
    return struct.unpack("<f", struct.pack("<f", v))[0]


def write_stl(path, triangles):
    """A binary STL (float32 coordinates) of the given triangles."""
    with open(path, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(triangles)))
        for t in triangles:
            f.write(struct.pack("<3f", 0, 0, 0))
            for v in t:
                f.write(struct.pack("<3f", *v))
            f.write(b"\0\0")


def witness_lines(out):
    return [l for l in out.splitlines() if l.startswith(("witness:", "     to"))]


def mpirun(*args, k=1):
    p = subprocess.run(["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(k), MPI_TOOL] + list(args),
                       capture_output=True, text=True, timeout=300, env=MPI_ENV)
    assert p.returncode == 0, (args, p.stdout, p.stderr)
    return p.stdout


@test
def derived_figures_print_four_significant_digits(tmp):
    args = [os.path.join(DATA, "cgal_lion_head.ply"), os.path.join(DATA, "cgal_lion.ply")]
    out, _ = run(args)
    alpha = re.search(r"^overlap alpha = (\S+);", out, re.M).group(1)
    assert alpha == "%.4g" % run_json(args)["alpha"], (alpha, out)
    assert len(alpha.replace("0.", "", 1).lstrip("0")) <= 4, alpha


@test
def distances_keep_the_shortest_text_that_reads_back(tmp):
    out, _ = run([os.path.join(DATA, "cgal_lion_head.ply"), os.path.join(DATA, "cgal_lion.ply")])
    assert "Hausdorff distance H(A,B) = 0.14468150162771326\n" in out, out


@test
def a_float32_files_coordinates_print_as_the_shortest_text_of_the_float(tmp):
    stl, origin = os.path.join(tmp, "part.stl"), os.path.join(tmp, "origin.xyz")
    write_stl(stl, [((11.2, 0.8, 3.3), (1, 2, 3), (4, 5, 6))])
    write_xyz(origin, [(0, 0, 0)])
    out, _ = run([stl, origin])
    x, y, z = f32(11.2), f32(0.8), f32(3.3)
    d = math.sqrt(x * x + y * y + z * z)  # the distance stays the double's
    assert "H(A,B) = %r\n" % d in out, out
    assert witness_lines(out) == ["witness: A[0] (11.2, 0.8, 3.3)", "     to  B[0] (0, 0, 0)"], out


@test
def float32_storage_prints_floats_and_double_input_keeps_its_doubles(tmp):
    a, origin = os.path.join(tmp, "a.xyz"), os.path.join(tmp, "origin.xyz")
    with open(a, "w") as f:
        f.write("0.1 0.2 0.3\n")
    write_xyz(origin, [(0, 0, 0)])
    out, _ = run(["--float32", a, origin])
    assert witness_lines(out)[0] == "witness: A[0] (0.1, 0.2, 0.3)", out
    with open(a, "w") as f:
        f.write("0.1000000001 0.2 0.3\n")
    out, _ = run([a, origin])
    assert witness_lines(out)[0] == "witness: A[0] (0.1000000001, 0.2, 0.3)", out


@test
def a_nifti1_masks_spacing_and_witness_print_as_floats(tmp):
    if os.environ.get("HD_CLI_NIFTI") != "ON":
        print("     (skipped: the tool is built without libnifti2)")
        return
    far, near = np.zeros((16, 2, 2), np.uint8), np.zeros((16, 2, 2), np.uint8)
    far[14, 0, 0] = near[0, 0, 0] = 1
    for version, x, spacing in ((1, "11.2", "0.8"), (2, repr(14 * 0.8), "0.8")):
        pa, pb = os.path.join(tmp, "far%d.nii" % version), os.path.join(tmp, "near%d.nii" % version)
        write_nifti(pa, far, pixdim=(0.8, 0.8, 0.8), version=version)
        write_nifti(pb, near, pixdim=(0.8, 0.8, 0.8), version=version)
        out, _ = run(["--directed", pa, pb])
        assert witness_lines(out) == ["witness: A[0] (%s, 0, 0)" % x, "     to  B[0] (0, 0, 0)"], (version, out)
        assert "spacing %s x %s x %s," % (spacing, spacing, spacing) in out, (version, out)
        d = 14 * (f32(0.8) if version == 1 else 0.8)
        assert "h(A,B) = %r mm\n" % d in out, (version, out)


@test
def times_print_in_seconds_never_in_exponent_form(tmp):
    a = os.path.join(tmp, "a.xyz")
    write_xyz(a, [(0, 0, 0), (1, 0, 0)])
    for args in ([a, a], ["--mean", a, a], [os.path.join(DATA, "cgal_lion_head.ply"), os.path.join(DATA, "cgal_lion.ply")]):
        out, _ = run(args)
        times = [l for l in out.splitlines() if l.startswith("time:")]
        assert times, out
        for l in times:
            for t in re.findall(r"(\S+) s\b", l):
                assert re.fullmatch(r"\d+(\.\d+)?", t), (l, out)
                assert len(t.replace(".", "").lstrip("0")) <= 3 or float(t) >= 1000, (l, out)


@test
def counts_are_singular_for_one(tmp):
    a, stl = os.path.join(tmp, "one.xyz"), os.path.join(tmp, "one.stl")
    write_xyz(a, [(1.5, 2, 3)])
    write_stl(stl, [((0, 0, 0), (1, 0, 0), (0, 1, 0))])
    out, _ = run([a, stl])
    assert "A: %s (1 point, xyz)\n" % a in out, out
    assert "B: %s (3 points, stl, 1 face)\n" % stl in out, out


@test
def sample_draws_on_the_mesh_and_leaves_a_point_side_as_its_points(tmp):
    stl, pts = os.path.join(tmp, "part.stl"), os.path.join(tmp, "scan.xyz")
    write_stl(stl, [((0, 0, 0), (1, 0, 0), (0, 1, 0))])
    write_xyz(pts, [(0, 0, 1), (2, 2, 2)])
    out, _ = run(["--sample", "50", "--seed", "3", stl, pts])
    assert "A: %s (50 points, stl sampled from 1 face)\n" % stl in out, out
    assert "B: %s (2 points, xyz)\n" % pts in out, out
    j = run_json(["--sample", "50", "--seed", "3", pts, pts])
    assert j["n_a"] == 2 and j["hausdorff"] == 0, j


@test
def hausdorff_mpi_prints_its_own_help(tmp):
    if not MPI_TOOL:
        print("     (skipped: hausdorff-mpi is not built)")
        return
    text = subprocess.run([MPI_TOOL, "--help"], capture_output=True, text=True, timeout=120, check=True,
                          env=MPI_ENV).stdout
    assert text.startswith("usage: mpirun -n K hausdorff-mpi [options] A B\n"), text
    assert "--allow-run-as-root" in text and "--oversubscribe" in text, text
    examples = text[text.index("Examples:"):]
    assert not re.search(r"^  hausdorff ", examples, re.M) and "  mpirun -n 64 hausdorff-mpi " in examples, text
    own, _ = run(["--help"])
    assert own.startswith("usage: hausdorff [options] A B\n") and "mpirun" not in own, own


@test
def hausdorff_mpi_prints_the_same_report_with_figures_for_a_person(tmp):
    if not MPI_TOOL:
        print("     (skipped: hausdorff-mpi is not built)")
        return
    stl, origin = os.path.join(tmp, "part.stl"), os.path.join(tmp, "origin.xyz")
    write_stl(stl, [((11.2, 0.8, 3.3), (1, 2, 3), (4, 5, 6))])
    write_xyz(origin, [(0, 0, 0)])
    keep = lambda out: [l for l in out.splitlines() if not l.startswith(("time:", "mpi:"))]
    for args in ([stl, origin], [os.path.join(DATA, "cgal_lion_head.ply"), os.path.join(DATA, "cgal_lion.ply")]):
        one, _ = run(args)
        out = mpirun(*args)
        assert keep(out) == keep(one), (one, out)
        m = re.search(r"^mpi: 1 rank, (\S+) bytes moved per point, (\S+) of the points forwarded, imbalance (\S+)$",
                      out, re.M)
        assert m, out
        for figure in m.groups():
            assert figure == "%.4g" % float(figure), (figure, out)


@test
def hausdorff_mpi_samples_the_mesh_and_reads_the_scan_by_point_ranges(tmp):
    if not MPI_TOOL:
        print("     (skipped: hausdorff-mpi is not built)")
        return
    args = ["--sample", "1000", "--seed", "7", os.path.join(DATA, "orig", "Wuson.stl"),
            os.path.join(DATA, "orig", "Haystack_Rock.las")]
    keep = lambda out: [l for l in out.splitlines() if not l.startswith(("time:", "mpi:"))]
    one, _ = run(args)
    assert "(21932 points, las)" in one, one
    assert keep(mpirun(*args, k=2)) == keep(one)
    j = json.loads(mpirun("--json", *args, k=2))
    assert j["mpi"]["read_by_points"] == [False, True], j["mpi"]


if __name__ == "__main__":
    main()
