"""Shared helpers of the analysis tests (cli_analysis*.py): a tiny runner,
the command line, files written byte by byte, and the brute force.

The brute force is numpy with every operation spelled out in the library's
order: d2 = (dx*dx + dy*dy) + dz*dz elementwise in float64 (numpy does not
fuse multiply-adds across separate ufunc calls), the minimum and the first
index attaining it (argmin), one sqrt.  Percentiles and histograms are
numpy's own (np.percentile, np.histogram), the reference for bit-exactness.
"""
import gzip
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import traceback
import zlib

import numpy as np

from nifti_header import nifti_header  # tests/nifti_header.py

TESTS = []


def test(fn):
    TESTS.append(fn)
    return fn


def main():
    """Run every @test (or those whose name contains argv[2])."""
    only = sys.argv[2] if len(sys.argv) > 2 else ""
    failed = 0
    for fn in TESTS:
        if only not in fn.__name__:
            continue
        try:
            with tempfile.TemporaryDirectory(prefix="hd-analysis-") as tmp:
                fn(tmp)
            print("ok   " + fn.__name__)
        except Exception:  # report every failure, keep going
            failed += 1
            print("FAIL " + fn.__name__)
            traceback.print_exc()
    print("%d passed, %d failed" % (len(TESTS) - failed, failed))
    sys.exit(1 if failed else 0)


def tool():
    return sys.argv[1]


def run(args, expect=0):
    """Run the tool; return (stdout, stderr), checking the exit status."""
    p = subprocess.run([tool()] + [str(a) for a in args], capture_output=True, text=True)
    if p.returncode != expect:
        raise AssertionError("exit %d (expected %d) for %s\nstdout: %s\nstderr: %s"
                             % (p.returncode, expect, args, p.stdout, p.stderr))
    return p.stdout, p.stderr


def run_json(args):
    out, _ = run(["--json"] + list(args))
    return json.loads(out)


def write_xyz(path, pts):
    with open(path, "w") as f:
        for p in pts:
            f.write("%r %r %r\n" % (float(p[0]), float(p[1]), float(p[2])))


def write_pair(tmp, a, b, names=("a.xyz", "b.xyz"), **kw):
    """A and B written into tmp under the two names: XYZ, or NIfTI masks
    (write_nifti, with kw) for .nii names; their two paths."""
    paths = tuple(os.path.join(tmp, name) for name in names)
    for path, v in zip(paths, (a, b)):
        if path.endswith((".nii", ".nii.gz")):
            write_nifti(path, v, **kw)
        else:
            write_xyz(path, v)
    return paths


def nearest(q, b):
    """(distance, nearest index) of every point of q to b, brute force."""
    d = np.empty(len(q))
    j = np.empty(len(q), dtype=np.int64)
    for s in range(0, len(q), 256):
        qq = q[s:s + 256, None, :]
        dx = qq[..., 0] - b[None, :, 0]
        dy = qq[..., 1] - b[None, :, 1]
        dz = qq[..., 2] - b[None, :, 2]
        d2 = (dx * dx + dy * dy) + dz * dz
        jj = np.argmin(d2, axis=1)
        j[s:s + 256] = jj
        d[s:s + 256] = np.sqrt(d2[np.arange(len(jj)), jj])
    return d, j


def value(x):
    """A JSON number as a double: null stands for NaN."""
    return math.nan if x is None else x


def same(a, b, what=""):
    """Bit-identical doubles (None in JSON stands for NaN/inf)."""
    fa, fb = float(a), float(b)
    if fa.hex() != fb.hex() and not (np.isnan(fa) and np.isnan(fb)):
        raise AssertionError("%s: %r != %r (%s vs %s)" % (what, fa, fb, fa.hex(), fb.hex()))


def lattice_clouds(seed, na, nb, side=6):
    """Clouds on an integer lattice: many equidistant neighbours (ties)."""
    r = np.random.default_rng(seed)
    a = r.integers(0, side, size=(na, 3)).astype(np.float64)
    b = r.integers(0, side, size=(nb, 3)).astype(np.float64) + np.array([0.5, 0, 0])
    return a, b


