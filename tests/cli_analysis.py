"""The command line's analysis options against numpy and a brute force:
the --percentile JSON contract (numpy's percentile to the bit, MONAI's
symmetric and medpy's pooled figures), --mean and --chamfer (their stated
definitions, to a rounding), --histogram (np.histogram's counts), the
--distances files (CSV, PLY, NPY: read back identically, CSV and PLY also by
the tool's own reader), the pictures (size, not blank, the witness markers
where the JSON says), --empty, and usage errors.

usage: cli_analysis.py HAUSDORFF [NAME-FILTER]
"""
import json
import math
import os
import re
import struct
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_analysis_support import (lattice_clouds, main, nearest, read_png, run, run_json, same,  # noqa: E402
                                  test, tool, write_pair, write_xyz)


def pictures_built():
    """False when the tool was built without libpng (HD_CLI_PNG=OFF)."""
    return os.environ.get("HD_CLI_PNG", "ON").upper() not in ("OFF", "0", "FALSE", "NO")


def refuses_pictures(args):
    """Without libpng, a picture option is a usage error that says why."""
    _, err = run(args, expect=1)
    assert "unavailable" in err and "libpng" in err, err


def gauss_clouds(seed, na, nb):
    r = np.random.default_rng(seed)
    return r.standard_normal((na, 3)), r.standard_normal((nb, 3)) + [0.4, 0, 0]


def cases():
    """(name, A, B): ties on lattices, duplicates, Gaussians, unequal sizes."""
    yield ("lattice", *lattice_clouds(1, 700, 500))
    yield ("small lattice, duplicates", *lattice_clouds(2, 300, 300, side=3))
    yield ("gauss", *gauss_clouds(3, 900, 800))
    yield ("1:100", *gauss_clouds(4, 1500, 15))


def cases_with_files(tmp):
    """(name, file A, file B, distances A->B, distances B->A) per case."""
    for name, a, b in cases():
        pa, pb = write_pair(tmp, a, b)
        yield name, pa, pb, nearest(a, b)[0], nearest(b, a)[0]


@test
def percentile_json_is_numpy_percentile_monai_and_medpy(tmp):
    for name, pa, pb, dab, dba in cases_with_files(tmp):
        for p in (0, 5, 50, 95, 99.5, 100, 37.123456789):
            r = run_json(["--percentile", repr(p), pa, pb])
            q = r["percentile"]
            what = "%s p=%r" % (name, p)
            same(q["p"], p, what)
            same(q["ab"], np.percentile(dab, p), what + " ab")
            same(q["ba"], np.percentile(dba, p), what + " ba")
            same(q["symmetric"], max(np.percentile(dab, p), np.percentile(dba, p)), what + " symmetric")
            same(q["pooled"], np.percentile(np.hstack((dab, dba)), p), what + " pooled")
            if p == 100:
                same(q["symmetric"], r["hausdorff"], name + " P=100 is H")
                same(q["ab"], r["directed_ab"], name + " P=100 is h(A,B)")


@test
def directed_percentile_has_only_the_ab_figure(tmp):
    a, b = lattice_clouds(5, 200, 150)
    pa, pb = write_pair(tmp, a, b)
    r = run_json(["--directed", "--percentile", "95", "--mean", pa, pb])
    same(r["percentile"]["ab"], np.percentile(nearest(a, b)[0], 95))
    assert r["percentile"]["ba"] is None and r["percentile"]["pooled"] is None
    assert r["mean"]["ba"] is None


@test
def mean_and_chamfer_follow_their_stated_definitions(tmp):
    for name, pa, pb, dab, dba in cases_with_files(tmp):
        r = run_json(["--mean", "--chamfer", pa, pb])
        m, c = r["mean"], r["chamfer"]
        mab, mba = math.fsum(dab) / len(dab), math.fsum(dba) / len(dba)
        s2ab, s2ba = math.fsum(dab * dab), math.fsum(dba * dba)
        both = np.concatenate([dab, dba])
        want = {"mean ab": (m["ab"], mab), "mean ba": (m["ba"], mba),
                "mean symmetric": (m["symmetric"], max(mab, mba)),
                "mean average": (m["average"], (mab + mba) / 2),
                "mean pooled": (m["pooled"], math.fsum(both) / (len(dab) + len(dba))),
                "chamfer": (c["value"], s2ab / len(dab) + s2ba / len(dba)),
                "chamfer sum of squares": (c["sum_squared"], math.fsum(both * both)),
                "chamfer unsquared": (c["mean"], mab + mba),
                "chamfer unsquared sum": (c["sum"], math.fsum(both))}
        # the sums are correctly rounded (math.fsum's; the pooled ones over
        # both lists at once), so every figure is the same double as its
        # definition computed from them
        for what, (got, ref) in want.items():
            assert got == ref, "%s %s: %r vs %r" % (name, what, got, ref)
        assert c["definition"] == "mean_squared" and c["value"] == c["mean_squared"]


