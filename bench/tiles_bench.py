"""Reading a side as tiles against the same points in one file (issue 14).

Writes N tiles of P random points each (seeded) and one file holding them
concatenated, then runs `hausdorff --json --directed --threads T` on each
(A = the tiles or the file, B = 1000 points) RUNS times, alternating, and
prints the medians of read_seconds and of the peak resident memory (the
child's ru_maxrss from wait4), with the ratios tiles / one file.  The
distances and witnesses must agree, or it stops.  Standard library only
(text as xyz written with repr; npy written by hand).

    python3 bench/tiles_bench.py build/hausdorff [--tiles 10] [--points 1000000]
                                 [--format npy|xyz] [--runs 5] [--threads 2]
"""
import argparse
import json
import os
import random
import statistics
import struct
import subprocess
import sys
import tempfile


def npy_head(n):
    head = "{'descr': '<f8', 'fortran_order': False, 'shape': (%d, 3), }" % n
    head = head.ljust(117) + "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(head)) + head.encode()


def npy_body(pts):
    return struct.pack("<%dd" % (3 * len(pts)), *[c for p in pts for c in p])


def xyz_body(pts):
    return "".join("%r %r %r\n" % p for p in pts).encode()


def generate(d, a):
    """The tiles and the one file, a tile at a time (run in a child process,
    so that the benchmark's own memory never shows in the tool's ru_maxrss:
    a forked child starts from its parent's)."""
    rng = random.Random(a.seed)
    body = npy_body if a.format == "npy" else xyz_body
    os.makedirs(os.path.join(d, "tiles"))
    with open(os.path.join(d, "one." + a.format), "wb") as one:
        if a.format == "npy":
            one.write(npy_head(a.tiles * a.points))
        for k in range(a.tiles):
            data = body([(rng.random(), rng.random(), rng.random()) for _ in range(a.points)])
            with open(os.path.join(d, "tiles", "%05d.%s" % (k, a.format)), "wb") as f:
                f.write(npy_head(a.points) if a.format == "npy" else b"")
                f.write(data)
            one.write(data)
    with open(os.path.join(d, "b.npy"), "wb") as f:
        f.write(npy_head(1000) + npy_body([(rng.random(), rng.random(), rng.random()) for _ in range(1000)]))


def run(tool, args):
    p = subprocess.Popen([tool] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out, err = p.stdout.read(), p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        sys.exit("hausdorff failed: %s" % err.decode())
    r = json.loads(out)
    return r, usage.ru_maxrss / 1024.0  # KiB on Linux -> MiB


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("tool")
    ap.add_argument("--tiles", type=int, default=10)
    ap.add_argument("--points", type=int, default=1000000)
    ap.add_argument("--format", choices=("npy", "xyz"), default="npy")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--generate", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.generate:
        return generate(a.generate, a)
    with tempfile.TemporaryDirectory(prefix="hd-tiles-bench-") as d:
        subprocess.run([sys.executable] + sys.argv + ["--generate", d], check=True)
        one, b = os.path.join(d, "one." + a.format), os.path.join(d, "b.npy")
        res = {"tiles": [], "one": []}
        for _ in range(a.runs):
            for name, side in (("tiles", os.path.join(d, "tiles")), ("one", one)):
                r, rss = run(a.tool, ["--json", "--directed", "--threads", str(a.threads), side, b])
                res[name].append((r["read_seconds"], rss, r["directed_ab"], r["witness_ab"]))
        answers = {(x[2], tuple(x[3])) for v in res.values() for x in v}
        if len(answers) != 1:
            sys.exit("tiles and one file disagree: %s" % answers)
        print("%d tiles x %d points (%s, seed %d), threads %d, medians of %d runs:"
              % (a.tiles, a.points, a.format, a.seed, a.threads, a.runs))
        med = {k: (statistics.median(x[0] for x in v), statistics.median(x[1] for x in v)) for k, v in res.items()}
        print("%-10s %14s %14s" % ("", "read_seconds", "peak RSS MiB"))
        for k in ("tiles", "one"):
            print("%-10s %14.3f %14.1f" % (k, med[k][0], med[k][1]))
        print("%-10s %14.2f %14.2f" % ("ratio", med["tiles"][0] / med["one"][0], med["tiles"][1] / med["one"][1]))


if __name__ == "__main__":
    main()
