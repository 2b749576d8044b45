"""Command-line tests of tiles: a side given as a directory or as @LIST is
its files' points concatenated in order (a directory by name in byte order,
not recursed; a list in its order, paths relative to the list's folder), the
witness is named by file and index, and every bad tile or list line is an
error that names it.  Standard library only (unittest); run as:
    cli_tiles.py PATH/TO/hausdorff [TilesCli.test_NAME ...]
Random points come from random.Random(SEED); a failure prints the seed.
"""
import json
import os
import random
import struct
import subprocess
import sys
import tempfile
import unittest

TESTS = []
TOOL = None  # the hausdorff executable, from the command line
HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(os.path.dirname(HERE), "data")
SEED = 20261123


def test(fn):
    TESTS.append(fn)
    return fn


def run(*args, cwd=None, env=None):
    p = subprocess.run([os.path.abspath(TOOL)] + list(args), capture_output=True, timeout=120, cwd=cwd, env=env)
    return p.returncode, p.stdout.decode(), p.stderr.decode()


def run_json(*args, cwd=None, env=None):
    rc, out, err = run("--json", *args, cwd=cwd, env=env)
    assert rc == 0, (args, rc, err)
    return json.loads(out)


def write(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)
    return path


def read(path):
    with open(path) as f:
        return f.read()


def xyz(points):
    return "".join("%r %r %r\n" % p for p in points)


def cloud(rng, n, scale=1.0, shift=0.0):
    return [tuple(rng.uniform(-scale, scale) + shift for _ in range(3)) for _ in range(n)]


def expect_error(args, needles, code=2, cwd=None):
    rc, out, err = run(*args, cwd=cwd)
    assert rc == code, "%s: exit %d, expected %d (stderr %r)" % (args, rc, code, err)
    assert err.startswith("hausdorff: ") and out == "", (out, err)
    for n in needles:
        assert n in err, "%r lacks %r" % (err, n)
    return err


def reference(d, rng):
    b = os.path.join(d, "b.xyz")
    write(b, xyz(cloud(rng, 300)))
    return b


@test
def a_directory_gives_the_distances_and_witness_of_its_files_concatenated(d):
    rng = random.Random(SEED)
    tiles = [cloud(rng, n) for n in (120, 1, 257)]
    tiles[2][17] = (9.0, 9.0, 9.0)  # the witness of h(A,B): tile 3, index 17
    for k, t in enumerate(tiles):
        write(os.path.join(d, "t", "t%d.xyz" % k), xyz(t))
    whole = write(os.path.join(d, "whole.xyz"), xyz([p for t in tiles for p in t]))
    b = reference(d, rng)
    r_dir, r_one = run_json(os.path.join(d, "t"), b), run_json(whole, b)
    for key in ("hausdorff", "directed_ab", "directed_ba", "witness_ab", "witness_ba", "n_a", "n_b"):
        assert r_dir[key] == r_one[key], (SEED, key, r_dir[key], r_one[key])
    assert r_dir["witness_ab"][0] == 121 + 17, (SEED, r_dir["witness_ab"])
    where = r_dir["witness_ab_files"][0]
    assert where == {"file": os.path.join(d, "t", "t2.xyz"), "index": 17, "global": 138}, (SEED, where)
    assert r_one["witness_ab_files"][0] == {"file": whole, "index": 138, "global": 138}, r_one
    rc, out, err = run(os.path.join(d, "t"), b)
    assert rc == 0 and "A[138] (9, 9, 9) = %s[17]" % os.path.join(d, "t", "t2.xyz") in out, (out, err)
    assert "3 files" in out, out


@test
def per_point_distances_of_a_directory_equal_those_of_the_concatenated_file(d):
    rng = random.Random(SEED + 1)
    tiles = [cloud(rng, n) for n in (50, 70)]
    for k, t in enumerate(tiles):
        write(os.path.join(d, "t", "t%d.xyz" % k), xyz(t))
    whole = write(os.path.join(d, "whole.xyz"), xyz([p for t in tiles for p in t]))
    b = reference(d, rng)
    outs = []
    for name, a in (("dir", os.path.join(d, "t")), ("one", whole)):
        out = os.path.join(d, name + ".csv")
        r = run_json("--percentile", "95", "--distances", out, a, b)
        outs.append((read(out), read(os.path.join(d, name + "_b.csv")), r["percentile"]))
    assert outs[0] == outs[1], SEED + 1


