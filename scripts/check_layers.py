#!/usr/bin/env python3
"""The layering check (make test): lower folders never include higher ones.

src/ is built in layers, each a folder, each offering one header:

    base     base/base.h       errors, memory, rng, threads, selection, heap
    points   points/points.h   distance, boxes, keys, views, sources, sort
    io, classic, engine, nearest, mesh, masks   (siblings: none includes another)
    src/*.c  api.c, index.c, stats.c, metrics.c: the public entry points, over all
    mpi      (hausdorff_mpi.h) the optional MPI library, over the public API

A file may include the standard library, "hausdorff.h", headers of its own
folder (bare names, "io.h"), and headers of lower layers by their path from
src/ ("points/points.h").  cli/ sees the public header and its own headers
only; so do tests/api/, whose tests use the public header and tests/support/
alone (the build does not give them src/ either); tests/internal/ and bench/
may include anything.  An argument names another
tree to check (tests/layers_check.py uses it to see the check fail).  Every violation is printed
as FILE:LINE: what, and the exit status is 1 when there is one.
"""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if len(sys.argv) > 1:  # another tree (the checker's own test)
    ROOT = os.path.abspath(sys.argv[1])
LEVEL = {"base": 0, "points": 1, "io": 2, "classic": 2, "engine": 2, "nearest": 2, "mesh": 2, "masks": 2, "": 3, "mpi": 4}
# The public headers: hausdorff.h anywhere, hausdorff_mpi.h only in the MPI
# library and the MPI tool (cli/mpi/).
PUBLIC_MPI = "hausdorff_mpi.h"
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def folder_of(rel):
    """'src/engine/grid.c' -> 'engine'; 'src/api.c' -> ''."""
    parts = rel.split("/")
    return parts[1] if len(parts) > 2 else ""


def check_src(rel, lines, bad):
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
        if "/" not in h:
            if not os.path.exists(os.path.join(ROOT, "src", own, h)):
                bad.append(f"{rel}:{n}: \"{h}\" is not a header of its own folder src/{own}/")
            continue
        if h.startswith("../"):
            bad.append(f"{rel}:{n}: \"{h}\": name headers of other layers from src/, not with ../")
            continue
        other = h.split("/")[0]
        if other not in LEVEL or other == "":
            bad.append(f"{rel}:{n}: \"{h}\" is not in a known layer")
        elif other != own and LEVEL[other] >= LEVEL[own]:
            bad.append(f"{rel}:{n}: src/{own or '.'}/ (layer {LEVEL[own]}) includes \"{h}\" "
                       f"(layer {LEVEL[other]}): only lower layers may be included")
        if not os.path.exists(os.path.join(ROOT, "src", h)):
            bad.append(f"{rel}:{n}: \"{h}\" does not exist under src/")


def check_cli(rel, lines, bad):
    for n, line in enumerate(lines, 1):
        m = INCLUDE.match(line)
        if m and m.group(1) == PUBLIC_MPI and rel.startswith("cli/mpi/"):
            continue
        # the tool's own headers: cli/'s, or its folder's (cli/mpi/mpi_cli.h)
        own = os.path.exists(os.path.join(ROOT, "cli", m.group(1))) or \
            os.path.exists(os.path.join(ROOT, os.path.dirname(rel), m.group(1))) if m else True
        if m and m.group(1) != "hausdorff.h" and not own:
            bad.append(f"{rel}:{n}: cli/ uses the public API only, not \"{m.group(1)}\"")


def check_api_tests(rel, lines, bad):
    for n, line in enumerate(lines, 1):
        m = INCLUDE.match(line)
        if m and m.group(1) != "hausdorff.h" and not os.path.exists(os.path.join(ROOT, "tests", "support", m.group(1))):
            bad.append(f"{rel}:{n}: tests/api/ uses the public header and tests/support/ only, "
                       f"not \"{m.group(1)}\" (a white-box test goes in tests/internal/)")


def main():
    bad = []
    count = 0
    for top, check in (("src", check_src), ("cli", check_cli), ("tests/api", check_api_tests)):
        for d, _, files in os.walk(os.path.join(ROOT, top)):
            for f in sorted(files):
                if not f.endswith((".c", ".h")):
                    continue
                path = os.path.join(d, f)
                rel = os.path.relpath(path, ROOT)
                with open(path, encoding="utf-8") as fh:
                    check(rel, fh.read().splitlines(), bad)
                count += 1
    for b in bad:
        print(b)
    print(f"layers: {count} files checked, {len(bad)} violations")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
