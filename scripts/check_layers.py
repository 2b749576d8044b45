#!/usr/bin/env python3
"""The layering check (make test): lower folders never use higher ones.

src/ is built in layers, each a folder, each offering one front header to
the folders above it; its other headers are private to the folder's files
(as SQLite's btree.h and btreeInt.h):

    base     base/base.h       errors, memory, rng, threads, selection, heap
    points   points/points.h   distance, boxes, keys, views, sources, sort
    io, classic, engine, nearest, mesh, masks   (siblings: none uses another)
    src/*.c  api.c, index.c, stats.c, metrics.c: the public entry points, over all
    mpi      (hausdorff_mpi.h) the optional MPI library, over the public API

What is checked:
  from the sources (always):
    - a file of src/ includes the standard library, "hausdorff.h", headers of
      its own folder, and the front headers of lower layers by their path
      from src/ ("points/points.h"), never a folder's private header;
    - cli/ sees the public headers and its own only; so do tests/api/,
      whose tests use the public header and tests/support/ alone;
      tests/internal/ and bench/ may include anything (white-box);
  from the built objects (--build DIR, the CMake build tree, read with nm):
    - no object of src/ uses a symbol defined in a higher layer or in a
      sibling folder;
    - every hd__ function that a header of src/ declares is defined in that
      header's folder (a declaration is a promise of the layer that makes it);
    - inside each folder of src/ the graph of its files (file x -> file y
      when x uses a symbol y defines) has no cycle;
    - with --cli, the same for the files of cli/ (cli/ and cli/mpi/ together).

Usage: check_layers.py [--build DIR] [--cli] [ROOT]
ROOT names another tree to check (tests/layers_check.py uses it to see the
check fail).  Every violation is printed as FILE[:LINE]: what, and the exit
status is 1 when there is one.  Needs python3 and nm (binutils) only.
"""
import argparse
import os
import re
import subprocess
import sys

LEVEL = {"base": 0, "points": 1, "io": 2, "classic": 2, "engine": 2, "nearest": 2, "mesh": 2, "masks": 2,
         "": 3, "mpi": 4}
# The front header of each folder: what the folders above may include.
FRONT = {f: f"{f}/{f}.h" for f in LEVEL if f}
# The public headers: hausdorff.h anywhere, hausdorff_mpi.h only in the MPI
# library and the MPI tool (cli/mpi/).
PUBLIC_MPI = "hausdorff_mpi.h"
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def folder_of(rel):
    """'src/engine/grid.c' -> 'engine'; 'src/api.c' -> ''."""
    parts = rel.split("/")
    return parts[1] if len(parts) > 2 else ""


# ---- includes ------------------------------------------------------------------

def check_src(root, rel, lines, bad):
    own = folder_of(rel)
    if own not in LEVEL:
        bad.append(f"{rel}:1: folder src/{own}/ is not a known layer (add it to scripts/check_layers.py)")
        return
    for n, line in enumerate(lines, 1):
        m = INCLUDE.match(line)
        if not m:
            continue
        h = m.group(1)
        if h == "hausdorff.h" or (h == PUBLIC_MPI and own == "mpi"):
            continue
        if h.startswith("../"):
            bad.append(f"{rel}:{n}: \"{h}\": name headers of other layers from src/, not with ../")
            continue
        if "/" not in h:
            if not os.path.exists(os.path.join(root, "src", own, h)):
                bad.append(f"{rel}:{n}: \"{h}\" is not a header of its own folder src/{own}/")
            continue
        other = h.split("/")[0]
        if not os.path.exists(os.path.join(root, "src", h)):
            bad.append(f"{rel}:{n}: \"{h}\" does not exist under src/")
        if other == own:
            continue
        if other not in LEVEL or other == "":
            bad.append(f"{rel}:{n}: \"{h}\" is not in a known layer")
        elif LEVEL[other] >= LEVEL[own]:
            bad.append(f"{rel}:{n}: src/{own or '.'}/ (layer {LEVEL[own]}) includes \"{h}\" "
                       f"(layer {LEVEL[other]}): only lower layers may be included")
        elif h != FRONT[other]:
            bad.append(f"{rel}:{n}: \"{h}\" is private to src/{other}/: outsiders include "
                       f"its front header \"{FRONT[other]}\"")


def check_cli(root, rel, lines, bad):
    for n, line in enumerate(lines, 1):
        m = INCLUDE.match(line)
        if not m:
            continue
        h = m.group(1)
        if h == "hausdorff.h" or (h == PUBLIC_MPI and rel.startswith("cli/mpi/")):
            continue
        # the tool's own headers: cli/'s, or its folder's (cli/mpi/mpi_cli.h)
        if os.path.exists(os.path.join(root, "cli", h)) or \
                os.path.exists(os.path.join(root, os.path.dirname(rel), h)):
            continue
        bad.append(f"{rel}:{n}: cli/ uses the public API only, not \"{h}\"")


def check_api_tests(root, rel, lines, bad):
    for n, line in enumerate(lines, 1):
        m = INCLUDE.match(line)
        if m and m.group(1) != "hausdorff.h" and \
                not os.path.exists(os.path.join(root, "tests", "support", m.group(1))):
            bad.append(f"{rel}:{n}: tests/api/ uses the public header and tests/support/ only, "
                       f"not \"{m.group(1)}\" (a white-box test goes in tests/internal/)")


