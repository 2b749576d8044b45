"""Command-line tests of writing: output that is lost is a failure (exit 3
with "hausdorff: WHAT: REASON" on stderr), never a quiet success.

Standard output on /dev/full or closed; --distances, --render and
--histogram-png into a read-only directory, a missing one, or past a file
size limit (RLIMIT_FSIZE: a disk that fills half-way, which also stops
root); a run whose second file (OUT_b.csv) cannot be written leaves neither;
a run killed by SIGTERM or cut off by SIGPIPE before its end leaves nothing;
outputs that name an input (by path, ./path, a link, a hard link, standard
input) are refused with exit 1 and the input is unchanged; a run that
succeeds leaves complete files with the usual permissions and no temporary.
Standard library only (unittest); run as:
    cli_output.py PATH/TO/hausdorff [WritingCli.test_NAME ...]
"""
import os
import shutil
import resource
import signal
import stat
import subprocess
import time
import unittest

from cli_checks import as_nobody, collector, temp_dir_cases, tool_from_argv

TESTS = []
TOOL = None  # the hausdorff executable, from the command line
HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(os.path.dirname(HERE), "data")
SMALL = os.path.join(DATA, "pinion_gear.ply")   # 650 points: a CSV of about 50 KB
OTHER = os.path.join(DATA, "teapot_792.ply")    # 792 points
LARGE = os.path.join(DATA, "armadillo.ply")     # many more points: a CSV of a few MB


test = collector(TESTS)


def run(*args, stdout=subprocess.PIPE, stdin=None, preexec_fn=None, cwd=None):
    p = subprocess.run([TOOL] + list(args), stdout=stdout, stderr=subprocess.PIPE, stdin=stdin,
                       preexec_fn=preexec_fn, cwd=cwd, timeout=300)
    out = p.stdout.decode() if p.stdout is not None else None
    return p.returncode, out, p.stderr.decode()


def expect(rc, err, code, *needles):
    assert rc == code, "exit %d, expected %d (stderr %r)" % (rc, code, err)
    assert err.startswith("hausdorff: "), err
    for n in needles:
        assert n in err, "%r lacks %r" % (err, n)


def read(path, mode="r"):
    with open(path, mode) as f:
        return f.read()


def listing(d):
    """Every name in d, temporaries (dot files) included."""
    return sorted(os.listdir(d))


def file_limit(nbytes):
    """preexec_fn: files may not grow beyond nbytes (SIGXFSZ as inherited:
    the fixed tool ignores it and reports EFBIG)."""
    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))
    return limit


def pictures_built():
    rc, out, _ = run("--help")
    return rc == 0 and "built without libpng" not in out


def write_csv_points(path, n=50):
    with open(path, "w") as f:
        f.write("x,y,z\n")
        for k in range(n):
            f.write("%d,%d,%d\n" % (k, k % 7, k % 3))


@test
def standard_output_on_dev_full_exits_3_with_a_message(d):
    with open("/dev/full", "w") as full:
        for args in ([SMALL, OTHER], ["--percentile", "95", "--histogram", SMALL, OTHER], ["--help"],
                     ["--version"], ["--formats"]):
            rc, _, err = run(*args, stdout=full)
            expect(rc, err, 3, "standard output: No space left on device")
        # the files of a run whose report was lost do not appear either
        rc, _, err = run("--distances", os.path.join(d, "out.csv"), SMALL, OTHER, stdout=full)
        expect(rc, err, 3, "standard output")
    assert listing(d) == [], listing(d)


@test
def json_on_dev_full_exits_3(d):
    with open("/dev/full", "w") as full:
        for args in (["--json", SMALL, OTHER], ["--json", "--histogram", "--bins", "20000", SMALL, OTHER],
                     ["--json", "--directed", "--empty", "nan", SMALL, write_empty(d)]):
            rc, _, err = run(*args, stdout=full)
            expect(rc, err, 3, "standard output: No space left on device")


def write_empty(d):
    path = os.path.join(d, "empty.xyz")
    open(path, "w").close()
    return path


@test
def closed_standard_output_exits_3(d):
    # `exec >&-` in a shell: descriptor 1 is closed when the tool starts
    out = os.path.join(d, "out.csv")
    for args in ([SMALL, OTHER], ["--json", SMALL, OTHER], ["--distances", out, SMALL, OTHER]):
        p = subprocess.run(["sh", "-c", 'exec >&-; exec "$@"', "sh", TOOL] + args, stderr=subprocess.PIPE,
                           timeout=300)
        expect(p.returncode, p.stderr.decode(), 3, "standard output: Bad file descriptor")
    assert listing(d) == [], listing(d)


