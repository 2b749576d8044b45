#!/usr/bin/python3
"""field_report.py -- issue 39's table: per-point work on cases a-e (1M + 1M,
1 thread), every column measured in one run.

usage: field_report.py --build build [--size N] [--runs R] [--doc docs/benchmarks.md]
                       [--command "make bench"]

Columns, each the median of R runs:
  H           hd_hausdorff (auto engine)                       field_bench
  field       hd_distances, both directions, with indices      field_bench
  build       its two structures                               field_bench
  percentile  hd_hausdorff_percentile, P = 95                  percentile_bench
  nanoflann   tree + 1-NN of every point, both directions      BUILD/bench/nanoflann_hd (make bench builds it)
  C2C         CloudCompare's cloud-to-cloud distance (float32), both directions, at one thread
              (-MAX_TCOUNT 1), when `CloudCompare` is installed (Debian package cloudcompare): the
              times it reports for its two steps, reading excluded
and the ratios nanoflann / field, nanoflann / percentile and C2C / field.  A
column whose program is missing prints "-".  With --doc the table replaces
what lies between <!-- field-results:begin --> and <!-- field-results:end -->
in the document (appended when the markers are missing).
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

BEGIN = "<!-- field-results:begin -->"
END = "<!-- field-results:end -->"
CASES = ["a_overlapping", "b_disjoint", "c_partial", "d_small_B", "e_shuffled"]


def seconds(cell):
    m = re.match(r"\s*([0-9.]+) s\s*$", cell)
    return float(m.group(1)) if m else None


def table_rows(text):
    """The rows of a markdown table printed by a bench program, by case."""
    rows = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells and cells[0] in CASES:
            rows[cells[0]] = cells
    return rows


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit("field_report: %s failed: %s" % (" ".join(cmd), r.stderr.strip()))
    return r.stdout


def nanoflann(prog, d, case, runs):
    if not prog:
        return None
    out = run([prog, os.path.join(d, case + "_A.bin"), os.path.join(d, case + "_B.bin"), "1", str(runs), "600"])
    return statistics.median(json.loads(out.strip().splitlines()[-1])["times"])


def write_ply(path, binpath):
    """A float32 binary PLY of a raw float64 file (CloudCompare's own type)."""
    import numpy as np

    p = np.fromfile(binpath, dtype="<f8").astype("<f4")
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
                 "property float y\nproperty float z\nend_header\n" % (p.size // 3)).encode())
        f.write(p.tobytes())


def cloudcompare_once(cc, compared, reference):
    """One C2C run at one thread: the sum of the times CloudCompare reports
    for its two steps (approximate distances, then the exact ones), which
    exclude reading; None when it fails."""
    cmd = [cc, "-SILENT", "-NO_TIMESTAMP", "-AUTO_SAVE", "OFF", "-O", compared, "-O", reference, "-C2C_DIST",
           "-MAX_TCOUNT", "1"]
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    steps = re.findall(r"\[(?:computeApproxDistances|ComputeDistances)\] Time: ([0-9.]+) s", r.stdout)
    return sum(float(t) for t in steps) if r.returncode == 0 and len(steps) == 2 else None


def cloudcompare(cc, d, case, runs):
    if not cc:
        return None
    a, b = os.path.join(d, case + "_A.ply"), os.path.join(d, case + "_B.ply")
    write_ply(a, os.path.join(d, case + "_A.bin"))
    write_ply(b, os.path.join(d, case + "_B.bin"))
    total = 0.0
    for compared, reference in ((a, b), (b, a)):
        times = [cloudcompare_once(cc, compared, reference) for _ in range(runs)]
        if None in times:
            return None
        total += statistics.median(times)
    return total


def fmt(s):
    return "-" if s is None else ("%.4f s" % s if s < 1 else "%.2f s" % s)


def ratio(x, y):
    return "-" if x is None or y is None or y <= 0 else "%.1fx" % (x / y)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--size", type=int, default=1000000)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--doc")
    ap.add_argument("--command", default="python3 bench/field_report.py --build build")
    args = ap.parse_args()
    bench = os.path.join(args.build, "bench")
    nf = os.path.join(bench, "nanoflann_hd")
    nf = nf if os.access(nf, os.X_OK) else None
    cc = shutil.which("CloudCompare")
    with tempfile.TemporaryDirectory(prefix="field_report") as d:
        pct = table_rows(run([os.path.join(bench, "percentile_bench"), str(args.size), str(args.runs), "1", "95",
                              "--write", d]))
        fld = table_rows(run([os.path.join(bench, "field_bench"), str(args.size), str(args.runs), "1"]))
        lines = ["| case | H | field | its build | percentile (P95) | nanoflann | CloudCompare C2C | "
                 "nanoflann / field | nanoflann / percentile | C2C / field |",
                 "|---|---|---|---|---|---|---|---|---|---|"]
        for case in CASES:
            f, p = fld.get(case), pct.get(case)
            h, fl, bl = (seconds(f[3]), seconds(f[4]), seconds(f[5])) if f else (None, None, None)
            pc = seconds(p[5]) if p else None
            n = nanoflann(nf, d, case, args.runs)
            c = cloudcompare(cc, d, case, args.runs)
            lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                case.replace("_", " "), fmt(h), fmt(fl), fmt(bl), fmt(pc), fmt(n), fmt(c), ratio(n, fl), ratio(n, pc),
                ratio(c, fl)))
            print(lines[-1] if len(lines) > 3 else "\n".join(lines), flush=True)
    load = os.getloadavg()[0]
    head = run(["git", "rev-parse", "--short", "HEAD"]).strip() if shutil.which("git") else "?"
    block = "\n".join([BEGIN, "", "Generated by `%s` at %s, commit %s, %d + %d points, %d runs, 1 thread, "
                       "load average %.1f when it ended (B of case d a hundredth of A):" % (args.command, time.strftime("%Y-%m-%d %H:%M UTC",
                                                                                          time.gmtime()),
                                                             head, args.size, args.size, args.runs, load),
                       ""] + lines + ["", END])
    if args.doc:
        with open(args.doc) as f:
            doc = f.read()
        if BEGIN in doc and END in doc:
            doc = doc[:doc.index(BEGIN)] + block + doc[doc.index(END) + len(END):]
        else:
            doc = doc.rstrip("\n") + "\n\n" + block + "\n"
        with open(args.doc, "w") as f:
            f.write(doc)


if __name__ == "__main__":
    main()
