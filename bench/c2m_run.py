#!/usr/bin/python3
"""c2m_run.py -- the cloud-to-mesh benchmark in one run (docs/benchmarks.md,
"Cloud to mesh"): hd_mesh_distances (build/bench/c2m_bench) against Open3D's
RaycastingScene.compute_distance (bench/peers/c2m_open3d.py) and CGAL's AABB
tree (build/bench/c2m_cgal) on the same points and triangles.

usage: c2m_run.py [--build DIR] [--quick] [--sizes N,N] [--meshes NAME,..]
                  [--clouds near,far] [--threads 1,2] [--peer-budget S]
                  [--out FILE.jsonl] [--doc docs/benchmarks.md] [--command TEXT]
       c2m_run.py --report FILE.jsonl --doc docs/benchmarks.md [--command TEXT]

Meshes (bundled models, split four ways per level with each new midpoint
moved by up to 1 % of its edge, c2m_bench --perturb): "1e3" pinion (1,300
triangles), "1e5" cow split twice (92,864), "1e6" armadillo split twice
(832,000).  Clouds: "near", points on the surface plus noise of 1e-3 of the
box's diagonal; "far", uniform in the box grown three times.  Sizes: 10^5,
10^6, 10^7 points (--quick: 10^5 and 10^6 points, the 1e3 and 1e5 meshes).
Every case runs hd_mesh_distances at each thread count, a brute force over
every triangle for a sample of its points (bit-identical distances and
triangles), Open3D at each thread count and CGAL at 1 thread (it has no
threads of its own).  A peer whose time, projected from the same case at the
previous size, would exceed --peer-budget seconds is not run ("-" in the
table), nor at the larger sizes after it.  The exact fallback's share of the time is its calls times the exact
path's cost a call (build/bench/tri_bench, measured at the start) over the
processor time.  Results: one JSON line a run in --out; with --doc, the
table between the markers "<!-- c2m-table begin -->" and "<!-- c2m-table
end -->" is replaced.
"""
import argparse
import datetime
import json
import os
import re
import subprocess
import sys

MESHES = {
    "1e3": ("data/orig/pinion.off", 0),
    "1e5": ("data/orig/cow.off", 2),
    "1e6": ("data/orig/armadillo.off", 2),
}
NUM = r"([0-9.eE+-]+)"


def run(cmd, env=None):
    e = dict(os.environ)
    e.update(env or {})
    r = subprocess.run(cmd, capture_output=True, text=True, env=e)
    if r.returncode != 0:
        sys.exit("c2m_run: %s failed (%d): %s%s" % (" ".join(cmd), r.returncode, r.stdout, r.stderr))
    return r.stdout


def exact_cost(build):
    """The exact path's seconds a call: the largest of tri_bench's kinds."""
    out = run([os.path.join(build, "bench", "tri_bench"), "20000", "1"])
    costs = [float(row.split("|")[4]) for row in out.splitlines() if row.count("|") > 6 and row.split("|")[2].strip().isdigit()]
    return max(costs) * 1e-9


def ours(build, mesh, levels, n, cloud, threads, runs, case=None, check=0):
    cmd = [os.path.join(build, "bench", "c2m_bench"), mesh, str(levels), str(n), cloud, str(threads), str(runs)]
    if case:
        cmd.append(case)
    cmd += ["--perturb", "--json"] + (["--check", str(check)] if check else [])
    return json.loads(run(cmd))


def open3d(case, threads, runs):
    out = run(["/usr/bin/python3", "bench/peers/c2m_open3d.py", case, str(threads), str(runs)],
              {"OMP_NUM_THREADS": str(threads)})
    m = re.search(r"median %s s of \d+ \(cpu %s s\); max error %s .*?, (\d+) of" % (NUM, NUM, NUM), out)
    return {"wall": float(m.group(1)), "cpu": float(m.group(2)), "max_error": float(m.group(3)),
            "differ": int(m.group(4))}


