#!/usr/bin/python3
"""The engine benchmark's cases from Python: hausdorff.directed against the
peers a Python user would reach for.

    /usr/bin/python3 bench/python_bench.py [--size 1000000] [--runs 5]
        [--timeout 120] [--build build] [--out table.md] [--doc docs/benchmarks.md]

Peers: scipy.spatial.distance.directed_hausdorff (EARLYBREAK, serial),
scipy.spatial.cKDTree (built on B, query(A, workers=-1), then the maximum)
and, when Debian's python3-open3d is installed, Open3D's
PointCloud.compute_point_cloud_distance (then the maximum).  Every timing is
the median of --runs runs of the whole call from Python (array in, distance
out; a tree's construction counts, Open3D's conversion of the numpy arrays
into point clouds does not).  A peer runs in its own process so that a slow
one can be stopped: a case that does not finish within --timeout seconds is
reported as "> T s"; a peer whose first run takes more than 20 s is not
repeated (marked "(1 run)").  Each peer's distance is compared with ours:
"=" when bit-identical, else the relative difference is shown.

The cases are the engine benchmark's (bench/bench.c): overlapping Gaussians,
partly overlapping (means 2 sigma apart), disjoint (20 sigma apart), 1M vs
10K and 10K vs 1M, a cloud against a copy perturbed by noise of 1e-3 sigma,
and real models from data/ (a model against every other one of its
vertices, two different models).  Points are generated with numpy's
default_rng and fixed seeds.
"""
import argparse
import json
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
SLOW_RUN = 20.0  # seconds: a peer slower than this runs once
BEGIN, END = "<!-- python-results:begin -->", "<!-- python-results:end -->"


def import_hausdorff(build):
    try:
        import hausdorff  # noqa: F401  (installed, or on PYTHONPATH)
    except ImportError:
        sys.path.insert(0, str(pathlib.Path(build).resolve() / "python"))
    import hausdorff
    return hausdorff


# ---- the peers, each returning the directed distance h(A, B) -------------
def peer_functions(hausdorff):
    def ours(a, b):
        return hausdorff.directed(a, b)[0]

    def ours_serial(a, b):
        return hausdorff.directed(a, b, threads=1)[0]

    def scipy_directed(a, b):
        from scipy.spatial.distance import directed_hausdorff
        return directed_hausdorff(a, b)[0]

    def scipy_ckdtree(a, b):
        from scipy.spatial import cKDTree
        d, _ = cKDTree(b).query(a, k=1, workers=-1)
        return float(d.max())

    return {"hausdorff": ours, "hausdorff-1": ours_serial,
            "scipy": scipy_directed, "ckdtree": scipy_ckdtree}


def open3d_runner(a, b):
    import open3d as o3d
    pa = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(a))
    pb = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(b))
    return lambda: float(np.asarray(pa.compute_point_cloud_distance(pb)).max())


PEERS = [  # (key, column title)
    ("hausdorff", "hausdorff.directed"),
    ("hausdorff-1", "hausdorff.directed, threads=1"),
    ("scipy", "scipy directed_hausdorff"),
    ("ckdtree", "scipy cKDTree, workers=-1"),
    ("open3d", "Open3D compute_point_cloud_distance"),
]


def worker(args):
    """Run one peer on one case, print {"times": [...], "distance": d}."""
    a, b = np.load(args.a), np.load(args.b)
    if args.worker == "open3d":
        run = open3d_runner(a, b)
    else:
        fn = peer_functions(import_hausdorff(args.build))[args.worker]
        run = lambda: fn(a, b)  # noqa: E731
    times, d = [], None
    for _ in range(args.runs):
        t0 = time.perf_counter()
        d = run()
        times.append(time.perf_counter() - t0)
        if times[-1] > SLOW_RUN:
            break
    print(json.dumps({"times": times, "distance": d}))


