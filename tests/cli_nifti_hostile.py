"""NIfTI masks whose headers lie: the tool checks the header itself before
libnifti2 reads any voxel, and refuses with exit status 2 and one line
"hausdorff: FILE: what is wrong" (naming the field) instead of crashing,
reading the wrong bytes, allocating gigabytes or answering from NaN.

Every case here failed before cli/nifti.c checked the header (a SIGSEGV, a
wrong distance with exit 0, a message without the file, or libnifti2's own
'** ERROR' lines ahead of ours); the docstring of each test says how.

usage: cli_nifti_hostile.py HAUSDORFF [NAME-FILTER]
"""
import gzip
import os
import struct
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_analysis_support import main, run, run_json, test, tool, voxels, write_nifti  # noqa: E402

NAN, INF = float("nan"), float("inf")
BITPIX = {2: 8, 4: 16, 8: 32, 16: 32, 64: 64, 256: 8, 512: 16, 768: 32, 1024: 64, 1280: 64, 128: 24}


def header(version=1, dims=(3, 4, 5, 6), datatype=2, pixdim=(1, 1, 1), qfac=1.0, vox_offset=None,
           qform=None, sform=None, units=2, endian="<", magic=None):
    """A NIfTI-1 (348 bytes) or NIfTI-2 (540 bytes) header plus the 4
    extension bytes, every field settable, in either byte order.
    qform: (code, (b, c, d, x, y, z)); sform: (code, 3x4 rows)."""
    e = endian
    dims = list(dims) + [1] * (8 - len(dims))
    pd = [qfac] + list(pixdim) + [1] * (7 - len(pixdim))
    qcode, qv = qform if qform else (0, (0, 0, 0, 0, 0, 0))
    scode, rows = sform if sform else (0, np.zeros((3, 4)))
    rows = np.asarray(rows, dtype=np.float64)
    bitpix = BITPIX.get(datatype, 8)
    if version == 1:
        h = bytearray(348)
        struct.pack_into(e + "i", h, 0, 348)
        struct.pack_into(e + "8h", h, 40, *dims)
        struct.pack_into(e + "hh", h, 70, datatype, bitpix)
        struct.pack_into(e + "8f", h, 76, *pd)
        struct.pack_into(e + "f", h, 108, 352.0 if vox_offset is None else vox_offset)
        struct.pack_into(e + "f", h, 112, 1.0)
        struct.pack_into("B", h, 123, units)
        struct.pack_into(e + "hh", h, 252, qcode, scode)
        struct.pack_into(e + "6f", h, 256, *qv)
        for r in range(3):
            struct.pack_into(e + "4f", h, 280 + 16 * r, *rows[r])
        h[344:348] = b"n+1\0" if magic is None else magic
    else:
        h = bytearray(540)
        struct.pack_into(e + "i", h, 0, 540)
        h[4:12] = b"n+2\0\r\n\x1a\n" if magic is None else magic
        struct.pack_into(e + "hh", h, 12, datatype, bitpix)
        struct.pack_into(e + "8q", h, 16, *dims)
        struct.pack_into(e + "8d", h, 104, *pd)
        struct.pack_into(e + "q", h, 168, 544 if vox_offset is None else vox_offset)
        struct.pack_into(e + "d", h, 176, 1.0)
        struct.pack_into(e + "ii", h, 344, qcode, scode)
        struct.pack_into(e + "6d", h, 352, *qv)
        for r in range(3):
            struct.pack_into(e + "4d", h, 400 + 32 * r, *rows[r])
        struct.pack_into(e + "i", h, 500, units)
    return bytes(h) + b"\0\0\0\0"


def put(path, head, data=b""):
    raw = head + data
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "wb") as f:
        f.write(raw)
    return path


def box(shape=(4, 5, 6)):
    """A small mask: a 2x3x3 block of ones, Fortran order bytes."""
    m = np.zeros(shape, np.uint8)
    m[1:3, 1:4, 2:5] = 1
    return m, m.tobytes(order="F")


def reference(tmp, version=1):
    m, _ = box()
    p = os.path.join(tmp, "good%d.nii" % version)
    write_nifti(p, m, version=version)
    return p