@test
def histogram_counts_are_numpys(tmp):
    a, b = lattice_clouds(6, 600, 400)  # many distances exactly on bin edges
    pa, pb = write_pair(tmp, a, b)
    dab, _ = nearest(a, b)
    dba, _ = nearest(b, a)
    top = max(dab.max(), dba.max())
    for bins, extra in ((20, []), (7, []), (13, ["--max-distance", "1.5"])):
        r = run_json(["--histogram", "--bins", str(bins)] + extra + [pa, pb])["histogram"]
        hi = 1.5 if extra else top
        assert r["bins"] == bins and r["range"] == [0, hi]
        assert r["ab"] == np.histogram(dab, bins, range=(0, hi))[0].tolist()
        assert r["ba"] == np.histogram(dba, bins, range=(0, hi))[0].tolist()
        assert r["above_ab"] == int((dab > hi).sum()) and r["above_ba"] == int((dba > hi).sum())
    out, _ = run(["--histogram", "--bins", "5", pa, pb])
    assert "histogram of distances (5 bins" in out


@test
def histogram_from_bounds_equals_the_histogram_of_every_distance(tmp):
    # --histogram alone or with --percentile counts from the library's
    # bounds (hd_hausdorff_histogram); with --mean every distance is
    # computed: the same counts, numpy's, at 1 and 3 threads
    for name, pa, pb, dab, dba in cases_with_files(tmp):
        top = max(dab.max(), dba.max())
        for bins, extra in ((1, []), (20, ["--percentile", "95"]), (500, []), (9, ["--max-distance", repr(top / 3)])):
            hi = top / 3 if "--max-distance" in extra else top
            want = (np.histogram(dab, bins, range=(0, hi))[0].tolist(), np.histogram(dba, bins, range=(0, hi))[0].tolist())
            for more in (["--threads", "1"], ["--threads", "3"], ["--mean"]):
                r = run_json(["--histogram", "--bins", str(bins)] + extra + more + [pa, pb])
                what = "%s bins=%d %s" % (name, bins, " ".join(extra + more))
                assert (r["histogram"]["ab"], r["histogram"]["ba"]) == want, what
                assert r["histogram"]["above_ba"] == int((dba > hi).sum()), what
                if extra and extra[0] == "--percentile":
                    same(r["percentile"]["pooled"], np.percentile(np.hstack((dab, dba)), 95), what)


def check_rows(rows, pts, d, j, what):
    assert rows.shape == (len(pts), 5), what
    assert np.array_equal(rows[:, :3], pts), what + ": coordinates"
    assert np.array_equal(rows[:, 3], d), what + ": distances"
    assert np.array_equal(rows[:, 4], j), what + ": nearest indices"


@test
def distances_csv_has_the_contract_columns_and_reads_back(tmp):
    a, b = gauss_clouds(7, 500, 400)
    pa, pb = write_pair(tmp, a, b)
    out = os.path.join(tmp, "dev.csv")
    r = run_json(["--distances", out, pa, pb])
    assert r["distances_file"] == {"a": out, "b": os.path.join(tmp, "dev_b.csv")}
    with open(out) as f:
        assert f.readline() == "x,y,z,distance,nearest\n"
    check_rows(np.loadtxt(out, delimiter=",", skiprows=1), a, *nearest(a, b), "A")
    check_rows(np.loadtxt(r["distances_file"]["b"], delimiter=",", skiprows=1), b, *nearest(b, a), "B")
    back = run_json([out, pa])  # the library's reader sees A's points again
    assert back["n_a"] == len(a) and back["hausdorff"] == 0


def read_ply(path):
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    assert header[1] == "format binary_little_endian 1.0", header
    types = {"double": "<f8", "int": "<i4", "uchar": "u1"}
    fields = [(ln.split()[2], types[ln.split()[1]]) for ln in header if ln.startswith("property")]
    n = int([ln for ln in header if ln.startswith("element vertex")][0].split()[2])
    return np.frombuffer(data[end:], dtype=np.dtype(fields), count=n)


