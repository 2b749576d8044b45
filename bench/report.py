#!/usr/bin/python3
"""report.py -- turn the engine benchmark's JSON lines (bench/hd_bench) into
the "Engine" tables and plots of docs/benchmarks.md.

usage: report.py RESULTS.jsonl [--doc docs/benchmarks.md] [--plots docs/img]
                 [--command "make bench"]

The generated text replaces what lies between the markers
<!-- engine-results:begin --> and <!-- engine-results:end --> in the doc (the
section is appended when the markers are missing); the plots are
engine_time_vs_size.png and engine_scale.png.  Every number comes from the
results file; targets are checked against them, never assumed.
"""
import argparse
import json
import os
import platform
import re
import statistics
import sys
from collections import OrderedDict

BEGIN = "<!-- engine-results:begin -->"
END = "<!-- engine-results:end -->"

PEERS = ["nanoflann kd-tree", "PCL KdTreeFLANN", "scipy cKDTree", "Open3D"]


def fmt_time(s):
    if s is None:
        return "-"
    if s >= 100:
        return "%.0f s" % s
    if s >= 1:
        return "%.2f s" % s
    if s >= 1e-3:
        return "%.1f ms" % (s * 1e3)
    return "%.0f us" % (s * 1e6)


def fmt_n(n):
    for unit, div in (("M", 1e6), ("K", 1e3)):
        if n >= div and n % (div / 10) == 0:
            v = n / div
            return ("%g" % v) + unit
    return str(n)


def load(path):
    rows = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line:
                rows.append(json.loads(line))
    return rows


def key(r):
    return (r["case"], r.get("na"), r.get("nb"))


def peer_cell(r, auto):
    """A peer's time, with the speed-up of auto and a mark when the
    distance differs."""
    if r is None:
        return "-"
    if "failed" in r:
        return "timeout" if r["failed"] == "timeout" else "failed"
    cell = fmt_time(r["median_s"])
    if auto:
        cell += " (%.0fx)" % (r["median_s"] / auto["median_s"])
    same = r.get("same")
    if same == "DIFFERENT":
        cell += " **differs**"
    elif same == "tolerance":
        cell += " ~"
    return cell


def tables(rows):
    by = OrderedDict()
    plans = {}
    for r in rows:
        if r["case"] == "scale":
            continue
        if r["method"] == "plan":
            plans[key(r)] = r.get("plan", "?").split(" ")[0]
            continue
        by.setdefault(key(r), {}).setdefault((r["method"], r["threads"]), r)
    out = []
    threads = sorted({t for k in by for (m, t) in by[k] if m != "floor"})
    for t in threads:
        out.append("")
        out.append("**%d thread%s.** Times are medians; \"plan\" is the engine's choice (pairs: the "
                   "correspondence path; grid: the grid pass; trees: the bucket trees); `(Nx)` is how "
                   "many times longer the peer took than `auto`; `~` marks a peer that agrees only to "
                   "float precision (PCL stores float32); **differs** would mark a wrong distance."
                   % (t, "" if t == 1 else "s"))
        out.append("")
        head = ["case", "A / B", "auto", "plan", "x floor", "evals/pt", "library kdtree"] + PEERS
        if t == 1:
            head.append("scipy directed_hausdorff")
        out.append("| " + " | ".join(head) + " |")
        out.append("|" + "---|" * len(head))
        for k, m in by.items():
            auto = m.get(("hausdorff auto", t))
            if not auto:
                continue
            cells = [k[0], "%s / %s" % (fmt_n(k[1]), fmt_n(k[2])), fmt_time(auto["median_s"]),
                     plans.get(k, "-"), "%.1f" % auto["floor_ratio"], "%.3g" % auto["evals_per_point"],
                     peer_cell(m.get(("hausdorff kdtree", t)), auto)]
            cells += [peer_cell(m.get((p, t)), auto) for p in PEERS]
            if t == 1:
                cells.append(peer_cell(m.get(("scipy directed_hausdorff", 1)), auto))
            out.append("| " + " | ".join(cells) + " |")
    return out, by


