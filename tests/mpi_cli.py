"""hausdorff-mpi on K ranks prints what hausdorff prints, bit for bit:
the same distances, witnesses (global and as file + index), alpha, counts
and files, in the JSON and in the report for a person; and bad input on one
rank is one clear message and the same exit status from every rank, never a
hang.  Standard library only; run as:
    mpi_cli.py HAUSDORFF HAUSDORFF_MPI K MPIRUN [MPIRUN ARGS...]
Random points come from random.Random(SEED); a failure prints the seed.
"""
import json
import math
import os
import re
import random
import struct
import subprocess
import sys
import tempfile
import threading

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(os.path.dirname(HERE), "data")
CORPUS = os.path.join(HERE, "corpus")
SEED = 1414
SAME_KEYS = ["hausdorff", "directed_ab", "directed_ba", "witness_ab", "witness_ba", "witness_ab_files",
             "witness_ba_files", "alpha", "disjoint", "n_a", "n_b", "file_a", "file_b", "tiles_a", "tiles_b",
             "skipped_a", "skipped_b", "requested_algorithm"]


def single(tool, *args):
    p = subprocess.run([tool] + list(args), capture_output=True, timeout=120)
    return p.returncode, p.stdout.decode(), p.stderr.decode()


def ranks(mpirun, k, tool, *args):
    p = subprocess.run(mpirun + ["-n", str(k), tool] + list(args), capture_output=True, timeout=120)
    return p.returncode, p.stdout.decode(), p.stderr.decode()


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    return path


def xyz(points):
    return "".join("%r %r %r\n" % p for p in points)


def make_tiles(tmp, rng):
    """A: a directory of 7 tiles of a jittered lattice (ties across tiles
    and regions, a duplicate point in two tiles, an empty-looking gap) and
    a README.txt (not a tile: skipped and reported);
    B: @list of 5 tiles of the same lattice shifted half a step in x, one
    tile far away (a nearest neighbour regions away)."""
    pts = [(float(x), float(y), float(z)) for x in range(9) for y in range(9) for z in range(6)]
    rng.shuffle(pts)
    a = pts[:300] + [pts[0]]
    for t in range(7):
        write(os.path.join(tmp, "A", "t%d.xyz" % t), xyz(a[t * 43:(t + 1) * 43]))
    write(os.path.join(tmp, "A", "README.txt"), "Tiles of a lattice.\nOne file a part.\n")  # skipped, reported
    b = [(x + 0.5, y, z) for (x, y, z) in pts[100:400]]
    names = []
    for t in range(4):
        names.append(write(os.path.join(tmp, "B", "b%d.xyz" % t), xyz(b[t * 75:(t + 1) * 75])))
    names.append(write(os.path.join(tmp, "B", "far.xyz"), xyz([(40.0, 40.0, 40.0), (40.0, 40.0, 41.0)])))
    write(os.path.join(tmp, "B", "list.txt"), "".join(os.path.basename(n) + "\n" for n in names))
    return os.path.join(tmp, "A"), "@" + os.path.join(tmp, "B", "list.txt")


def write_ply_binary(path, points):
    """Binary little-endian PLY of doubles with an extra uchar per vertex."""
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
            "property uchar i\nproperty double z\nend_header\n" % len(points)).encode()
    with open(path, "wb") as f:
        f.write(head + b"".join(struct.pack("<ddBd", x, y, 7, z) for (x, y, z) in points))
    return path, len(head)


def write_npy(path, points):
    d = "{'descr': '<f8', 'fortran_order': False, 'shape': (%d, 3), }" % len(points)
    d += " " * ((64 - (10 + len(d) + 1) % 64) % 64) + "\n"
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(d)) + d.encode())
        f.write(b"".join(struct.pack("<3d", *p) for p in points))
    return path


