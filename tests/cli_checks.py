"""cli_checks.py -- the runner shared by the command-line scripts that print
one line a check ("ok" or "FAIL", the process shown on failure) and exit 1
when any failed: cli_surface.py, cli_m2m.py.

    from cli_checks import check, finish, run, start, writer
    start(sys.argv[1])                 # the hausdorff binary
    put = writer(tmpdir)               # put(name, text) -> path
    check(run("--json", a, b).returncode == 0, "what is checked")
    finish()
"""
import os
import subprocess
import sys

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
