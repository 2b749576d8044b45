#!/usr/bin/env python3
"""cli_m2m.py -- `hausdorff --surface A B` with a mesh as A: every point of
A's surface against B (a mesh or a point set), the distance enclosed in
[lower, upper] with its witness, as text and JSON; --tolerance (absolute or
relative with the d suffix), --within, --directed, the same answer at 1 and
3 threads, bad meshes (exit 2), an empty B under --empty, and the options
refused where they do not apply.

usage: cli_m2m.py PATH/TO/hausdorff
"""
import json
import math
import sys
import tempfile

from cli_checks import check, finish, run, start, writer

start(sys.argv[1])


def js(p):
    return json.loads(p.stdout) if p.returncode == 0 else {}


with tempfile.TemporaryDirectory() as tmp:
    put = writer(tmp)

    # two triangulations of one bent quad: every vertex shared, the surfaces
    # apart along the diagonals (a vertex-only distance would say 0)
    quad = "v 0 0 0\nv 4 0 0\nv 4 4 4\nv 0 4 0\n"
    qa = put("qa.obj", quad + "f 1 2 3\nf 1 3 4\n")
    qb = put("qb.obj", quad + "f 1 2 4\nf 2 3 4\n")
    diag = math.sqrt(48)

    p = run("--surface", "--json", qa, qb)
    out = js(p)
    lo, hi, tol = out.get("lower", 0), out.get("upper", -1), out.get("tolerance", 0)
    check(p.returncode == 0 and lo <= hi and hi - lo <= tol and lo > 1.15,
          "two triangulations of a bent quad: an enclosure above the diagonal's midpoint", p)
    check(tol == 1e-9 * diag or abs(tol - 1e-9 * diag) <= 1e-24, "the default tolerance is 1e-9 of the diagonal", p)
    w = out.get("witness", {})
    a, b = w.get("a", {}), w.get("b", {})
    check(a.get("face") in (0, 1) and len(a.get("bary", [])) == 3 and abs(sum(a.get("bary", [])) - 1) < 1e-15
          and len(a.get("point", [])) == 3 and b.get("face") in (0, 1) and len(b.get("point", [])) == 3,
          "the JSON witness: A's face, weights and point, B's face and point", p)
    check(out.get("ab", {}).get("lower") == lo and out.get("ba", {}).get("upper", 1e9) <= hi,
          "both directions are reported and H is the larger", p)

    p = run("--surface", qa, qb)
    check(p.returncode == 0 and p.stdout.startswith("H(A, B) in [") and "witness on A: triangle" in p.stdout
          and "enclosure" in p.stdout, "the text report gives the enclosure and the witness", p)

    p = run("--surface", "--json", "--tolerance", "1e-3", qa, qb)
    out = js(p)
    check(out.get("tolerance") == 1e-3 and out["upper"] - out["lower"] <= 1e-3, "--tolerance 1e-3 is absolute", p)
    p = run("--surface", "--json", "--tolerance", "1e-6d", qa, qb)
    check(abs(js(p).get("tolerance", 0) - 1e-6 * diag) <= 1e-20, "--tolerance 1e-6d is a fraction of the diagonal", p)
    p = run("--surface", "--json", "--tolerance", "0", qa, qb)
    out = js(p)
    check(p.returncode == 0 and 0 < out.get("tolerance", 0) < 1e-12, "--tolerance 0: as tight as doubles allow", p)

    for d, want in (("1.2", "no"), ("1.6", "yes")):
        p = run("--surface", "--within", d, qa, qb)
        check(p.returncode == 0 and p.stdout.startswith("H(A, B) <= %s: %s\n" % (d, want)),
              "--within %s answers %s" % (d, want), p)
    p = run("--surface", "--json", "--within", "1.6", qa, qb)
    check(js(p).get("within") == {"d": 1.6, "answer": True}, "--within in JSON", p)

    p = run("--surface", "--json", "--directed", qa, qb)
    check(js(p).get("ba", 0) is None and js(p).get("lower", 0) > 1.15, "--directed: h(A, B) alone", p)

    p = run("--surface", "--json", qa, qa)
    check(js(p).get("lower") == 0 and js(p).get("upper") == 0, "a mesh against itself: [0, 0]", p)

    runs = [run("--surface", "--json", "--threads", t, "data/orig/cow.off", "data/orig/pinion.off") for t in ("1", "3")]
    outs = [js(r) for r in runs]
    for o in outs:
        for k in ("ab", "ba"):
            o.get(k, {}).pop("seconds", None)
        o.pop("read_seconds", None)
    check(outs[0] and outs[0] == outs[1], "1 and 3 threads give the same enclosure and witness", runs[1])

    # a mesh against a point set: h(surface, points) enclosed, h(points, surface) exact
    tri = put("tri.off", "OFF\n3 1 0\n0 0 0\n4 0 0\n0 4 0\n3 0 1 2\n")
    corners = put("corners.xyz", "0 0 0\n4 0 0\n0 4 0\n")
    p = run("--surface", "--json", "--tolerance", "1e-12d", tri, corners)
    out = js(p)
    check(p.returncode == 0 and out["lower"] <= math.sqrt(8) <= out["upper"]
          and out["ab"]["witness"]["b"]["face"] is None and out["ab"]["witness"]["b"]["index"] in (0, 1, 2)
          and out["ba"]["lower"] == out["ba"]["upper"] == 0,
          "a triangle against its corners: the circumradius, the points' side exact", p)

    empty = put("empty.xyz", "")
    p = run("--surface", tri, empty)
    check(p.returncode == 2 and p.stdout == "", "an empty B is an error by default (exit 2)", p)
    p = run("--surface", "--json", "--empty", "inf", tri, empty)
    check(p.returncode == 0 and js(p).get("upper") is None or js(p).get("upper") == float("inf")
          or "inf" in p.stdout, "an empty B follows --empty", p)

    bad = put("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n")
    p = run("--surface", bad, qb)
    check(p.returncode == 2 and "bad.off" in p.stderr, "a bad mesh as A: exit 2, the file named", p)
    nan = put("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
    p = run("--surface", qa, nan)
    check(p.returncode == 2 and p.stdout == "", "a NaN vertex in B: exit 2", p)

    for args in (["--tolerance", "1e-3", qa, qb], ["--within", "1", qa, qb]):
        p = run(*args)
        check(p.returncode == 1 and "--surface" in p.stderr, "%s without --surface is refused" % args[0], p)
    for v in ("abc", "-1", "1e-3x", "inf"):
        p = run("--surface", "--tolerance", v, qa, qb)
        check(p.returncode == 1 and "--tolerance" in p.stderr, "--tolerance %s is refused" % v, p)
    pts = put("p.xyz", "0.5 0.5 2\n")
    p = run("--surface", "--within", "1", pts, qb)
    check(p.returncode == 1 and "mesh as A" in p.stderr, "--within with points as A is refused", p)

finish()