def check_includes(root, bad):
    count = 0
    for top, check in (("src", check_src), ("cli", check_cli), ("tests/api", check_api_tests)):
        for d, _, files in os.walk(os.path.join(root, top)):
            for f in sorted(files):
                if not f.endswith((".c", ".h")):
                    continue
                rel = os.path.relpath(os.path.join(d, f), root)
                with open(os.path.join(d, f), encoding="utf-8") as fh:
                    check(root, rel, fh.read().splitlines(), bad)
                count += 1
    return count


# ---- symbols -------------------------------------------------------------------

OBJECT = re.compile(r"\.dir/((?:src|cli)/.+\.c)\.o$")


def objects(build):
    """{source path from the root ('src/engine/grid.c'): object path}, one
    object a source (a source built for several targets is the same code)."""
    out = {}
    for d, _, files in os.walk(build):
        for f in sorted(files):
            m = OBJECT.search(os.path.join(d, f).replace(os.sep, "/"))
            if m and m.group(1) not in out:
                out[m.group(1)] = os.path.join(d, f)
    return out


def nm_symbols(path):
    """(defined, used) global symbols of one object."""
    r = subprocess.run(["nm", "-P", "-g", path], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"check_layers: nm {path}: {r.stderr.strip()}")
    defined, used = set(), set()
    for line in r.stdout.splitlines():
        parts = line.split()
        if len(parts) < 2:
            continue
        name, kind = parts[0], parts[1]
        if kind == "U":
            used.add(name)
        elif kind not in ("w", "v"):
            defined.add(name)
    return defined, used


def file_cycles(graph):
    """The cycles of a directed graph {node: set(nodes)}, each as a list
    (one per strongly connected component of more than one node, or a node
    with an edge to itself)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


DECL = re.compile(r"\b(hd__[A-Za-z0-9_]+)\s*\(")


def header_declarations(text):
    """[(line, name)] of the hd__ functions a header declares (outside every
    brace, so not the calls in an inline function's body, nor macros)."""
    out, depth, line = [], 0, 1
    for raw in strip_comments(text).split("\n"):
        if raw.lstrip().startswith("#"):
            line += 1
            continue
        if depth == 0:
            for m in DECL.finditer(raw):
                if raw.count("{", 0, m.start()) == 0:
                    out.append((line, m.group(1)))
        depth += raw.count("{") - raw.count("}")
        line += 1
    return out


def check_symbols(root, build, with_cli, bad):
    objs = objects(build)
    if not any(s.startswith("src/") for s in objs):
        bad.append(f"{build}: no objects of src/ under this build tree (build it first)")
        return 0
    sym = {s: nm_symbols(p) for s, p in sorted(objs.items())}
    where = {}
    for s, (defined, _) in sym.items():
        for name in defined:
            where.setdefault(name, s)

    # layers: what each object of src/ uses
    for s, (_, used) in sym.items():
        if not s.startswith("src/"):
            continue
        own = folder_of(s)
        if own not in LEVEL:
            bad.append(f"{s}: folder src/{own}/ is not a known layer")
            continue
        for name in sorted(used):
            d = where.get(name)
            if not d or not d.startswith("src/"):
                continue
            other = folder_of(d)
            if other == own or other not in LEVEL:
                continue
            if LEVEL[other] > LEVEL[own]:
                bad.append(f"{s}: src/{own or '.'}/ (layer {LEVEL[own]}) uses {name}, defined in {d} "
                           f"(layer {LEVEL[other]}): only lower layers may be used")
            elif LEVEL[other] == LEVEL[own]:
                bad.append(f"{s}: uses {name}, defined in {d}: siblings never use each other")

    # declarations: a header promises only what its own folder defines
    for d, _, files in os.walk(os.path.join(root, "src")):
        for f in sorted(files):
            if not f.endswith(".h"):
                continue
            rel = os.path.relpath(os.path.join(d, f), root).replace(os.sep, "/")
            own = folder_of(rel)
            with open(os.path.join(d, f), encoding="utf-8") as fh:
                decls = header_declarations(fh.read())
            for n, name in decls:
                at = where.get(name)
                if at and at.startswith("src/") and folder_of(at) != own:
                    bad.append(f"{rel}:{n}: declares {name}, defined in {at}: a folder's headers "
                               f"declare only what the folder defines")

    # the file graph inside each folder (and cli/)
    groups = {}
    for s in sym:
        if s.startswith("src/"):
            groups.setdefault("src/" + folder_of(s), []).append(s)
        elif with_cli and s.startswith("cli/"):
            groups.setdefault("cli", []).append(s)
    for g, members in sorted(groups.items()):
        inside = set(members)
        graph = {s: {where[n] for n in sym[s][1] if where.get(n) in inside and where[n] != s}
                 for s in members}
        for cycle in file_cycles(graph):
            edges = [f"{a} -> {b}" for a in cycle for b in sorted(graph[a]) if b in cycle]
            bad.append(f"{g}: its files use each other in a cycle ({', '.join(edges)})")
    return len(sym)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("root", nargs="?", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--build", help="the CMake build tree whose objects are checked")
    ap.add_argument("--cli", action="store_true", help="check that cli/'s files form no cycle")
    a = ap.parse_args()
    root = os.path.abspath(a.root)
    bad = []
    count = check_includes(root, bad)
    nobj = check_symbols(root, os.path.abspath(a.build), a.cli, bad) if a.build else 0
    for b in bad:
        print(b)
    print(f"layers: {count} files and {nobj} objects checked, {len(bad)} violations")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
