"""cli_checks.py -- the runners shared by the command-line test scripts.

One line a check ("ok" or "FAIL", the process shown on failure), exit 1 when
any failed: cli_surface.py, cli_m2m.py.

    from cli_checks import check, finish, run, start, writer
    start(sys.argv[1])                 # the hausdorff binary
    put = writer(tmpdir)               # put(name, text) -> path
    check(run("--json", a, b).returncode == 0, "what is checked")
    finish()

unittest, one test a function, each in a fresh temporary directory:
cli_io.py, cli_output.py, cli_hostile.py.

    TESTS = []
    test = collector(TESTS)            # @test def name_says_what_holds(d): ...
    ReadingCli = temp_dir_cases("ReadingCli", TESTS, "hd-cli-io-")
    if __name__ == "__main__":
        TOOL = tool_from_argv()        # argv[1], the hausdorff binary
        unittest.main(verbosity=2)
"""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_tool = None
_failures = 0


def start(tool):
    global _tool
    _tool = tool


def run(*args):
    """The tool with these arguments, from the repository's root."""
    return subprocess.run([_tool, *args], capture_output=True, text=True, cwd=ROOT)


def check(cond, what, proc=None):
    global _failures
    if not cond:
        _failures += 1
        print("FAIL", what)
        if proc is not None:
            print("  exit", proc.returncode, "stdout:", proc.stdout.strip()[:2000], "stderr:", proc.stderr.strip())
    else:
        print("ok  ", what)


def writer(directory):
    """put(name, text): a file of that text in directory, its path."""
    def put(name, text):
        path = os.path.join(directory, name)
        with open(path, "w") as f:
            f.write(text)
        return path
    return put


def finish():
    print("%d failed" % _failures)
    sys.exit(1 if _failures else 0)


NOBODY = 65534  # the user a read-only directory is tried as


def as_nobody():
    """preexec_fn running the tool as NOBODY when the tests run as root (to
    whom a directory's missing write bit means nothing); None otherwise."""
    if os.geteuid() != 0:
        return None

    def drop():
        os.setgroups([])
        os.setgid(NOBODY)
        os.setuid(NOBODY)
    return drop


def collector(tests):
    """A decorator that appends each function it marks to tests."""
    def test(fn):
        tests.append(fn)
        return fn
    return test


def temp_dir_cases(name, tests, prefix):
    """A unittest.TestCase class with a test_NAME calling each function of
    tests with a fresh temporary directory, removed after it (its folders
    made writable first: a test may take their write bits away)."""
    def set_up(self):
        self.tmp = tempfile.TemporaryDirectory(prefix=prefix)

    def tear_down(self):
        for root, dirs, _ in os.walk(self.tmp.name):
            for x in dirs:
                os.chmod(os.path.join(root, x), 0o755)
        self.tmp.cleanup()

    members = {"__doc__": "Each test function becomes one test, run in a fresh temporary directory.",
               "setUp": set_up, "tearDown": tear_down}
    for fn in tests:
        members["test_" + fn.__name__] = lambda self, fn=fn: fn(self.tmp.name)
    return type(name, (unittest.TestCase,), members)


def tool_from_argv():
    """The hausdorff binary, argv[1], taken out of sys.argv (the rest are
    unittest's) as an absolute path."""
    return os.path.abspath(sys.argv.pop(1))