def refused(tmp, path, *words, args=()):
    """The tool refuses PATH (as B, against a good mask) with exit status 2
    and exactly one line: 'hausdorff: PATH: ...' containing every word."""
    p = subprocess.run([tool()] + list(args) + [reference(tmp), path], capture_output=True, text=True)
    assert p.returncode == 2, "exit %d for %s\nstdout: %s\nstderr: %s" % (
        p.returncode, os.path.basename(path), p.stdout[:300], p.stderr)
    lines = p.stderr.splitlines()
    assert len(lines) == 1, "one line expected, got:\n" + p.stderr
    assert lines[0].startswith("hausdorff: %s: " % path), lines[0]
    for w in words:
        assert w in lines[0], "%r not in %r" % (w, lines[0])
    return lines[0]


@test
def dims_whose_product_wraps_past_2_64_are_refused_not_walked(tmp):
    """Issue 17: 3 * 6148914691236517206 = 2^64 + 2.  libnifti2's int64 voxel
    count wraps to 2, it reads 2 bytes, and the tool walked 2^64 voxels
    (SIGSEGV).  Now refused from the header, naming the overflow."""
    p = put(os.path.join(tmp, "wrap.nii"), header(2, (3, 3, 6148914691236517206, 1)), b"\1\1")
    refused(tmp, p, "overflow")
    # 2^64 exactly (wraps to 0) and, in NIfTI-1, 32767^7 (about 2^105)
    p = put(os.path.join(tmp, "wrap0.nii"), header(2, (3, 2 ** 32, 2 ** 32, 1)), b"\1\1")
    refused(tmp, p, "overflow")
    p = put(os.path.join(tmp, "wrap1.nii"), header(1, (7,) + (32767,) * 7), b"\1\1")
    refused(tmp, p, "overflow")


@test
def vox_offset_inside_the_header_or_not_a_number_is_refused(tmp):
    """Issue 19: vox_offset -352 or NaN made libnifti2 read the voxels from
    byte 348, shifting the mask by 4 voxels: H = 1 with exit 0 where the
    answer is 0."""
    _, d = box()
    cases = [(1, -352.0, ".nii"), (1, NAN, ".nii"), (1, INF, ".nii"), (1, 0.0, ".nii"),
             (1, 348.0, ".nii"), (1, 352.5, ".nii"), (1, NAN, ".nii.gz"), (1, 100.0, ".nii.gz"),
             (2, -544, ".nii"), (2, 0, ".nii"), (2, 540, ".nii.gz"), (2, 543, ".nii")]
    for k, (version, off, ext) in enumerate(cases):
        p = put(os.path.join(tmp, "off%d%s" % (k, ext)), header(version, vox_offset=off), d)
        refused(tmp, p, "vox_offset")
    # beyond the end of the file
    p = put(os.path.join(tmp, "far.nii"), header(1, vox_offset=4096.0), d)
    refused(tmp, p, "vox_offset")
    # a vox_offset past the header, with padding, is fine: H = 0
    p = put(os.path.join(tmp, "pad.nii"), header(1, vox_offset=368.0), b"\0" * 16 + d)
    assert run_json([reference(tmp), p])["hausdorff"] == 0
    p = put(os.path.join(tmp, "pad2.nii.gz"), header(2, vox_offset=560), b"\0" * 16 + d)
    assert run_json([reference(tmp), p])["hausdorff"] == 0


@test
def more_voxels_than_the_file_can_hold_are_refused_before_any_allocation(tmp):
    """Issue 19: 2000^3 voxels over 64 bytes of data made libnifti2 calloc
    8 GB before failing on a short read (its '** ERROR' lines first)."""
    for ext in (".nii", ".nii.gz"):
        p = put(os.path.join(tmp, "big" + ext), header(1, (3, 2000, 2000, 2000)), b"\1" * 64)
        refused(tmp, p, "8000000000 bytes")
    # one byte short, uncompressed: the exact size is known
    _, d = box()
    p = put(os.path.join(tmp, "short.nii"), header(1), d[:-1])
    refused(tmp, p, "119 bytes", "120 bytes")
    # int16 voxels need twice the bytes
    p = put(os.path.join(tmp, "short16.nii"), header(1, datatype=4), d)
    refused(tmp, p, "240 bytes")


