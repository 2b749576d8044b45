#!/usr/bin/env python3
"""fuzz/make_seeds.py -- writes the seeds of the newer fuzz targets into
tests/corpus/ (standard library only; the files are committed, so this is
only rerun to change them):

  tests/corpus/nifti/  NIfTI-1 and NIfTI-2 masks for fuzz_nifti
  tests/corpus/cli/    command lines (arguments separated by NUL) for fuzz_cli
  tests/corpus/{ply,obj,off,stl}/  meshes with more kinds of faces, for the
                       fuzz_FORMAT_sample targets (and the vertex ones)
  regress-*            the hostile files of issue 17, one per reader fault, and
                       issue 35's text shapes (byte-order marks, UTF-16/32,
                       decimal commas and thousands separators, first lines,
                       line ends of a '\r' alone)

Files not named regress-* are valid: tests/api/test_io_corpus.c reads every file
of the reader directories and requires those to read.
"""
import gzip
import os
import struct
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "corpus")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from nifti_header import nifti_header  # noqa: E402  (tests/nifti_header.py)


def put(rel, data):
    path = os.path.join(ROOT, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    if len(data) > 65536:
        sys.exit(f"{rel}: {len(data)} bytes, beyond the fuzzers' -max_len")
    with open(path, "wb") as f:
        f.write(data)


# ---- NIfTI -------------------------------------------------------------------
DT = {"u8": (2, 8, "B"), "i16": (4, 16, "h"), "i32": (8, 32, "i"), "f32": (16, 32, "f"),
      "f64": (64, 64, "d"), "i8": (256, 8, "b"), "u16": (512, 16, "H")}


def nifti(version, dims, dtype, voxels, pixdim=(1, 1, 1), sform=None, quatern=None, units=2,
          ndim=None):
    """dims: the dim[1..] list; voxels: values in storage order (i fastest)."""
    code, bitpix, fmt = DT[dtype]
    dim = [ndim if ndim is not None else len(dims)] + list(dims)
    dim += [1] * (8 - len(dim))
    qfac = quatern[6] if quatern else 1
    pd = [qfac] + list(pixdim) + [1] * (7 - len(pixdim))
    head = nifti_header(version, dim, code, bitpix, pd, quatern=quatern[:6] if quatern else None,
                        sform=sform if sform else None, units=units)
    return head + struct.pack("<%d%s" % (len(voxels), fmt), *voxels)


def block(nx, ny, nz, lo, hi, value=1):
    return [value if all(lo[a] <= c <= hi[a] for a, c in enumerate((i, j, k))) else 0
            for k in range(nz) for j in range(ny) for i in range(nx)]


def nifti_seeds():
    put("nifti/v1_u8_pixdim.nii", nifti(1, (5, 5, 4), "u8", block(5, 5, 4, (1, 1, 1), (3, 3, 2)),
                                        pixdim=(1, 1, 2)))
    put("nifti/v1_i16_sform_metres.nii",
        nifti(1, (4, 3, 3), "i16", block(4, 3, 3, (0, 0, 0), (2, 1, 2), 7),
              sform=[[0, -0.001, 0, 0.01], [0.001, 0, 0, -0.02], [0, 0, 0.002, 0.5]], units=1))
    put("nifti/v1_f32_qform.nii.gz",
        gzip.compress(nifti(1, (3, 3, 3), "f32", block(3, 3, 3, (1, 0, 0), (2, 2, 1), 0.5),
                            pixdim=(0.5, 0.5, 1.5), quatern=(0, 0, 0.7071068, 1, 2, 3, -1)), mtime=0))
    put("nifti/v2_u8_sform.nii",
        nifti(2, (4, 4, 4), "u8", block(4, 4, 4, (1, 1, 1), (2, 2, 3), 3),
              sform=[[0.8, 0.1, 0, -10], [0, 0.9, 0.2, 5], [0.1, 0, 1.1, 0]]))
    put("nifti/v2_f64_4d.nii", nifti(2, (3, 2, 2, 1), "f64", block(3, 2, 2, (0, 0, 0), (1, 1, 0), -1.0),
                                     pixdim=(2, 2, 2, 1)))
    put("nifti/v1_i8_empty.nii", nifti(1, (2, 2, 2), "i8", [0] * 8))
    put("nifti/v1_u16_micron.nii", nifti(1, (2, 3, 2), "u16", block(2, 3, 2, (0, 1, 0), (1, 2, 1), 9),
                                         pixdim=(500, 500, 800), units=3))
    # issue 17 (b): a NIfTI-2 mask whose dimensions multiply to 2^64 + 2
    # (3 * 6148914691236517206), which wraps to 2 voxels in 64 bits
    put("nifti/regress-nifti2-dims-2e64-plus-2.nii",
        nifti(2, (3, 6148914691236517206, 1, 1), "u8", [1, 1], ndim=3))


# ---- command lines ------------------------------------------------------------
def cli_seeds():
    lines = {
        "two_files": ["a.ply", "b.ply"],
        "json_framework": ["--json", "--directed", "--algorithm", "framework", "a.xyz", "b.xyz"],
        "sample_seed": ["--sample=100", "--seed", "7", "--float32", "part.stl", "scan.las"],
        "analysis": ["--percentile", "95", "--mean", "--chamfer", "--histogram", "--bins=30",
                     "--max-distance", "2.5", "--distances", "out.csv", "a.ply", "b.ply"],
        "masks": ["--mask-points", "all", "--empty", "inf", "--percentile=99.5", "seg.nii.gz", "truth.nii"],
        "tuning": ["--threads", "1", "--depth=8", "--lambda", "0.5", "--theta=0.2", "--no-early-break",
                   "--no-culling", "--format", "ply", "--quiet", "--", "-x", "-"],
        "pictures": ["--render", "dev.png", "--histogram-png=h.png", "-q", "--vertices", "a", "b"],
        "help": ["--help"],
        "version": ["--version"],
        "formats": ["--formats"],
        "bad_threads": ["--threads", "-1", "a", "b"],
        "bad_sample": ["--sample", "0", "a", "b"],
        "missing_value": ["a", "b", "--seed"],
        "three_files": ["a", "b", "c"],
        "empty_zero_npy": ["--empty=zero", "--distances=d.npy", "--algorithm=ohd", "x.npy", "-"],
        "surface": ["--surface", "--signed", "--tolerance", "1e-6d", "--within=0.25", "--distances", "d.ply",
                    "--percentile", "95", "--tau", "0.5,1,,2", "--dtu-cap=inf", "part.stl", "model.obj"],
        "surface_absolute": ["--surface", "--tolerance=0", "--directed", "--dtu-cap", "20", "ply:a.dat", "b.off"],
        "labels": ["--labels", "all", "--components", "26", "--csv", "--tau=1", "--tau-rule", "lt",
                   "--connectivity", "3", "--mask-dims=2", "--empty", "monai", "--units", "mm", "p.nii.gz", "r.nii"],
        "labels_list": ["--labels=1,2,40", "--components=8", "--mask-dims", "auto", "--tau-rule=le", "p.nii", "r.nii"],
        "subsets": ["--farther-than", "0.5", "far.laz", "--nearer-than", "1e-3", "near.xyz", "--json",
                    "--distances", "all.las", "scan.laz", "model.ply"],
        "streams": ["--max-stream-size", "64K", "--fifo-wait=5", "--laz-points-per-byte", "4096",
                    "--decimal-comma", "--seed=18446744073709551615", "--sample", "7", "--vertices", "csv:-", "b.pcd"],
        "streams_bytes": ["--max-stream-size=1g", "--laz-points-per-byte=1", "--fifo-wait", "86400", "a.npy", "b.las"],
    }
    for name, args in lines.items():
        put("cli/" + name, "\0".join(args))


# ---- meshes -----------------------------------------------------------------------
def mesh_seeds():
    # faces declared before the vertices (legal: elements come in header order)
    put("ply/face_first.ply",
        "ply\nformat ascii 1.0\nelement face 2\nproperty list uchar int vertex_indices\n"
        "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
        "3 0 1 2\n4 0 2 3 1\n0 0 0\n1 0 0\n1 1 0\n0 1 1\n")
    # binary: uint list counts, an edge element to skip, vertex_index spelling
    v = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 1), (1, 1, 3)]
    faces = [[0, 1, 2], [0, 2, 3], [1, 2, 4, 3, 0]]
    body = b"".join(struct.pack("<fff", *p) for p in v)
    body += b"".join(struct.pack("<I%di" % len(f), len(f), *f) for f in faces)
    body += struct.pack("<iiB", 0, 1, 7)
    put("ply/binary_uint_faces.ply",
        b"ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty float32 x\n"
        b"property float32 y\nproperty float32 z\nelement face 3\nproperty list uint32 int32 vertex_index\n"
        b"element edge 1\nproperty int vertex1\nproperty int vertex2\nproperty uchar red\nend_header\n" + body)
    put("obj/features.obj",
        "# every statement kind\nmtllib m.mtl\no thing\ng part\nusemtl red\ns 1\n"
        "v 0 0 0 1\nv 1 0 0 1 0.5 0.5 0.5\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
        "f 1/1 2/2 3/3 4/1 # a quad\nf -1//1 -2//1 -3//1\nf 1/1/1 2/2/1 5/3/1\n"
        "l 1 2\np 3\nf 2 3 5 \\\n")
    put("off/noff_quads.off",
        "NOFF\n# normals after each vertex\n5 3 8\n"
        "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n0.5 0.5 1 0 0 1\n\n"
        "4 0 1 2 3 0.1 0.2 0.3\n3 0 1 4 # comment\n5 0 1 2 3 4\n")
    put("stl/two_solids.stl",
        "solid first\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n"
        "      vertex 1 1 0\n    endloop\n  endfacet\nendsolid first\nsolid second\n"
        "  facet normal 0 0 -1\n    outer loop\n      vertex 0 0 1e-3\n      vertex -1 0 2.5E+1\n"
        "      vertex 0 -1 0\n    endloop\n  endfacet\nendsolid second\n")


