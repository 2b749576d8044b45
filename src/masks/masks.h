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
    int d[26][3];       /* and as index differences along each axis */
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

/* ---- windows (labels.c, surfels.c, components.c) ----------------------------
 * A window is the box of voxels [off, off + w) of a larger image, held as
 * its own binary image fg (w[0] x w[1] x w[2], i fastest, nonzero =
 * foreground); points are placed by the image's indices (off + the
 * window's), so a window's points are bit for bit the whole image's. */

/* The surface voxels (hd__on_surface with nb, made for the window's
 * sizes) of the window, in storage order: xyz (3 doubles each) and, when
 * `voxel` is not NULL, each one's voxel index in the window.  Both arrays
 * have room for *count, counted first with xyz NULL. */
void hd__window_points(const uint8_t *fg, const size_t w[3], const size_t off[3], const double m[3][4], double scale,
                       const hd__neighbourhood_t *nb, double *xyz, size_t *voxel, size_t *count);

/* Surfels: positions (3 doubles each) and areas, grown by realloc. */
typedef struct hd__surfels {
    double *xyz;
    double *area;
    size_t count, cap;
} hd__surfels_t;

/* The area of the surface in each 2 x 2 x 2 configuration (dims 3; bit v
 * of the code is corner (v & 1, v >> 1 & 1, v >> 2 & 1)) or 2 x 2 one
 * (dims 2, codes 0..15, the length of the boundary), after the linear map
 * lin (the spacing); 0 for the empty and the full configuration. */
void hd__surfel_areas(int dims, const double lin[3][3], double area[256]);
/* The loops of a configuration as cube edges (edge e along axis e / 4),
 * each loop ended by -1; returns the entries written (at most 48). */
int hd__surfel_loops(int code, int dims, int *edges);

/* Appends the window's surfels (every cube of 2 x 2 x 2 voxels, 2 x 2 in
 * each slice k with dims 2, meeting the window, whose corners are not all
 * alike; the outside is background) at the cubes' centres, with their
 * areas from `area`.  -1 when out of memory. */
int hd__window_surfels(const uint8_t *fg, const size_t w[3], const size_t off[3], const double m[3][4], double scale,
                       int dims, const double area[256], hd__surfels_t *out);
void hd__surfels_free(hd__surfels_t *s);

/* Connected components of the window's foreground: comp[v] = 1.. for the
 * component of voxel v (numbered in storage order of their first voxel), 0
 * for background; neighbours are those of nb (its axes and connectivity:
 * 6, 18, 26 in 3-D, 4, 8 in 2-D).  Returns the number of components, or
 * -1 when out of memory. */
long long hd__components(const uint8_t *fg, const size_t w[3], const hd__neighbourhood_t *nb, uint32_t *comp);

#endif
