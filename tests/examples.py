"""Every example command of the documentation runs as written.

The examples are taken from README.md (the lines of its ```sh blocks that
run build/hausdorff or build/hausdorff-mpi), from `hausdorff --help` and
`hausdorff-mpi --help` (the indented lines of "Examples:", a line ending in
a backslash joined with the next) and from docs/hausdorff.1 (each command
of its EXAMPLES section).  Each runs through /bin/sh, unchanged, in a
fixture directory whose files carry the examples' placeholder names, made
from the bundled models (data/README.md):

  scan.ply a.ply part.ply a.xyz scan.csv cloud.csv points.dat
      cgal_lion_head's points, as PLY, XYZ, CSV with a header, XYZ text
  model.ply b.ply reference.ply b.xyz reference.dat
      cgal_lion's points
  tiles2019/  cgal_lion_head's points in 4 XYZ tiles
  tiles2024.txt  a list of 3 tiles of cgal_lion's points (in tiles2024/)
  part.stl scan.las  data/orig/Wuson.stl, data/orig/Haystack_Rock.las
  seg.nii.gz truth.nii.gz  NIfTI-1 masks (two balls), spacing 0.8 mm
  build/hausdorff, build/hausdorff-mpi  the tools under test (also on PATH)

so every example comparing a head-like side with a lion-like side must
print h(head, lion) = H = 0.14468150162771326, the value data/README.md
gives (SciPy's, checked to the bit by the readers' tests).  A placeholder
name without a fixture makes its example fail: add the fixture here.

mpirun examples run on 2 processes with --allow-run-as-root
--oversubscribe (Open MPI refuses root, and more processes than slots,
without them), where hausdorff-mpi is built (HD_MPI_TOOL); NIfTI and PNG
examples where the tool has them (HD_CLI_NIFTI, HD_CLI_PNG).  A skipped
example is printed as skipped.

Usage: examples.py HAUSDORFF (hausdorff-mpi from HD_MPI_TOOL)
"""
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DATA = os.path.join(ROOT, "data")
sys.path.insert(0, HERE)
from cli_analysis_support import write_nifti  # noqa: E402  (numpy: Debian's python3-numpy)

import numpy as np  # noqa: E402

MPI_ENV = dict(os.environ, ASAN_OPTIONS="detect_leaks=0")  # Open MPI's own leaks, in a sanitizer build
HEAD_TO_LION = "0.14468150162771326"  # data/README.md: h(cgal_lion_head, cgal_lion), = H
HEAD = ("scan.ply", "a.ply", "part.ply", "a.xyz", "scan.csv", "cloud.csv", "points.dat", "tiles2019/")
LION = ("model.ply", "b.ply", "reference.ply", "b.xyz", "reference.dat", "@tiles2024.txt")


# ---- the examples, as the documents write them ----------------------------------

def readme_examples():
    out, block = [], False
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
        for line in f:
            if line.startswith("```"):
                block = line.strip() == "```sh"
                continue
            if block and re.search(r"(^|\s)build/hausdorff(-mpi)?\s", line):
                out.append(("README.md", line.rstrip("\n")))
    return out


def help_examples(tool, name):
    text = subprocess.run([tool, "--help"], capture_output=True, text=True, check=True, env=MPI_ENV).stdout
    out, inside, pending = [], False, ""
    for line in text.splitlines():
        if line == "Examples:":
            inside = True
            continue
        if not inside:
            continue
        if not line.strip():
            break
        if not line.startswith(" "):
            continue
        cmd = pending + line.strip()
        if cmd.endswith("\\"):
            pending = cmd[:-1]
            continue
        pending = ""
        out.append((name + " --help", cmd))
    return out


def man_examples():
    """The bold command after each .TP of the EXAMPLES section, unescaped."""
    out, inside, after_tp = [], False, False
    with open(os.path.join(ROOT, "docs", "hausdorff.1"), encoding="utf-8") as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith(".SH"):
                inside = line.strip() == ".SH EXAMPLES"
                continue
            if not inside:
                continue
            if line.startswith(".TP"):
                after_tp = True
                continue
            if after_tp and line.startswith(".B "):
                out.append(("docs/hausdorff.1", line[3:].replace("\\-", "-").replace("\\(dq", '"')))
            after_tp = False
    return out


# ---- the fixture directory ---------------------------------------------------------

def ply_points(name):
    """The vertices of a bundled ascii PLY as their text (each reads back exactly)."""
    with open(os.path.join(DATA, name)) as f:
        lines = f.read().splitlines()
    end = lines.index("end_header")
    n = int(next(l.split()[2] for l in lines[:end] if l.startswith("element vertex")))
    return [l.split() for l in lines[end + 1:end + 1 + n]]


