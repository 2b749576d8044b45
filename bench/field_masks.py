#!/usr/bin/python3
"""field_masks.py -- HD95 of two 512 x 512 x 300 masks: the command-line tool
on NIfTI files (reading, surface extraction, the percentile without every
distance) against MONAI's algorithm (the border by binary erosion, scipy's
Euclidean distance transform of the other border with the voxel spacing,
read at this border; MONAI's HD95 is the larger of the two directed 95th
percentiles), in one run, with the ratio.

    /usr/bin/python3 bench/field_masks.py --cli build/hausdorff [--runs 3] [--shape 512,512,300]

The masks: two overlapping ellipsoids (semi-axes about 0.4 of each side,
centres and axes a few voxels apart), spacing (0.7, 0.7, 1.25) mm, written
as uncompressed NIfTI-1 (uint8) in a temporary folder.  The tool's time is
the whole command (its own reading included); MONAI's starts from the
arrays in memory.  Both give the same HD95 (printed; the tool's with
--json).  Medians of --runs runs, wall and processor time (the tool's from
the kernel's account of the child, MONAI's from time.process_time): on a
loaded machine the processor times are the comparable figures.
"""
import argparse
import json
import os
import resource
import statistics
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy import ndimage


def write_nifti(path, mask, spacing):
    """A minimal NIfTI-1 single file (.nii): uint8, sform = the spacing."""
    hdr = bytearray(352)
    struct.pack_into("<i", hdr, 0, 348)
    dims = [3] + list(mask.shape) + [1, 1, 1, 1]
    struct.pack_into("<8h", hdr, 40, *dims)
    struct.pack_into("<h", hdr, 70, 2)  # datatype: unsigned char
    struct.pack_into("<h", hdr, 72, 8)  # bits per voxel
    struct.pack_into("<8f", hdr, 76, 1.0, *spacing, 1.0, 1.0, 1.0, 1.0)
    struct.pack_into("<f", hdr, 108, 352.0)  # vox_offset
    struct.pack_into("<f", hdr, 112, 1.0)  # scl_slope
    struct.pack_into("<B", hdr, 123, 2)  # xyzt_units: mm
    struct.pack_into("<h", hdr, 252, 0)  # qform_code
    struct.pack_into("<h", hdr, 254, 1)  # sform_code: scanner
    struct.pack_into("<4f", hdr, 280, spacing[0], 0, 0, 0)
    struct.pack_into("<4f", hdr, 296, 0, spacing[1], 0, 0)
    struct.pack_into("<4f", hdr, 312, 0, 0, spacing[2], 0)
    hdr[344:348] = b"n+1\0"
    with open(path, "wb") as f:
        f.write(bytes(hdr))
        f.write(np.asfortranarray(mask.astype(np.uint8)).tobytes(order="F"))


def ellipsoid(shape, centre, axes):
    x, y, z = np.ogrid[:shape[0], :shape[1], :shape[2]]
    return ((x - centre[0]) ** 2 / axes[0] ** 2 + (y - centre[1]) ** 2 / axes[1] ** 2 +
            (z - centre[2]) ** 2 / axes[2] ** 2) <= 1


def children_cpu():
    """Processor seconds (user + system) of the waited-for children so far."""
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def monai_hd95(pred, gt, spacing):
    """MONAI's compute_hausdorff_distance(percentile=95): borders by erosion
    (connectivity 1), the EDT of the other border, both directions."""
    def border(m):
        return m & ~ndimage.binary_erosion(m)
    ep, eg = border(pred), border(gt)
    d_pg = ndimage.distance_transform_edt(~eg, sampling=spacing)[ep]
    d_gp = ndimage.distance_transform_edt(~ep, sampling=spacing)[eg]
    return max(np.percentile(d_pg, 95), np.percentile(d_gp, 95)), int(ep.sum()), int(eg.sum())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", default="build/hausdorff")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--shape", default="512,512,300")
    args = ap.parse_args()
    shape = tuple(int(v) for v in args.shape.split(","))
    sp = (0.7, 0.7, 1.25)
    c = [s / 2 for s in shape]
    gt = ellipsoid(shape, c, [0.40 * s for s in shape])
    pred = ellipsoid(shape, [c[0] + 3, c[1] - 2, c[2] + 1], [0.41 * shape[0], 0.39 * shape[1], 0.40 * shape[2]])
    with tempfile.TemporaryDirectory(prefix="field_masks") as d:
        pa, ga = os.path.join(d, "pred.nii"), os.path.join(d, "gt.nii")
        write_nifti(pa, pred, sp)
        write_nifti(ga, gt, sp)
        tool, tool_cpu, ours = [], [], None
        for _ in range(args.runs):
            t0, c0 = time.perf_counter(), children_cpu()
            r = subprocess.run([args.cli, "--json", "--threads", "1", "--percentile", "95", pa, ga],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            tool.append(time.perf_counter() - t0)
            tool_cpu.append(children_cpu() - c0)
            if r.returncode != 0:
                sys.exit("field_masks: %s" % r.stderr.strip())
            ours = r.stdout.strip()
        ref, ref_cpu = [], []
        sp32 = tuple(float(np.float32(v)) for v in sp)  # the spacing the NIfTI header holds (float32)
        for _ in range(args.runs):
            t0, c0 = time.perf_counter(), time.process_time()
            v, npred, ngt = monai_hd95(pred, gt, sp32)
            ref.append(time.perf_counter() - t0)
            ref_cpu.append(time.process_time() - c0)
    tt, tr = statistics.median(tool), statistics.median(ref)
    ct, cr = statistics.median(tool_cpu), statistics.median(ref_cpu)
    print("masks %s, spacing %s, border voxels %d + %d, load average %.1f" %
          ("x".join(map(str, shape)), sp, npred, ngt, os.getloadavg()[0]))
    print("hausdorff CLI (NIfTI, 1 thread): wall %.3f s, processor %.3f s   %s" % (tt, ct, ours))
    print("MONAI's algorithm (scipy EDT):   wall %.3f s, processor %.3f s   HD95 %.17g" % (tr, cr, v))
    print("ratio: wall %.1fx, processor %.1fx" % (tr / tt, cr / ct))


if __name__ == "__main__":
    main()
