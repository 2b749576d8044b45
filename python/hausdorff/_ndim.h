/*
 * _ndim.h -- exact distances between point sets of any number of
 * coordinates, for the Python module's points of 4 or more columns (the
 * C library computes in 3-D; 1 and 2 columns are lifted to it exactly).
 *
 * Sets are C-ordered float64 rows of `dims` coordinates, finite and small
 * enough that no squared distance overflows (the caller checks).  The
 * squared distance of two points is the sum over coordinates, from the
 * first to the last, of (p[k] - q[k]) * (p[k] - q[k]), each operation
 * rounded (built with the exactness flags: no fused multiply-add), and a
 * distance is one sqrt of it: the doubles a brute force computes, and
 * scipy's directed_hausdorff too.  Ties go to the smallest index.
 *
 * Both functions run without the GIL: they touch no Python object.
 * They return 0, or -1 when memory or a thread could not be had (nothing
 * is then written).
 */
#ifndef HD_PY_NDIM_H
#define HD_PY_NDIM_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    double d2;               /* h(A, B)^2, the largest nearest squared distance */
    size_t i, j;             /* its witness: smallest i, then smallest j */
    uint64_t distance_evals; /* candidate pairs looked at */
} nd_directed_t;

/* h(A, B) with its canonical witness.  early: the early-break algorithm
 * (points visited in an order drawn from `seed`, which never changes the
 * result); else every pair in index order.  threads >= 1. */
int nd_directed(const double *A, size_t na, const double *B, size_t nb, size_t dims,
                int early, uint64_t seed, int threads, nd_directed_t *out);

/* For every point of A, the distance to its nearest point of B (dist) and
 * that point's index (nearest; either may be NULL).  threads >= 1. */
int nd_nearest(const double *A, size_t na, const double *B, size_t nb, size_t dims,
               int threads, double *dist, size_t *nearest);

#endif
