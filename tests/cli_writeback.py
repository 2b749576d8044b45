"""Command-line tests of the files written back into the inputs' formats:
--distances OUT when OUT has A's format (.las, .laz, text, and .ply when
A is a PLY file: a `distance` field added to A's file, B's to OUT_b; a PLY
also gets the table's `nearest`, and --surface's `face`; --signed adds
`sign`; .ply of a side that is not a PLY file, or into a FIFO, stays the
table), and
--farther-than D OUT / --nearer-than D OUT (the points past D in their
file's format), against the table --distances writes (.csv:
x,y,z,distance,nearest), which gives every distance: the field written
back equals it bit for bit (checked by parsers written here: text and PLY
ascii lines, LAS extra bytes).  Mismatched formats, --sample, masks,
are usage errors (exit 1) before
anything is read; a file that cannot be written is exit 3 and leaves none.
Layered LAZ subsets (formats 6-8) keep every record: the library's decoder
of whole records (lazgen --records) gives the input fixture's records as
laz-perf decoded them (tests/laz_lazperf/lazperf.txt) and the subset's as
those records with their distances.
Standard library only; run as:  cli_writeback.py PATH/TO/hausdorff PATH/TO/lazgen
"""
import hashlib
import json
import os
import resource
import shutil
import struct
import subprocess
import sys
import tempfile
import threading

TOOL = None
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
A = os.path.join(ROOT, "data", "pinion_gear.ply")  # ascii PLY
FACES = os.path.join(ROOT, "tests", "corpus", "ply", "binary_little_endian.ply")  # with faces
BIG_ENDIAN = os.path.join(ROOT, "tests", "corpus", "ply", "binary_big_endian.ply")
B = os.path.join(ROOT, "data", "teapot_792.ply")
LAS = os.path.join(ROOT, "data", "orig", "Haystack_Rock.las")
LAS_B = os.path.join(ROOT, "tests", "corpus", "las", "v14_fmt6.las")
LAZ = os.path.join(ROOT, "tests", "corpus", "laz", "fmt6_channels.laz")
LAZPERF_FIXTURES = os.path.join(ROOT, "tests", "laz_lazperf")
LAZGEN = None
TESTS = []


def test(fn):
    TESTS.append(fn)
    return fn


def run(*args):
    p = subprocess.run([TOOL] + list(args), capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout, p.stderr


def table(path):
    """The distances of a --distances CSV, as floats parsed from their text."""
    with open(path) as f:
        rows = f.read().splitlines()[1:]
    return [float(r.split(",")[3]) for r in rows]


def ply_field(path, name="distance"):
    """The values of a vertex property of an ascii PLY, parsed here."""
    with open(path) as f:
        lines = f.read().splitlines()
    end = lines.index("end_header")
    props, count, in_vertex = [], 0, False
    for line in lines[:end]:
        w = line.split()
        if w[:2] == ["element", "vertex"]:
            in_vertex, count = True, int(w[2])
        elif w and w[0] == "element":
            in_vertex = False
        elif in_vertex and w and w[0] == "property":
            props.append(w[-1])
    col = props.index(name)
    return [float(l.split()[col]) for l in lines[end + 1:end + 1 + count]]


def las_field(path, name="distance"):
    """An extra-bytes dimension (a double) of a LAS file, read from its VLR."""
    d = open(path, "rb").read()
    header, offset, n_vlr = struct.unpack_from("<HII", d, 94)
    fmt, rec = d[104] & 0x3F, struct.unpack_from("<H", d, 105)[0]
    count = struct.unpack_from("<I", d, 107)[0] or (struct.unpack_from("<Q", d, 247)[0] if header >= 375 else 0)
    at, p = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67][fmt], header
    for _ in range(n_vlr):
        length = struct.unpack_from("<H", d, p + 20)[0]
        if d[p + 2:p + 11] == b"LASF_Spec" and struct.unpack_from("<H", d, p + 18)[0] == 4:
            for q in range(p + 54, p + 54 + length, 192):
                if d[q + 4:q + 36].rstrip(b"\0").decode() == name:
                    return [struct.unpack_from("<d", d, offset + k * rec + at)[0] for k in range(count)]
                at += d[q + 3] if d[q + 2] == 0 else 8
        p += 54 + length
    raise KeyError(name)


PLY_TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h", "ushort": "H",
             "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I", "float": "f", "float32": "f",
             "double": "d", "float64": "d"}