# ---- the cases ------------------------------------------------------------
def cases(n, hausdorff):
    def g(seed, m, mean=(0.0, 0.0, 0.0), sigma=1.0):
        return np.random.default_rng(seed).normal(mean, sigma, size=(m, 3))

    small = max(n // 100, 1)
    yield "overlapping Gaussians", lambda: (g(1, n), g(2, n))
    yield "partly overlapping Gaussians (2 sigma apart)", lambda: (g(3, n), g(4, n, (2, 0, 0)))
    yield "disjoint Gaussians (20 sigma apart)", lambda: (g(5, n), g(6, n, (20, 0, 0)))
    yield "large vs small", lambda: (g(7, n), g(8, small))
    yield "small vs large", lambda: (g(9, small), g(10, n))

    def perturbed(m):
        a = g(11, m)
        return a, a + g(12, m, sigma=1e-3)
    yield "perturbed copy (noise 1e-3 sigma)", lambda: perturbed(n)
    yield "perturbed copy, a tenth of the size", lambda: perturbed(max(n // 10, 1))

    data = ROOT / "data"

    def model(name):
        return np.ascontiguousarray(hausdorff.read(data / name), dtype=np.float64)
    yield "armadillo vs every other vertex", lambda: (model("armadillo.ply"),
                                                     model("armadillo.ply")[::2].copy())
    yield "lion vs lion head", lambda: (model("cgal_lion.ply"), model("cgal_lion_head.ply"))
    yield "wuson OBJ vs STL", lambda: (model("wuson_obj.ply"), model("wuson_stl.ply"))


def fmt_time(s):
    if s < 1e-3:
        return f"{s * 1e6:.0f} us"
    if s < 1:
        return f"{s * 1e3:.3g} ms"
    return f"{s:.3g} s"


def measure(args, key, fa, fb):
    cmd = [sys.executable, __file__, "--worker", key, "--a", fa, "--b", fb,
           "--runs", str(args.runs), "--build", args.build]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
    except subprocess.TimeoutExpired:
        return {"timeout": args.timeout}
    if p.returncode != 0:
        return {"error": (p.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(p.stdout.strip().splitlines()[-1])


def have_open3d():
    p = subprocess.run([sys.executable, "-c", "import open3d"], capture_output=True)
    return p.returncode == 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=1_000_000, help="points per large set")
    ap.add_argument("--runs", type=int, default=5, help="runs per measurement (median)")
    ap.add_argument("--timeout", type=float, default=120, help="seconds per peer and case")
    ap.add_argument("--build", default=str(ROOT / "build"), help="CMake build directory")
    ap.add_argument("--only", help="run only the cases whose name contains this")
    ap.add_argument("--out", help="also write the markdown table to this file")
    ap.add_argument("--doc", help="replace the table between the python-results markers "
                                  "of this markdown file (docs/benchmarks.md)")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    ap.add_argument("--a", help=argparse.SUPPRESS)
    ap.add_argument("--b", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        return worker(args)

    hausdorff = import_hausdorff(args.build)
    peers = [(k, t) for k, t in PEERS if k != "open3d" or have_open3d()]
    lines = [
        f"hausdorff {hausdorff.__version__} ({hausdorff.__file__}), numpy {np.__version__}, "
        f"Python {platform.python_version()}, {os.cpu_count()} cores; "
        f"median of {args.runs} runs; timeout {args.timeout:g} s; "
        f"load average at the start {os.getloadavg()[0]:.2f}.",
        "",
        "| case | \\|A\\| | \\|B\\| | h(A,B) | " + " | ".join(t for _, t in peers) + " |",
        "|---|---:|---:|---:|" + "---:|" * len(peers),
    ]
    print("\n".join(lines), flush=True)
    ratios = []  # (case, {peer key: peer time / our time, or (">", bound)})
    with tempfile.TemporaryDirectory(prefix="hd-pybench-") as tmp:
        for name, make in cases(args.size, hausdorff):
            if args.only and args.only not in name:
                continue
            a, b = make()
            fa, fb = os.path.join(tmp, "a.npy"), os.path.join(tmp, "b.npy")
            np.save(fa, a)
            np.save(fb, b)
            ref = None
            cells = []
            ours = None
            ratio = {}
            for key, _ in peers:
                r = measure(args, key, fa, fb)
                if "timeout" in r:
                    cells.append(f"> {r['timeout']:g} s")
                    if ours:
                        ratio[key] = f"> {r['timeout'] / ours:.3g}x"
                    continue
                if "error" in r:
                    cells.append(f"failed: {r['error'][:60]}")
                    continue
                t = statistics.median(r["times"])
                if key == "hausdorff":
                    ours = t
                elif ours:
                    ratio[key] = f"{t / ours:.3g}x"
                d = r["distance"]
                if ref is None:
                    ref = d
                cell = fmt_time(t)
                if len(r["times"]) == 1 and args.runs > 1:
                    cell += " (1 run)"
                if d != ref:
                    cell += f" (differs: {abs(d - ref) / ref:.1e})" if ref else f" (gives {d!r})"
                elif key not in ("hausdorff", "hausdorff-1"):
                    cell += " ="
                cells.append(cell)
            row = (f"| {name} | {len(a):,} | {len(b):,} | {ref!r} | " + " | ".join(cells) + " |")
            lines.append(row)
            print(row, flush=True)
            ratios.append((name, ratio))
    others = [(k, t) for k, t in peers if k != "hausdorff"]
    tail = ["", "Time of each peer divided by the time of hausdorff.directed (default threads):", "",
            "| case | " + " | ".join(t for _, t in others) + " |",
            "|---|" + "---:|" * len(others)]
    tail += [f"| {name} | " + " | ".join(r.get(k, "") for k, _ in others) + " |"
             for name, r in ratios]
    tail += ["", f"Load average at the end {os.getloadavg()[0]:.2f}. Command: "
             "`/usr/bin/python3 bench/python_bench.py " + " ".join(sys.argv[1:]) + "`"]
    print("\n".join(tail))
    lines += tail
    if args.out:
        pathlib.Path(args.out).write_text("\n".join(lines) + "\n")
    if args.doc:
        doc = pathlib.Path(args.doc).read_text()
        if BEGIN not in doc or END not in doc:
            sys.exit(f"{args.doc}: no {BEGIN} ... {END} markers to replace")
        table = "\n".join([BEGIN] + lines + [END])
        doc = doc[:doc.index(BEGIN)] + table + doc[doc.index(END) + len(END):]
        pathlib.Path(args.doc).write_text(doc)


if __name__ == "__main__":
    main()