# ---- issue 17's hostile files -------------------------------------------------
def hostile_seeds():
    # (a) a face element before the vertices whose uchar list count is 2^64 - 1,
    # followed by huge indices (2000 here, 20000 in the issue, to stay under 64 KiB)
    put("ply/regress-face-first-list-count-2e64",
        "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
        "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
        "18446744073709551615" + " 4702111234474983745" * 2000 + "\n0 0 0\n1 0 0\n0 1 0\n")
    # (c) a relative reference of -(2^62 - 1)
    put("obj/regress-relative-index-2e62",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 2 -4611686018427387903\n"
        "v 2 0 0\nv 0 2 0\nv 0 0 2\n")
    # (d) decimal commas with semicolons: must not read as 1, 5, 2 ...
    put("xyz/regress-decimal-comma.csv", "1,5;2,5;3,5\n4,25;5,5;6,75\n")
    # (e) binary STL whose 80-byte header is "solid ..." ending in a newline
    head = b"solid exported by a CAD tool".ljust(79, b" ") + b"\n"
    tris = [((0, 0, 1), (0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 1), (1, 0, 0), (1, 1, 0), (0, 1, 0))]
    body = b"".join(struct.pack("<12fH", *(c for p in t for c in p), 0) for t in tris)
    put("stl/regress-binary-solid-header", head + struct.pack("<I", len(tris)) + body)