@test
def a_short_gzip_stream_is_one_message_from_us(tmp):
    """Within the gzip bound but short: libnifti2 fails on the read and its
    '** ERROR' lines came ahead of ours; now they are captured and the
    first useful one is appended to our single line."""
    m, d = box((40, 40, 40))
    p = os.path.join(tmp, "trunc.nii.gz")
    with gzip.open(p, "wb") as f:
        f.write(header(1, (3, 40, 40, 40)) + d[:1000])
    line = refused(tmp, p, "could not be read", "libnifti2: ", "data bytes needed = 64000")
    assert "**" not in line, line


@test
def dim0_and_the_used_dims_must_be_sensible(tmp):
    _, d = box()
    for k, dims in enumerate([(0, 4, 5, 6), (8, 4, 5, 6), (-1, 4, 5, 6)]):
        p = put(os.path.join(tmp, "d%d.nii" % k), header(1, dims), d)
        refused(tmp, p, "dim[0]")
    for k, (dims, field) in enumerate([((3, 4, 0, 6), "dim[2]"), ((3, 4, 5, -6), "dim[3]"),
                                       ((4, 4, 5, 6, 0), "dim[4]")]):
        p = put(os.path.join(tmp, "u%d.nii" % k), header(2, dims), d)
        refused(tmp, p, field)
    # several volumes: refused from the header, before reading them
    p = put(os.path.join(tmp, "t.nii"), header(1, (4, 4, 5, 6, 3)), d * 3)
    refused(tmp, p, "volume")


@test
def voxel_types_a_mask_cannot_have_are_refused_from_the_header(tmp):
    _, d = box()
    for k, dt in enumerate((128, 32, 0, 9999)):  # RGB24, complex64, unknown, nonsense
        p = put(os.path.join(tmp, "t%d.nii" % k), header(1, datatype=dt), d * 8)
        refused(tmp, p, "datatype %d" % dt)


@test
def nan_or_infinite_qform_fields_are_refused(tmp):
    """Issue 19: a NaN or infinite quaternion or offset was taken as the
    identity or zero (exit 0)."""
    _, d = box()
    names = ["quatern_b", "quatern_c", "quatern_d", "qoffset_x", "qoffset_y", "qoffset_z"]
    for version in (1, 2):
        for f, bad in ((0, NAN), (2, INF), (3, NAN), (4, -INF), (5, NAN)):
            q = [0.0] * 6
            q[f] = bad
            p = put(os.path.join(tmp, "q%d%d.nii" % (version, f)), header(version, qform=(1, q)), d)
            refused(tmp, p, names[f])
    # a NaN qfac (pixdim[0]) leaves the handedness unknown
    p = put(os.path.join(tmp, "qfac.nii"), header(1, qfac=NAN, qform=(1, [0] * 6)), d)
    refused(tmp, p, "pixdim[0]")
    # with qform_code 0 the quaternion is not used: no check, H = 0
    q = [NAN] * 6
    p = put(os.path.join(tmp, "unused.nii"), header(1, qform=(0, q)), d)
    assert run_json([reference(tmp), p])["hausdorff"] == 0


@test
def nan_or_infinite_sform_rows_are_refused_naming_the_file(tmp):
    """Issue 19: a NaN sform was refused as 'point set B: point 0 has a NaN
    coordinate', naming no file and no field."""
    _, d = box()
    for version in (1, 2):
        for r, c, bad in ((0, 3, NAN), (1, 1, INF), (2, 2, NAN)):
            rows = np.eye(3, 4)
            rows[r, c] = bad
            p = put(os.path.join(tmp, "s%d%d.nii" % (version, r)), header(version, sform=(1, rows)), d)
            refused(tmp, p, "srow_%s[%d]" % ("xyz"[r], c))


@test
def coordinates_beyond_1e153_are_refused_naming_the_file(tmp):
    _, d = box()
    rows = np.eye(3, 4) * 1e300
    p = put(os.path.join(tmp, "far.nii"), header(2, sform=(1, rows)), d)
    refused(tmp, p, "1e153")
    # metres: 3e38 m fits the header's float32 but not, in millimetres, --float32
    rows = np.eye(3, 4) * 3e38
    p = put(os.path.join(tmp, "farf.nii"), header(1, sform=(1, rows), units=1), d)
    refused(tmp, p, "float", args=["--float32"])
    assert run_json([reference(tmp), p])["hausdorff"] > 1e41