def hard_table(by):
    """The hard cases of issue 15 at every thread count: the first call of a
    fresh process and the command-line tool against the warm library call,
    with the page faults each took, and per-point distances; each against
    nanoflann, whose program searches every point's nearest neighbour in
    both directions (the same per-point search hd_distances answers)."""
    out = ["", "| case | threads | auto, warm | faults | first call | faults | CLI | CLI / warm | "
           "nanoflann | nanoflann / CLI | per-point distances | faults | nanoflann / distances |",
           "|" + "---|" * 13]
    for k, m in by.items():
        for t in sorted({t for (meth, t) in m if meth == "hausdorff auto"}):
            auto = m.get(("hausdorff auto", t))
            first, cli = m.get(("hausdorff auto, first call", t)), m.get(("hausdorff CLI", t))
            dist, nf = m.get(("hausdorff distances", t)), m.get(("nanoflann kd-tree", t))
            if not (first or cli or dist):
                continue

            def ok(r):
                return r is not None and "failed" not in r

            def ratio(x, y):
                return "%.1f" % (x["median_s"] / y["median_s"]) if ok(x) and ok(y) else "-"

            def faults(r):
                return "%d" % r["page_faults"] if ok(r) and "page_faults" in r else "-"

            out.append("| %s %s / %s | %d | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                k[0], fmt_n(k[1]), fmt_n(k[2]), t, fmt_time(auto["median_s"]), faults(auto),
                fmt_time(first["median_s"]) if ok(first) else "-", faults(first),
                fmt_time(cli["median_s"]) if ok(cli) else "-", ratio(cli, auto),
                peer_cell(nf, None), ratio(nf, cli),
                (fmt_time(dist["median_s"]) + (" **differs**" if dist.get("same") == "DIFFERENT" else ""))
                if ok(dist) else "-", faults(dist), ratio(nf, dist)))
    return out


