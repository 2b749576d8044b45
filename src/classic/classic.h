/*
 * classic.h -- the front header of the paper's algorithms (src/classic/):
 * NAIVEHDD, EARLYBREAK, INC, NOHD, OHD and the framework that chooses among
 * them, and the kd-tree baseline.  Each computes h(A,B) on a job of packed
 * doubles; the dispatcher (framework.c) runs one by name.  What the
 * folder's own files share besides (the octree, the scans) is in the
 * private classic_int.h.
 */
#ifndef HD_CLASSIC_H
#define HD_CLASSIC_H

#include "points/points.h"

/* What every directed algorithm receives: A and B as packed doubles (after
 * any transform), their boxes, the options and the thread count. */
typedef struct hd__job {
    const double *a;
    size_t na;
    const double *b;
    size_t nb;
    hd__box_t box_a, box_b;
    const hd_options_t *opt;
    int threads;
} hd__job_t;

/* Each algorithm computes h(A,B) into out (distance2, i, j, stats; the
 * caller fills distance, algorithm and seconds).  The witness must already
 * be canonical (smallest i, smallest j). */
typedef int (*hd__directed_fn)(const hd__job_t *job, hd_result_t *out,
                               hd_error_t *err);

int hd__naive(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__earlybreak(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__inc(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__nohd(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__ohd(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__kdtree(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
/* Run h(A,B) on a prepared job (fills seconds, distance, algorithm). */
int hd__run_directed(hd__job_t *job, hd_algorithm_t alg, hd_result_t *out,
                     hd_error_t *err);

/* The overlap degree (see hd_overlap in the public header). */
double hd__alpha(const hd__box_t *a, const hd__box_t *b, int *disjoint);
/* The framework's choice for h(A,B). */
hd_algorithm_t hd__framework_choice(const hd__box_t *a, const hd__box_t *b,
                                    double theta);

/* ---- the kd-tree (kdtree.c) ------------------------------------------------ */
/* An exact kd-tree over one point set: build, nearest-neighbour search,
 * and the "kdtree" algorithm (hd__kdtree, one exact search per point of A);
 * the per-point distances (stats.c) search it too.  The tree owns a
 * structure-of-arrays copy of the points in tree order (x[], y[], z[]) and
 * the original index of each (idx[]).  Nodes live in one flat array in
 * preorder: a node's left child is the next node, its right child is node
 * `right`.  Every node's box is the exact bounding box of the points below
 * it, so hd__box_lb2 of a node never exceeds the computed squared distance
 * to any of its points (see the essay in points/points.h). */

/* Largest number of points in a leaf. */
#define HD__KD_LEAF 16

typedef struct hd__kdnode {
    hd__box_t box;
    size_t begin, end; /* the node's points are [begin, end) in tree order */
    size_t right;      /* index of the right child; 0 for a leaf */
} hd__kdnode_t;

typedef struct hd__kd {
    size_t n;
    double *x, *y, *z;    /* coordinates in tree order */
    size_t *idx;          /* original index of each point in tree order */
    hd__kdnode_t *nodes;  /* preorder; nodes[0] is the root */
    size_t n_nodes;
} hd__kd_t;

/* Counters of one search (added to, never reset). */
typedef struct hd__kdcount {
    uint64_t evals;
    uint64_t nodes;
} hd__kdcount_t;

/* Build the tree of a validated view (every point finite and in range),
 * using up to `threads` threads.  Returns HD_OK, HD_ENOMEM or HD_EOVERFLOW. */
int hd__kd_build(hd__kd_t *kd, const hd_points_t *p, int threads, hd_error_t *err);
void hd__kd_free(hd__kd_t *kd);

/* The exact nearest squared distance from q to the set, with *j the
 * smallest original index at that distance.  When `stop2` is positive the
 * search may end early, as soon as it has found a point with squared
 * distance < stop2 (strictly): it then returns that distance, which is
 * < stop2, and *j is that point, not necessarily the nearest.  A result
 * >= stop2 is always the exact nearest distance.  Pass stop2 = 0 for a full
 * search. */
double hd__kd_nearest(const hd__kd_t *kd, const double q[3], double stop2, size_t *j,
                      hd__kdcount_t *count);

#endif /* HD_CLASSIC_H */
