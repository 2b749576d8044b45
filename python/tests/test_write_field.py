"""write_field(): the deviation written back into the input's own format,
read back by parsers written here (not the library's readers): PLY with
numpy's structured dtypes, LAS from its header, VLRs and extra-bytes
descriptors, text by lines.  Every fixture format round-trips: the points
read back as before, the values bit for bit."""
import os
import shutil
import struct
import subprocess

import numpy as np
import pytest

import hausdorff

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
CORPUS = os.path.join(ROOT, "tests", "corpus")

PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
             "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
             "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def parse_ply(path):
    """(format, [(element, count, [(name, type or (count type, item type))])], data bytes)."""
    raw = open(path, "rb").read()
    end = raw.index(b"end_header") + len(b"end_header")
    end = raw.index(b"\n", end) + 1
    elements, fmt = [], None
    for line in raw[:end].decode().splitlines():
        w = line.split()
        if not w:
            continue
        if w[0] == "format":
            fmt = w[1]
        elif w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property":
            elements[-1][2].append((w[-1], (w[2], w[3]) if w[1] == "list" else w[1]))
    return fmt, elements, raw[end:]


def ply_vertices(path):
    """The vertex element as a structured array (fixed-size properties), and
    the bytes or lines of every other element."""
    fmt, elements, data = parse_ply(path)
    out, rest = None, []
    if fmt == "ascii":
        lines = data.decode().splitlines()
        at = 0
        for name, count, props in elements:
            rows = lines[at:at + count]
            at += count
            if name == "vertex":
                dt = np.dtype([(p, PLY_TYPES[t]) for p, t in props])
                out = np.zeros(count, dt)
                for k, row in enumerate(rows):
                    for (p, t), tok in zip(props, row.split()):
                        out[p][k] = float(tok) if t in ("float", "double", "float32", "float64") else int(tok)
            else:
                rest.append(rows)
        return out, rest
    order = "<" if fmt == "binary_little_endian" else ">"
    pos = 0
    for name, count, props in elements:
        if name == "vertex":
            dt = np.dtype([(p, order + PLY_TYPES[t]) for p, t in props])
            out = np.frombuffer(data, dt, count, pos)
            pos += count * dt.itemsize
        else:
            rest.append(data[pos:])  # the elements after the vertices, as bytes
            break
    return out, rest


def bits(a):
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def test_ply_fixtures_gain_the_property_and_keep_the_others(tmp_path):
    for name in ("ascii.ply", "binary_big_endian.ply", "binary_little_endian.ply", "binary_uint_faces.ply",
                 "face_first.ply"):
        src = os.path.join(CORPUS, "ply", name)
        pts = hausdorff.read(src)
        d = np.random.default_rng(len(name)).random(len(pts)) * 10
        out = tmp_path / name
        assert hausdorff.write_field(src, out, d) == len(pts)
        v0, rest0 = ply_vertices(src)
        v1, rest1 = ply_vertices(out)
        assert v1.dtype.names == v0.dtype.names + ("distance",), name
        for p in v0.dtype.names:
            assert np.array_equal(v0[p], v1[p]), (name, p)
        assert np.array_equal(bits(v1["distance"]), bits(d)), name
        assert rest0 == rest1, name  # faces and every other element as they were
        assert np.array_equal(hausdorff.read(out), pts)


def test_ply_from_real_distances_and_the_changed_points(tmp_path):
    a = os.path.join(ROOT, "data", "bunny_3511.ply")
    A = hausdorff.read(a)
    B = A + np.random.default_rng(7).normal(scale=1e-3, size=A.shape)
    d, _ = hausdorff.distances(A, B)
    out = tmp_path / "bunny_dev.ply"
    hausdorff.write_field(a, out, d)
    v, _ = ply_vertices(out)
    assert np.array_equal(bits(v["distance"]), bits(d))
    D = float(np.median(d))
    far, near = tmp_path / "far.ply", tmp_path / "near.ply"
    nf = hausdorff.write_field(a, far, d, farther_than=D)
    nn = hausdorff.write_field(a, near, d, nearer_than=D)
    assert nf == int((d > D).sum()) and nn == int((d <= D).sum()) and nf + nn == len(A)
    assert np.array_equal(hausdorff.read(far), A[d > D])
    vf, rest = ply_vertices(far)
    assert np.array_equal(bits(vf["distance"]), bits(d[d > D]))
    assert rest == [] or rest == [[]] or all(not r for r in rest)  # the subset is the vertices alone