def read_png(path):
    """An 8-bit RGB, non-interlaced PNG as an (h, w, 3) uint8 array (the
    tool writes only those), decoded here so no imaging library is needed."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, w = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert (depth, ctype, interlace) == (8, 2, 0), "8-bit RGB, not interlaced"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = 3 * w
    img = np.zeros((h, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(h):
        ftype = raw[y * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1).astype(np.int32)
        if ftype == 0:
            cur = line
        elif ftype == 2:
            cur = (line + prev) & 255
        else:  # sub (1), average (3), Paeth (4) depend on the left neighbour
            cur = np.zeros(stride, dtype=np.int32)
            for x in range(stride):
                a = cur[x - 3] if x >= 3 else 0
                b, c = prev[x], (prev[x - 3] if x >= 3 else 0)
                if ftype == 1:
                    pred = a
                elif ftype == 3:
                    pred = (a + b) // 2
                else:
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + pred) & 255
        img[y] = cur
        prev = cur
    return img.reshape(h, w, 3).astype(np.uint8)


# ---- NIfTI written byte by byte (nibabel is not needed) -----------------------

DT = {np.dtype(np.uint8): (2, 8), np.dtype(np.int16): (4, 16), np.dtype(np.int32): (8, 32),
      np.dtype(np.float32): (16, 32), np.dtype(np.float64): (64, 64)}


def write_nifti(path, vol, pixdim=(1, 1, 1), sform=None, qform=None, version=1, units=2):
    """Write vol (x, y, z indexing; i fastest on disk) as NIfTI-1 or -2.
    sform: 3x4 rows (srow_x, srow_y, srow_z), sform_code 1.  qform: dict with
    b, c, d, qfac and offset (qform_code 1).  .gz names are gzipped."""
    vol = np.asarray(vol)
    code, bitpix = DT[vol.dtype]
    dims = [3, vol.shape[0], vol.shape[1], vol.shape[2], 1, 1, 1, 1]
    qfac = qform["qfac"] if qform else 1.0
    pd = [qfac, pixdim[0], pixdim[1], pixdim[2], 1, 1, 1, 1]
    quatern = (qform["b"], qform["c"], qform["d"], *qform["offset"]) if qform else None
    rows = np.asarray(sform, dtype=np.float64) if sform is not None else None
    head = nifti_header(version, dims, code, bitpix, pd, quatern=quatern, sform=rows, units=units)
    data = head + np.asarray(vol, dtype=vol.dtype.newbyteorder("<")).tobytes(order="F")
    if path.endswith(".gz"):
        with gzip.open(path, "wb") as f:
            f.write(data)
    else:
        with open(path, "wb") as f:
            f.write(data)


def stored(rows, version):
    """The transform as the file stores it: float32 in NIfTI-1."""
    rows = np.asarray(rows, dtype=np.float64)
    return rows.astype(np.float32).astype(np.float64) if version == 1 else rows


def world(ijk, m):
    """World coordinates in the tool's documented order:
    x = ((m00*i + m01*j) + m02*k) + m03, and so on."""
    i, j, k = (ijk[:, 0].astype(np.float64), ijk[:, 1].astype(np.float64),
               ijk[:, 2].astype(np.float64))
    out = np.empty((len(ijk), 3))
    for c in range(3):
        out[:, c] = ((m[c, 0] * i + m[c, 1] * j) + m[c, 2] * k) + m[c, 3]
    return out


def voxels(mask, surface):
    """Foreground (or surface) voxel indices in storage order (i fastest):
    surface = foreground with a 6-neighbour in the background or outside."""
    fg = mask != 0
    keep = fg.copy()
    if surface:
        p = np.pad(fg, 1, constant_values=False)
        inner = (p[:-2, 1:-1, 1:-1] & p[2:, 1:-1, 1:-1] & p[1:-1, :-2, 1:-1] &
                 p[1:-1, 2:, 1:-1] & p[1:-1, 1:-1, :-2] & p[1:-1, 1:-1, 2:])
        keep = fg & ~inner
    idx = np.argwhere(keep)  # C order: i slowest; reorder to storage order
    order = np.lexsort((idx[:, 0], idx[:, 1], idx[:, 2]))
    return idx[order]
