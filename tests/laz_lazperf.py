#!/usr/bin/env python3
"""laz_lazperf.py -- the tests' LAZ writer checked by an independent decoder.

    laz_lazperf.py offline LAZGEN FIXTURES WORKDIR
    laz_lazperf.py npm     LAZGEN FIXTURES WORKDIR [--update]

The reader's own tests (test_io_laz) read the files of the tests' LAZ writer
(tests/internal/lazwrite.c): a model or context mistake shared by writer and
reader would pass them.  laz-perf (the npm package: LASzip's format compiled
to WebAssembly, pinned to one version) decodes the writer's files
independently.  The cases named field_* are hd_write_fields's LAZ output
(the library's LAZ writer; their lines "X Y Z HEX" carry the value added to
each point, decoded by laz-perf too; fieldsN_* "X Y Z HEX..." N values); record_* are its pointwise LAZ output
on files whose every field varies, compared record by record in hexadecimal).  FIXTURES (tests/laz_lazperf/) holds
the files LAZGEN wrote
when laz-perf last decoded them, and laz-perf's decoding of each in
lazperf.txt: the number of points and the SHA-256 of their "X Y Z" lines.

offline  (make test; no network): LAZGEN writes its cases into WORKDIR; each
         must be byte for byte the fixture laz-perf decoded, and the points
         the writer was given must be laz-perf's decoding of it.  So the
         cross-check still holds for the writer as it is now.  And the
         library's decoder of whole records (LAZGEN --records: every field
         of every item, every layer of layered LAZ) must give each
         fixture's records as laz-perf decoded them.  A change to
         the writer's output fails here until `npm ... --update` has had
         laz-perf decode the new files.
npm      (the extra, where node, npm and the npm registry are reachable):
         installs laz-perf into WORKDIR/npm, decodes every fixture and every
         file LAZGEN writes now, and compares with the points written and
         with lazperf.txt.  --update rewrites FIXTURES from LAZGEN's files
         once laz-perf has decoded every one exactly as written.  Without
         node, npm or the registry it prints "NOT RUN" and why, and exits 77
         (CTest: skipped).
"""
import hashlib
import os
import re
import shutil
import subprocess
import sys

LAZPERF = "laz-perf@0.0.7"
NOT_RUN = 77
DIGESTS = "lazperf.txt"