def read_ply(path):
    """A PLY file (ascii or binary, either byte order) parsed here: (header
    lines, [(element, [property names], [rows])]), a row a tuple of values
    (a list property's values as a tuple)."""
    data = open(path, "rb").read()
    end = data.index(b"end_header") + len(b"end_header")
    end = data.index(b"\n", end) + 1
    header = data[:end].decode().splitlines()
    fmt = header[1].split()[1]
    elems = []
    for line in header:
        w = line.split()
        if w[:1] == ["element"]:
            elems.append((w[1], int(w[2]), []))
        elif w[:1] == ["property"]:
            elems[-1][2].append((w[-1], w[1:-1]))
    bo = ">" if fmt == "binary_big_endian" else "<"
    pos, out = end, []
    text = data[end:].decode().split() if fmt == "ascii" else None
    t = 0
    for name, count, props in elems:
        rows = []
        for _ in range(count):
            row = []
            for pname, kind in props:
                if kind[0] == "list":
                    if text is not None:
                        n = int(text[t]); t += 1
                        row.append(tuple(float(x) for x in text[t:t + n])); t += n
                    else:
                        c = PLY_TYPES[kind[1]]
                        n = struct.unpack_from(bo + c, data, pos)[0]; pos += struct.calcsize(c)
                        e = PLY_TYPES[kind[2]]
                        row.append(struct.unpack_from(bo + e * n, data, pos)); pos += n * struct.calcsize(e)
                elif text is not None:
                    row.append(float(text[t])); t += 1
                else:
                    c = PLY_TYPES[kind[0]]
                    row.append(struct.unpack_from(bo + c, data, pos)[0]); pos += struct.calcsize(c)
            rows.append(tuple(row))
        out.append((name, [p for p, _ in props], rows))
    return header, out


def table_columns(path):
    """The columns of a --distances CSV by name, as floats parsed from their text."""
    with open(path) as f:
        rows = f.read().splitlines()
    names = rows[0].split(",")
    return {n: [float(r.split(",")[i]) for r in rows[1:]] for i, n in enumerate(names)}


def check_written_back(inp, out, fields):
    """out is inp with the vertex properties fields (name: values, equal bit
    for bit) appended, every other element and property as they were."""
    h_in, e_in = read_ply(inp)
    h_out, e_out = read_ply(out)
    adds = ["property double %s" % n for n in fields]
    at = h_out.index(adds[0])
    assert h_out[:at] + h_out[at + len(adds):] == h_in and h_out[at:at + len(adds)] == adds, (h_in, h_out)
    for (name, props, rows), (name2, props2, rows2) in zip(e_in, e_out):
        if name != "vertex":
            assert (name, props, rows) == (name2, props2, rows2), name
            continue
        assert props2 == props + list(fields), props2
        assert [r[:len(props)] for r in rows2] == rows, "the vertices' own properties changed"
        for k, (n, want) in enumerate(fields.items()):
            got = [r[len(props) + k] for r in rows2]
            assert [struct.pack("<d", x) for x in got] == [struct.pack("<d", x) for x in want], n


@test
def a_ply_side_gets_distance_and_nearest_in_its_own_file(tmp):
    """--distances OUT.ply writes a PLY A (binary, with faces) and a PLY B
    (ascii, big-endian binary) back: the table's distance and nearest as
    doubles, every other element and property kept."""
    for a, b in ((FACES, B), (A, BIG_ENDIAN)):
        rc, out, err = run("--distances", tmp + "/t.csv", a, b)
        assert rc == 0, err
        rc, out, err = run("--json", "--distances", tmp + "/w.ply", a, b)
        assert rc == 0, err
        j = json.loads(out)
        assert j.get("distances_written_back", {}).get("a", {}).get("file") == tmp + "/w.ply" and \
            "distances_file" not in j, j
        for side, path in (("", a), ("_b", b)):
            t = table_columns(tmp + "/t%s.csv" % side)
            check_written_back(path, tmp + "/w%s.ply" % side, {"distance": t["distance"], "nearest": t["nearest"]})


