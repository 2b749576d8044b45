#!/usr/bin/env python3
"""laz_lazperf.py -- the tests' LAZ writer checked by an independent decoder.

    laz_lazperf.py LAZGEN WORKDIR

Installs the npm package laz-perf (LASzip's format compiled to WebAssembly,
pinned to one version) into WORKDIR/npm with npm, has LAZGEN write its
files into WORKDIR/files, decodes each with laz-perf under node
(tests/laz_lazperf.js) and compares the points, in order, with the ones
the writer was given.  The reader's own tests (test_io_laz) read the same
writer's files: a model or context mistake shared by writer and reader
would pass them, but not this check.  Without node, npm or the registry
the test FAILS (never skips): CI runs it with the npm registry reachable.
"""
import os
import shutil
import subprocess
import sys

LAZPERF = "laz-perf@0.0.7"


def fail(msg):
    print("laz_lazperf: FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def main():
    lazgen, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    here = os.path.dirname(os.path.abspath(__file__))
    node, npm = shutil.which("node") or shutil.which("nodejs"), shutil.which("npm")
    if not node or not npm:
        fail("node and npm are needed (Debian: nodejs npm; scripts/deps.sh test installs them)")
    modules = os.path.join(work, "npm", "node_modules")
    if not os.path.isfile(os.path.join(modules, "laz-perf", "package.json")):
        os.makedirs(os.path.join(work, "npm"), exist_ok=True)
        r = subprocess.run([npm, "install", "--no-audit", "--no-fund", "--prefix", os.path.join(work, "npm"), LAZPERF],
                           capture_output=True, text=True, timeout=600)
        if r.returncode != 0:
            fail("npm install %s failed (is the npm registry reachable?):\n%s%s" % (LAZPERF, r.stdout, r.stderr))
    files = os.path.join(work, "files")
    shutil.rmtree(files, ignore_errors=True)
    os.makedirs(files)
    names = subprocess.run([lazgen, files], capture_output=True, text=True, check=True).stdout.split()
    if len(names) < 10:
        fail("lazgen wrote %d cases" % len(names))
    bad = 0
    for name in names:
        r = subprocess.run([node, os.path.join(here, "laz_lazperf.js"), modules, os.path.join(files, name + ".laz")],
                           capture_output=True, text=True)
        if r.returncode != 0:
            print("%s: laz-perf failed: %s" % (name, r.stderr.strip()[-500:]))
            bad += 1
            continue
        got = r.stdout.split("\n")
        want = open(os.path.join(files, name + ".txt")).read().split("\n")[:-1]
        if got[0] != "count %d" % len(want):
            print("%s: laz-perf says %s, the writer wrote %d points" % (name, got[0], len(want)))
            bad += 1
            continue
        diff = [k for k in range(len(want)) if got[1 + k] != want[k]]
        if diff:
            k = diff[0]
            print("%s: %d points differ, first point %d: laz-perf %s, written %s" % (name, len(diff), k, got[1 + k], want[k]))
            bad += 1
        else:
            print("%s: %d points identical" % (name, len(want)))
    if bad:
        fail("%d of %d files differ" % (bad, len(names)))
    print("laz_lazperf: %d files decoded by laz-perf exactly as written" % len(names))


main()
