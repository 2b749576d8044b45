#!/usr/bin/env python3
"""m2m_predicate.py -- the predicate "H(A, B) <= d?" against computing H and against CGAL.

For every pair that bench/m2m_cases.c wrote (CASES/cases.tsv), it takes H from hd_surface_hausdorff's enclosure
at tolerance 0 (build/bench/m2m_run), then for d = 0.5, 0.99, 1.01 and 2 times H (its upper bound) times
  - hd_surface_within(A, B, d) (build/bench/m2m_run ... sym within d) at 1 and 2 threads,
  - hd_surface_hausdorff at the same tolerance (what answering by computing H costs),
  - CGAL 5.5's is_Hausdorff_distance_larger, symmetric, sequential (build/bench/m2m_cgal larger), if built,
all at the absolute tolerance 1e-4 H (so that 0.99 H and 1.01 H are decidable), and checks that every answer
agrees with the enclosure (0 below it, 1 above it).  Prints a Markdown table (processor seconds, medians of
--repeats runs; the machine is shared) and the raw results as JSON lines to --json.

    python3 bench/m2m_predicate.py --cases /tmp/pairs [--build build] [--repeats 3]
"""
import argparse
import json
import os
import subprocess
import sys

FACTORS = [0.5, 0.99, 1.01, 2.0]


def run_json(cmd, timeout):
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"timeout": timeout}
    lines = p.stdout.strip().splitlines()
    if p.returncode != 0 or not lines:
        return {"error": (p.stderr.strip() or "no output")[-300:]}
    return json.loads(lines[-1])


def median_cpu(cmd, repeats, timeout):
    runs = [run_json(cmd, timeout) for _ in range(repeats)]
    bad = [r for r in runs if "cpu" not in r]
    if bad:
        return bad[0]
    cpus = sorted(r["cpu"] for r in runs)
    out = dict(runs[-1])
    out["cpu"] = cpus[len(cpus) // 2]
    return out


def seconds(r):
    if "timeout" in r:
        return "> %gs" % r["timeout"]
    if "cpu" not in r:
        return "error"
    return "%.3g ms" % (1e3 * r["cpu"]) if r["cpu"] < 1 else "%.3g s" % r["cpu"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", required=True)
    ap.add_argument("--build", default="build")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--json")
    a = ap.parse_args()
    run = os.path.join(a.build, "bench", "m2m_run")
    cgal = os.path.join(a.build, "bench", "m2m_cgal")
    have_cgal = os.path.exists(cgal)
    rows, raw, wrong = [], [], 0
    with open(os.path.join(a.cases, "cases.tsv")) as f:
        cases = [line.rstrip("\n").split("\t") for line in f if line.strip()]
    for name, pa, pb, *_ in cases:
        tight = run_json([run, pa, pb, "0", "1", "1", "sym"], a.timeout)
        lo = max(tight["ab"]["lower"], tight["ba"]["lower"])
        hi = max(tight["ab"]["upper"], tight["ba"]["upper"])
        tol = 1e-4 * hi
        full = median_cpu([run, pa, pb, repr(tol), "1", "1", "sym"], a.repeats, a.timeout)
        for k in FACTORS:
            d = k * hi
            want = 0 if d < lo else 1 if d >= hi else None
            ours = {t: median_cpu([run, pa, pb, repr(tol), str(t), "1", "sym", "within", repr(d)], a.repeats,
                                  a.timeout) for t in (1, 2)}
            peer = median_cpu([cgal, "larger", pa, pb, repr(d), repr(tol), "sym"], a.repeats,
                              a.timeout) if have_cgal else {"error": "not built"}
            answers = [ours[1].get("answer"), ours[2].get("answer"), peer.get("within")]
            bad = [x for x in answers[:2] if x != want] + ([answers[2]] if answers[2] not in (None, want) else [])
            wrong += len(bad)
            ratio = "%.3gx" % (peer["cpu"] / ours[1]["cpu"]) if "cpu" in peer and ours[1].get("cpu") else "-"
            vs_h = "%.3gx" % (full["cpu"] / ours[1]["cpu"]) if "cpu" in full and ours[1].get("cpu") else "-"
            rows.append("| %s | %g | %s | %s | %s | %s | %s | %s | %s |" % (
                name, k, answers[0], seconds(ours[1]), seconds(ours[2]), seconds(full), vs_h,
                seconds(peer), ratio))
            raw.append({"case": name, "factor": k, "d": d, "H": [lo, hi], "tolerance": tol, "ours": ours,
                        "hausdorff": full, "cgal": peer})
            print(rows[-1], file=sys.stderr)
    print("| case | d / H | answer | ours, 1 thread | 2 threads | computing H | H / ours | CGAL | CGAL / ours |")
    print("|---|---|---|---|---|---|---|---|---|")
    print("\n".join(rows))
    print("\nanswers that disagree with the enclosure: %d" % wrong)
    if a.json:
        with open(a.json, "w") as f:
            for r in raw:
                f.write(json.dumps(r) + "\n")
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main())