def parse_las(path):
    """Header fields, the extra-bytes descriptors and the records, read here."""
    raw = open(path, "rb").read()
    assert raw[:4] == b"LASF"
    minor = raw[25]
    header, offset, n_vlr = struct.unpack_from("<HII", raw, 94)
    fmt, rec = raw[104] & 0x3F, struct.unpack_from("<H", raw, 105)[0]
    count = struct.unpack_from("<I", raw, 107)[0]
    if minor >= 4 and header >= 375:
        count = struct.unpack_from("<Q", raw, 247)[0] or count
    descriptors, p = [], header
    for _ in range(n_vlr):
        user, rid, length = raw[p + 2:p + 18].rstrip(b"\0"), *struct.unpack_from("<HH", raw, p + 18)
        if user == b"LASF_Spec" and rid == 4:
            for q in range(p + 54, p + 54 + length, 192):
                t, opts = raw[q + 2], raw[q + 3]
                descriptors.append((raw[q + 4:q + 36].rstrip(b"\0").decode(), t, opts))
        p += 54 + length
    base = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67][fmt]
    records = np.frombuffer(raw, np.dtype((np.void, rec)), count, offset)
    return dict(minor=minor, fmt=fmt, rec=rec, count=count, base=base, descriptors=descriptors,
                records=records, raw=raw)


def las_dimension(L, name):
    """The values of the extra-bytes dimension `name` (a double), found by
    walking the descriptors' sizes."""
    sizes = {1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 8, 8: 8, 9: 4, 10: 8}
    at = L["base"]
    for dname, t, opts in L["descriptors"]:
        size = opts if t == 0 else sizes[t]
        if dname == name:
            assert t == 10
            b = np.frombuffer(L["records"].tobytes(), np.uint8).reshape(-1, L["rec"])[:, at:at + 8]
            return np.ascontiguousarray(b).view("<f8").ravel()
        at += size
    raise KeyError(name)


def test_las_fixtures_gain_an_extra_bytes_dimension(tmp_path):
    files = [os.path.join(ROOT, "data", "orig", "Haystack_Rock.las")] + [
        os.path.join(CORPUS, "las", f) for f in ("v12_fmt0.las", "v14_fmt6.las")]
    for src in files:
        pts = hausdorff.read(src)
        d = np.random.default_rng(3).random(len(pts))
        d[::5] = 0.0
        out = tmp_path / os.path.basename(src)
        hausdorff.write_field(src, out, d)
        L0, L1 = parse_las(src), parse_las(out)
        assert L1["rec"] == L0["rec"] + 8 and L1["count"] == L0["count"] and L1["minor"] == L0["minor"]
        assert np.array_equal(bits(las_dimension(L1, "distance")), bits(d))
        old = np.frombuffer(L1["records"].tobytes(), np.uint8).reshape(-1, L1["rec"])[:, :L0["rec"]]
        assert old.tobytes() == L0["records"].tobytes()  # every record's own bytes
        assert np.array_equal(hausdorff.read(out), pts)
        far = tmp_path / ("far_" + os.path.basename(src))
        n = hausdorff.write_field(src, far, d, farther_than=0.5)
        Lf = parse_las(far)
        assert n == Lf["count"] == int((d > 0.5).sum())
        assert np.array_equal(bits(las_dimension(Lf, "distance")), bits(d[d > 0.5]))
        assert np.array_equal(hausdorff.read(far), pts[d > 0.5])


def test_laz_fixtures_read_back(tmp_path):
    for name in ("fmt6_channels.laz", "fmt6_variable_extra1.laz", "fmt0_chunks16.laz", "fmt1_variable.laz",
                 "fmt3_extra2.laz"):
        src = os.path.join(CORPUS, "laz", name)
        pts = hausdorff.read(src)
        out = tmp_path / name
        assert hausdorff.write_field(src, out, np.arange(len(pts), dtype=float)) == len(pts)
        assert np.array_equal(hausdorff.read(out), pts)
    with pytest.raises(ValueError, match="LASzip 1.x compression"):
        src = os.path.join(CORPUS, "laz", "fmt3_laszip1_extra1.laz")
        hausdorff.write_field(src, tmp_path / "x.laz", np.zeros(len(hausdorff.read(src))))


def test_text_fixtures_keep_their_lines(tmp_path):
    for name in ("plain.xyz", "header.csv", "leica.pts"):
        src = os.path.join(CORPUS, "xyz", name)
        pts = hausdorff.read(src)
        d = np.linspace(0, 1, len(pts)) / 3
        out = tmp_path / name
        hausdorff.write_field(src, out, d)
        assert np.array_equal(hausdorff.read(out), pts)
        lines0, lines1 = open(src).read().splitlines(), open(out).read().splitlines()
        assert len(lines0) == len(lines1)
        vals = []
        for a, b in zip(lines0, lines1):
            if a.rstrip() != b:
                assert b.startswith(a.rstrip())
                vals.append(b[len(a.rstrip()) + 1:])
        nums = [float(x) for x in vals if x != "distance"]
        assert np.array_equal(bits(np.array(nums)), bits(d))
    src = os.path.join(CORPUS, "obj", "mesh.obj")
    pts = hausdorff.read(src)
    d = np.arange(len(pts), dtype=float)
    n = hausdorff.write_field(src, tmp_path / "near.obj", d, nearer_than=1)
    assert n == 2 and np.array_equal(hausdorff.read(tmp_path / "near.obj"), pts[:2])