@test
def distances_ply_carries_distance_nearest_and_viridis_colour(tmp):
    a, b = lattice_clouds(8, 400, 300)
    b[0] = a[5]  # one distance 0
    pa, pb = write_pair(tmp, a, b)
    out = os.path.join(tmp, "dev.ply")
    run(["--distances", out, pa, pb])
    v = read_ply(out)
    d, j = nearest(a, b)
    rows = np.column_stack([v["x"], v["y"], v["z"], v["distance"], v["nearest"]])
    check_rows(rows, a, d, j, "PLY A")
    rgb = np.column_stack([v["red"], v["green"], v["blue"]])
    top = max(d.max(), nearest(b, a)[0].max())  # the colour scale is H
    assert tuple(rgb[np.argmin(d)]) == (68, 1, 84), "viridis at 0"
    if d.max() == top:
        assert tuple(rgb[np.argmax(d)]) == (253, 231, 37), "viridis at 1"
    back = run_json([out, pa])
    assert back["n_a"] == len(a) and back["hausdorff"] == 0
    check_rows(np.column_stack([read_ply(os.path.join(tmp, "dev_b.ply"))[k] for k in
                                ("x", "y", "z", "distance", "nearest")]), b, *nearest(b, a), "PLY B")


@test
def distances_npy_is_an_n_by_5_float64_array(tmp):
    a, b = gauss_clouds(9, 300, 350)
    pa, pb = write_pair(tmp, a, b)
    out = os.path.join(tmp, "dev.npy")
    run(["--distances", out, pa, pb])
    m = np.load(out)
    assert m.dtype == np.float64 and m.shape == (300, 5)
    check_rows(m, a, *nearest(a, b), "NPY A")
    check_rows(np.load(os.path.join(tmp, "dev_b.npy")), b, *nearest(b, a), "NPY B")


@test
def render_is_a_picture_with_the_witness_pair_marked(tmp):
    a, b = gauss_clouds(10, 3000, 2500)
    b[7] = [6.0, 5.0, -4.0]  # a far point of B: h(B,A) wins, witness B[7]
    pa, pb = write_pair(tmp, a, b)
    png = os.path.join(tmp, "r.png")
    if not pictures_built():
        return refuses_pictures(["--render", png, pa, pb])
    r = run_json(["--render", png, pa, pb])
    img = read_png(png)
    rd = r["render"]
    assert img.shape == (rd["height"], rd["width"], 3)
    colours = np.unique(img.reshape(-1, 3), axis=0)
    assert len(colours) > 100, "a picture, not a blank page"
    assert r["witness_ba"][0] == 7
    marks = rd["witness_markers"]
    assert len(marks) == 6 and {m["view"] for m in marks} == {"front", "side", "top"}
    for m in marks:
        want = (255, 0, 0) if (m["set"], m["index"]) == ("B", 7) else (255, 140, 0)
        if m["set"] == "A":
            assert m["index"] == r["witness_ba"][1]
        assert tuple(img[m["y"], m["x"]]) == want, (m, img[m["y"], m["x"]])
    # the points of A carry viridis colours: its darkest end is present
    assert ((img[..., 0] < 90) & (img[..., 2] > 60) & (img[..., 1] < 60)).any()


def histogram_picture(tmp):
    """The JSON and the pixels of --histogram-png with --percentile 95 on two
    Gaussian clouds; None (after checking the refusal) without libpng."""
    a, b = gauss_clouds(11, 800, 700)
    pa, pb = write_pair(tmp, a, b)
    png = os.path.join(tmp, "h.png")
    if not pictures_built():
        refuses_pictures(["--histogram-png", png, pa, pb])
        return None
    r = run_json(["--histogram-png", png, "--percentile", "95", pa, pb])
    assert r["histogram_png"] == png
    return r, read_png(png).astype(int)


@test
def histogram_png_is_a_picture(tmp):
    got = histogram_picture(tmp)
    if got is None:
        return
    img = got[1]
    assert img.shape[0] > 300 and img.shape[1] > 600
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 3