def cgal(build, case, runs):
    out = run([os.path.join(build, "bench", "c2m_cgal"), case, str(runs)])
    m = re.search(r"median %s s of \d+ \(cpu %s s\); max error %s, (\d+) of" % (NUM, NUM, NUM), out)
    return {"wall": float(m.group(1)), "cpu": float(m.group(2)), "max_error": float(m.group(3)),
            "differ": int(m.group(4))}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--sizes")
    ap.add_argument("--meshes")
    ap.add_argument("--clouds", default="near,far")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--peer-budget", type=float, default=120.0)
    ap.add_argument("--out")
    ap.add_argument("--doc")
    ap.add_argument("--command", default="make bench-c2m")
    ap.add_argument("--report", help="only rewrite --doc's table from this JSON-lines file of an earlier run")
    a = ap.parse_args()
    if a.report:
        rows = [json.loads(line) for line in open(a.report)]
        write_doc(a.doc, rows, [int(t) for t in a.threads.split(",")], a.command, rows[0]["load"])
        return
    sizes = [int(float(s)) for s in (a.sizes or ("1e5,1e6" if a.quick else "1e5,1e6,1e7")).split(",")]
    meshes = (a.meshes or ("1e3,1e5" if a.quick else "1e3,1e5,1e6")).split(",")
    threads = [int(t) for t in a.threads.split(",")]
    xcost = exact_cost(a.build)
    commit = run(["git", "rev-parse", "--short", "HEAD"]).strip()
    date = datetime.date.today().isoformat()
    load = os.getloadavg()[0]
    out = open(a.out, "w") if a.out else None
    rows = []
    for mname in meshes:
        mesh, levels = MESHES[mname]
        case = os.path.join(a.build, "bench", "c2m_case_%s.bin" % mname)
        for cloud in a.clouds.split(","):
            prev = {}
            for n in sizes:
                runs = 3 if n <= 10 ** 5 else 1
                peer_runs = 3 if n <= 10 ** 5 else 1
                res = {"mesh": mname, "cloud": cloud, "points": n, "date": date, "commit": commit,
                       "load": round(load, 1)}
                for t in threads:
                    check = max(10, min(2000, int(3e7 // MESHES_TRI[mname])))
                    r = ours(a.build, mesh, levels, n, cloud, t, runs, case if t == threads[0] else None,
                             check if t == threads[0] else 0)
                    r["exact_share"] = r["exact"] * xcost / r["cpu"] if r["cpu"] > 0 else 0.0
                    res["ours_%d" % t] = r
                    print("hd %s %s %d pts %d thr: wall %.3f cpu %.3f" % (mname, cloud, n, t, r["wall"], r["cpu"]),
                          flush=True)
                for peer in ["open3d_%d" % t for t in threads] + ["cgal_1"]:
                    if peer in prev and (prev[peer] is None or prev[peer]["wall"] * n / prev["n"] > a.peer_budget):
                        res[peer] = None
                        continue
                    t = int(peer.split("_")[1])
                    res[peer] = open3d(case, t, peer_runs) if peer.startswith("open3d") else cgal(a.build, case, peer_runs)
                    print("%s %s %s %d pts: wall %.3f cpu %.3f" % (peer, mname, cloud, n, res[peer]["wall"],
                                                                    res[peer]["cpu"]), flush=True)
                prev = dict(res, n=n)
                rows.append(res)
                if out:
                    out.write(json.dumps(res) + "\n")
                    out.flush()
                os.remove(case)
    if a.doc:
        write_doc(a.doc, rows, threads, a.command, load)


MESHES_TRI = {"1e3": 1300, "1e5": 92864, "1e6": 832000}


def fmt_t(x):
    return "-" if x is None else ("%.3g s" % x)


def ratio(peer, me):
    return "-" if peer is None or me <= 0 else "%.2gx" % (peer / me) if peer / me < 10 else "%.0fx" % (peer / me)


def table(rows, threads):
    head = ("| points / triangles, cloud | hd 1 thread (cpu) | Open3D 1 (cpu) | CGAL 1 (cpu) | over Open3D, 1 | "
            "over CGAL, 1 | hd 2 threads (wall) | Open3D 2 (wall) | over Open3D, 2 | kernel calls a point | "
            "exact share | brute-force sample | Open3D max error, points differing | CGAL max error, points differing |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        o1, o2 = r.get("ours_1"), r.get("ours_%d" % threads[-1])
        p1, p2, c1 = r.get("open3d_1"), r.get("open3d_%d" % threads[-1]), r.get("cgal_1")
        peer = p1 or p2
        lines.append("| 10^%d / %s, %s | %s | %s | %s | %s | %s | %s | %s | %s | %.2f | %.2g %% | %d of %d agree | %s | %s |" % (
            len(str(r["points"])) - 1, "{:,}".format(o1["triangles"]), r["cloud"], fmt_t(o1["cpu"]),
            fmt_t(p1 and p1["cpu"]), fmt_t(c1 and c1["cpu"]), ratio(p1 and p1["cpu"], o1["cpu"]),
            ratio(c1 and c1["cpu"], o1["cpu"]), fmt_t(o2["wall"]), fmt_t(p2 and p2["wall"]),
            ratio(p2 and p2["wall"], o2["wall"]), o1["kernel"], 100 * o1["exact_share"],
            o1["checked"] - o1["check_differ"], o1["checked"],
            "-" if not peer else "%.2g, %d of %d" % (peer["max_error"], peer["differ"], r["points"]),
            "-" if not c1 else "%.2g, %d of %d" % (c1["max_error"], c1["differ"], r["points"])))
    return "\n".join(lines)


def write_doc(path, rows, threads, command, load):
    text = open(path).read()
    begin, end = "<!-- c2m-table begin -->", "<!-- c2m-table end -->"
    i, j = text.index(begin) + len(begin), text.index(end)
    r0 = rows[0]
    body = "\n\nRun %s at commit %s, load average %.1f at the start; command `%s`.\n\n%s\n\n" % (
        r0["date"], r0["commit"], load, command, table(rows, threads))
    open(path, "w").write(text[:i] + body + text[j:])


main()
