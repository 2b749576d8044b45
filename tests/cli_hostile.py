"""Command-line tests of hostile inputs and outputs that once gave a wrong,
lost or unreadable result, or a hang:

 - a Chamfer distance whose sum of squares is beyond DBL_MAX (coordinates
   within 1e153) is reported, not inf / null;
 - file names that are not UTF-8, or hold control characters, give valid
   JSON from which the name's bytes come back (surrogateescape), and a text
   report without raw control characters;
 - an output FIFO without a reader fails (exit 3) after --fifo-wait, and is
   written once a reader comes;
 - --max-distance takes a subnormal number; an output in a directory that
   cannot hold its temporary says so and where; a message longer than the
   error record keeps its reason;
 - a file that cannot be mapped for want of memory exits 3 (out of memory),
   not 2 (bad input) (not under the sanitizers, whose shadow memory an
   address-space limit would refuse).
Standard library only (unittest); run as:
    cli_hostile.py PATH/TO/hausdorff [--sanitized] [HostileCli.test_NAME ...]
"""
import json
import os
import resource
import subprocess
import sys
import threading
import time
import unittest

from cli_checks import as_nobody, collector, temp_dir_cases, tool_from_argv

TESTS = []
TOOL = None  # the hausdorff executable, from the command line
SANITIZED = False


test = collector(TESTS)


def run(*args, cwd=None, preexec_fn=None, timeout=120):
    p = subprocess.run([TOOL] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=cwd,
                       preexec_fn=preexec_fn, timeout=timeout)
    return p.returncode, p.stdout, p.stderr.decode("utf-8", "surrogateescape")


def write(d, name, text):
    path = os.path.join(os.fsencode(d), name if isinstance(name, bytes) else os.fsencode(name))
    with open(path, "w") as f:
        f.write(text)
    return path


def pictures_built():
    rc, out, _ = run("--help")
    return rc == 0 and b"built without libpng" not in out


@test
def chamfer_is_reported_when_the_sum_of_squares_is_beyond_dbl_max(d):
    big = write(d, "big.xyz", "1e153 1e153 1e153\n" * 100)
    neg = write(d, "neg.xyz", "-1e153 -1e153 -1e153\n")
    rc, out, err = run("--json", "--chamfer", "--mean", big, neg)
    assert rc == 0, err
    c = json.loads(out)["chamfer"]
    square = 3 * 2e153 ** 2  # every distance's square, 1.2e307
    assert c["mean_squared_ab"] == square and c["mean_squared_ba"] == square, c
    assert c["mean_squared"] == c["value"] == 2 * square, c
    assert c["sum_squared"] is None, c  # 1.2e309 + 1.2e307: no double holds it
    rc, out, err = run("--chamfer", big, neg)
    assert rc == 0, err
    assert b"Chamfer distance (mean squared A->B + mean squared B->A) = 2.4e+307\n" in out, out


@test
def a_name_that_is_not_utf8_gives_valid_json_and_comes_back_whole(d):
    name = b"Z\xfcrich.xyz"  # Latin-1
    path = write(d, name, "1 1 1\n")
    ctl = write(d, b"e\x1b[31mvil\xc2\x9b.xyz", "0 0 0\n")  # ESC, and C1's CSI in UTF-8
    rc, out, err = run("--json", name, b"e\x1b[31mvil\xc2\x9b.xyz", cwd=d)
    assert rc == 0, err
    text = out.decode("utf-8")  # valid UTF-8 (it is ASCII)
    assert "\x1b" not in text and "\\udcfc" in text and "\\u001b" in text and "\\u009b" in text, text
    r = json.loads(text)
    assert os.fsencode(r["file_a"]) == name, r["file_a"]
    assert os.fsencode(r["file_b"]) == os.path.basename(ctl), r["file_b"]
    assert os.path.exists(os.path.join(d, r["witness_ab_files"][0]["file"])), r["witness_ab_files"]
    assert path.endswith(name)


@test
def the_text_report_and_messages_escape_control_characters_and_bytes_not_utf8(d):
    write(d, b"Z\xfcrich.xyz", "1 1 1\n")
    write(d, b"e\x1b[31mvil.xyz", "0 0 0\n")
    rc, out, err = run("--mean", b"Z\xfcrich.xyz", b"e\x1b[31mvil.xyz", cwd=d)
    assert rc == 0, err
    assert b"A: Z\\xfcrich.xyz (1 point," in out and b"B: e\\x1b[31mvil.xyz (1 point," in out, out
    assert b"\x1b" not in out and b"\xfc" not in out, out
    rc, out, err = run(b"missing\x1b]0;owned\x07.xyz", b"e\x1b[31mvil.xyz", cwd=d)
    assert rc == 2, err
    assert "missing\\x1b]0;owned\\x07.xyz: cannot open" in err and "\x1b" not in err, err
    rc, out, err = run("--distances", b"out\x1b[2J.dat", b"e\x1b[31mvil.xyz", b"e\x1b[31mvil.xyz", cwd=d)
    assert rc == 1 and "'out\\x1b[2J.dat'" in err and "\x1b" not in err, err
    # UTF-8 names stay as they are
    write(d, "Zürich.xyz", "1 1 1\n")
    rc, out, err = run("Zürich.xyz", b"e\x1b[31mvil.xyz", cwd=d)
    assert rc == 0 and "A: Zürich.xyz (1 point,".encode() in out, out