@test
def distances_into_a_read_only_directory_exits_3_and_leaves_no_file(d):
    os.chmod(d, 0o755)  # let nobody reach ro/
    ro = os.path.join(d, "ro")
    os.mkdir(ro, 0o555)
    os.chmod(ro, 0o555)
    if os.geteuid() == 0:
        probe = subprocess.run(["sh", "-c", "test -x \"$0\" && test -r \"$1\"", TOOL, SMALL],
                               preexec_fn=as_nobody())
        if probe.returncode != 0:
            raise unittest.SkipTest("user nobody cannot run the tool or read the data")
    for name in ("out.csv", "out.ply", "out.npy"):
        for extra in ([], ["--directed"]):
            rc, out, err = run("--distances", os.path.join(ro, name), *extra, SMALL, OTHER, preexec_fn=as_nobody())
            expect(rc, err, 3, os.path.join(ro, name), "Permission denied")
            assert out == "", out
    if pictures_built():
        rc, _, err = run("--render", os.path.join(ro, "r.png"), SMALL, OTHER, preexec_fn=as_nobody())
        expect(rc, err, 3, "r.png", "Permission denied")
    assert listing(ro) == [], listing(ro)
    # a directory that does not exist: an output failure too (was 2, bad input)
    rc, _, err = run("--distances", os.path.join(d, "missing", "out.csv"), SMALL, OTHER)
    expect(rc, err, 3, "No such file or directory")


@test
def a_file_that_cannot_be_finished_exits_3_and_leaves_nothing(d):
    # a disk that fills half-way: a file size limit stops every user
    for name in ("big.csv", "big.ply", "big.npy"):
        rc, _, err = run("--distances", os.path.join(d, name), "--directed", LARGE, SMALL,
                         preexec_fn=file_limit(20000))
        expect(rc, err, 3, name, "File too large")
        assert listing(d) == [], (name, listing(d))
    if pictures_built():
        for opt in ("--render", "--histogram-png"):
            rc, _, err = run(opt, os.path.join(d, "p.png"), LARGE, SMALL, preexec_fn=file_limit(4000))
            expect(rc, err, 3, "p.png", "File too large")
            assert listing(d) == [], (opt, listing(d))


@test
def when_the_second_file_of_a_pair_fails_neither_appears(d):
    out = os.path.join(d, "out.csv")
    # OUT_b.csv is a directory: it cannot be replaced
    os.mkdir(os.path.join(d, "out_b.csv"))
    rc, _, err = run("--distances", out, SMALL, OTHER)
    expect(rc, err, 3, "out_b.csv", "Is a directory")
    assert listing(d) == ["out_b.csv"], listing(d)
    os.rmdir(os.path.join(d, "out_b.csv"))
    # A's rows fit (about 50 KB), B's (a few MB) do not
    rc, _, err = run("--distances", out, SMALL, LARGE, preexec_fn=file_limit(200000))
    expect(rc, err, 3, "out_b.csv", "File too large")
    assert listing(d) == [], listing(d)
    # files of an earlier run are left as they were
    for name in ("out.csv", "out_b.csv"):
        with open(os.path.join(d, name), "w") as f:
            f.write("old\n")
    rc, _, err = run("--distances", out, SMALL, LARGE, preexec_fn=file_limit(200000))
    expect(rc, err, 3, "out_b.csv")
    assert listing(d) == ["out.csv", "out_b.csv"], listing(d)
    for name in ("out.csv", "out_b.csv"):
        assert read(os.path.join(d, name)) == "old\n", name


def temporaries(d):
    return [n for n in listing(d) if ".tmp." in n]