@test
def a_directory_is_read_in_byte_order_of_names_whatever_the_locale(d):
    names = ["a.xyz", "B.xyz", "_x.xyz", "10.xyz", "9.xyz"]
    for k, n in enumerate(names):
        write(os.path.join(d, "t", n), "%d 0 0\n" % k)
    env = dict(os.environ, LC_ALL="en_US.UTF-8", LC_COLLATE="en_US.UTF-8")
    r = run_json(os.path.join(d, "t"), os.path.join(d, "t", "a.xyz"), env=env)
    got = [os.path.basename(t["file"]) for t in r["tiles_a"]]
    assert got == sorted(names) == ["10.xyz", "9.xyz", "B.xyz", "_x.xyz", "a.xyz"], got
    assert [t["first"] for t in r["tiles_a"]] == [0, 1, 2, 3, 4], r["tiles_a"]


@test
def a_list_is_read_in_its_own_order(d):
    for n in ("a", "b", "c"):
        write(os.path.join(d, n + ".xyz"), "%d 0 0\n%d 1 0\n" % (ord(n), ord(n)))
    lst = write(os.path.join(d, "l.txt"), "c.xyz\na.xyz\nb.xyz\n")
    r = run_json("--directed", "@" + lst, os.path.join(d, "a.xyz"))
    assert [os.path.basename(t["file"]) for t in r["tiles_a"]] == ["c.xyz", "a.xyz", "b.xyz"], r["tiles_a"]
    # c (x = 99) is farthest from a (x = 97): its first point, global index 0
    assert r["witness_ab"][0] == 0 and r["witness_ab_files"][0]["file"].endswith("c.xyz"), r


@test
def list_paths_are_relative_to_the_list_folder(d):
    write(os.path.join(d, "tiles", "a.xyz"), "0 0 0\n")
    absolute = write(os.path.join(d, "elsewhere", "b.xyz"), "1 0 0\n")
    write(os.path.join(d, "lists", "l.txt"), "../tiles/a.xyz\n%s\n" % absolute)
    other = os.path.join(d, "cwd")
    os.makedirs(other)
    r = run_json("@../lists/l.txt", absolute, cwd=other)
    assert r["n_a"] == 2 and [t["count"] for t in r["tiles_a"]] == [1, 1], r
    assert r["tiles_a"][0]["file"] == "../lists/../tiles/a.xyz", r["tiles_a"]


@test
def list_comments_blank_lines_and_surrounding_blanks_are_ignored(d):
    write(os.path.join(d, "a.xyz"), "0 0 0\n")
    write(os.path.join(d, "b.xyz"), "1 0 0\n")
    lst = write(os.path.join(d, "l.txt"), "# tiles of epoch 1\r\n\r\n   # indented comment\n  a.xyz  \r\n\tb.xyz\n\n")
    r = run_json("@" + lst, os.path.join(d, "a.xyz"))
    assert r["n_a"] == 2 and len(r["tiles_a"]) == 2, r


@test
def a_missing_file_in_a_list_is_a_read_error_naming_list_and_line(d):
    write(os.path.join(d, "a.xyz"), "0 0 0\n")
    lst = write(os.path.join(d, "l.txt"), "# one\na.xyz\n\nmissing.xyz\n")
    expect_error(["@" + lst, os.path.join(d, "a.xyz")], ["%s:4: %s: cannot open" % (lst, os.path.join(d, "missing.xyz"))])
    expect_error(["@" + os.path.join(d, "nolist.txt"), lst], ["nolist.txt: cannot open the list"])


@test
def a_list_with_a_utf8_byte_order_mark_reads_its_first_file_and_utf16_is_refused(d):
    write(os.path.join(d, "a.xyz"), "0 0 0\n")
    write(os.path.join(d, "b.xyz"), "1 0 0\n")
    lst = write(os.path.join(d, "l.txt"), b"\xef\xbb\xbfa.xyz\nb.xyz\n")
    r = run_json("@" + lst, os.path.join(d, "a.xyz"))
    assert r["n_a"] == 2 and len(r["tiles_a"]) == 2, r
    for enc in ("utf-16", "utf-16-be", "utf-32-le"):
        lst = write(os.path.join(d, "w.txt"), "a.xyz\nb.xyz\n".encode(enc))
        expect_error(["@" + lst, os.path.join(d, "a.xyz")], ["w.txt:1: UTF-%s text; convert to UTF-8" % enc[4:6]])