@test
def other_sides_get_the_table_and_fifos_the_file_written_back(tmp):
    """.ply of a side that is not a PLY file is the table; a FIFO gets the
    bytes a regular file gets (PLY and LAS written back); a text A gets its
    column."""
    xyz = os.path.join(tmp, "a.xyz")
    with open(xyz, "w") as f:
        f.write("# a comment\n1.5 2 3\n4 5 6.25\n")
    rc, out, err = run("--distances", tmp + "/t.ply", xyz, B)
    assert rc == 0, err
    head = open(tmp + "/t.ply", "rb").read().split(b"end_header")[0].decode()
    assert "property int nearest" in head and "element face" not in head, head
    head = open(tmp + "/t_b.ply", "rb").read().split(b"end_header")[0].decode()
    assert "property double distance\nproperty double nearest\nend_header" in head + "end_header", head
    for a, ext, more in ((FACES, "ply", []), (LAS, "las", ["--surface", "--signed"])):
        b = B if ext == "ply" else os.path.join(tmp, "cube.off")
        with open(os.path.join(tmp, "cube.off"), "w") as f:
            f.write(CUBE)
        fifo = os.path.join(tmp, "fifo." + ext)
        os.mkfifo(fifo)
        got = []
        reader = threading.Thread(target=lambda: got.append(open(fifo, "rb").read()))
        reader.start()
        rc, out, err = run(*more, "--directed", "--distances", fifo, a, b)
        if reader.is_alive():
            open(fifo, "wb").close()
        reader.join()
        rc2, out2, err2 = run(*more, "--directed", "--distances", tmp + "/r." + ext, a, b)
        assert rc == 0 and rc2 == 0 and got and got[0] == open(tmp + "/r." + ext, "rb").read(), (ext, rc, err, err2)
    assert sorted(os.listdir(tmp)) == sorted(["a.xyz", "t.ply", "t_b.ply", "cube.off", "fifo.ply", "fifo.las",
                                              "r.ply", "r.las"]), os.listdir(tmp)
    rc, out, err = run("--directed", "--distances", tmp + "/t.csv", xyz, B)
    assert rc == 0, err
    rc, out, err = run("--directed", "--distances", tmp + "/w.txt", xyz, B)
    assert rc == 0, err
    lines = open(tmp + "/w.txt").read().splitlines()
    assert lines[0] == "# a comment" and lines[1].startswith("1.5 2 3 ") and lines[2].startswith("4 5 6.25 "), lines
    assert [float(l.split()[3]) for l in lines[1:]] == table(tmp + "/t.csv")


CUBE = ("OFF\n8 12 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
        "3 0 2 3\n3 0 3 1\n3 4 5 7\n3 4 7 6\n3 0 1 5\n3 0 5 4\n3 2 6 7\n3 2 7 3\n3 0 4 6\n3 0 6 2\n"
        "3 1 3 7\n3 1 7 5\n")


@test
def surface_distances_are_written_back_with_face_and_sign(tmp):
    """--surface --signed: A's PLY gets distance, face and sign, its LAS
    distance and sign, its subsets distance and sign, equal to the table's."""
    cube = os.path.join(tmp, "cube.off")
    with open(cube, "w") as f:
        f.write(CUBE)
    pts = [(0.5, 0.5, 0.5), (2, 0.5, 0.5), (0.5, 0, 0), (0.25, 0.5, 0.75), (-1, 0.125, 3.5)]
    ply = os.path.join(tmp, "p.ply")
    with open(ply, "wb") as f:
        f.write(b"ply\nformat binary_big_endian 1.0\nelement vertex 5\nproperty double x\nproperty float y\n"
                b"property double z\nproperty uchar q\nend_header\n")
        for k, (x, y, z) in enumerate(pts):
            f.write(struct.pack(">dfdB", x, y, z, k))
    rc, out, err = run("--surface", "--signed", "--distances", tmp + "/t.csv", ply, cube)
    assert rc == 0, err
    t = table_columns(tmp + "/t.csv")
    rc, out, err = run("--surface", "--signed", "--distances", tmp + "/w.ply", "--farther-than", "0.25",
                       tmp + "/f.ply", ply, cube)
    assert rc == 0, err
    check_written_back(ply, tmp + "/w.ply", {"distance": t["distance"], "face": t["face"], "sign": t["sign"]})
    far = [k for k, d in enumerate(t["distance"]) if d > 0.25]
    _, el = read_ply(tmp + "/f.ply")
    assert el[0][1][-2:] == ["distance", "sign"] and [r[-2:] for r in el[0][2]] == \
        [(t["distance"][k], t["sign"][k]) for k in far], el
    rc, out, err = run("--surface", "--signed", "--distances", tmp + "/t.csv", LAS, cube)
    assert rc == 0, err
    t = table_columns(tmp + "/t.csv")
    rc, out, err = run("--surface", "--signed", "--distances", tmp + "/w.las", LAS, cube)
    assert rc == 0, err
    assert las_field(tmp + "/w.las") == t["distance"] and las_field(tmp + "/w.las", "sign") == t["sign"]