def test_several_fields_in_one_call_every_format(tmp_path):
    """A dict of fields: each becomes a PLY property, a LAS/LAZ extra-bytes
    dimension or a text column, in the dict's order, bit for bit; a subset
    is chosen by the first field."""
    cases = [os.path.join(CORPUS, "ply", f) for f in ("ascii.ply", "binary_big_endian.ply")] + [
        os.path.join(CORPUS, "las", f) for f in ("v12_fmt0.las", "v14_fmt6.las")] + [
        os.path.join(CORPUS, "laz", f) for f in ("fmt6_channels.laz", "fmt3_extra2.laz")] + [
        os.path.join(CORPUS, "xyz", "header.csv")]
    for src in cases:
        name = os.path.basename(src)
        pts = hausdorff.read(src)
        rng = np.random.default_rng(len(name))
        for nf in (2, 3):
            fields = {"distance": rng.random(len(pts)) * 10, "nearest": np.arange(len(pts), dtype=float),
                      "sign": np.where(np.arange(len(pts)) % 3, 1.0, -1.0)}
            fields = dict(list(fields.items())[:nf])
            for far in (None, 5.0):
                out = tmp_path / ("%d_%s_%s" % (nf, far, name))
                n = hausdorff.write_field(src, out, fields, farther_than=far)
                keep = fields["distance"] > far if far is not None else np.ones(len(pts), bool)
                assert n == int(keep.sum()), name
                if src.endswith(".laz"):
                    if far is None:  # the points as they were (the values: tests/laz_lazperf, test_write_laz)
                        assert np.array_equal(hausdorff.read(out), pts), name
                    continue
                assert np.array_equal(hausdorff.read(out), pts[keep]), name
                for j, (fname, v) in enumerate(fields.items()):
                    if src.endswith(".ply"):
                        got = ply_vertices(out)[0][fname]
                    elif src.endswith(".las"):
                        got = las_dimension(parse_las(out), fname)
                    else:
                        rows = open(out).read().splitlines()
                        assert rows[0].split(",")[-nf:] == list(fields), name
                        got = np.array([float(r.split(",")[j - nf]) for r in rows[1:]])
                    assert np.array_equal(bits(got), bits(v[keep])), (name, fname, far)


def test_refusals_raise_with_the_reason(tmp_path):
    src = os.path.join(CORPUS, "ply", "ascii.ply")
    n = len(hausdorff.read(src))
    with pytest.raises(ValueError, match="values for"):
        hausdorff.write_field(src, tmp_path / "a.ply", np.zeros(n + 1))
    with pytest.raises(ValueError, match="name it with the extension of that format"):
        hausdorff.write_field(src, tmp_path / "a.las", np.zeros(n))
    with pytest.raises(ValueError, match="not both"):
        hausdorff.write_field(src, tmp_path / "a.ply", np.zeros(n), farther_than=1, nearer_than=2)
    with pytest.raises(ValueError, match="one-dimensional"):
        hausdorff.write_field(src, tmp_path / "a.ply", np.zeros((n, 1)))
    with pytest.raises(OSError, match="cannot create"):
        hausdorff.write_field(src, tmp_path / "missing" / "a.ply", np.zeros(n))
    hausdorff.write_field(src, tmp_path / "b.ply", np.zeros(n))
    with pytest.raises(ValueError, match="already has a property 'distance'"):
        hausdorff.write_field(tmp_path / "b.ply", tmp_path / "c.ply", np.zeros(n))
    assert hausdorff.write_field(tmp_path / "b.ply", tmp_path / "c.ply", np.ones(n), name="second") == n
    assert not os.path.exists(tmp_path / "a.ply")
    with pytest.raises(ValueError, match="names are its keys"):
        hausdorff.write_field(src, tmp_path / "a.ply", {"distance": np.zeros(n)}, name="x")
    with pytest.raises(ValueError, match="'nearest' has 1 values"):
        hausdorff.write_field(src, tmp_path / "a.ply", {"distance": np.zeros(n), "nearest": np.zeros(1)})
    with pytest.raises(ValueError, match="already has a property 'distance'"):
        hausdorff.write_field(tmp_path / "b.ply", tmp_path / "a.ply", {"d2": np.zeros(n), "distance": np.zeros(n)})
    with pytest.raises(ValueError, match="empty"):
        hausdorff.write_field(src, tmp_path / "a.ply", {})
    assert not os.path.exists(tmp_path / "a.ply")


def test_a_full_disk_leaves_no_file(tmp_path):
    """ENOSPC from a 64 KiB tmpfs (mounting needs root)."""
    full = tmp_path / "full"
    full.mkdir()
    if os.geteuid() != 0 or not shutil.which("mount"):
        pytest.skip("NOT RUN: the full file system case needs root to mount a 64 KiB tmpfs")
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(full)], capture_output=True)
    if r.returncode != 0:
        pytest.skip("NOT RUN: cannot mount a 64 KiB tmpfs: %s" % r.stderr.decode().strip())
    try:
        src = tmp_path / "big.xyz"
        np.savetxt(src, np.random.default_rng(1).random((20000, 3)), fmt="%.17g")
        with pytest.raises(OSError, match="No space left on device"):
            hausdorff.write_field(src, full / "big.xyz", np.ones(20000))
        assert os.listdir(full) == []
    finally:
        subprocess.run(["umount", str(full)])
