"""A NIfTI-1 or NIfTI-2 header written byte by byte (standard library only):
one writer for the tests' masks (cli_analysis_support.write_nifti) and the
fuzz seeds (fuzz/make_seeds.py)."""
import struct


def nifti_header(version, dim, code, bitpix, pixdim, quatern=None, sform=None, units=2):
    """The header of a NIfTI-`version` file and its four-byte extension flag
    (the voxels follow).  dim and pixdim: the header's 8 values each (dim[0]
    the dimension count, pixdim[0] qfac); code, bitpix: the voxel type;
    quatern: (b, c, d, x, y, z) with qform_code 1, or None; sform: the rows
    srow_x, srow_y, srow_z with sform_code 1, or None; units: xyzt_units."""
    qcode, scode = int(quatern is not None), int(sform is not None)
    q = tuple(quatern) if quatern is not None else (0, 0, 0, 0, 0, 0)
    rows = sform if sform is not None else [[0] * 4] * 3
    if version == 1:
        h = bytearray(348)
        struct.pack_into("<i", h, 0, 348)
        struct.pack_into("<8h", h, 40, *dim)
        struct.pack_into("<hh", h, 70, code, bitpix)
        struct.pack_into("<8f", h, 76, *pixdim)
        struct.pack_into("<f", h, 108, 352.0)
        struct.pack_into("<B", h, 123, units)
        struct.pack_into("<hh", h, 252, qcode, scode)
        struct.pack_into("<6f", h, 256, *q)
        for r in range(3):
            struct.pack_into("<4f", h, 280 + 16 * r, *rows[r])
        h[344:348] = b"n+1\0"
    else:
        h = bytearray(540)
        struct.pack_into("<i", h, 0, 540)
        h[4:12] = b"n+2\0\r\n\x1a\n"
        struct.pack_into("<hh", h, 12, code, bitpix)
        struct.pack_into("<8q", h, 16, *dim)
        struct.pack_into("<8d", h, 104, *pixdim)
        struct.pack_into("<q", h, 168, 544)
        struct.pack_into("<ii", h, 344, qcode, scode)
        struct.pack_into("<6d", h, 352, *q)
        for r in range(3):
            struct.pack_into("<4d", h, 400 + 32 * r, *rows[r])
        struct.pack_into("<i", h, 500, units)
    return bytes(h) + b"\0\0\0\0"