def main():
    hausdorff, tool, k, mpirun = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4:]
    failures, skipped = [], []

    def check(cond, what):
        if not cond:
            failures.append(what)
            print("FAIL (K=%d, seed %d): %s" % (k, SEED, what), file=sys.stderr)

    # --version names the library's version and the MPI it runs on, once
    rc, out, err = ranks(mpirun, k, tool, "--version")
    check(rc == 0 and out.startswith("hausdorff-mpi ") and "(MPI " in out and out.count("\n") == 1,
          "--version: exit %d: %r %r" % (rc, out, err))

    # what only hausdorff computes is refused when parsing, never answered as another question: every option
    # that hausdorff-mpi's --help names as refused, the first one given named in the message
    rc, out, err = ranks(mpirun, k, tool, "--help")
    refused = re.search(r"Computed by hausdorff only, and refused here:(.*?)\.\n", out, re.S)
    names = refused.group(1).split() if refused else []
    check(rc == 0 and {"--surface", "--labels", "--tau", "--dtu-cap"} <= set(names),
          "--help names the refused options: %r" % names)
    values = {"--tolerance": "1d", "--within": "0.01", "--tau": "1", "--tau-rule": "lt", "--dtu-cap": "20",
              "--labels": "all", "--components": "26"}
    refusals = [[n] + ([values[n]] if n in values else []) for n in names]
    refusals += [["--surface", "--signed"], ["--percentile", "95", "--tau", "1,2"]]
    for extra in refusals:
        first = next(a for a in extra if a in names)
        rc, out, err = ranks(mpirun, k, tool, *extra, os.path.join(DATA, "cgal_lion_head.ply"),
                             os.path.join(DATA, "cgal_lion.ply"))
        check(rc == 1 and out == "" and "%s is computed by hausdorff only" % first in err,
              "%s: exit %d, expected 1 and the refusal: %r %r" % (extra, rc, out, err))

    def same_json(args, keys=SAME_KEYS):
        """The members `keys` equal (None: every member but the times, the
        engine's counters and "mpi"); None if a run failed, else both."""
        rc1, out1, err1 = single(hausdorff, "--json", *args)
        rc2, out2, err2 = ranks(mpirun, k, tool, "--json", *args)
        check(rc1 == 0 and rc2 == 0, "%s: exit %d / %d: %s %s" % (args, rc1, rc2, err1, err2))
        if rc1 or rc2:
            return None
        j1, j2 = json.loads(out1), json.loads(out2)
        if keys is None:
            keys = [key for key in j1 if key not in ("seconds", "read_seconds", "distances_seconds", "stats_ab",
                                                     "stats_ba")]
            check(sorted(j2) == sorted(list(j1) + ["mpi"]), "%s: members %r, %r" % (args, sorted(j1), sorted(j2)))
        for key in keys:
            check(j1.get(key) == j2.get(key), "%s: %s: %r != %r" % (args, key, j1.get(key), j2.get(key)))
        m = j2.get("mpi", {})
        check(m.get("ranks") == k and len(m.get("peak_rss_bytes_per_rank", [])) == k, "%s: mpi figures %r" % (args, m))
        points = j1["n_a"] + j1["n_b"]
        check_call_figures(args, m, points, returned=False)
        per_point = "distances_seconds" in j1
        check(("distances" in m) == per_point, "%s: a \"distances\" member in mpi only with per-point outputs: %r"
              % (args, sorted(m)))
        if per_point and "distances" in m:
            check_call_figures(args, m["distances"], points, returned=True)
        return j1, j2

    def check_call_figures(args, f, points, returned):
        """One call's exchange figures (the Hausdorff distance's, or the
        per-point distances' with the answers returned to their ranks) agree
        with each other and with the run: K entries a rank, bytes moved that
        add up (28 a moved point, 40 a forwarded query, 16 a returned answer),
        nothing moved on one rank."""
        what = "%s: %s figures %r" % (args, "distances'" if returned else "the distance's", f)
        keys = ("rounds", "bytes_per_point", "bytes_partition", "bytes_forwarding", "bytes_returned",
                "forwarded_fraction", "forwarded_queries", "shell_points", "imbalance", "work_imbalance",
                "seconds_per_rank", "buffer_bytes_per_rank")
        if not all(key in f for key in keys):
            check(False, what + ": members missing")
            return
        moved = f["bytes_partition"] + f["bytes_forwarding"] + f["bytes_returned"]
        check(len(f["seconds_per_rank"]) == k and len(f["buffer_bytes_per_rank"]) == k, what + ": per rank")
        check(f["bytes_per_point"] == moved / points, what + ": bytes_per_point")
        check(f["bytes_forwarding"] == 40 * f["forwarded_queries"], what + ": 40 bytes a forwarded query")
        check(f["forwarded_fraction"] * points <= f["forwarded_queries"] + 1e-9, what + ": forwarded points")
        check(f["bytes_returned"] % 16 == 0 and f["bytes_returned"] <= 16 * points, what + ": returned answers")
        check(f["imbalance"] >= 1 and f["work_imbalance"] >= 1, what + ": imbalance at least 1")
        if k == 1:
            check(moved == 0 and f["rounds"] == 0, what + ": one rank moves nothing")
        else:
            check(f["bytes_partition"] > 0 and (returned or f["bytes_returned"] == 0), what + ": bytes moved")

    def same_text(args):
        rc1, out1, _ = single(hausdorff, *args)
        rc2, out2, err2 = ranks(mpirun, k, tool, *args)
        keep = lambda out: [l for l in out.splitlines() if not l.startswith(("time:", "mpi:"))]
        check(rc1 == 0 and rc2 == 0 and keep(out1) == keep(out2), "%s: text differs:\n%s\n%s%s" %
              (args, out1, out2, err2))
        check(out2.count("mpi: %d ranks" % k) == 1, "%s: no mpi line once: %s" % (args, out2))

    rng = random.Random(SEED)
    with tempfile.TemporaryDirectory() as tmp:
        lion, head = os.path.join(DATA, "cgal_lion.ply"), os.path.join(DATA, "cgal_lion_head.ply")
        same_json([lion, head])
        same_text([lion, head])
        A, B = make_tiles(tmp, rng)
        same_json([A, B])
        same_json(["--directed", B, A])
        same_text([A, B])
        # 1e-9 and 1e9 scales
        small = [tuple(rng.uniform(0, 1e-9) for _ in range(3)) for _ in range(200)]
        big = [tuple(1e9 + rng.uniform(0, 1) for _ in range(3)) for _ in range(200)]
        for name, pts in (("small", small), ("big", big)):
            for t in range(3):
                write(os.path.join(tmp, name, "a%d.xyz" % t), xyz(pts[t * 50:(t + 1) * 50]))
            write(os.path.join(tmp, name + "_b.xyz"), xyz(pts[25:200:3]))
            same_json([os.path.join(tmp, name), os.path.join(tmp, name + "_b.xyz")])

        # One big binary file a side: every rank reads a range of it
        # (hd_read_count, range reads), and the answer is the same.
        pa = [tuple(rng.gauss(0, 1) for _ in range(3)) for _ in range(3001)]
        pb = [tuple(c + rng.gauss(0, 1e-3) for c in p) for p in pa[::2]] + [(0.5, 0.5, 9.0)]
        os.makedirs(os.path.join(tmp, "one"))
        ply, head_len = write_ply_binary(os.path.join(tmp, "one", "a.ply"), pa)
        npy = write_npy(os.path.join(tmp, "one", "b.npy"), pb)
        same_json([ply, npy])
        same_json(["--directed", npy, ply])
        rc, out, err = ranks(mpirun, k, tool, "--json", ply, npy)
        check(rc == 0 and json.loads(out)["mpi"]["read_by_points"] == [True, True],
              "one file a side is read by points: %r %r" % (out[-300:], err))
        laz = os.path.join(HERE, "corpus", "laz", "fmt0_chunks16.laz")
        same_json([laz, os.path.join(HERE, "corpus", "laz", "fmt1_variable.laz")])
        rc, out, err = ranks(mpirun, k, tool, "--json", A, npy)
        check(rc == 0 and json.loads(out)["mpi"]["read_by_points"] == [False, True],
              "text tiles are shared by tiles: %r %r" % (out[-300:], err))
        # A NaN in the last third of the one file, which the last rank's
        # range holds: the message hausdorff gives, byte offset included.
        bad = list(pa)
        bad[2900] = (1.0, math.nan, 2.0)
        badply, _ = write_ply_binary(os.path.join(tmp, "one", "bad.ply"), bad)
        rc, out, err = ranks(mpirun, k, tool, badply, npy)
        rc1, _, err1 = single(hausdorff, badply, npy)
        lines = [l for l in err.splitlines() if l.startswith("hausdorff-mpi:")]
        want = "byte %d: point 2900:" % (head_len + 2900 * 25 + 8)
        check(rc == 2 and rc1 == 2 and len(lines) == 1 and want in lines[0] and want in err1,
              "NaN in a split file: exit %d/%d, %r, %r, want %r" % (rc, rc1, err, err1, want))

        # Bad input in the last tile of A, which the last rank reads: one
        # message naming it, exit 2 from every rank, within the timeout.
        write(os.path.join(tmp, "bad", "a0.xyz"), xyz(small[:50]))
        write(os.path.join(tmp, "bad", "a1.xyz"), xyz(small[50:100]))
        write(os.path.join(tmp, "bad", "a2.xyz"), xyz(small[100:140]) + "1 2 zebra\n")
        rc, out, err = ranks(mpirun, k, tool, os.path.join(tmp, "bad"), os.path.join(tmp, "small_b.xyz"))
        lines = [l for l in err.splitlines() if l.startswith("hausdorff-mpi:")]
        check(rc == 2, "bad tile: exit %d, expected 2: %s" % (rc, err))
        check(len(lines) == 1 and "a2.xyz:41" in lines[0], "bad tile: one message naming a2.xyz:41: %r" % err)
        check(out == "", "bad tile: nothing on stdout: %r" % out)
        rc1, _, err1 = single(hausdorff, os.path.join(tmp, "bad"), os.path.join(tmp, "small_b.xyz"))
        check(rc1 == 2 and err1.strip().split(": ", 1)[1] in lines[0] if lines else False,
              "bad tile: hausdorff's message %r within %r" % (err1, lines))
        # A missing file: every rank fails alike.
        rc, out, err = ranks(mpirun, k, tool, os.path.join(tmp, "nope.xyz"), lion)
        check(rc == 2 and err.count("nope.xyz") == 1, "missing file: exit %d, %r" % (rc, err))
        # A stream cannot be a tile, nor a side: the ranks read each input
        # themselves, some twice (a count, then ranges); a FIFO listed as a
        # tile was used up by the count and read empty (with --empty zero,
        # a wrong distance).  Refused at once, with hausdorff's message for
        # a list.
        fifo = os.path.join(tmp, "stream", "f.xyz")
        os.makedirs(os.path.dirname(fifo))
        os.mkfifo(fifo)
        lst = write(os.path.join(tmp, "stream", "l.txt"), "f.xyz\n" + os.path.join(tmp, "small_b.xyz") + "\n")
        rc, out, err = ranks(mpirun, k, tool, "--empty", "zero", "@" + lst, lion)
        rc1, _, err1 = single(hausdorff, "--empty", "zero", "@" + lst, lion)
        lines = [l for l in err.splitlines() if l.startswith("hausdorff-mpi:")]
        want = "l.txt:1: %s is a FIFO or pipe, not a regular file" % fifo
        check(rc == 2 and rc1 == 2 and len(lines) == 1 and want in lines[0] and out == "" and
              err1.split(": ", 1)[1] == lines[0].split(": ", 1)[1] + "\n",
              "a FIFO in a list: exit %d / %d, %r, %r" % (rc, rc1, err, err1))
        for side, stdin in ((fifo, None), ("-", b"1 2 3\n")):
            p = subprocess.run(mpirun + ["-n", str(k), tool, side, lion], input=stdin, capture_output=True,
                               timeout=120)
            err = p.stderr.decode()
            lines = [l for l in err.splitlines() if l.startswith("hausdorff-mpi:")]
            check(p.returncode == 2 and len(lines) == 1 and "cannot be read by hausdorff-mpi" in lines[0] and
                  "save it to a file" in lines[0], "%s as a side: exit %d, %r" % (side, p.returncode, err))
        # --empty: an empty side gets the policy's answer, as hausdorff gives it.
        empty = write(os.path.join(tmp, "empty.xyz"), "# no points\n")
        for args in (["--empty", "inf", empty, lion], ["--empty", "zero", "--directed", lion, empty],
                     ["--empty", "monai", empty, empty]):
            for fmt in (["--json"], []):
                rc1, out1, err1 = single(hausdorff, *fmt, *args)
                rc2, out2, err2 = ranks(mpirun, k, tool, *fmt, *args)
                check(rc1 == 0 and rc2 == 0 and out1 == out2, "%s: %d %d\n%s\n%s%s" % (fmt + args, rc1, rc2, out1, out2, err2))
        rc, out, err = ranks(mpirun, k, tool, empty, lion)
        check(rc == 2 and err.count("hausdorff-mpi:") == 1 and "--empty" in err, "empty without --empty: %d %r" % (rc, err))

        # The figures (--percentile, --mean, --chamfer, --histogram): the
        # JSON and the text hausdorff prints, every member and line but the
        # times, the engine's counters (the ranks run other searches) and
        # the mpi figures.
        def same_all(args):
            same_json(args, None)
            same_text(args)

        figures = ["--percentile", "95", "--mean", "--chamfer", "--histogram"]
        same_all(figures + [A, B])
        same_all(figures + [lion, head])
        same_all(figures + ["--directed", B, A])
        same_all(figures + [ply, npy])
        for p in ("0", "50", "100", "99.9"):
            same_all(["--percentile", p, A, B])
        same_all(["--histogram", "--bins", "7", "--max-distance", "0.25", "--units", "mm", lion, head])
        # the histogram picture, byte for byte, with its markers
        d = tempfile.mkdtemp(dir=tmp)
        s_png, m_png = os.path.join(d, "s.png"), os.path.join(d, "m.png")
        rc1, out1, err1 = single(hausdorff, "--json", "--percentile", "90", "--mean", "--histogram-png", s_png, A, B)
        rc2, out2, err2 = ranks(mpirun, k, tool, "--json", "--percentile", "90", "--mean", "--histogram-png", m_png,
                                A, B)
        check(rc1 == 0 and rc2 == 0 and os.path.exists(m_png) and
              open(s_png, "rb").read() == open(m_png, "rb").read(),
              "--histogram-png: exit %d / %d, the pictures differ: %s %s" % (rc1, rc2, err1, err2))
        if rc1 == 0 and rc2 == 0:
            j1, j2 = json.loads(out1), json.loads(out2)
            check(j1["histogram_markers"] == j2["histogram_markers"] and j2["histogram_png"] == m_png,
                  "--histogram-png: markers %r != %r" % (j1["histogram_markers"], j2["histogram_markers"]))
        # --render: hausdorff's picture byte for byte (the ranks' layers
        # merged on rank 0), and the same JSON member (markers, captions)
        def same_picture(args):
            d = tempfile.mkdtemp(dir=tmp)
            s_png, m_png = os.path.join(d, "s.png"), os.path.join(d, "m.png")
            rc1, out1, err1 = single(hausdorff, "--json", "--render", s_png, *args)
            rc2, out2, err2 = ranks(mpirun, k, tool, "--json", "--render", m_png, *args)
            same = rc1 == 0 and rc2 == 0 and os.path.exists(m_png) and open(s_png, "rb").read() == open(m_png, "rb").read()
            check(same, "--render %s: exit %d / %d, the pictures differ: %s %s" % (args, rc1, rc2, err1, err2))
            if rc1 == 0 and rc2 == 0:
                r1, r2 = json.loads(out1)["render"], json.loads(out2)["render"]
                r2["file"] = r1["file"]
                check(r1 == r2, "--render %s: %r != %r" % (args, r1, r2))

        same_picture([A, B])
        same_picture(["--percentile", "95", "--max-distance", "0.01", "--units", "mm", lion, head])
        same_picture(["--directed", head, lion])
        same_picture([ply, npy])
        # --empty with a per-point figure: the policy's values
        for args in (["--empty", "inf", "--mean", "--percentile", "95", empty, lion],
                     ["--empty", "nan", "--chamfer", "--directed", lion, empty]):
            for fmt in (["--json"], []):
                rc1, out1, err1 = single(hausdorff, *fmt, *args)
                rc2, out2, err2 = ranks(mpirun, k, tool, *fmt, *args)
                check(rc1 == 0 and rc2 == 0 and out1 == out2, "%s: %d %d\n%s\n%s%s" % (fmt + args, rc1, rc2, out1,
                                                                                    out2, err2))

        # --distances: the files hausdorff writes, byte for byte, in each
        # format: the tiles with ties (B's shares rotated, so the ranks'
        # rows are not in rank order), a bundled model, --directed (no
        # _b file), one binary file a side read by points.
        def same_files(args, ext, directed):
            d = tempfile.mkdtemp(dir=tmp)
            s_out, m_out = os.path.join(d, "s." + ext), os.path.join(d, "m." + ext)
            rc1, out1, err1 = single(hausdorff, "--distances", s_out, *args)
            rc2, out2, err2 = ranks(mpirun, k, tool, "--distances", m_out, *args)
            what = "--distances %s %s" % (ext, args)
            check(rc1 == 0 and rc2 == 0, "%s: exit %d / %d: %s %s" % (what, rc1, rc2, err1, err2))
            for suffix in ([""] if directed else ["", "_b"]):
                f1, f2 = os.path.join(d, "s%s.%s" % (suffix, ext)), os.path.join(d, "m%s.%s" % (suffix, ext))
                same = os.path.exists(f1) and os.path.exists(f2) and open(f1, "rb").read() == open(f2, "rb").read()
                check(same, "%s: %s differs from hausdorff's" % (what, f2))
            check(not directed or not os.path.exists(os.path.join(d, "m_b." + ext)), "%s: a _b file" % what)
            check(sorted(os.listdir(d)) == sorted(["s." + ext, "m." + ext] +
                                                   ([] if directed else ["s_b." + ext, "m_b." + ext])),
                  "%s: files left: %r" % (what, os.listdir(d)))
            keep = lambda out: [l.replace("m.", "s.").replace("m_b.", "s_b.") for l in out.splitlines()
                                if not l.startswith(("time:", "mpi:"))]
            check(keep(out1) == keep(out2), "%s: report differs:\n%s\n%s" % (what, out1, out2))

        for ext in ("csv", "ply", "npy"):
            same_files([A, B], ext, False)
            same_files([lion, head], ext, False)
            same_files(["--directed", B, A], ext, True)
        same_files([ply, npy], "ply", False)
        # --empty: the rows at the policy's value, nearest -1; an empty side's file has no rows
        same_files(["--empty", "inf", empty, lion], "csv", False)
        same_files(["--empty", "zero", "--directed", lion, empty], "ply", True)
        same_files(["--empty", "monai", empty, empty], "npy", False)
        same_files(["--max-distance", "0.25", A, B], "ply", False)

        # Files written back into the sides' own formats (rank 0 writes them
        # from the gathered distances): PLY sides above, LAS, LAZ, text, and
        # the subsets of --farther-than / --nearer-than, byte for byte.
        las, las_b = os.path.join(DATA, "orig", "Haystack_Rock.las"), os.path.join(CORPUS, "las", "v14_fmt6.las")
        laz = os.path.join(CORPUS, "laz", "fmt6_channels.laz")
        same_files([las, las_b], "las", False)
        same_files(["--directed", laz, las_b], "laz", True)
        same_files([os.path.join(tmp, "A", "t0.xyz"), os.path.join(tmp, "B", "b0.xyz")], "xyz", False)

        def same_subsets(args, ext, d_cut):
            d = tempfile.mkdtemp(dir=tmp)
            outs = lambda p: ["--farther-than", d_cut, os.path.join(d, p + "f." + ext), "--nearer-than", d_cut,
                              os.path.join(d, p + "n." + ext)]
            rc1, out1, err1 = single(hausdorff, *outs("s"), *args)
            rc2, out2, err2 = ranks(mpirun, k, tool, *outs("m"), *args)
            what = "--farther-than / --nearer-than %s %s" % (d_cut, args)
            check(rc1 == 0 and rc2 == 0, "%s: exit %d / %d: %s %s" % (what, rc1, rc2, err1, err2))
            for name in ("f", "n", "f_b", "n_b"):
                f1, f2 = os.path.join(d, "s%s.%s" % (name, ext)), os.path.join(d, "m%s.%s" % (name, ext))
                check(os.path.exists(f1) and os.path.exists(f2) and open(f1, "rb").read() == open(f2, "rb").read(),
                      "%s: %s differs from hausdorff's" % (what, f2))

        same_subsets([lion, head], "ply", "0.01")
        same_subsets([las, las_b], "las", "1")

        # A FIFO (not a regular file: no offsets to write at) gets the bytes
        # hausdorff writes, through rank 0, in order.
        def same_through_fifo(args, ext):
            d = tempfile.mkdtemp(dir=tmp)
            s_out, fifo = os.path.join(d, "s." + ext), os.path.join(d, "fifo." + ext)
            os.mkfifo(fifo)
            got = []
            reader = threading.Thread(target=lambda: got.append(open(fifo, "rb").read()))
            reader.start()
            rc1, _, err1 = single(hausdorff, "--directed", "--distances", s_out, *args)
            rc2, _, err2 = ranks(mpirun, k, tool, "--directed", "--distances", fifo, *args)
            if reader.is_alive():  # the run failed before opening the FIFO: release the reader
                open(fifo, "wb").close()
            reader.join()
            what = "--distances into a FIFO (%s) %s" % (ext, args)
            check(rc1 == 0 and rc2 == 0, "%s: exit %d / %d: %s %s" % (what, rc1, rc2, err1, err2))
            check(rc1 == 0 and got and got[0] == open(s_out, "rb").read(),
                  "%s: %d bytes read, hausdorff wrote %d" % (what, len(got[0]) if got else -1,
                                                             os.path.getsize(s_out) if rc1 == 0 else -1))

        same_through_fifo([A, B], "csv")
        same_through_fifo([lion, head], "npy")
        same_through_fifo(["--empty", "zero", lion, empty], "ply")  # A's PLY written back
        same_through_fifo(["--empty", "zero", npy, empty], "ply")  # the table
        # A file that cannot be written (B's rows' name is a directory),
        # after A's was: one message, exit 3 from every rank, no file.
        d = tempfile.mkdtemp(dir=tmp)
        os.makedirs(os.path.join(d, "x_b.csv"))
        rc, out, err = ranks(mpirun, k, tool, "--distances", os.path.join(d, "x.csv"), lion, head)
        lines = [l for l in err.splitlines() if l.startswith("hausdorff-mpi:")]
        check(rc == 3 and len(lines) == 1 and "x_b.csv: cannot write" in lines[0] and out == "",
              "unwritable --distances: exit %d, %r" % (rc, err))
        check(os.listdir(d) == ["x_b.csv"], "unwritable --distances left %r" % os.listdir(d))
        rc, out, err = ranks(mpirun, k, tool, "--distances", os.path.join(tmp, "nodir", "x.npy"), lion, head)
        check(rc == 3 and err.count("hausdorff-mpi:") == 1 and "cannot write" in err,
              "--distances in no directory: exit %d, %r" % (rc, err))
        # A file system that fills up (a 64 KiB tmpfs: A's CSV rows fit,
        # B's are cut mid-row; 1000 NPY rows twice do not fit) and a file beyond the size limit (ulimit -f, on the
        # ranks only; SIGXFSZ not ignored, so hausdorff-mpi must ignore it):
        # exit 3 from every rank, one message with the reason, and no file
        # left, no temporary either, as hausdorff.  MPI-IO had reported
        # success for the writes that failed, and the run exited 0 with the
        # files cut short.
        full_a = write(os.path.join(tmp, "full", "a.xyz"), xyz([tuple(rng.random() for _ in range(3))
                                                                 for _ in range(600)]))
        full_b = write(os.path.join(tmp, "full", "b.xyz"), xyz([tuple(rng.random() + 3 for _ in range(3))
                                                                 for _ in range(300)]))
        full_c = write(os.path.join(tmp, "full", "c.xyz"), xyz([tuple(rng.random() for _ in range(3))
                                                                 for _ in range(1000)]))

        def refused(args, out_dir, reason, launcher=None):
            p = subprocess.run((launcher or mpirun + ["-n", str(k), tool]) + args, capture_output=True, timeout=120)
            err = p.stderr.decode()
            lines = [l for l in err.splitlines() if l.startswith("hausdorff-mpi:")]
            check(p.returncode == 3 and len(lines) == 1 and ": cannot write: " + reason in lines[0],
                  "%s: exit %d, expected 3 and one message %r: %r" % (args, p.returncode, reason, err))
            check(os.listdir(out_dir) == [], "%s: files left: %r" % (args, os.listdir(out_dir)))

        fullfs = os.path.join(tmp, "fullfs")
        os.makedirs(fullfs)
        m = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", fullfs], capture_output=True)
        if m.returncode != 0:
            skipped.append("the full file system case: cannot mount a 64 KiB tmpfs (%s); it runs as root"
                           % m.stderr.decode().strip())
            print("mpi_cli: SKIPPED " + skipped[-1], file=sys.stderr)
        else:
            try:
                refused(["--distances", os.path.join(fullfs, "d.csv"), full_a, full_b], fullfs,
                        "No space left on device")
                refused(["--distances", os.path.join(fullfs, "d.npy"), full_c, full_c], fullfs,
                        "No space left on device")
            finally:
                subprocess.run(["umount", fullfs])
        limited = os.path.join(tmp, "limited")
        os.makedirs(limited)
        # Open MPI's shared-memory transport makes files of megabytes: TCP on
        # the loopback instead, so that only the --distances file meets the limit
        ulimit = mpirun + ["--mca", "btl", "self,tcp", "--mca", "btl_tcp_if_include", "lo", "-n", str(k),
                           "sh", "-c", 'ulimit -f 20 && exec "$0" "$@"', tool]
        for args in (["--distances", os.path.join(limited, "d.csv")],
                     ["--directed", "--distances", os.path.join(limited, "d.ply")]):
            refused(args + [full_a, full_b], limited, "File too large", ulimit)
    print("mpi_cli on %d ranks: %s%s" % (k, "%d failed" % len(failures) if failures else "passed",
                                         "".join("; SKIPPED " + s for s in skipped)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