def write_text(path, rows, sep=" ", header=None):
    with open(path, "w") as f:
        if header:
            f.write(header + "\n")
        for r in rows:
            f.write(sep.join(r) + "\n")


def ball(shape, centre, radius):
    i, j, k = np.indices(shape)
    return (((i - centre[0]) ** 2 + (j - centre[1]) ** 2 + (k - centre[2]) ** 2) <= radius ** 2).astype(np.uint8)


def make_fixtures(d, tool, mpi_tool):
    head, lion = ply_points("cgal_lion_head.ply"), ply_points("cgal_lion.ply")
    for name in ("scan.ply", "a.ply", "part.ply"):
        shutil.copy(os.path.join(DATA, "cgal_lion_head.ply"), os.path.join(d, name))
    for name in ("model.ply", "b.ply", "reference.ply"):
        shutil.copy(os.path.join(DATA, "cgal_lion.ply"), os.path.join(d, name))
    for name in ("a.xyz", "points.dat"):
        write_text(os.path.join(d, name), head)
    for name in ("b.xyz", "reference.dat"):
        write_text(os.path.join(d, name), lion)
    for name in ("scan.csv", "cloud.csv"):
        write_text(os.path.join(d, name), head, ",", "x,y,z")
    os.mkdir(os.path.join(d, "tiles2019"))
    for t in range(4):
        part = head[t * len(head) // 4:(t + 1) * len(head) // 4]
        write_text(os.path.join(d, "tiles2019", "t%d.xyz" % t), part)
    os.mkdir(os.path.join(d, "tiles2024"))
    with open(os.path.join(d, "tiles2024.txt"), "w") as f:
        f.write("# the 2024 epoch, west to east\n")
        for t in range(3):
            part = lion[t * len(lion) // 3:(t + 1) * len(lion) // 3]
            write_text(os.path.join(d, "tiles2024", "t%d.xyz" % t), part)
            f.write("tiles2024/t%d.xyz\n" % t)
    shutil.copy(os.path.join(DATA, "orig", "Wuson.stl"), os.path.join(d, "part.stl"))
    shutil.copy(os.path.join(DATA, "orig", "Haystack_Rock.las"), os.path.join(d, "scan.las"))
    lazperf = os.path.join(ROOT, "tests", "laz_lazperf")  # layered LAZ 1.4 whose every field varies
    shutil.copy(os.path.join(lazperf, "record_format6_channels_v4.laz"), os.path.join(d, "epoch1.laz"))
    shutil.copy(os.path.join(lazperf, "record_format7_v4.laz"), os.path.join(d, "epoch2.laz"))
    sp = (0.8, 0.8, 0.8)
    write_nifti(os.path.join(d, "seg.nii.gz"), ball((40, 40, 30), (20, 20, 15), 9), pixdim=sp)
    write_nifti(os.path.join(d, "truth.nii.gz"), ball((40, 40, 30), (21, 19, 15), 10), pixdim=sp)
    os.mkdir(os.path.join(d, "build"))
    os.symlink(os.path.abspath(tool), os.path.join(d, "build", "hausdorff"))
    if mpi_tool:
        os.symlink(os.path.abspath(mpi_tool), os.path.join(d, "build", "hausdorff-mpi"))


# ---- running one example -------------------------------------------------------------

def on_two_processes(cmd):
    """mpirun with -n 2, --allow-run-as-root and --oversubscribe, whatever
    process count and options the example gives."""
    words = shlex.split(cmd, comments=True)
    k = words.index("mpirun")
    rest, keep = words[k + 1:], []
    while rest and rest[0].startswith("-"):
        opt = rest.pop(0)
        if opt in ("-n", "-np", "-c"):
            rest.pop(0)
        elif opt not in ("--allow-run-as-root", "--oversubscribe"):
            keep.append(opt)
    words = words[:k + 1] + ["--allow-run-as-root", "--oversubscribe", "-n", "2"] + keep + rest
    return " ".join(shlex.quote(w) for w in words)


def outputs_of(words):
    """The files an example asks to be written."""
    files = []
    for opt, suffix in (("--render", None), ("--histogram-png", None), ("--distances", "_b")):
        if opt in words:
            path = words[words.index(opt) + 1]
            files.append(path)
            if suffix and "--directed" not in words:
                stem, ext = os.path.splitext(path)
                files.append(stem + suffix + ext)
    return files


def sides(words):
    """The two sides: the last two words, standard input named by the file
    `cat` pipes into it."""
    a, b = words[-2], words[-1]
    if a.endswith(":-") and words[0] == "cat":
        a = words[1]
    return a, b


def check_output(src, cmd, words, out):
    a, b = sides(words)
    if "--labels" in words:  # a table of labels (text, --csv or --json), no H line
        assert re.match(r"labels: [1-9]|label,|\{", out), (src, cmd, out)
        return
    if "--json" in words:
        j = json.loads(out)
        d = j["directed_ab"]
        assert isinstance(d, float) and d == d and d != float("inf"), (src, cmd, j)
        if a in HEAD and b in LION:
            assert repr(d) == HEAD_TO_LION, (src, cmd, d)
            assert "--directed" in words or repr(j["hausdorff"]) == HEAD_TO_LION, (src, cmd, j["hausdorff"])
        if "--percentile" in words:
            assert j["percentile"]["ab"] <= d, (src, cmd, j["percentile"])
        return
    m = re.search(r"(?:Hausdorff distance H\(A,B\)|^h\(A,B\)) = (\S+)", out, re.M)
    assert m, (src, cmd, out)
    assert float(m.group(1)) > 0, (src, cmd, out)
    if a in HEAD and b in LION:
        assert m.group(1) == HEAD_TO_LION, (src, cmd, out)
    if a == "part.stl" and "--sample" in words:  # the mesh sampled, the scan as its points
        n = words[words.index("--sample") + 1]
        assert "A: part.stl (%s points, stl sampled from 3732 faces)" % n in out, (src, cmd, out)
        assert "B: scan.las (21932 points, las)" in out, (src, cmd, out)
    if "--percentile" in words:
        assert "percentile P = " in out, (src, cmd, out)
    if "--mean" in words:
        assert "mean distance" in out, (src, cmd, out)


def run_example(d, src, cmd, env, mpi_tool):
    """None when it passed, else why it was skipped (an assertion fails it)."""
    words = shlex.split(cmd, comments=True)
    if "mpirun" in words:
        if not mpi_tool:
            return "hausdorff-mpi is not built (no MPI)"
        cmd = on_two_processes(cmd)
        words = shlex.split(cmd, comments=True)
    if any(w.endswith((".nii", ".nii.gz")) for w in words) and os.environ.get("HD_CLI_NIFTI") != "ON":
        return "the tool is built without libnifti2"
    if any(w in ("--render", "--histogram-png") for w in words) and os.environ.get("HD_CLI_PNG") != "ON":
        return "the tool is built without libpng"
    made = outputs_of(words)
    for f in made:
        if os.path.exists(os.path.join(d, f)):
            os.remove(os.path.join(d, f))
    if "hausdorff-mpi" in cmd:
        env = dict(env, ASAN_OPTIONS="detect_leaks=0")  # Open MPI's own leaks, in a sanitizer build
    p = subprocess.run(["/bin/sh", "-c", cmd], cwd=d, env=env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, "%s: `%s` (run as `%s`) exited %d\nstdout: %s\nstderr: %s" % (
        src, words, cmd, p.returncode, p.stdout, p.stderr)
    check_output(src, cmd, words, p.stdout)
    for f in made:
        assert os.path.getsize(os.path.join(d, f)) > 0, (src, cmd, f)
    return None


def main():
    tool = sys.argv[1]
    mpi_tool = os.environ.get("HD_MPI_TOOL") or None
    examples = readme_examples() + help_examples(tool, "hausdorff") + man_examples()
    if mpi_tool:
        examples += help_examples(mpi_tool, "hausdorff-mpi")
    counts = {}
    for src, _ in examples:
        counts[src] = counts.get(src, 0) + 1
    print("examples: %s" % ", ".join("%d from %s" % (n, s) for s, n in counts.items()))
    # every document shows examples, and the README's tool lines were found
    assert counts.get("README.md", 0) >= 8 and counts.get("hausdorff --help", 0) >= 6 and \
        counts.get("docs/hausdorff.1", 0) >= 6, counts
    failed = 0
    with tempfile.TemporaryDirectory(prefix="hd-examples-") as d:
        make_fixtures(d, tool, mpi_tool)
        env = dict(os.environ)
        env["PATH"] = os.path.join(d, "build") + os.pathsep + env.get("PATH", "")
        for src, cmd in examples:
            try:
                skipped = run_example(d, src, cmd, env, mpi_tool)
                print(("skip %s: %s (%s)" % (src, cmd, skipped)) if skipped else ("ok   %s: %s" % (src, cmd)))
            except Exception as e:  # report every failure, keep going
                failed += 1
                print("FAIL %s: %s\n  %s" % (src, cmd, e))
    print("%d examples, %d failed" % (len(examples), failed))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