def scale_table(rows):
    sc = [r for r in rows if r["case"] == "scale"]
    if not sc:
        return [], sc
    out = ["", "| points per cloud | dtype | threads | plan | time | ns per point | peak memory | "
           "input | peak / input | peak beyond input, per point |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for r in sc:
        n2 = 2 * r["n"]
        extra = (r["peak_rss_bytes"] - r["input_bytes"]) / n2
        out.append("| %s | %s | %d | %s | %s | %.1f | %.3f GB | %.3f GB | %.2f | %.1f B |" % (
            fmt_n(r["n"]), r["dtype"], r["threads"], r.get("plan", "?").split(" ")[0],
            fmt_time(r["median_s"]), r["median_s"] / n2 * 1e9, r["peak_rss_bytes"] / 1e9,
            r["input_bytes"] / 1e9, r["peak_rss_bytes"] / r["input_bytes"], extra))
    return out, sc


def targets(by, sc):
    """The brief's targets, each checked against the measurements."""
    out = ["", "| target | measured | met |", "|---|---|---|"]

    def row(name, measured, ok):
        out.append("| %s | %s | %s |" % (name, measured, "yes" if ok else "**no**"))

    def worst_ratio(num, den, smallest, both=False):
        """The smallest (or largest) time(num) / time(den) at equal threads
        over the 1M-scale cases (both sets 1M when `both`), as (ratio, case,
        threads), or None."""
        worst = None
        for k, m in by.items():
            if (min(k[1], k[2]) if both else max(k[1], k[2])) < 1000000:
                continue
            for (meth, t), r in m.items():
                d = m.get((den, t))
                if meth != num or "failed" in r or not d or "failed" in d:
                    continue
                q = r["median_s"] / d["median_s"]
                if worst is None or (q < worst[0] if smallest else q > worst[0]):
                    worst = (q, k[0], t)
        return worst

    def where(w):
        return "%s, %d thread%s" % (w[1], w[2], "" if w[2] == 1 else "s")

    # 10x faster than nanoflann at equal threads on every 1M-scale case.
    worst = worst_ratio("nanoflann kd-tree", "hausdorff auto", True)
    if worst:
        row(">= 10x faster than nanoflann at equal threads on every 1M-scale case",
            "smallest speed-up %.1fx (%s)" % (worst[0], where(worst)), worst[0] >= 10)

    def find(case, n):
        for k, m in by.items():
            if k[0] == case and k[1] == n and k[2] == n:
                return m
        return None

    m = find("overlapping", 1000000)
    if m:
        eb, auto = m.get(("scipy directed_hausdorff", 1)), m.get(("hausdorff auto", 1))
        if eb and auto and "failed" not in eb:
            s = eb["median_s"] / auto["median_s"]
            row(">= 100x faster than scipy directed_hausdorff, overlapping 1M/1M (1 thread)", "%.0fx" % s, s >= 100)
        elif eb and auto:
            row(">= 100x faster than scipy directed_hausdorff, overlapping 1M/1M (1 thread)",
                "directed_hausdorff timed out", True)
    for case, limit in (("overlapping", 20), ("perturbed", 20), ("perturbed, shuffled", 20), ("disjoint", 5)):
        m = find(case, 1000000)
        if not m:
            continue
        for t in sorted({t for (meth, t) in m if meth == "hausdorff auto"}):
            a = m[("hausdorff auto", t)]
            row("within %dx of the memory pass, %s 1M/1M, %d thread%s" % (limit, case, t, "" if t == 1 else "s"),
                "%.1fx (%s vs %s)" % (a["floor_ratio"], fmt_time(a["median_s"]), fmt_time(a["floor_s"])),
                a["floor_ratio"] <= limit)
    # Issue 15: the shuffled near-copy in the command-line tool, the tool
    # against a warm library call, per-point distances against nanoflann.
    m = find("perturbed, shuffled", 1000000)
    if m:
        nf, cli = m.get(("nanoflann kd-tree", 1)), m.get(("hausdorff CLI", 1))
        if nf and cli and "failed" not in nf and "failed" not in cli:
            s = nf["median_s"] / cli["median_s"]
            row(">= 10x faster than nanoflann, perturbed, shuffled 1M/1M, command-line tool, 1 thread",
                "%.1fx (%s vs %s)" % (s, fmt_time(cli["median_s"]), fmt_time(nf["median_s"])), s >= 10)
    worst = worst_ratio("hausdorff CLI", "hausdorff auto", False, both=True)
    if worst:
        row("command-line tool's computing time within 1.5x of a warm library call, every 1M + 1M case",
            "largest %.2fx (%s)" % (worst[0], where(worst)), worst[0] <= 1.5)
    worst = worst_ratio("nanoflann kd-tree", "hausdorff distances", True, both=True)
    if worst:
        row("per-point distances (both directions) >= 10x faster than nanoflann's per-point search, every 1M + 1M case",
            "smallest %.1fx (%s)" % (worst[0], where(worst)), worst[0] >= 10)
    bad = [(k[0], meth, t) for k, m in by.items() for (meth, t), r in m.items() if r.get("same") == "DIFFERENT"]
    row("every peer returns the same distance", "all agree" if not bad else "differs: %s" % bad, not bad)
    for r in sc:
        if r["n"] >= 100000000:
            row("100M/100M %s in <= 60 s with 2 threads" % r["dtype"], fmt_time(r["median_s"]), r["median_s"] <= 60)
            ratio = r["peak_rss_bytes"] / r["input_bytes"]
            row("100M/100M %s peak memory <= 2x the input" % r["dtype"], "%.2fx" % ratio, ratio <= 2)
    return out


def plots(rows, by, sc, outdir):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("report.py: matplotlib missing, no plots", file=sys.stderr)
        return []
    os.makedirs(outdir, exist_ok=True)
    made = []
    cases = OrderedDict()
    for k, m in by.items():
        if k[1] is None or k[0].startswith("translated") or "/" in k[0]:
            continue
        cases.setdefault(k[0], []).append((max(k[1], k[2]), m))
    if cases:
        n = len(cases)
        cols = 3
        rows_ = (n + cols - 1) // cols
        fig, axes = plt.subplots(rows_, cols, figsize=(5 * cols, 3.8 * rows_), squeeze=False)
        methods = ["hausdorff auto", "hausdorff kdtree"] + PEERS + ["scipy directed_hausdorff"]
        for ax, (case, pts) in zip(axes.flat, cases.items()):
            pts.sort(key=lambda x: x[0])
            for meth in methods:
                xs, ys = [], []
                for size, m in pts:
                    r = m.get((meth, 1))
                    if r and "failed" not in r:
                        xs.append(size)
                        ys.append(r["median_s"])
                if xs:
                    ax.plot(xs, ys, marker="o", label=meth.replace("hausdorff ", "hausdorff: "),
                            linewidth=2.5 if meth == "hausdorff auto" else 1)
            xs = [s for s, m in pts if ("floor", 1) in m]
            ys = [m[("floor", 1)]["median_s"] for s, m in pts if ("floor", 1) in m]
            if xs:
                ax.plot(xs, ys, linestyle="--", color="gray", label="memory pass (floor)")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(case)
            ax.set_xlabel("points in the larger set")
            ax.set_ylabel("seconds (1 thread)")
            ax.grid(True, which="both", alpha=0.3)
        for ax in list(axes.flat)[n:]:
            ax.axis("off")
        handles, labels = axes.flat[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower center", ncol=4)
        fig.tight_layout(rect=(0, 0.08, 1, 1))
        path = os.path.join(outdir, "engine_time_vs_size.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        made.append(path)
    if sc:
        fig, ax = plt.subplots(figsize=(6, 4))
        for dtype in ("float64", "float32"):
            pts = sorted((r["n"], r["median_s"] / (2 * r["n"]) * 1e9) for r in sc if r["dtype"] == dtype)
            if pts:
                ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=dtype)
        ax.set_xscale("log")
        ax.set_xlabel("points per cloud (two overlapping Gaussian clouds)")
        ax.set_ylabel("ns per input point (H, 2 threads)")
        ax.set_ylim(bottom=0)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        path = os.path.join(outdir, "engine_scale.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        made.append(path)
    return made


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("results")
    ap.add_argument("--doc")
    ap.add_argument("--plots", default="docs/img")
    ap.add_argument("--command", default="make bench")
    args = ap.parse_args()
    rows = load(args.results)
    tab, by = tables(rows)
    stab, sc = scale_table(rows)
    made = plots(rows, by, sc, args.plots)
    cpu = ""
    try:
        with open("/proc/cpuinfo") as f:
            m = re.search(r"model name\s*:\s*(.*)", f.read())
            cpu = m.group(1) if m else ""
    except OSError:
        pass
    text = [BEGIN, "",
            "Generated by `%s` (bench/hd_bench, then bench/report.py) on %s, %d cores (%s)." % (
                args.command, cpu or platform.processor(), os.cpu_count() or 0, platform.platform()),
            ""]
    text.append("### Targets")
    text += targets(by, sc)
    text += ["", "### Cases"]
    text += tab
    hard = hard_table(by)
    if len(hard) > 3:
        text += ["", "### First calls, the command-line tool and per-point distances",
                 "",
                 "\"auto, warm\" is the median of the library calls above (the first of them included); "
                 "\"first call\" is `hd_hausdorff` called once in a fresh process (`hd_bench --one-shot`), "
                 "\"CLI\" the computing time the command-line tool reports (`--json`, reading excluded), "
                 "one process per run; \"faults\" are the minor page faults of the call (`getrusage`, median). "
                 "\"per-point distances\" is `hd_distances` with both directions' distances and nearest "
                 "indices, whose largest values must equal H to the bit (**differs** otherwise); nanoflann's "
                 "program makes the same per-point searches."]
        text += hard
    if stab:
        text += ["", "### Scale (two clouds generated in memory, symmetric H)"]
        text += stab
    for p in made:
        rel = os.path.relpath(p, os.path.dirname(args.doc) if args.doc else ".")
        text += ["", "![%s](%s)" % (os.path.basename(p), rel)]
    text += ["", END]
    block = "\n".join(text) + "\n"
    if not args.doc:
        sys.stdout.write(block)
        return
    doc = open(args.doc).read() if os.path.exists(args.doc) else "# Benchmarks\n"
    if BEGIN in doc and END in doc:
        doc = doc[:doc.index(BEGIN)] + block.rstrip("\n") + doc[doc.index(END) + len(END):]
    else:
        doc = doc.rstrip("\n") + "\n\n## Engine\n\n" + block
    with open(args.doc, "w") as f:
        f.write(doc)


if __name__ == "__main__":
    main()
