/*
 * m2m_dense_check.h -- the independent dense check of a surface-to-surface
 * enclosure [lower, upper] of h(A, B) = sup over the points a of surface A
 * of the distance from a to surface B.  It uses the public API only
 * (hd_mesh_distances, the exact cloud-to-mesh distance), never the
 * enclosure's own code, so a fault there cannot hide itself here.
 *
 * The samples: every vertex that a triangle of A uses, and on each
 * triangle (a, b, c) of A the points (w_a a + w_b b + w_c c) / level for
 * integer weights w_a + w_b + w_c = level (a grid of level^2 sub-triangles;
 * the corners are the vertices).  A sample p computed in doubles may lie a
 * rounding error off A, so its rigorous lower bound on h(A, B) is
 *     d(p, B) - d(p, A)
 * (the point of A nearest p is at least that far from B), taken with
 * d(p, B) one double down and d(p, A) one double up (both are correctly
 * rounded) and the difference rounded down once more; a vertex is on A, and
 * its bound is d(p, B) itself.  Because rounding to nearest is monotone,
 * a double `upper` with h(A, B) <= upper is at least every such bound:
 * the check fails exactly when some bound exceeds `upper`, which proves
 * the claimed enclosure wrong.
 */
#ifndef HD_M2M_DENSE_CHECK_H
#define HD_M2M_DENSE_CHECK_H

#include <hausdorff.h>

#include <stddef.h>

typedef struct m2m_dense {
    double largest;    /* the largest lower bound on h(A, B) found */
    double at[3];      /* its sample point */
    size_t face;       /* A's triangle it lies on; SIZE_MAX for a vertex */
    double off;        /* that sample's distance to A (0 for a vertex) */
    size_t samples;    /* points measured */
    int level;         /* grid level used */
} m2m_dense_t;

/* The grid level that puts about `samples` points on A's n_triangles
 * triangles (at least 1). */
int m2m_dense_level(size_t n_triangles, size_t samples);

/* Measures every sample of A at grid `level` (>= 1) against B with
 * `threads` threads (0: every core).  Returns HD_OK or the error of
 * hd_mesh_distances (HD_ENOMEM when the samples cannot be held), with
 * err filled. */
int m2m_dense_run(const hd_mesh_t *A, const hd_mesh_t *B, int level, int threads, m2m_dense_t *out,
                  hd_error_t *err);

/* The exact distance from the point w to the surface of M (one point
 * through hd_mesh_distances); NAN when the call fails (err says why). */
double m2m_dense_point(const double w[3], const hd_mesh_t *M, int threads, hd_error_t *err);

#endif