@test
def a_list_names_files_not_standard_input_or_directories(d):
    write(os.path.join(d, "a.xyz"), "0 0 0\n")
    os.makedirs(os.path.join(d, "sub"))
    lst = write(os.path.join(d, "l.txt"), "a.xyz\n-\n")
    expect_error(["@" + lst, os.path.join(d, "a.xyz")], ["l.txt:2: standard input ('-') cannot be a tile"])
    lst = write(os.path.join(d, "m.txt"), "sub\n")
    expect_error(["@" + lst, os.path.join(d, "a.xyz")], ["m.txt:1: ", "sub is a directory"])


@test
def a_list_that_is_not_text_is_refused_at_its_first_bad_line(d):
    write(os.path.join(d, "a.xyz"), "0 0 0\n")
    lst = write(os.path.join(d, "bin.txt"), b"a.xyz\n\x93NUMPY\x00\x01\n")
    expect_error(["@" + lst, os.path.join(d, "a.xyz")], ["bin.txt:2: a NUL byte"])
    lst = write(os.path.join(d, "long.txt"), "a.xyz\n" + "x" * 5000 + "\n")
    expect_error(["@" + lst, os.path.join(d, "a.xyz")], ["long.txt:2: a line longer than 4096 bytes"])
    expect_error(["@", os.path.join(d, "a.xyz")], ["'@' names no list"])


@test
def a_directory_skips_and_reports_other_entries_and_does_not_recurse(d):
    t = os.path.join(d, "t")
    write(os.path.join(t, "a.xyz"), "0 0 0\n")
    write(os.path.join(t, "notes.md"), "not points\n")
    write(os.path.join(t, "a.lax"), b"\x00\x01")
    write(os.path.join(t, ".hidden.xyz"), "5 5 5\n")
    write(os.path.join(t, "sub", "deep.xyz"), "7 7 7\n")  # nested: not read
    r = run_json(t, os.path.join(t, "a.xyz"))
    assert r["n_a"] == 1 and r["hausdorff"] == 0, r
    skipped = {s["name"]: s["reason"] for s in r["skipped_a"]}
    assert skipped == {".hidden.xyz": "hidden", "a.lax": "no point format has this extension",
                       "notes.md": "no point format has this extension", "sub": "a directory, not recursed"}, skipped
    rc, out, err = run(t, os.path.join(t, "a.xyz"))
    assert rc == 0 and "1 file; skipped 4: .hidden.xyz (hidden), a.lax (" in out and "and 1 more)" in out, out


@test
def a_directory_skips_text_in_which_no_line_starts_with_a_number_and_reads_numeric_text(d):
    t = os.path.join(d, "t")
    write(os.path.join(t, "a.xyz"), "0 0 0\n")
    write(os.path.join(t, "README.txt"), "Tiles of the 2019 survey, EPSG:2056.\nOne file a square kilometre.\n")
    write(os.path.join(t, "index.csv"), "tile,date\nA1,2019-05-01\n")
    write(os.path.join(t, "p.txt"), "x y z\n5 0 0\n")
    r = run_json(t, os.path.join(t, "a.xyz"))
    assert r["n_a"] == 2 and r["hausdorff"] == 5, r
    why = "text without a line that starts with a number"
    assert r["skipped_a"] == [{"name": "README.txt", "reason": why}, {"name": "index.csv", "reason": why}], r
    rc, out, err = run(t, os.path.join(t, "a.xyz"))
    assert rc == 0 and "2 files; skipped 2: README.txt (%s), index.csv" % why in out, (out, err)
    # a text tile that starts with a number and breaks later is an error, never a skip
    bad = write(os.path.join(t, "q.txt"), "1 2 3\n4 five 6\n")
    expect_error([t, os.path.join(t, "a.xyz")], [bad + ":2: 'five' is not a number"])


