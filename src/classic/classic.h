/*
 * classic.h -- the paper's algorithms (src/classic/): NAIVEHDD, EARLYBREAK,
 * INC, NOHD, OHD and the framework that chooses among them, with the
 * octree they share and the kd-tree baseline.  Each computes h(A,B) on a
 * job of packed doubles; the dispatcher (framework.c) runs one by name.
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

/* ---- brute-force scans (naive.c) --------------------------------------- */
/* Exact nearest distance of p to n packed points with the smallest index at
 * that distance (a full scan). */
double hd__nn_scan(const double *p, const double *xyz, size_t n, size_t *j,
                   uint64_t *evals);

/* Smallest j in B with d2(p, B[j]) == d2; used to canonicalise a witness
 * after an algorithm found *some* nearest point at the winning distance. */
size_t hd__first_at(const double *p, const double *xyz, size_t n, double d2,
                    uint64_t *evals);

/* ---- shared by the paper's algorithms (earlybreak.c, nohd.c, ohd.c) ---- */
/* The inner loop of Algorithms 2 and 5: scan the n packed points for x's
 * nearest neighbour, giving up ("cut short") when some squared distance d is
 * below `bound` or equal to `tie`.  Returns 1 with the minimum in *d2 and
 * the smallest original index at it in *j (idx[k] is point k's original
 * index; NULL means k), or 0 when cut short.  Whether a scan is cut short
 * does not depend on the order of the points, so it is decided per block,
 * and *evals counts every distance evaluated. */
int hd__scan_break(const double *x, const double *pts, const size_t *idx, size_t n,
                   double bound, double tie, double *d2, size_t *j, uint64_t *evals);

/* EARLYBREAK's loop (Algorithm 2, lines 4-15) over the points of A listed
 * in `order` (visited in that order), against B scanned in a random order
 * drawn from rng; with exclude_common, points of A equal to a point of B
 * are skipped (counted in stats->points_culled).  On return *best is the
 * largest exact nearest-neighbour distance among the points that were not
 * cut short, with the smallest i among those and the smallest j at that
 * distance.  A point is cut short only when a distance below the shared
 * bound proves its nn distance smaller than the final value, or equal to a
 * value already found at a smaller index; so the witness is canonical among
 * the points not excluded.  OHD uses it for its AHD. */
int hd__eb_loop(const hd__job_t *job, const size_t *order, size_t n_order,
                int exclude_common, hd__rng_t *rng, hd__best_t *best,
                hd_stats_t *stats, hd_error_t *err);

#include "classic/octree.h"
#include "classic/kdtree.h"

#endif /* HD_CLASSIC_H */