@test
def a_run_killed_or_cut_off_before_its_end_leaves_no_file(d):
    # A report of some MB on a pipe that nobody reads: the tool waits in its
    # final flush with its files still temporaries.  SIGTERM then, or the
    # reader leaving (SIGPIPE), must remove them.
    for how in ("SIGTERM", "SIGPIPE"):
        p = subprocess.Popen([TOOL, "--histogram", "--bins", "100000", "--distances", os.path.join(d, "out.csv"),
                              SMALL, OTHER], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
        deadline = time.time() + 60
        while not listing(d) and p.poll() is None and time.time() < deadline:  # a file or its temporary
            time.sleep(0.02)
        time.sleep(0.3)  # into the flush
        assert p.poll() is None, "the tool did not wait for its reader (%s)" % how
        if how == "SIGTERM":
            p.send_signal(signal.SIGTERM)
            p.stdout.close()
        else:
            p.stdout.close()
        rc = p.wait(timeout=60)
        sig = signal.SIGTERM if how == "SIGTERM" else signal.SIGPIPE
        assert rc == -sig, (how, rc)
        assert listing(d) == [], (how, listing(d))


@test
def an_output_naming_an_input_is_refused_and_the_input_is_unchanged(d):
    a, b = os.path.join(d, "a.csv"), os.path.join(d, "b_b.csv")
    write_csv_points(a, 50)
    write_csv_points(b, 60)
    before = {p: read(p, "rb") for p in (a, b)}
    os.symlink("a.csv", os.path.join(d, "link.csv"))
    os.link(a, os.path.join(d, "hard.csv"))
    cases = [
        (["--distances", a, a, OTHER], "--distances %s" % a, "input A (%s)" % a),
        (["--distances", "a.csv", "./a.csv", OTHER], "--distances a.csv", "input A (./a.csv)"),
        (["--distances", "link.csv", OTHER, "a.csv"], "--distances link.csv", "input B (a.csv)"),
        (["--distances", "hard.csv", "--directed", "a.csv", OTHER], "--distances hard.csv", "input A (a.csv)"),
        (["--distances", "b.csv", SMALL, "b_b.csv"], "b_b.csv", "input B (b_b.csv)"),
    ]
    if pictures_built():  # a picture's name ends in .png or has no extension
        shutil.copyfile(a, os.path.join(d, "apts"))
        before[os.path.join(d, "apts")] = before[a]
        os.symlink("b_b.csv", os.path.join(d, "pic.png"))
        cases.append((["--render", "apts", SMALL, "xyz:apts"], "--render apts", "input B (apts)"))
        cases.append((["--histogram-png", "pic.png", "b_b.csv", SMALL], "--histogram-png pic.png", "input A"))
    for args, *needles in cases:
        rc, out, err = run(*args, cwd=d)
        expect(rc, err, 1, "would overwrite", *needles)
        assert out == "", out
    with open(a, "rb") as f:  # standard input that is the file
        rc, _, err = run("--distances", a, "-", OTHER, stdin=f)
    expect(rc, err, 1, "would overwrite input A (standard input)")
    for p, data in before.items():
        assert read(p, "rb") == data, p
    pictures = ["apts", "pic.png"] if pictures_built() else []
    assert sorted(listing(d)) == sorted(["a.csv", "b_b.csv", "hard.csv", "link.csv"] + pictures), listing(d)


@test
def two_outputs_naming_one_file_are_refused(d):
    if not pictures_built():
        raise unittest.SkipTest("built without libpng")
    for second in ("p.png", "./p.png"):
        rc, _, err = run("--render", "p.png", "--histogram-png", second, SMALL, OTHER, cwd=d)
        expect(rc, err, 1, "--render p.png and --histogram-png %s are the same file" % second)
    assert listing(d) == [], listing(d)


@test
def a_run_that_succeeds_leaves_complete_files_and_no_temporary(d):
    # regression guard for the temporaries: permissions as fopen gives them,
    # an old file replaced with its mode kept, a link followed
    out = os.path.join(d, "out.csv")
    names = ["out.csv", "out_b.csv"]
    args = ["--distances", out]
    if pictures_built():
        args += ["--render", os.path.join(d, "r.png"), "--histogram-png", os.path.join(d, "h.png")]
        names += ["h.png", "r.png"]
    old = os.umask(0o027)
    try:
        rc, _, err = run(*args, SMALL, OTHER)
    finally:
        os.umask(old)
    assert rc == 0 and err == "", err
    assert listing(d) == sorted(names), listing(d)
    for n in names:
        assert stat.S_IMODE(os.stat(os.path.join(d, n)).st_mode) == 0o640, n
    rows = read(out).splitlines()
    assert rows[0] == "x,y,z,distance,nearest" and len(rows) == 651, len(rows)
    # replace: the mode of the old file stays, a link stays a link
    os.chmod(out, 0o600)
    os.rename(os.path.join(d, "out_b.csv"), os.path.join(d, "real_b.csv"))
    os.symlink("real_b.csv", os.path.join(d, "out_b.csv"))
    rc, _, err = run("--distances", out, OTHER, SMALL)
    assert rc == 0, err
    assert stat.S_IMODE(os.stat(out).st_mode) == 0o600
    assert len(read(out).splitlines()) == 793
    assert os.path.islink(os.path.join(d, "out_b.csv"))
    assert len(read(os.path.join(d, "real_b.csv")).splitlines()) == 651
    assert not [n for n in listing(d) if n.startswith(".")], listing(d)
    # a device is written in place, not replaced
    if pictures_built():
        rc, _, err = run("--render", "/dev/null", SMALL, OTHER)
        assert rc == 0, err
        assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
        assert not [n for n in os.listdir("/dev") if n.startswith(".null.")]


WritingCli = temp_dir_cases("WritingCli", TESTS, "hd-cli-output-")

if __name__ == "__main__":
    TOOL = tool_from_argv()
    unittest.main(verbosity=2)