@test
def pixdim_nan_infinite_zero_or_negative(tmp):
    """Issue 19: a NaN pixdim became 1 silently (exit 0), and so did 0; a
    negative one mirrored the mask with qform_code 0.  NaN and infinity are
    refused always; 0 and negative when pixdim sets the coordinates (no
    sform); with an sform, pixdim is only reported."""
    _, d = box()
    for k, (pd, field) in enumerate([((1, NAN, 1), "pixdim[2]"), ((INF, 1, 1), "pixdim[1]"),
                                     ((1, 1, -INF), "pixdim[3]")]):
        for version in (1, 2):
            p = put(os.path.join(tmp, "n%d%d.nii" % (k, version)), header(version, pixdim=pd), d)
            refused(tmp, p, field)
    for k, (pd, field) in enumerate([((1, 0, 1), "pixdim[2]"), ((-2, 1, 1), "pixdim[1]")]):
        for qcode in (0, 1):
            p = put(os.path.join(tmp, "z%d%d.nii" % (k, qcode)),
                     header(1, pixdim=pd, qform=(qcode, [0] * 6)), d)
            refused(tmp, p, field)
        # an sform sets the coordinates: pixdim 0 or negative is only reported
        p = put(os.path.join(tmp, "zs%d.nii" % k), header(1, pixdim=pd, sform=(1, np.eye(3, 4))), d)
        r = run_json([reference(tmp), p])
        assert r["hausdorff"] == 0 and r["masks"]["b"]["spacing"] == list(map(float, pd)), r["masks"]
    # a 2-D mask (dim[0] = 2) may leave pixdim[3] at 0
    m2 = np.zeros((5, 4), np.uint8)
    m2[1:4, 1:3] = 1
    p = put(os.path.join(tmp, "flat.nii"), header(1, (2, 5, 4), pixdim=(1, 1, 0)), m2.tobytes(order="F"))
    assert run_json(["--mask-points", "all", p, p])["n_a"] == 6


@test
def magic_must_name_a_single_file_nifti(tmp):
    _, d = box()
    p = put(os.path.join(tmp, "pair.nii"), header(1, magic=b"ni1\0"), d)
    refused(tmp, p, "magic")
    p = put(os.path.join(tmp, "analyze.nii"), header(1, magic=b"\0\0\0\0"), d)
    refused(tmp, p, "magic")
    p = put(os.path.join(tmp, "v2.nii"), header(2, magic=b"n+1\0\r\n\x1a\n"), d)
    refused(tmp, p, "magic")


@test
def byte_swapped_headers_are_checked_after_swapping(tmp):
    """sizeof_hdr (348 or 540) read in the other byte order says the file is
    big-endian: the checks must see the swapped values."""
    m, _ = box()
    be = m.astype(">i2").tobytes(order="F")
    for version in (1, 2):
        for ext in (".nii", ".nii.gz"):
            p = put(os.path.join(tmp, "be%d%s" % (version, ext)), header(version, datatype=4, endian=">"), be)
            r = run_json([reference(tmp), p])
            assert r["hausdorff"] == 0 and r["masks"]["b"]["nifti"] == version
            p = put(os.path.join(tmp, "bebad%d%s" % (version, ext)),
                    header(version, datatype=4, endian=">", vox_offset=(NAN if version == 1 else 8)), be)
            refused(tmp, p, "vox_offset")
            p = put(os.path.join(tmp, "bewrap%d%s" % (version, ext)),
                    header(version, (3, 3, 6148914691236517206, 1) if version == 2 else (3, 4, 5, 0),
                           datatype=4, endian=">"), be)
            refused(tmp, p, "overflow" if version == 2 else "dim[3]")