# ---- issue 35's text shapes -----------------------------------------------------
STL_FACET = ("solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
             "endloop\nendfacet\nendsolid s\n")


def text_seeds():
    bom = b"\xef\xbb\xbf"
    # a UTF-8 byte-order mark, skipped by every text reader (the first point was lost)
    put("xyz/regress-bom.xyz", bom + b"9 9 9\n1 1 1\n")
    put("xyz/regress-bom-header.csv", bom + b"x,y,z\n9,9,9\n1,1,1\n")
    put("obj/regress-bom.obj", bom + b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    put("off/regress-bom.off", bom + b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    put("ply/regress-bom.ply", bom + b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
        b"property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
        b"end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    put("pcd/regress-bom.pcd", bom + b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
        b"WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n9 9 9\n1 1 1\n")
    put("stl/regress-bom.stl", bom + STL_FACET.encode())
    # UTF-16 and UTF-32, refused by name (the STL was binary with 1818521189 triangles)
    put("xyz/regress-utf16.xyz", "9 9 9\n1 1 1\n".encode("utf-16"))
    put("xyz/regress-utf16-no-bom.txt", "x y z\n9 9 9\n".encode("utf-16-le"))
    put("obj/regress-utf32.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".encode("utf-32"))
    put("stl/regress-utf16-solid.stl", STL_FACET.encode("utf-16"))
    # decimal commas and thousands separators between blank-separated fields
    put("xyz/regress-tab-decimal-comma.txt", "4,25\t5,5\t6,75\n1,5\t2,5\t3,5\n")
    put("xyz/regress-thousands.xyz", "1,234.5 2,345.6 3,456.7\n")
    # a malformed number on line 1, once skipped as a header
    put("xyz/regress-qnan-line1.xyz", "1.#QNAN 2 3\n1 1 1\n")
    put("xyz/regress-fortran-exponent-line1.xyz", "1.5D+03 0 0\n1 1 1\n")
    # classic Mac OS line ends (a '\r' alone): the file was one line, read as its first point alone
    put("xyz/regress-mac-line-ends.xyz", "1.5 2 3\r4 5 6\r7 8 9\r")
    put("obj/regress-mac-line-ends.obj", "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r")
    # an ascii STL on one line, once its solid line alone: no points
    put("stl/regress-one-line.stl", STL_FACET.replace("\n", " ").replace("endsolid s ", "endsolid s\n"))
    # quoted numbers, once a header: the file read as no points
    put("xyz/regress-quoted-numbers.csv", '"x","y","z"\n"1.5","2","3"\n')


if __name__ == "__main__":
    nifti_seeds()
    cli_seeds()
    mesh_seeds()
    hostile_seeds()
    text_seeds()
