#!/usr/bin/env python3
"""cli_surface.py -- `hausdorff --surface A B`: each point of A to the
nearest triangle of the mesh B, h(A, surface of B) with its witness
(point, triangle, closest point), as text and JSON; the same at 1 and 3
threads; the analysis options on the surface distances (--distances with
the face, closest point and weights, --mean, --percentile, --histogram,
--render, --tau); --signed's signs; --sample, a bad mesh and an open mesh
with --signed are refused with their reason (a mesh as A:
tests/cli_m2m.py).

usage: cli_surface.py PATH/TO/hausdorff
"""
import json
import os
import sys
import tempfile

from cli_checks import check, finish, run, start, writer

start(sys.argv[1])


with tempfile.TemporaryDirectory() as tmp:
    put = writer(tmp)

    # a unit square as one quad (two triangles) and a degenerate triangle
    square = put("square.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 0 0\n")
    # above the face (2), below it (1), beside the edge x = 1 (2): a tie at 2
    pts = put("p.xyz", "0.5 0.5 2\n0.25 0.75 -1\n3 0.5 0\n")

    p = run("--surface", "--json", pts, square)
    out = json.loads(p.stdout) if p.returncode == 0 else {}
    check(p.returncode == 0 and out.get("distance") == 2.0, "the largest distance is to the face and the edge", p)
    w = out.get("witness", {})
    check(w.get("i") == 0 and w.get("triangle") == 0 and w.get("closest") == [0.5, 0.5, 0],
          "the witness is the first point at the maximum, with its triangle and closest point", p)
    b = out.get("b", {})
    check(b.get("triangles") == 3 and b.get("faces") == 2 and b.get("degenerate") == 1,
          "the quad is two triangles and the repeated corner is counted as degenerate", p)

    p = run("--surface", pts, square)
    check(p.returncode == 0 and p.stdout.startswith("h(A, surface of B) = 2\n") and "measured as its surface" in p.stdout,
          "the text report names the surface", p)

    # a point exactly on the edge between the quad's two triangles is 0 away
    on_edge = put("edge.xyz", "0.5 0.5 0\n")
    p = run("--surface", "--json", on_edge, square)
    out = json.loads(p.stdout) if p.returncode == 0 else {}
    check(out.get("distance") == 0.0 and out.get("witness", {}).get("triangle") == 0,
          "a point on a shared edge is at 0 from the smaller triangle", p)

    # threads do not change a bit: bundled STL, the pinion's vertices as A
    runs = [run("--surface", "--json", "--threads", t, "data/pinion_gear.ply", "data/orig/Wuson.stl") for t in ("1", "3")]
    outs = [json.loads(r.stdout) if r.returncode == 0 else None for r in runs]
    check(outs[0] is not None and outs[1] is not None and outs[0]["distance"] == outs[1]["distance"]
          and outs[0]["witness"] == outs[1]["witness"], "1 and 3 threads give the same answer", runs[1])

    p = run("--surface", square, pts)
    check(p.returncode == 0 and p.stdout.startswith("H(A, B) in ["),
          "a mesh as A is measured as its surface, enclosed (tests/cli_m2m.py has the rest)", p)
    # the analysis options on the surface distances (2, 1, 2)
    p = run("--surface", "--json", "--mean", "--percentile", "50", "--histogram", "--bins", "2", pts, square)
    out = json.loads(p.stdout) if p.returncode == 0 else {}
    check(out.get("mean", {}).get("ab") == 5 / 3 and out.get("percentile", {}).get("ab") == 2.0
          and out.get("histogram", {}).get("ab") == [0, 3], "--mean, --percentile, --histogram on surface distances", p)
    p = run("--surface", "--tau", "1.5", "--dtu-cap", "1", pts, square)
    check(p.returncode == 0 and "tau" in p.stdout, "--tau and --dtu-cap on surface distances", p)
    csv = os.path.join(tmp, "d.csv")
    p = run("--surface", "--distances", csv, pts, square)
    rows = open(csv).read().splitlines() if p.returncode == 0 else []
    check(rows[:1] == ["x,y,z,distance,face,closest_x,closest_y,closest_z,u,v,w"]
          and rows[1].split(",")[3:8] == ["2", "0", "0.5", "0.5", "0"] and rows[2].split(",")[3] == "1"
          and rows[3].split(",")[3:8] == ["2", "0", "1", "0.5", "0"],
          "--distances writes distance, face, closest point and weights a row", p)
    npy = os.path.join(tmp, "d.npy")
    p = run("--surface", "--distances", npy, pts, square)
    raw = open(npy, "rb").read() if p.returncode == 0 else b""
    check(b"'shape': (3, 11)" in raw[:128] and len(raw) - (raw.index(b"\n") + 1) == 3 * 11 * 8,
          "--distances .npy: 11 float64 columns", p)
    ply = os.path.join(tmp, "d.ply")
    p = run("--surface", "--distances", ply, pts, square)
    head = open(ply, "rb").read().split(b"end_header")[0] if p.returncode == 0 else b""
    check(b"property int face" in head and b"property double w" in head and b"sign" not in head,
          "--distances .ply: the face and the weights as properties", p)

    # --signed: a closed cube; inside, outside, on an edge, a ray along an edge
    cube = put("cube.off", "OFF\n8 12 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
               "3 0 2 3\n3 0 3 1\n3 4 5 7\n3 4 7 6\n3 0 1 5\n3 0 5 4\n3 2 6 7\n3 2 7 3\n3 0 4 6\n3 0 6 2\n"
               "3 1 3 7\n3 1 7 5\n")
    cpts = put("c.xyz", "0.5 0.5 0.5\n2 0.5 0.5\n0.5 0 0\n0.25 0.5 0.5\n-1 0 0\n")
    p = run("--surface", "--signed", "--json", "--distances", csv, cpts, cube)
    out = json.loads(p.stdout) if p.returncode == 0 else {}
    rows = open(csv).read().splitlines() if p.returncode == 0 else []
    check(out.get("signs") == {"inside": 2, "outside": 2, "on": 1} and out.get("witness", {}).get("sign") == 1,
          "--signed counts the signs and gives the witness's", p)
    check(rows[:1] == ["x,y,z,distance,face,closest_x,closest_y,closest_z,u,v,w,sign"]
          and [r.split(",")[-1] for r in rows[1:]] == ["-1", "1", "0", "-1", "1"],
          "--signed adds the sign column: -1 inside, +1 outside, 0 on the surface", p)
    p = run("--surface", "--signed", cpts, cube)
    check(p.returncode == 0 and "2 inside (-1), 2 outside (+1), 1 on the surface (0)" in p.stdout,
          "the text report counts the signs", p)
    p = run("--surface", "--signed", cpts, square)
    check(p.returncode == 2 and "not closed" in p.stderr and "edge between vertices" in p.stderr and p.stdout == "",
          "--signed refuses an open mesh, naming an edge: exit 2", p)
    p = run("--signed", cpts, cube)
    check(p.returncode == 1 and "--signed needs --surface" in p.stderr, "--signed without --surface is refused", p)
    outs = []
    for t in ("1", "3"):
        path = os.path.join(tmp, "t%s.csv" % t)
        run("--surface", "--signed", "--threads", t, "--distances", path, "data/pinion_gear.ply", "data/orig/cow.off")
        outs.append(open(path).read() if os.path.exists(path) else None)
    check(outs[0] is not None and outs[0] == outs[1], "1 and 3 threads write the same signed distances file")
    png = os.path.join(tmp, "r.png")
    p = run("--surface", "--json", "--render", png, cpts, cube)
    if p.returncode == 0:
        out = json.loads(p.stdout)
        check("closest point on triangle" in out.get("render", {}).get("caption", ["", ""])[1]
              and os.path.getsize(png) > 0, "--render draws the surface distances and names the triangle", p)
    else:
        check("unavailable" in p.stderr, "--render without libpng says so", p)
    p = run("--surface", "--sample", "10", pts, square)
    check(p.returncode == 1 and "--sample" in p.stderr, "--sample is refused with --surface", p)
    bad = put("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n")
    p = run("--surface", pts, bad)
    check(p.returncode == 2 and "bad.off" in p.stderr and "vertex 5" in p.stderr,
          "a face out of range: exit 2, the file and the vertex named", p)
    nofaces = put("nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n")
    p = run("--surface", pts, nofaces)
    check(p.returncode == 2 and "no faces" in p.stderr, "a mesh without faces: exit 2", p)

finish()