@test
def every_refusal_of_random_header_damage_is_one_named_line(tmp):
    """Random bytes of a good header overwritten (a seeded fuzz of 150
    files, NIfTI-1 and -2, plain and gzip): the tool answers (exit 0) or
    refuses with one line naming the file (exit 2); never a signal, never
    libnifti2's lines."""
    rng = np.random.default_rng(19)
    m, d = box()
    ref = reference(tmp)
    for k in range(150):
        version = 1 + k % 2
        h = bytearray(header(version))
        hlen = 348 if version == 1 else 540
        for _ in range(int(rng.integers(1, 6))):
            pos = int(rng.integers(4, hlen))
            h[pos] = int(rng.integers(0, 256))
        ext = ".nii.gz" if k % 3 == 0 else ".nii"
        p = put(os.path.join(tmp, "f%d%s" % (k, ext)), bytes(h), d)
        r = subprocess.run([tool(), "--json", ref, p], capture_output=True, text=True)
        assert r.returncode in (0, 2), "exit %d for header %s" % (r.returncode, bytes(h).hex())
        if r.returncode == 2:
            lines = r.stderr.splitlines()
            assert len(lines) == 1 and lines[0].startswith("hausdorff: %s: " % p), r.stderr


def erosion_border(m):
    """medpy's surface of a mask as the array it is given: the mask minus its
    binary erosion (connectivity 1, border value 0) in m.ndim dimensions."""
    from scipy import ndimage
    m = m.astype(bool)
    return m ^ ndimage.binary_erosion(m, structure=ndimage.generate_binary_structure(m.ndim, 1))


def medpy_hd95(a, b, spacing):
    """medpy.metric.binary.hd95 on 2-D arrays: the pooled 95th percentile of
    the surface distances (distance transforms of the other border)."""
    from scipy import ndimage
    sa, sb = erosion_border(a), erosion_border(b)
    dt_b = ndimage.distance_transform_edt(~sb, sampling=spacing)
    dt_a = ndimage.distance_transform_edt(~sa, sampling=spacing)
    return np.percentile(np.hstack((dt_b[sa], dt_a[sb])), 95)


@test
def a_single_slice_mask_has_the_in_plane_surface_medpy_gives_for_2d(tmp):
    """Issue 18: a mask with one slice (nz = 1, or dim[0] = 2) counted every
    foreground voxel as surface because its z neighbours lie outside the
    image (HD95 4.47 where medpy gives 6.71 on the 2-D arrays).  An axis of
    one voxel is not an axis of the mask: the surface is the in-plane border
    of the 2-D erosion, and HD95 is medpy's."""
    rng = np.random.default_rng(18)
    g = np.indices((40, 32)).astype(float)
    a = (((g[0] - 20) / 13) ** 2 + ((g[1] - 15) / 9) ** 2 + 0.2 * rng.standard_normal((40, 32))) < 1
    b = (((g[0] - 18) / 11) ** 2 + ((g[1] - 17) / 12) ** 2 + 0.2 * rng.standard_normal((40, 32))) < 1
    sp = (0.75, 1.25)  # exact in float32, as the header stores them
    for k, dims3 in enumerate((False, True)):
        pa, pb = os.path.join(tmp, "a%d.nii" % k), os.path.join(tmp, "b%d.nii" % k)
        for path, m in ((pa, a), (pb, b)):
            dims = (3, 40, 32, 1) if dims3 else (2, 40, 32)
            put(path, header(1, dims, pixdim=sp + (2.5,)), m.astype(np.uint8).tobytes(order="F"))
        r = run_json(["--percentile", "95", pa, pb])
        assert r["n_a"] == int(erosion_border(a).sum()) and r["n_b"] == int(erosion_border(b).sum()), \
            (r["n_a"], int(erosion_border(a).sum()), int(a.sum()))
        ref = medpy_hd95(a, b, sp)
        assert abs(r["percentile"]["pooled"] - ref) < 1e-12, (r["percentile"], ref)
    # and the surface points are exactly the 2-D border voxels, in storage order
    csv = os.path.join(tmp, "d.csv")
    run(["--distances", csv, pa, pa])
    rows = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
    ij = np.argwhere(erosion_border(a))
    ij = ij[np.lexsort((ij[:, 0], ij[:, 1]))]
    assert np.array_equal(rows[:, :2], ij * np.array(sp))
    # a 3-D mask is unchanged: its surface is the 3-D erosion's
    m3 = np.zeros((6, 6, 6), np.uint8)
    m3[1:5, 1:5, 1:5] = 1
    p3 = os.path.join(tmp, "c.nii")
    write_nifti(p3, m3)
    assert run_json([p3, p3])["n_a"] == int(erosion_border(m3).sum()) == len(voxels(m3, True))


if __name__ == "__main__":
    main()
