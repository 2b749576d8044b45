"""Command-line tests of reading: exit codes and messages for bad input in
every format, standard input, --format, --formats, --sample, --version,
--help, and the progress bar (only on a terminal, never with --quiet or
--json).  Standard library only (unittest); run as:
    cli_io.py PATH/TO/hausdorff [ReadingCli.test_NAME ...]
"""
import json
import os
import re
import pty
import select
import struct
import subprocess
import time
import unittest

from cli_checks import collector, temp_dir_cases, tool_from_argv

TESTS = []
TOOL = None  # the hausdorff executable, from the command line
HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(os.path.dirname(HERE), "data")


test = collector(TESTS)


def run(*args, stdin=None):
    p = subprocess.run([TOOL] + list(args), input=stdin, capture_output=True, timeout=120)
    return p.returncode, p.stdout.decode(), p.stderr.decode()


def write(d, name, data):
    path = os.path.join(d, name)
    with open(path, "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)
    return path


def expect_bad(path, needle, code=2, args=()):
    rc, out, err = run(*args, path, os.path.join(DATA, "pinion_gear.ply"))
    assert rc == code, "%s: exit %d, expected %d (stderr %r)" % (path, rc, code, err)
    assert err.startswith("hausdorff: "), err
    assert needle in err, "%r lacks %r" % (err, needle)
    assert out == "", out


PLY_HEAD = "ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nend_header\n"


@test
def bad_text_input_exits_2_naming_the_file_and_line(d):
    expect_bad(write(d, "a.xyz", "1 2 3\n4 five 6\n"), "a.xyz:2: 'five' is not a number")
    expect_bad(write(d, "b.ply", PLY_HEAD.format(n=2) + "1 2 3\n1 nan 3\n"), "b.ply:9: coordinate is NaN or infinite")
    expect_bad(write(d, "c.ply", PLY_HEAD.format(n=4611686018427387904) + "1 2 3\n"), "c.ply:3: element vertex")
    expect_bad(write(d, "d.obj", "v 1 2\n"), "d.obj:1: vertex: expected x y z")
    expect_bad(write(d, "e.off", "OFF\n3 0 0\n1.000 2.000 3.000\n4.000 5.000 6.000\n"), "e.off:5: file ends after 2 of 3 vertices")
    expect_bad(write(d, "f.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 1 2 x\n"), "f.stl:4:")
    expect_bad(write(d, "g.pcd", "VERSION .7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\nDATA ascii\n1 2\n"),
               "g.pcd: FIELDS has no 'z'")
    expect_bad(write(d, "h.csv", "x,y,z\n1,2,1e999\n"), "h.csv:2: coordinate is NaN or infinite")


@test
def obj_vertex_line_with_a_second_statement_is_refused(d):
    expect_bad(write(d, "two.obj", "v 0 0 0\nv 1 2 3 v 4 5 6\n"),
               "two.obj:2: vertex: 'v' after x y z is not a number")


@test
def obj_vertex_line_keeps_w_colour_and_comment(d):
    path = write(d, "tail.obj", "v 0 0 0 1 # w\nv 3 4 0 0.5 0.25 1.0\n")
    o = write(d, "o.xyz", "0 0 0\n")
    rc, out, err = run(path, o)
    assert rc == 0, err
    assert "H(A,B) = 5\n" in out, out


@test
def decimal_comma_csv_is_refused_unless_decimal_comma_is_given(d):
    eu = write(d, "german.csv", "1,5;2,5;3,5\n4,25;5,5;6,75\n")
    o = write(d, "o.xyz", "0 0 0\n")
    expect_bad(eu, "german.csv:1: '1,5' has a decimal comma (column 1)")
    rc, out, err = run("--decimal-comma", "--json", eu, o)
    assert rc == 0, (rc, out, err)
    r = json.loads(out)
    # the farthest point of A from the origin is (4.25, 5.5, 6.75)
    assert r["directed_ab"] == (4.25 ** 2 + 5.5 ** 2 + 6.75 ** 2) ** 0.5, r


@test
def decimal_commas_and_thousands_between_blank_separated_fields_are_refused_unless_decimal_comma(d):
    tab = write(d, "tab.txt", "4,25\t5,5\t6,75\n1,5\t2,5\t3,5\n")
    o = write(d, "o.xyz", "0 0 0\n")
    expect_bad(tab, "tab.txt:1: '4,25' has a comma between digits where blanks separate fields")
    expect_bad(write(d, "th.xyz", "0 0 0\n1,234.5 2,345.6 3,456.7\n"), "th.xyz:2: '1,234.5'")
    rc, out, err = run("--decimal-comma", "--json", tab, o)
    assert rc == 0, (rc, out, err)
    r = json.loads(out)
    assert r["n_a"] == 2 and r["directed_ab"] == (4.25 ** 2 + 5.5 ** 2 + 6.75 ** 2) ** 0.5, r


@test
def a_byte_order_mark_is_skipped_and_utf16_is_refused(d):
    o = write(d, "o.xyz", "0 0 0\n")
    for name, text in (("bom.xyz", "9 9 9\n1 1 1\n"), ("bom.obj", "v 9 9 9\nv 1 1 1\n")):
        path = write(d, name, b"\xef\xbb\xbf" + text.encode())
        for args in ((path, o), ("-", o)):
            rc, out, err = run("--json", *args, stdin=open(path, "rb").read())
            assert rc == 0 and json.loads(out)["n_a"] == 2, (name, args, rc, out, err)
    for enc in ("utf-16", "utf-16-le", "utf-32"):
        bits = enc[4:6]
        expect_bad(write(d, "w.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                      "vertex 0 1 0\nendloop\nendfacet\nendsolid s\n".encode(enc)),
                   "w.stl:1: UTF-%s text; convert to UTF-8" % bits)
        rc, out, err = run("-", o, stdin="1 2 3\n".encode(enc))
        assert rc == 2 and "UTF-%s text; convert to UTF-8" % bits in err, (enc, rc, err)


@test
def a_malformed_number_on_the_first_line_is_refused_not_taken_for_a_header(d):
    for bad in ("1.#QNAN 2 3", "1.5D+03 0 0", "3.14abc 1 1"):
        expect_bad(write(d, "m.xyz", bad + "\n1 1 1\n"), "m.xyz:1: '%s' is not a number" % bad.split()[0])
    rc, out, err = run("--json", write(d, "h.csv", "# scan\nX,Y,Z\n1,1,1\n"), write(d, "o.xyz", "0 0 0\n"))
    assert rc == 0 and json.loads(out)["n_a"] == 1, (rc, out, err)


@test
def bad_binary_input_exits_2_naming_the_file_and_byte_offset(d):
    head = PLY_HEAD.replace("ascii", "binary_little_endian").format(n=3)
    expect_bad(write(d, "a.ply", head.encode() + struct.pack("<6f", 1, 2, 3, 4, 5, 6)),
               "a.ply: byte %d: file ends inside element vertex" % (len(head) + 24))
    stl = b"binary".ljust(80, b"\0") + struct.pack("<I", 9) + b"\0" * 50
    expect_bad(write(d, "b.stl", stl), "b.stl: byte 80: binary STL declares 9 triangles")
    las = b"LASF" + b"\0" * 100
    expect_bad(write(d, "c.las", las), "c.las: byte 104: file ends inside the LAS header")
    npy = b"\x93NUMPY\x01\x00" + struct.pack("<H", 60) + b"{'descr': '<f8', 'fortran_order': False, 'shape': (9, 3), }".ljust(59) + b"\n"
    expect_bad(write(d, "d.npy", npy + struct.pack("<3d", 1, 2, 3)), "d.npy: byte 94: file ends inside the data")
    expect_bad(write(d, "e.npy", npy.replace(b"(9, 3)", b"(1, 3)") + struct.pack("<3d", 1, float("inf"), 3)),
               "d.npy" if False else "e.npy: byte 78: point 0: coordinate is NaN or infinite")


@test
def unsupported_and_missing_files_exit_2_with_a_way_out(d):
    expect_bad(os.path.join(d, "scan.laz"), "scan.laz: cannot open")
    expect_bad(os.path.join(d, "missing.ply"), "missing.ply: cannot open")
    expect_bad(write(d, "blob.bin", b"\x01\x02\x03"), "use --format")
    expect_bad(write(d, "las.ply", b"LASF" + b"\0" * 300), "the name says ply but the content is las; use --format las")


@test
def laz_files_are_read_by_extension_and_by_format(d):
    laz = os.path.join(HERE, "corpus", "laz", "fmt6_channels.laz")
    rc, out, err = run(laz, laz)
    assert rc == 0 and "(60 points, laz)" in out and "H(A,B) = 0" in out, (rc, out, err)
    rc, out, err = run("--format", "laz", "-", laz, stdin=open(laz, "rb").read())
    assert rc == 0 and "H(A,B) = 0" in out, (rc, out, err)
    bad = open(laz, "rb").read()[:-40]
    expect_bad(write(d, "cut.laz", bad), "cut.laz: byte ")


@test
def a_laz_file_denser_than_the_points_per_byte_limit_is_refused_unless_the_limit_is_raised(d):
    """A million points in 2 KB (one point repeated): refused by default,
    naming the limit and the option; read with the limit raised."""
    dense = os.path.join(HERE, "corpus", "laz", "regress-dense-1000000-points.laz")
    expect_bad(dense, "above the limit of 256 points a compressed byte (the default)")
    expect_bad(dense, "--laz-points-per-byte N")
    rc, out, err = run("--laz-points-per-byte", "1024", dense, dense)
    assert rc == 0 and "(1000000 points, laz)" in out, (rc, out, err)
    rc, out, err = run("--laz-points-per-byte", "4097", dense, dense)
    assert rc == 1 and "--laz-points-per-byte needs a whole number 1..4096" in err, (rc, err)


@test
def usage_errors_exit_1(d):
    for args in (["--format", "dxf"], ["--sample", "0"], ["--sample", "-5"], ["--sample"], ["--seed", " -1"]):
        rc, out, err = run(*args, "a.ply", "b.ply")
        assert rc == 1, (args, rc, err)
        assert "hausdorff: " in err, err


@test
def formats_version_and_help_describe_the_reader(d):
    rc, out, _ = run("--formats")
    assert rc == 0
    for name in ("ply", "obj", "off", "stl", "xyz", "pcd", "las", "laz", "npy"):
        assert ("  %s " % name) in out, (name, out)
    assert ".laz" in out
    rc, out, _ = run("--version")
    assert rc == 0 and out.startswith("hausdorff ") and out.count(".") >= 2, out
    rc, out, _ = run("--help")
    assert rc == 0
    for needle in ("--format", "--formats", "--sample", "--vertices", "--quiet", "Examples", " - ", "Exit status"):
        assert needle in out, needle


@test
def standard_input_is_read_with_or_without_format(d):
    text = open(os.path.join(DATA, "derived", "pinion_gear_ascii.pcd")).read()
    for args in (["--format", "pcd"], []):  # --format applies to both files
        rc, out, err = run("--json", *args, "-", os.path.join(DATA, "derived", "pinion_gear_binary.pcd"), stdin=text.encode())
        assert rc == 0, err
        r = json.loads(out)
        assert r["hausdorff"] == 0 and r["n_a"] == 650, r
    rc, out, err = run("--json", "-", os.path.join(DATA, "pinion_gear.ply"), stdin=b"1 2 3\n4 5 6\n")
    assert rc == 0 and json.loads(out)["n_a"] == 2, err


@test
def human_output_names_files_counts_distance_witness_and_time(d):
    a, b = os.path.join(DATA, "orig", "lion.off"), os.path.join(DATA, "cgal_lion_head.ply")
    rc, out, err = run(a, b)
    assert rc == 0, err
    assert "A: %s (7529 points" % a in out and "B: %s (8356 points" % b in out, out
    assert "0.14468150162771326" in out, out
    assert "witness:" in out and "(" in out and "time:" in out, out
    assert err == "", err


@test
def sampling_is_reproducible_and_follows_the_seed(d):
    mesh = os.path.join(DATA, "orig", "WusonOBJ.obj")
    stl = os.path.join(DATA, "orig", "Wuson.stl")
    outs = []
    for seed in ("1", "1", "2"):
        rc, out, err = run("--json", "--sample", "2000", "--seed", seed, mesh, stl)
        assert rc == 0, err
        r = json.loads(out)
        assert r["n_a"] == 2000 and r["n_b"] == 2000, r
        outs.append(r["hausdorff"])
    assert outs[0] == outs[1] and outs[0] != outs[2], outs


def run_on_terminal(args, feed_after=None, stdin_data=b""):
    """Run with stderr on a pseudo-terminal (stdout and stdin on pipes);
    return (exit code, stdout, what the terminal received).  A machine
    without pseudo-terminals (a container without /dev/pts) skips the test:
    there is no terminal to draw a progress bar on."""
    try:
        master, slave = pty.openpty()
    except OSError as e:
        raise unittest.SkipTest("no pseudo-terminal available: %s" % e)
    p = subprocess.Popen([TOOL] + args, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    if feed_after:
        time.sleep(feed_after)
    p.stdin.write(stdin_data)
    p.stdin.close()
    term = b""
    while True:
        r, _, _ = select.select([master], [], [], 0.1)
        if r:
            try:
                chunk = os.read(master, 4096)
            except OSError:
                break
            if not chunk:
                break
            term += chunk
        elif p.poll() is not None:
            break
    out = p.stdout.read()
    p.wait()
    os.close(master)
    return p.returncode, out.decode(), term.decode(errors="replace")


@test
def progress_bar_appears_on_a_terminal_for_a_slow_phase_only(d):
    ply = os.path.join(DATA, "derived", "pinion_gear_binary.pcd")
    data = open(os.path.join(DATA, "derived", "pinion_gear_ascii.pcd"), "rb").read()
    # standard input that arrives after 1.6 s makes "reading A" a slow phase
    rc, out, term = run_on_terminal(["--format", "pcd", "-", ply], feed_after=1.6, stdin_data=data)
    assert rc == 0, term
    assert "reading A: -" in term and "[" in term and "\033[K" in term, repr(term)
    assert "reading A" not in out and "Hausdorff distance" in out
    for quiet in (["--quiet"], ["--json"]):
        rc, out, term = run_on_terminal(quiet + ["--format", "pcd", "-", ply], feed_after=1.6, stdin_data=data)
        assert rc == 0 and term == "", (quiet, repr(term))
    # a fast run draws nothing, and stderr on a pipe never gets the bar
    rc, out, term = run_on_terminal([ply, ply])
    assert rc == 0 and term == "", repr(term)
    p = subprocess.Popen([TOOL, "--format", "pcd", "-", ply], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE)
    time.sleep(1.6)
    out, err = p.communicate(data)
    assert p.returncode == 0 and err == b"", err


@test
def a_format_per_file_is_written_format_colon_path(d):
    csv = "x,y,z\n0,0,0\n1,1,1\n"
    pts = write(d, "p.dat", "0 0 0\n1 1 1\n")
    # xyz:- reads standard input as text while B keeps its own format
    rc, out, err = run("--json", "xyz:-", os.path.join(DATA, "pinion_gear.ply"), stdin=csv.encode())
    assert rc == 0, err
    # an unknown extension made readable by its prefix
    rc, out, err = run("--json", "xyz:" + pts, "xyz:" + pts)
    assert rc == 0 and '"hausdorff": 0' in out, (rc, out, err)
    # a prefix that names no format is part of the path
    rc, out, err = run("nosuch:" + pts, pts)
    assert rc == 2 and "nosuch:" in err and "cannot open" in err, err
    # FORMAT: wins over --format for its file only
    ply = os.path.join(DATA, "pinion_gear.ply")
    rc, out, err = run("--format", "ply", "xyz:" + pts, ply)
    assert rc == 0, err


@test
def a_file_whose_name_holds_a_colon_is_named_with_a_directory(d):
    write(d, "ply:x", "0 0 0\n1 1 1\n")
    p = subprocess.run([os.path.abspath(TOOL), "--format", "xyz", "./ply:x", "./ply:x"], cwd=d,
                       capture_output=True, timeout=120)
    assert p.returncode == 0, p.stderr


@test
def a_csv_with_a_header_on_standard_input_is_read_without_format(d):
    rc, out, err = run("--json", "-", os.path.join(DATA, "pinion_gear.ply"), stdin=b"x,y,z\r\n0,0,0\n1,1,1\n")
    assert rc == 0, err
    assert '"n_a": 2' in out, out


def significant_digits(tok):
    """Digits of a decimal token that carry value ("0.0708876" -> 6)."""
    m = tok.lower().lstrip("+-").split("e")[0].replace(".", "")
    m = m.lstrip("0").rstrip("0")
    return max(len(m), 1)


def assert_shortest(tok):
    v = float(tok)
    assert float(tok) == v
    want = significant_digits(repr(v))  # Python's repr is the shortest round trip
    assert significant_digits(tok) == want, "%s has more digits than %r" % (tok, v)
    mant = tok.lower().split("e")[0]
    assert not ("." in mant and mant.endswith("0")), "%s has trailing zeros (%r)" % (tok, v)  # once "1.000"


NUMBER = re.compile(r"(?<![\w.])-?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])")


@test
def every_number_printed_is_the_shortest_that_reads_back(d):
    a, b = os.path.join(DATA, "cgal_lion.ply"), os.path.join(DATA, "cgal_lion_head.ply")
    out_csv = os.path.join(d, "dist.csv")
    rc, out, err = run("--json", "--percentile", "95", "--mean", "--chamfer", "--distances", out_csv, a, b)
    assert rc == 0, err
    toks = NUMBER.findall(out)
    assert len(toks) > 10, out
    for t in toks:
        assert_shortest(t)
    assert '"seconds": ' in out
    rc, text, err = run("--percentile", "95", "--mean", "--chamfer", a, b)
    assert rc == 0, err
    assert "(0.0708876, -0.102745, 0.223258)" in text, text  # once 0.070887599999999995, ...
    assert "pooled (medpy)" in text and "Chamfer distance" in text, text
    for t in NUMBER.findall(text):
        assert_shortest(t)
    with open(out_csv) as f:
        rows = f.read().split("\n")[1:200]
    for row in rows:
        for t in row.split(",")[:4] if row else []:
            assert_shortest(t)


@test
def small_surprises_of_a_first_hour_are_gone(d):
    rc, out, err = run("--formats")
    assert rc == 0 and "nifti" in out and ".nii.gz" in out, out
    rc, out, err = run(os.path.join(DATA, "pinion_gear.ply"))
    assert rc == 1 and "expected two files" in err and len(err.splitlines()) <= 3, err
    p = os.path.join(DATA, "pinion_gear.ply")
    rc, out, err = run("--json", "--directed", p, p)
    assert rc == 0, err
    r = json.loads(out)
    assert r["hausdorff"] is None and r["directed_ab"] == 0 and r["directed_ba"] is None, r
    # timings to the microsecond, the per-point distances' too (were 0.011584724999920581)
    rc, out, err = run("--json", "--mean", p, p)
    r = json.loads(out)
    for key in ("seconds", "read_seconds", "distances_seconds"):
        assert r[key] == round(r[key], 6), (key, r[key])
    # the text extensions name the xyz reader, as --format and as FORMAT:PATH (were "unknown format 'csv'"
    # and "csv:-: cannot open")
    pts = write(d, "pts.dat", "x,y,z\n0,0,0\n1,1,1\n")
    for args in (["--format", "csv", pts, pts], ["csv:" + pts, "TXT:" + pts], ["csv:-", "asc:" + pts]):
        rc, out, err = run("--json", *args, stdin=b"x,y,z\n0,0,0\n1,1,1\n")
        assert rc == 0 and json.loads(out)["n_a"] == 2, (args, err)
    rc, out, err = run("--formats")
    assert "csv, txt, pts and asc" in out, out


@test
def every_option_of_the_help_is_in_the_man_page(d):
    """A user who reads `man hausdorff` meets every option --help lists
    (--max-stream-size and --fifo-wait were missing)."""
    rc, out, err = run("--help")
    assert rc == 0, err
    with open(os.path.join(os.path.dirname(HERE), "docs", "hausdorff.1")) as f:
        man = f.read().replace("\\-", "-")
    missing = sorted({o for o in re.findall(r"--[a-z][a-z0-9-]*", out) if o not in man})
    assert not missing, missing


@test
def empty_monai_is_inf_for_one_empty_set_and_nan_for_two(d):
    empty = write(d, "empty.xyz", "")
    full = write(d, "full.xyz", "0 0 0\n1 1 1\n")
    rc, out, err = run("--empty", "monai", "--mean", empty, full)
    assert rc == 0 and "H(A,B) = inf" in out and "mean distance: inf" in out, (out, err)
    rc, out, err = run("--empty", "monai", full, empty)
    assert rc == 0 and "H(A,B) = inf" in out, (out, err)
    rc, out, err = run("--empty", "monai", empty, empty)
    assert rc == 0 and "H(A,B) = nan" in out, (out, err)
    rc, out, err = run("--json", "--empty", "monai", empty, empty)
    r = json.loads(out)
    assert r["hausdorff"] is None and r["empty"]["policy"] == "monai", r


ReadingCli = temp_dir_cases("ReadingCli", TESTS, "hd-cli-io-")

if __name__ == "__main__":
    TOOL = tool_from_argv()
    unittest.main(verbosity=2)