@test
def histogram_png_marks_means_and_percentiles_visibly_over_the_bars(tmp):
    got = histogram_picture(tmp)
    if got is None:
        return
    r, img = got
    marks = r["histogram_markers"]
    assert sorted((m["line"], m["direction"]) for m in marks) == [
        ("mean", "ab"), ("mean", "ba"), ("percentile", "ab"), ("percentile", "ba")], marks
    for m in marks:
        x, rgb = m["x"], np.array(m["rgb"])
        # solid for the mean; dashes of 6 rows every 12 for the percentile
        rows = range(m["y0"], m["y1"]) if m["line"] == "mean" else range(m["y0"] + 3, m["y1"], 12)
        for y in rows:
            others = [o for o in marks if o is not m and abs(o["x"] - x) <= 3]
            if others:
                continue  # lines drawn within a few pixels of each other overlap
            assert (img[y, x] == rgb).all(), (m, y, img[y, x])
            # a dark edge on both sides, also where the line crosses a bar of its colour
            assert img[y, x - 2].sum() < 200 and img[y, x + 1].sum() < 200, (m, y, img[y, x - 2])


@test
def render_marks_the_percentile_on_the_colour_bar_and_says_the_unit(tmp):
    """Issue 18: the picture showed neither HD95 when it was asked for nor a
    unit.  With --percentile 95 the A->B figure (A's distances are the
    colours) is a white line with red edges across the colour bar, labelled
    P95, and the caption gives all three figures; --units names the unit of
    the bar and the caption; without either, neither appears."""
    a, b = gauss_clouds(15, 1500, 1400)
    pa, pb = write_pair(tmp, a, b)
    png = os.path.join(tmp, "p.png")
    if not pictures_built():
        return refuses_pictures(["--render", png, "--percentile", "95", pa, pb])
    r = run_json(["--render", png, "--percentile", "95", "--units", "mm", pa, pb])
    rd, p = r["render"], r["percentile"]
    assert r["units"] == "mm" and rd["bar_title"] == "distance (mm)", rd["bar_title"]
    assert rd["caption"][2].startswith("P95: A->B %.4g " % p["ab"]), rd["caption"]
    assert ("symmetric (MONAI) %.4g" % p["symmetric"]) in rd["caption"][2] and rd["caption"][2].endswith(" mm")
    assert " mm between " in rd["caption"][1], rd["caption"]
    mark = rd["percentile_mark"]
    img = read_png(png)
    # the bar runs from the top (the scale's top, H here) down to 0 over 460 rows
    top = mark["y"] - round(459 * (1 - p["ab"] / r["hausdorff"]))
    assert abs(top - 92) <= 1, (mark, top)
    assert tuple(img[mark["y"], (mark["x0"] + mark["x1"]) // 2]) == (255, 255, 255)
    assert tuple(img[mark["y"] - 2, mark["x0"] + 3]) == (255, 0, 0)
    assert tuple(img[mark["y"], mark["x0"] - 5]) == (255, 0, 0)
    plain = run_json(["--render", png, pa, pb])
    assert plain["render"]["percentile_mark"] is None and len(plain["render"]["caption"]) == 2
    assert plain["render"]["bar_title"] == "distance" and "units" not in plain
    img2 = read_png(png)
    assert tuple(img2[mark["y"], (mark["x0"] + mark["x1"]) // 2]) != (255, 255, 255)


@test
def pictures_refuse_a_name_that_is_not_png(tmp):
    """Issue 18: --render x.jpg wrote a PNG under a .jpg name.  Another
    extension is a usage error (nothing written); .png in any case and a
    name without an extension (/dev/stdout) are fine."""
    a, b = gauss_clouds(16, 50, 40)
    pa, pb = write_pair(tmp, a, b)
    for opt in ("--render", "--histogram-png"):
        for name in ("x.jpg", "x.jpeg", "x.png.gif", "x.tif"):
            _, err = run([opt, os.path.join(tmp, name), pa, pb], expect=1)
            if pictures_built():
                assert "PNG only" in err and name in err, err
            assert not os.path.exists(os.path.join(tmp, name))
    if pictures_built():
        run(["--render", os.path.join(tmp, "x.PNG"), "--histogram-png", os.path.join(tmp, "noext"), pa, pb])
        assert read_png(os.path.join(tmp, "x.PNG")).shape[2] == 3 and read_png(os.path.join(tmp, "noext")).size


@test
def answers_do_not_depend_on_the_thread_count(tmp):
    a, b = lattice_clouds(12, 2000, 1800, side=9)
    pa, pb = write_pair(tmp, a, b)
    keys = ("percentile", "mean", "chamfer", "histogram", "hausdorff", "witness_ab", "witness_ba")
    args = ["--percentile", "90", "--mean", "--chamfer", "--histogram", pa, pb]
    one = run_json(["--threads", "1"] + args)
    two = run_json(["--threads", "2"] + args)
    three = run_json(["--threads", "3"] + args)
    for k in keys:
        assert one[k] == two[k] == three[k], k


@test
def an_empty_file_is_an_error_unless_empty_chooses_a_value(tmp):
    a, _ = gauss_clouds(13, 50, 1)
    pa, pe = os.path.join(tmp, "a.xyz"), os.path.join(tmp, "e.xyz")
    write_xyz(pa, a)
    open(pe, "w").close()
    _, err = run([pa, pe], expect=2)
    assert "e.xyz" in err and "--empty" in err, err
    out = os.path.join(tmp, "d.csv")
    r = run_json(["--empty", "zero", "--mean", "--distances", out, pa, pe])
    assert r["hausdorff"] == 0 and r["mean"]["pooled"] == 0 and r["empty"]["policy"] == "zero"
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    assert rows.shape == (50, 5) and (rows[:, 3] == 0).all() and (rows[:, 4] == -1).all()
    with open(os.path.join(tmp, "d_b.csv")) as f:
        assert f.read() == "x,y,z,distance,nearest\n"
    r = run_json(["--empty", "nan", pe, pa])
    assert r["hausdorff"] is None and r["empty"] == {"a": True, "b": False, "policy": "nan"}


@test
def an_empty_set_fills_the_report_every_run_prints(tmp):
    a, b = gauss_clouds(17, 30, 20)
    pa, pb, pe = os.path.join(tmp, "a.xyz"), os.path.join(tmp, "b.xyz"), os.path.join(tmp, "e.xyz")
    write_xyz(pa, a)
    write_xyz(pb, b)
    open(pe, "w").close()
    tiles = os.path.join(tmp, "tiles")
    os.mkdir(tiles)
    write_xyz(os.path.join(tiles, "t.xyz"), a)
    full = run_json(["--directed", tiles, pb])
    empty = run_json(["--directed", "--empty", "zero", tiles, pe])
    # the members of the report, in its order: those of nothing computed left out
    computed = {"algorithm", "requested_algorithm", "alpha", "disjoint", "seconds", "read_seconds", "stats_ab",
                "stats_ba"}
    assert [k for k in full if k not in computed] == [k for k in empty if k != "empty"], (list(full), list(empty))
    # --directed: H is not computed, in either case; the witnesses are null
    assert full["hausdorff"] is None and empty["hausdorff"] is None and empty["directed_ab"] == 0, empty
    assert empty["witness_ab"] is None and empty["tiles_a"] == [{"file": os.path.join(tiles, "t.xyz"), "first": 0,
                                                                  "count": 30}], empty
    out, _ = run(["--empty", "inf", pe, pb])
    assert out.startswith("A: %s (0 points)\nB: %s (20 points, xyz)\n" % (pe, pb)), out


@test
def every_option_the_help_lists_is_one_the_parser_knows(tmp):
    out, _ = run(["--help"])
    names = sorted({w.rstrip(",") for line in out.splitlines() for w in line.split()[:2]
                    if re.fullmatch(r"--[a-z0-9-]+,?", w)})
    assert len(names) > 35 and "--bins" in names, names
    for name in names:
        p = subprocess.run([tool(), name], capture_output=True, text=True)
        assert "unknown option" not in p.stderr, (name, p.stderr)


@test
def bad_analysis_options_are_usage_errors(tmp):
    a, b = gauss_clouds(14, 5, 5)
    pa, pb = write_pair(tmp, a, b)
    for args, words in ((["--percentile", "101"], "[0, 100]"), (["--percentile", "x"], "percentile"),
                        (["--distances", "out.dat"], ".csv, .ply or .npy"),
                        (["--bins", "0"], "--bins"), (["--max-distance", "-1"], "positive"),
                        (["--mask-points", "edges"], "surface or all"), (["--units", ""], "--units"), (["--empty", "none"], "inf, nan, zero or monai"),
                        (["--percentile"], "needs a value")):
        _, err = run([pa, pb] + args, expect=1)
        assert words in err, (args, err)
    out, _ = run(["--help"])
    for words in ("--percentile P", "--mask-points surface|all", "--empty inf|nan|zero|monai", "6-neighbour"):
        assert words in out, words
    long = [line for line in out.splitlines() if len(line) > 79]
    assert not long, long  # fits an 80-column terminal


if __name__ == "__main__":
    main()
