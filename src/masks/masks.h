/*
 * masks.h -- binary images as point sets (surface.c): which voxels are the
 * surface, as medpy and MONAI define it, and where their centres lie.
 * Over base/ only; the public entry point is hd_mask_points (src/metrics.c).
 */
#ifndef HD_MASKS_H
#define HD_MASKS_H

#include "base/base.h"

/* The erosion's neighbourhood: scipy's generate_binary_structure(rank,
 * connectivity) over the axes in use, as voxel index differences, face
 * neighbours first (most border voxels are told by the first few). */
typedef struct hd__neighbourhood {
    int used[3];        /* the axes of the neighbourhood */
    int rank;           /* how many */
    int connectivity;   /* as asked, at most rank */
    int n;              /* offsets */
    ptrdiff_t step[26]; /* each offset as a voxel index difference */
} hd__neighbourhood_t;

/* dims: 0 (the axes of more than one voxel), 2 (i and j) or 3 (all);
 * connectivity 1..3 (above the rank it acts as the rank, as scipy's). */
void hd__neighbourhood(hd__neighbourhood_t *nb, const size_t n[3], int dims, int connectivity);

/* 1 when the foreground voxel (i, j, k) of fg (n[0] x n[1] x n[2], i
 * fastest, nonzero = foreground) is removed by binary erosion with nb, the
 * outside counting as background; 1 for every voxel when nb has no axis. */
int hd__on_surface(const uint8_t *fg, const size_t n[3], const hd__neighbourhood_t *nb, size_t i, size_t j,
                   size_t k);

/* The world coordinate c of voxel (i, j, k): (((m0 i + m1 j) + m2 k) + m3),
 * times scale unless scale is 1. */
double hd__voxel_world(const double m[3][4], double scale, int c, double i, double j, double k);

#endif