@test
def farther_and_nearer_split_the_points(tmp):
    d = table_of(tmp)
    D = sorted(d)[len(d) // 2]
    rc, out, err = run("--json", "--farther-than", str(D), tmp + "/far.ply", "--nearer-than", str(D), tmp + "/near.ply",
                       A, B)
    assert rc == 0, err
    j = json.loads(out)
    far, near = ply_field(tmp + "/far.ply"), ply_field(tmp + "/near.ply")
    assert far == [x for x in d if x > D] and near == [x for x in d if x <= D]
    assert j["farther_than"]["a"] == {"file": tmp + "/far.ply", "points": len(far)}
    assert j["nearer_than"]["b"]["points"] + j["farther_than"]["b"]["points"] == 792
    head = open(tmp + "/far.ply").read().split("end_header")[0]
    assert "element vertex %d" % len(far) in head and "element face" not in head


def table_of(tmp):
    rc, out, err = run("--directed", "--distances", tmp + "/d.csv", A, B)
    assert rc == 0, err
    return table(tmp + "/d.csv")


@test
def las_gets_an_extra_bytes_dimension(tmp):
    rc, out, err = run("--directed", "--distances", tmp + "/t.csv", LAS, LAS_B)
    assert rc == 0, err
    rc, out, err = run("--directed", "--distances", tmp + "/w.las", LAS, LAS_B)
    assert rc == 0, err
    assert las_field(tmp + "/w.las") == table(tmp + "/t.csv")
    rc, out, err = run("--directed", "--farther-than", "0", tmp + "/f.las", LAS, LAS_B)
    assert rc == 0, err
    assert las_field(tmp + "/f.las") == [x for x in table(tmp + "/t.csv") if x > 0]


@test
def laz_written_back_reads_back(tmp):
    rc, out, err = run("--directed", "--distances", tmp + "/w.laz", LAZ, LAS_B)
    assert rc == 0, err
    rc2, out2, err2 = run("--directed", tmp + "/w.laz", LAS_B)
    rc3, out3, err3 = run("--directed", LAZ, LAS_B)
    assert rc2 == 0 and out2.splitlines()[2] == out3.splitlines()[2], (err2, out2, out3)  # h(A,B)


def laz_records(path):
    """Every whole record of a LAZ file as the library decodes it (every
    field, every layer: lazgen --records)."""
    p = subprocess.run([LAZGEN, "--records", path], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    return [bytes.fromhex(l) for l in p.stdout.split()]


def lazperf_digest(name):
    """laz-perf's decoding of fixture NAME (tests/laz_lazperf/lazperf.txt):
    its count and the SHA-256 of its records' hexadecimal lines."""
    for line in open(os.path.join(LAZPERF_FIXTURES, "lazperf.txt")):
        w = line.split()
        if w and w[0] == name:
            return int(w[1]), w[2]
    raise AssertionError("no fixture " + name)


@test
def layered_laz_subsets_keep_every_record(tmp):
    # inputs whose every field varies (POINT14's nine layers in four scanner
    # channels; RGB14), as laz-perf decoded them
    for name in ("record_format6_channels_v3", "record_format7_v4"):
        a = os.path.join(LAZPERF_FIXTURES, name + ".laz")
        recs = laz_records(a)
        lines = "".join(r.hex() + "\n" for r in recs).encode()
        assert (len(recs), hashlib.sha256(lines).hexdigest()) == lazperf_digest(name), name
        rc, out, err = run("--directed", "--distances", tmp + "/t.csv", a, LAS_B)
        assert rc == 0, err
        d = table(tmp + "/t.csv")
        D = sorted(d)[len(d) // 2]
        rc, out, err = run("--directed", "--json", "--farther-than", str(D), tmp + "/far.laz", "--nearer-than", str(D),
                           tmp + "/near.laz", a, LAS_B)
        assert rc == 0, err
        j = json.loads(out)
        for part, keep in (("far", lambda x: x > D), ("near", lambda x: x <= D)):
            path = tmp + "/" + part + ".laz"
            want = [recs[k] + struct.pack("<d", d[k]) for k in range(len(d)) if keep(d[k])]
            got = laz_records(path)
            assert got == want, (name, part, len(got), len(want))
            data = open(path, "rb").read()
            assert struct.unpack_from("<Q", data, 247)[0] == len(want), (name, part)
            key = "farther_than" if part == "far" else "nearer_than"
            assert j[key]["a"]["points"] == len(want), (name, j[key])
            # the project's reader (the x/y and z layers) reads the subset back
            rc, out, err = run("--directed", "--distances", tmp + "/" + part + ".csv", path, LAS_B)
            assert rc == 0, err
            assert table(tmp + "/" + part + ".csv") == [x for x in d if keep(x)], (name, part)


@test
def mismatches_are_usage_errors_before_reading(tmp):
    cases = [
        (["--distances", tmp + "/o.las", A, B], "A (%s) is ply, %s/o.las is las" % (A, tmp)),
        (["--farther-than", "1", tmp + "/o.ply", LAS, B], "is las, %s/o.ply is ply" % tmp),
        (["--farther-than", "1", tmp + "/o.ply", A, LAS], "B (%s) is las" % LAS),
        (["--sample", "100", "--farther-than", "0", tmp + "/o.ply", FACES, B],
         "with --sample the points are drawn on the faces"),
        (["--farther-than", "x", tmp + "/o.ply", A, B], "needs a distance >= 0"),
        (["--farther-than", "1", tmp + "/o.dat", A, B], "cannot tell the format of"),
        (["--farther-than", "1"], "needs a distance and a file"),
        (["--surface", "--farther-than", "1", tmp + "/o.las", A, B], "A (%s) is ply, %s/o.las is las" % (A, tmp)),
    ]
    for args, needle in cases:
        rc, out, err = run(*args)
        assert rc == 1, (args, rc, err)
        assert err.startswith("hausdorff: ") and needle in err, (args, err)
    assert os.listdir(tmp) == [], os.listdir(tmp)


@test
def an_unwritable_file_is_exit_3_and_leaves_nothing(tmp):
    rc, out, err = run("--farther-than", "0", tmp + "/missing/far.ply", A, B)
    assert rc == 3, (rc, err)
    assert err.startswith("hausdorff: %s/missing/far.ply: cannot write" % tmp), err
    rc, out, err = run("--directed", "--distances", tmp + "/w.ply", tmp + "/x.ply", B)
    assert rc == 2, (rc, err)  # A missing: its read fails before anything is written
    assert os.listdir(tmp) == [], os.listdir(tmp)
    # a file size limit above the size of the file with `distance` alone
    # (30,172 bytes) and below the one with `nearest` too: exit 3, and no
    # temporary left
    limit = lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (31000, 31000))
    p = subprocess.run([TOOL, "--directed", "--distances", tmp + "/w.ply", A, B], capture_output=True, text=True,
                       timeout=300, preexec_fn=limit)
    assert p.returncode == 3 and "w.ply: cannot write: File too large" in p.stderr, (p.returncode, p.stderr)
    assert os.listdir(tmp) == [], os.listdir(tmp)


@test
def a_field_already_there_is_refused(tmp):
    rc, out, err = run("--directed", "--farther-than", "0", tmp + "/w.ply", A, B)
    assert rc == 0, err
    rc, out, err = run("--directed", "--farther-than", "0", tmp + "/w2.ply", tmp + "/w.ply", B)
    assert rc != 0 and "already has a property 'distance'" in err, (rc, err)
    assert not os.path.exists(tmp + "/w2.ply")


def main():
    global TOOL, LAZGEN
    TOOL = os.path.abspath(sys.argv[1])
    LAZGEN = os.path.abspath(sys.argv[2])
    passed = failed = 0
    for fn in TESTS:
        tmp = tempfile.mkdtemp(prefix="hd-writeback-")
        try:
            fn(tmp)
            passed += 1
            print("ok   " + fn.__name__)
        except AssertionError as e:
            failed += 1
            print("FAIL %s: %s" % (fn.__name__, e))
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    print("%d passed, %d failed" % (passed, failed))
    sys.exit(1 if failed else 0)


main()