def fifo_without_reader_fails(d, option, name):
    fifo = os.path.join(d, name)
    os.mkfifo(fifo)
    a = write(d, "a.xyz", "0 0 0\n1 1 1\n")
    start = time.monotonic()
    rc, out, err = run("--fifo-wait", "1", option, fifo, a, a, timeout=60)
    took = time.monotonic() - start
    assert rc == 3, (rc, err)
    assert err.startswith("hausdorff: ") and fifo in err and "no reader opened within 1 s" in err, err
    assert took < 30, took
    assert sorted(os.listdir(d)) == sorted(["a.xyz", name]), os.listdir(d)  # no temporary, no _b file left


@test
def distances_onto_a_fifo_without_a_reader_exit_3_after_fifo_wait(d):
    fifo_without_reader_fails(d, "--distances", "out.csv")


@test
def a_picture_onto_a_fifo_without_a_reader_exits_3_after_fifo_wait(d):
    if not pictures_built():
        raise unittest.SkipTest("built without libpng")
    fifo_without_reader_fails(d, "--render", "out.png")


@test
def a_fifo_whose_reader_comes_late_gets_the_whole_file(d):
    fifo = os.path.join(d, "out.csv")
    os.mkfifo(fifo)
    a = write(d, "a.xyz", "0 0 0\n1 1 1\n")
    got = []

    def reader():
        time.sleep(0.5)
        with open(fifo, "rb") as f:
            got.append(f.read())
    t = threading.Thread(target=reader)
    t.start()
    rc, out, err = run("--fifo-wait", "20", "--directed", "--distances", fifo, a, a, timeout=60)
    t.join(30)
    assert rc == 0, err
    assert got == [b"x,y,z,distance,nearest\n0,0,0,0,0\n1,1,1,0,1\n"], got


@test
def max_distance_takes_a_subnormal_number(d):
    a = write(d, "a.xyz", "0 0 0\n1 1 1\n")
    rc, out, err = run("--max-distance", "1e-320", "--histogram", a, a)
    assert rc == 0, err
    assert b"[9.481e-321, 1e-320]" in out, out
    rc, out, err = run("--max-distance", "1e-400", a, a)
    assert rc == 1 and "1e-400 is below the smallest positive double" in err, err
    rc, out, err = run("--max-distance", "-1e-320", a, a)
    assert rc == 1 and "needs a positive number" in err, err


@test
def a_writable_file_in_a_read_only_directory_names_the_temporary_and_where(d):
    os.chmod(d, 0o755)
    ro = os.path.join(d, "ro")
    os.mkdir(ro)
    a = write(d, "a.xyz", "0 0 0\n1 1 1\n")
    out_csv = os.path.join(ro, "out.csv")
    with open(out_csv, "w") as f:
        f.write("old\n")
    os.chmod(out_csv, 0o666)
    os.chmod(ro, 0o555)
    if os.geteuid() == 0 and subprocess.run(["sh", "-c", 'test -x "$0" && test -r "$1"', TOOL, a],
                                            preexec_fn=as_nobody()).returncode != 0:
        raise unittest.SkipTest("user nobody cannot run the tool or read the data")
    rc, out, err = run("--directed", "--distances", out_csv, a, a, preexec_fn=as_nobody())
    assert rc == 3, err
    want = "hausdorff: %s: cannot write: no temporary file can be created in %s/ (the output is written there, " \
           "then renamed over its name): Permission denied" % (out_csv, ro)
    assert err.startswith(want), err
    with open(out_csv) as f:
        assert f.read() == "old\n"


@test
def a_message_longer_than_the_error_record_keeps_its_reason(d):
    deep = d
    for k in range(5):
        deep = os.path.join(deep, "d" * 240 + str(k))
    os.makedirs(deep)
    bad = write(deep, "bad.xyz", "1 2 3\n4 5 x\n")
    rc, out, err = run(bad, bad)
    assert rc == 2, err
    assert err.startswith("hausdorff: " + d) and "..." in err, err
    assert err.endswith("/bad.xyz:2: 'x' is not a number (column 3)\n"), err


@test
def a_file_that_cannot_be_mapped_for_want_of_memory_exits_3(d):
    if SANITIZED:
        raise unittest.SkipTest("an address-space limit cannot be set under the sanitizers")
    big = os.path.join(d, "big.xyz")
    with open(big, "wb") as f:
        f.truncate(3 << 30)  # sparse: no disk used
    a = write(d, "a.xyz", "0 0 0\n")

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))
    rc, out, err = run(big, a, preexec_fn=limit)
    assert rc == 3, (rc, err)
    assert "big.xyz: cannot map its 3221225472 bytes: Cannot allocate memory (out of memory)" in err, err


HostileCli = temp_dir_cases("HostileCli", TESTS, "hd-cli-hostile-")

if __name__ == "__main__":
    TOOL = tool_from_argv()
    if len(sys.argv) > 1 and sys.argv[1] == "--sanitized":
        SANITIZED = True
        sys.argv.pop(1)
    unittest.main(verbosity=2)
