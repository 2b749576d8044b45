#!/usr/bin/env python3
"""cli_surface.py -- `hausdorff --surface A B`: each point of A to the
nearest triangle of the mesh B, h(A, surface of B) with its witness
(point, triangle, closest point), as text and JSON; the same at 1 and 3
threads; a mesh as A, --sample, the analysis options and a bad mesh are
refused with their reason.

usage: cli_surface.py PATH/TO/hausdorff
"""
import json
import os
import subprocess
import sys
import tempfile

TOOL = sys.argv[1]
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
failures = 0


def run(*args):
    return subprocess.run([TOOL, *args], capture_output=True, text=True, cwd=ROOT)


def check(cond, what, proc=None):
    global failures
    if not cond:
        failures += 1
        print("FAIL", what)
        if proc is not None:
            print("  exit", proc.returncode, "stdout:", proc.stdout.strip(), "stderr:", proc.stderr.strip())
    else:
        print("ok  ", what)


with tempfile.TemporaryDirectory() as tmp:
    def put(name, text):
        path = os.path.join(tmp, name)
        with open(path, "w") as f:
            f.write(text)
        return path

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
    check(p.returncode == 1 and "mesh to mesh" in p.stderr and p.stdout == "",
          "a mesh as A is refused: the direction from a surface is mesh to mesh", p)
    for opt in (["--mean"], ["--tau", "0.5"], ["--dtu-cap", "1"]):
        p = run("--surface", *opt, pts, square)
        check(p.returncode == 1 and "analysis options" in p.stderr and p.stdout == "",
              "the analysis options are refused with --surface: %s" % opt[0], p)
    p = run("--surface", "--sample", "10", pts, square)
    check(p.returncode == 1 and "--sample" in p.stderr, "--sample is refused with --surface", p)
    bad = put("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n")
    p = run("--surface", pts, bad)
    check(p.returncode == 2 and "bad.off" in p.stderr and "vertex 5" in p.stderr,
          "a face out of range: exit 2, the file and the vertex named", p)
    nofaces = put("nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n")
    p = run("--surface", pts, nofaces)
    check(p.returncode == 2 and "no faces" in p.stderr, "a mesh without faces: exit 2", p)

print("%d failed" % failures)
sys.exit(1 if failures else 0)