def fail(msg):
    print("laz_lazperf: FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def not_run(msg):
    print("laz_lazperf: NOT RUN: %s (the offline check, laz_lazperf_fixtures, still ran)" % msg)
    sys.exit(NOT_RUN)


def digest(lines):
    """(count, sha256) of points given as "X Y Z" lines."""
    return len(lines), hashlib.sha256("".join(l + "\n" for l in lines).encode()).hexdigest()


def generate(lazgen, work):
    """Runs LAZGEN into WORK/files; returns its case names."""
    files = os.path.join(work, "files")
    shutil.rmtree(files, ignore_errors=True)
    os.makedirs(files)
    names = subprocess.run([lazgen, files], capture_output=True, text=True, check=True).stdout.split()
    if len(names) < 10:
        fail("lazgen wrote %d cases" % len(names))
    return files, names


def written_points(files, name):
    with open(os.path.join(files, name + ".txt")) as f:
        return f.read().split("\n")[:-1]


def read_digests(fixtures):
    path = os.path.join(fixtures, DIGESTS)
    out = {}
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            name, count, sha = line.split()
            out[name] = (int(count), sha)
    if not out:
        fail("%s lists no file" % path)
    return out


def offline(lazgen, fixtures, work):
    files, names = generate(lazgen, work)
    want = read_digests(fixtures)
    if sorted(names) != sorted(want):
        fail("lazgen writes the cases %s, laz-perf decoded %s (tests/laz_lazperf/%s): "
             "run `tests/laz_lazperf.py npm ... --update` where npm is reachable"
             % (sorted(names), sorted(want), DIGESTS))
    bad = 0
    for name in names:
        with open(os.path.join(files, name + ".laz"), "rb") as f:
            made = f.read()
        with open(os.path.join(fixtures, name + ".laz"), "rb") as f:
            checked = f.read()
        got = digest(written_points(files, name))
        if made != checked:
            print("%s: lazgen's file (%d bytes) is not the one laz-perf decoded (%d bytes)" % (name, len(made), len(checked)))
            bad += 1
        elif got != want[name]:
            print("%s: the writer was given %d points (sha256 %s), laz-perf decoded %d (%s)"
                  % (name, got[0], got[1], want[name][0], want[name][1]))
            bad += 1
        else:
            print("%s: the file laz-perf decoded, its %d points as written" % (name, got[0]))
    if bad:
        fail("%d of %d files differ from what laz-perf decoded: if the writer changed on purpose, run "
             "`tests/laz_lazperf.py npm LAZGEN tests/laz_lazperf WORKDIR --update` where npm is reachable"
             % (bad, len(names)))
    print("laz_lazperf: %d files as laz-perf (%s) decoded them" % (len(names), LAZPERF))
    # The library's own decoder of whole records (every field, every layer)
    # gives each fixture's records as laz-perf decoded them.
    for name in names:
        got = library_lines(lazgen, os.path.join(fixtures, name + ".laz"), name)
        if got is None or digest(got) != want[name]:
            print("%s: the library decodes %s, laz-perf decoded %d points (sha256 %s)"
                  % (name, "nothing" if got is None else "%d points (sha256 %s)" % digest(got), want[name][0], want[name][1]))
            bad += 1
    if bad:
        fail("%d of %d fixtures are decoded by the library otherwise than by laz-perf" % (bad, len(names)))
    print("laz_lazperf: %d fixtures' whole records decoded by the library as by laz-perf" % len(names))


def library_lines(lazgen, path, name):
    """The library's decoding of PATH's whole records (lazgen --records) as
    the lines of case NAME (see lazperf.txt), or None after saying why."""
    r = subprocess.run([lazgen, "--records", path], capture_output=True, text=True)
    if r.returncode != 0:
        print("%s: %s" % (path, r.stderr.strip()[-500:]))
        return None
    recs = [bytes.fromhex(l) for l in r.stdout.split()]
    if name.startswith("record_"):
        return [b.hex() for b in recs]
    fields = re.match(r"fields(\d+)_", name)
    nf = int(fields.group(1)) if fields else 1 if name.startswith("field_") else 0
    out = []
    for b in recs:
        line = "%d %d %d" % tuple(int.from_bytes(b[4 * c:4 * c + 4], "little", signed=True) for c in range(3))
        for j in range(nf):
            end = len(b) - 8 * (nf - j)
            line += " %016x" % int.from_bytes(b[end:end + 8], "little")
        out.append(line)
    return out


def install_lazperf(work):
    node, npm = shutil.which("node") or shutil.which("nodejs"), shutil.which("npm")
    if not node or not npm:
        not_run("node and npm are not installed (Debian: nodejs npm)")
    modules = os.path.join(work, "npm", "node_modules")
    if not os.path.isfile(os.path.join(modules, "laz-perf", "package.json")):
        os.makedirs(os.path.join(work, "npm"), exist_ok=True)
        try:
            r = subprocess.run([npm, "install", "--no-audit", "--no-fund", "--fetch-retries=1",
                                "--fetch-timeout=30000", "--prefix", os.path.join(work, "npm"), LAZPERF],
                               capture_output=True, text=True, timeout=300)
        except subprocess.TimeoutExpired:
            not_run("npm install %s took over 300 s (is the npm registry reachable?)" % LAZPERF)
        if r.returncode != 0:
            not_run("npm install %s failed (is the npm registry reachable?):\n%s%s" % (LAZPERF, r.stdout, r.stderr))
    return node, modules


def lazperf_decode(node, modules, path):
    """laz-perf's points of PATH as "X Y Z" lines, or None after saying why."""
    here = os.path.dirname(os.path.abspath(__file__))
    base = os.path.basename(path)
    fields = re.match(r"fields(\d+)_", base)
    field = (["field", fields.group(1)] if fields else ["field"] if base.startswith("field_")
             else ["record"] if base.startswith("record_") else [])
    r = subprocess.run([node, os.path.join(here, "laz_lazperf.js"), modules, path] + field, capture_output=True, text=True)
    if r.returncode != 0:
        print("%s: laz-perf failed: %s" % (path, r.stderr.strip()[-500:]))
        return None
    out = r.stdout.split("\n")[:-1]
    if not out or out[0] != "count %d" % (len(out) - 1):
        print("%s: laz-perf says %s and gave %d points" % (path, out[0] if out else "nothing", len(out) - 1))
        return None
    return out[1:]


def npm(lazgen, fixtures, work, update):
    node, modules = install_lazperf(work)
    bad = 0
    # The fixtures: laz-perf's decoding is the one recorded.
    if not update:
        for name, rec in sorted(read_digests(fixtures).items()):
            got = lazperf_decode(node, modules, os.path.join(fixtures, name + ".laz"))
            if got is None or digest(got) != rec:
                print("fixture %s: laz-perf's decoding is not the one recorded in %s" % (name, DIGESTS))
                bad += 1
    # The writer as it is now: laz-perf decodes the points it was given.
    files, names = generate(lazgen, work)
    digests = {}
    for name in names:
        got, want = lazperf_decode(node, modules, os.path.join(files, name + ".laz")), written_points(files, name)
        if got is None:
            bad += 1
            continue
        diff = [k for k in range(min(len(got), len(want))) if got[k] != want[k]]
        if len(got) != len(want) or diff:
            k = diff[0] if diff else min(len(got), len(want))
            print("%s: laz-perf decoded %d points, %d written; first difference at point %d" % (name, len(got), len(want), k))
            bad += 1
            continue
        digests[name] = digest(got)
        print("%s: %d points identical" % (name, len(want)))
    if bad:
        fail("%d files decoded by laz-perf differ from what was written or recorded" % bad)
    if update:
        for f in os.listdir(fixtures):
            if f.endswith(".laz"):
                os.remove(os.path.join(fixtures, f))
        for name in names:
            shutil.copyfile(os.path.join(files, name + ".laz"), os.path.join(fixtures, name + ".laz"))
        with open(os.path.join(fixtures, DIGESTS), "w") as f:
            f.write("# %s's decoding of each file here, written by `tests/laz_lazperf.py npm ... --update`\n"
                    "# once it decoded every one exactly as the writer was given it (tests/laz_lazperf.py).\n"
                    "# NAME  POINTS  SHA-256 of its \"X Y Z\" lines (integer coordinates, file order; field_*: \"X Y Z HEX\", fieldsN_*: N HEX; record_*: the whole record in hexadecimal)\n" % LAZPERF)
            for name in sorted(digests):
                f.write("%s %d %s\n" % (name, digests[name][0], digests[name][1]))
        print("laz_lazperf: %d fixtures written into %s" % (len(names), fixtures))
    print("laz_lazperf: %d files decoded by laz-perf exactly as written%s"
          % (len(names), "" if update else ", the fixtures as recorded"))


def main():
    args = sys.argv[1:]
    update = "--update" in args
    args = [a for a in args if a != "--update"]
    if len(args) != 4 or args[0] not in ("offline", "npm") or (update and args[0] != "npm"):
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    mode, lazgen, fixtures, work = args[0], os.path.abspath(args[1]), os.path.abspath(args[2]), os.path.abspath(args[3])
    os.makedirs(work, exist_ok=True)
    if mode == "offline":
        offline(lazgen, fixtures, work)
    else:
        npm(lazgen, fixtures, work, update)


main()