@test
def a_stream_cannot_be_a_tile_of_a_list(d):
    fifo = os.path.join(d, "f.xyz")
    os.mkfifo(fifo)
    a = write(os.path.join(d, "a.xyz"), "0 0 0\n")
    lst = write(os.path.join(d, "l.txt"), "a.xyz\nf.xyz\n")
    expect_error(["--empty", "zero", "@" + lst, a], ["l.txt:2: %s is a FIFO or pipe, not a regular file" % fifo,
                                                     "save it to a file"])
    lst = write(os.path.join(d, "m.txt"), "/dev/stdin\n")
    p = subprocess.run([os.path.abspath(TOOL), "@" + lst, a], input=b"1 2 3\n", capture_output=True, timeout=120)
    assert p.returncode == 2 and b"m.txt:1: /dev/stdin is a FIFO or pipe, not a regular file" in p.stderr, p


@test
def a_directory_of_mixed_formats_reads_each_file_by_its_own_format(d):
    rng = random.Random(SEED + 2)
    pts = [cloud(rng, 40) for _ in range(4)]
    t = os.path.join(d, "t")
    write(os.path.join(t, "1.ply"), "ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
          "property double z\nend_header\n%s" % (len(pts[0]), xyz(pts[0])))
    head = "{'descr': '<f8', 'fortran_order': False, 'shape': (%d, 3), }" % len(pts[1])
    head = head.ljust(117) + "\n"
    write(os.path.join(t, "2.npy"), b"\x93NUMPY\x01\x00" + struct.pack("<H", len(head)) + head.encode() +
          b"".join(struct.pack("<3d", *p) for p in pts[1]))
    write(os.path.join(t, "3.pcd"), "VERSION .7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH %d\n"
          "HEIGHT 1\nPOINTS %d\nDATA ascii\n%s" % (len(pts[2]), len(pts[2]), xyz(pts[2])))
    write(os.path.join(t, "4.csv"), "x,y,z\n" + "".join("%r,%r,%r\n" % p for p in pts[3]))
    whole = write(os.path.join(d, "whole.xyz"), xyz([p for q in pts for p in q]))
    b = reference(d, rng)
    r_dir, r_one = run_json(t, b), run_json(whole, b)
    for key in ("hausdorff", "directed_ab", "directed_ba", "witness_ab", "witness_ba", "n_a"):
        assert r_dir[key] == r_one[key], (SEED + 2, key)
    rc, out, err = run(t, b)
    assert rc == 0 and "(160 points, mixed, 4 files)" in out, out


@test
def a_bad_tile_is_an_error_that_names_the_file_and_its_list_line(d):
    t = os.path.join(d, "t")
    write(os.path.join(t, "good.xyz"), "0 0 0\n")
    bad = write(os.path.join(t, "bad.xyz"), "1 two 3\n")
    expect_error([t, os.path.join(t, "good.xyz")], ["%s:1: 'two' is not a number" % bad])
    lst = write(os.path.join(d, "l.txt"), "t/good.xyz\nt/bad.xyz\n")
    expect_error(["@" + lst, os.path.join(t, "good.xyz")], ["bad.xyz:1: 'two' is not a number",
                                                              "(listed at %s:2)" % lst])


@test
def a_tile_that_cannot_be_opened_is_an_error_not_skipped(d):
    t = os.path.join(d, "t")
    write(os.path.join(t, "a.xyz"), "0 0 0\n")
    os.symlink(os.path.join(d, "gone.xyz"), os.path.join(t, "b.xyz"))  # dangling: root cannot read it either
    expect_error([t, os.path.join(t, "a.xyz")], [os.path.join(t, "b.xyz") + ": cannot open"])


@test
def an_empty_directory_or_list_is_an_error_or_follows_the_empty_policy(d):
    os.makedirs(os.path.join(d, "e"))
    write(os.path.join(d, "e", "readme.md"), "nothing\n")
    full = write(os.path.join(d, "full.xyz"), "0 0 0\n")
    expect_error([os.path.join(d, "e"), full], ["e: no point files in the directory; skipped 1: readme.md", "--empty"])
    lst = write(os.path.join(d, "l.txt"), "# nothing yet\n")
    expect_error(["@" + lst, full], ["l.txt: the list names no files", "--empty"])
    r = run_json("--empty", "inf", os.path.join(d, "e"), full)
    assert r["hausdorff"] is None and r["empty"]["a"] is True and r["n_a"] == 0, r
    assert r["witness_ab_files"] is None, r


@test
def an_empty_tile_is_an_error_unless_the_empty_policy_allows_it(d):
    t = os.path.join(d, "t")
    write(os.path.join(t, "a.xyz"), "0 0 0\n")
    empty = write(os.path.join(t, "b.xyz"), "")
    write(os.path.join(t, "c.xyz"), "3 0 0\n")
    expect_error([t, os.path.join(t, "a.xyz")], [empty + ": ", "--empty"])
    r = run_json("--empty", "nan", t, os.path.join(t, "a.xyz"))
    assert r["hausdorff"] == 3 and r["n_a"] == 2, r
    assert [(x["first"], x["count"]) for x in r["tiles_a"]] == [(0, 1), (1, 0), (1, 1)], r["tiles_a"]
    assert r["witness_ab_files"][0] == {"file": os.path.join(t, "c.xyz"), "index": 0, "global": 1}, r


@test
def a_format_prefix_applies_to_a_list_line_or_to_a_whole_side(d):
    write(os.path.join(d, "p.dat"), "0 0 0\n")
    write(os.path.join(d, "q.dat"), "1 0 0\n")
    write(os.path.join(d, "r.xyz"), "2 0 0\n")
    lst = write(os.path.join(d, "l.txt"), "xyz:p.dat\nr.xyz\n")
    r = run_json("@" + lst, os.path.join(d, "r.xyz"))
    assert r["n_a"] == 2, r
    # the side's prefix reads q.dat as PLY; p.dat's own prefix wins
    lst = write(os.path.join(d, "m.txt"), "xyz:p.dat\nq.dat\n")
    expect_error(["ply:@" + lst, os.path.join(d, "r.xyz")], [os.path.join(d, "q.dat") + ":", "(listed at %s:2)" % lst])
    r = run_json("xyz:@" + lst, os.path.join(d, "r.xyz"))
    assert r["n_a"] == 2 and r["hausdorff"] == 2, r


@test
def sampling_draws_each_mesh_tile_with_the_seed_plus_its_place(d):
    t = os.path.join(d, "t")
    meshes = [os.path.join(DATA, "orig", "pinion.off"), os.path.join(DATA, "orig", "Wuson.stl")]
    os.makedirs(t)
    os.symlink(meshes[0], os.path.join(t, "1.off"))
    os.symlink(meshes[1], os.path.join(t, "2.stl"))
    b = os.path.join(DATA, "orig", "cow.off")

    def sampled(seed, a):
        out = os.path.join(d, "s.csv")
        run_json("--directed", "--sample", "100", "--seed", str(seed), "--distances", out, a, b)
        return [row.split(",")[:3] for row in read(out).splitlines()[1:]]
    both = sampled(5, t)
    assert len(both) == 200 and both == sampled(5, meshes[0]) + sampled(6, meshes[1]), "seed 5"


@test
def an_output_may_not_overwrite_a_tile(d):
    t = os.path.join(d, "t")
    write(os.path.join(t, "a.csv"), "0,0,0\n")
    write(os.path.join(t, "b.xyz"), "1 0 0\n")
    expect_error(["--distances", os.path.join(t, "a.csv"), t, os.path.join(t, "b.xyz")],
                 ["would overwrite input A (%s)" % os.path.join(t, "a.csv")], code=1)
    lst = write(os.path.join(d, "l.csv"), "t/b.xyz\n")
    expect_error(["--distances", lst, os.path.join(t, "a.csv"), "@" + lst],
                 ["would overwrite input B (%s)" % lst], code=1)


class TilesCli(unittest.TestCase):
    """Each function above becomes one test, run in a fresh temporary directory."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="hd-cli-tiles-")

    def tearDown(self):
        self.tmp.cleanup()


for _fn in TESTS:
    setattr(TilesCli, "test_" + _fn.__name__, lambda self, fn=_fn: fn(self.tmp.name))

if __name__ == "__main__":
    TOOL = sys.argv.pop(1)
    unittest.main(verbosity=2)
