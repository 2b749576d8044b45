/*
 * nearest.h -- exact all-nearest-neighbours between two point sets
 * (layer src/nearest/): for every point of one set, its nearest point in the other,
 * as hd_distances needs them.  See allnearest.c for the design and the
 * exactness argument.
 *
 * One structure per set serves both directions: it is searched by the
 * other set's points, and it groups its own points as queries.  It holds a
 * structure-of-arrays copy of the points in Morton order (x[], y[], z[],
 * original indices idx[]) and the octree the Morton keys define, cut where
 * a cell holds at most HD__AN_BUCKET points (the buckets, searched) and,
 * coarser, HD__AN_GROUP points (the groups, asking), with the exact box of
 * every node.
 */
#ifndef HD_ALLNEAREST_H
#define HD_ALLNEAREST_H

#include "points/points.h"

/* Points per bucket and per group, at most (unless their keys are equal);
 * the sizes around these were within noise of each other
 * (docs/journal/benchmarks.md, "Analysis", "Earlier measurements"). */
#define HD__AN_BUCKET 64
#define HD__AN_GROUP 128

_Static_assert(HD__AN_BUCKET <= HD__AN_GROUP, "a group is a union of whole buckets");

typedef struct hd__an {
    size_t n;
    double *x, *y, *z;     /* n + 4 coordinates in Morton order (the last repeated) */
    uint32_t *idx;         /* original index of each */
    uint32_t *key32;       /* n: Morton key of each on the grid of both sets (the
                            * key before any refinement: equal in a refined cell) */
    size_t nb;             /* buckets (the octree's leaves), in key order */
    uint32_t *start;       /* nb + 1: bucket b is points [start[b], start[b+1]) */
    uint32_t *key;         /* nb: Morton key of each bucket's first point */
    uint32_t *stop;        /* nb: where a scan of the bucket may stop (start + 1 for
                            * copies of one point, else the next start) */
    uint32_t *leaf;        /* nb: the node of each bucket */
    size_t ng;             /* groups of queries, in key order */
    uint32_t *gstart;      /* ng + 1: group g is points [gstart[g], gstart[g+1]) */
    uint32_t *glead;       /* ng: the first bucket of each group */
    size_t nn;             /* octree nodes; node 0 is the root */
    uint32_t *first;       /* first child (children are consecutive), or bucket of a leaf */
    uint8_t *count;        /* children, 0 for a leaf */
    double *lo[3], *hi[3]; /* exact box of each node */
    size_t peak;           /* the most bytes the build held at once */
} hd__an_t;

/* Most points per set (node and point numbers fit 32 bits with room). */
#define HD__AN_MAX_POINTS (UINT32_MAX / 2 - 8)

/* Build the structure of a validated view of at most HD__AN_MAX_POINTS,
 * each point moved by T if T is not NULL (the transformed points must be
 * finite and in range), its Morton order taken on a grid over `keybox`
 * (the same box for both sets lines their orders up).  Returns HD_OK,
 * HD_ENOMEM or HD_EOVERFLOW. */
int hd__an_build(hd__an_t *s, const hd_points_t *p, const hd_transform_t *T, const hd__box_t *keybox,
                 int threads, hd_error_t *err);
void hd__an_free(hd__an_t *s);

/* The structure of the m points p[sel[0]], ..., p[sel[m - 1]] (each
 * below p->count, m at most HD__AN_MAX_POINTS), point t named names[t], or
 * sel[t] when names is NULL, the names increasing with t (asserted): the
 * tie rule needs it.  idx[] holds the names, so searched, the
 * structure answers with names (the smallest name among ties), and
 * asking, its answers are written at their names (arrays that long).
 * No copy of the points is made beyond the structure's own.  Returns as
 * hd__an_build. */
int hd__an_build_sel(hd__an_t *s, const hd_points_t *p, const uint32_t *sel, const uint32_t *names, size_t m,
                     const hd__box_t *keybox, int threads, hd_error_t *err);

/* The bytes a built structure holds (its build held at most s->peak). */
size_t hd__an_bytes(const hd__an_t *s);

/* The most bytes hd__an_nearest allocates for its own use with these
 * structures and threads (the candidate lists of every worker, a list
 * the length of searched's buckets, and two answers per asking point). */
size_t hd__an_nearest_bytes(const hd__an_t *asking, const hd__an_t *searched, int threads);

/* What the searches of one hd__an_nearest took (for tests: no answer
 * depends on it). */
typedef struct hd__an_counts {
    size_t paired;   /* groups of queries settled by the partners */
    size_t windowed; /* groups settled by the window on the other curve */
    size_t apart;    /* queries of those searched on their own */
    size_t solo;     /* queries of sparse groups, each searched on its own */
    size_t pointed;  /* queries answered from a chunk's list of candidate points */
    size_t far;      /* far groups: candidates within a bound from boxes alone, no
                      * seed scanned (allnearest.c, "Far groups") */
    size_t shared;   /* groups answered from their run's shared point list (allnearest.c,
                      * "Shared point lists") */
} hd__an_counts_t;

/* For every point of `asking`, the exact nearest distance to `searched`
 * (sqrt of the smallest hd__d2s) into dist[i] and the smallest original
 * index attaining it into nearest[i], i being the point's original index;
 * either output may be NULL.  `partner`, when not NULL, is the view
 * `searched` was built from, of as many points as `asking`: its point i is
 * tried first as the answer of asking's point i (a copy and its original
 * in the same order settle fast); the answers do not depend on it, nor on
 * the window (the points of `searched` at each query's place on its
 * curve, tried when the partners are not).  *counts (if not NULL) says
 * what the searches took.  Returns HD_OK or HD_ENOMEM (with err filled). */
int hd__an_nearest(const hd__an_t *asking, const hd__an_t *searched, const hd_points_t *partner,
                   int threads, double *dist, size_t *nearest, hd__an_counts_t *counts, hd_error_t *err);

/* hd__an_nearest with partners given by position: pair_at[k], for the
 * point at position k of `asking` (its order, not its original index), is
 * the position in `searched` of the point tried first as its answer, or
 * HD__AN_NO_PARTNER.  For sets of different sizes whose points still pair
 * up (the MPI layer's local parts of a copy and its original: a point and
 * the one of the same global index).  The answers do not depend on
 * pair_at.  Returns as hd__an_nearest. */
#define HD__AN_NO_PARTNER UINT32_MAX
int hd__an_nearest_paired(const hd__an_t *asking, const hd__an_t *searched, const uint32_t *pair_at, int threads,
                          double *dist, size_t *nearest, hd__an_counts_t *counts, hd_error_t *err);

/* Every point of `asking` classified by its exact nearest squared distance
 * d2 to `searched` (the smallest hd__d2s) against the band [lo2, hi2]:
 * out->below counts d2 < lo2, out->above counts d2 > hi2, and out->v
 * holds the out->n values d2 with lo2 <= d2 <= hi2, in no particular order
 * (malloc'd; the caller frees it).  The counts and the values as a
 * multiset are the same at any thread count.  Only the points near the
 * band are searched completely (allnearest.c, "within a band"), so a band
 * that brackets a percentile closely costs far less than every distance.
 * lo2 = 0 counts nothing below, hi2 = +inf nothing above.  Returns HD_OK
 * or HD_ENOMEM (out zeroed, err filled). */
typedef struct hd__an_band {
    size_t below, above;
    size_t n;
    double *v;
    size_t solo; /* points whose candidates were listed around the point alone
                  * (a sparse set asking a dense one; for tests) */
} hd__an_band_t;
int hd__an_band(const hd__an_t *asking, const hd__an_t *searched, double lo2, double hi2, int threads,
                hd__an_band_t *out, hd_error_t *err);

/* hd__an_band, and each point's class into each[name] (an array as long
 * as the asking names go): -1 for a point counted below, +inf above, its
 * exact d2 inside the band.  The classes are the same at any thread
 * count.  Returns as hd__an_band. */
int hd__an_band_each(const hd__an_t *asking, const hd__an_t *searched, double lo2, double hi2, int threads,
                     hd__an_band_t *out, double *each, hd_error_t *err);

/* hd__an_band with whole nodes of asking settled from bounds (settle.c):
 * an asking node whose box is proven below or above the band is counted
 * without its points, and the points of the buckets left open are
 * classified by hd__an_band on a structure of them alone (P is the view
 * asking was built from, on keybox).  The same counts and kept values (as
 * a multiset) as hd__an_band, at any thread count; it runs hd__an_band
 * itself when a probe of the bounds says they would settle too little.
 * out->solo counts the open points' only; *settled (when not NULL)
 * receives how many points bounds counted without their distance (for
 * tests).  Returns HD_OK or HD_ENOMEM (out zeroed, err filled). */
int hd__an_band_settled(const hd__an_t *asking, const hd__an_t *searched, const hd_points_t *P,
                        const hd__box_t *keybox, double lo2, double hi2, int threads, hd__an_band_t *out,
                        size_t *settled, hd_error_t *err);

/* Both structures of A and B (validated views of at most
 * HD__AN_MAX_POINTS each) on one key box, built side by side on the
 * threads.  On failure neither is left allocated.  Returns as
 * hd__an_build. */
int hd__an_build_pair(const hd_points_t *A, const hd_points_t *B, const hd__box_t *keybox, int threads,
                      hd__an_t s[2], hd_error_t *err);

/* The percentile figures of hd_hausdorff_percentile from the structures
 * s[0] of A and s[1] of B (hd__an_build_pair on keybox), without every
 * distance (percentile.c): the same bits as hd_percentile_of on every
 * exact distance, at any thread count.  Returns HD_OK, HD_ENOMEM or
 * HD_EOVERFLOW. */
int hd__percentile_points(const hd_points_t *A, const hd_points_t *B, const hd__an_t s[2],
                          const hd__box_t *keybox, int threads, double p, hd_percentile_t *out, hd_error_t *err);

/* A sample of a direction's exact squared distances: m values (sorted
 * ascending; +inf allowed) standing for n points (n >= m; m = 0 stands
 * for nothing). */
typedef struct hd__pct_sample {
    double *v;
    size_t m, n;
} hd__pct_sample_t;

/* The band [*lo2, *hi2] in which ranks r1 <= r2 of the points the ns
 * samples stand for are expected (percentile.c's step 2): lo2 the largest
 * sample value whose estimated rank (each value weighing n / m of its
 * sample) lies SPREAD standard deviations below r1, hi2 the smallest
 * whose estimated count at most it reaches that far above r2; 0 and +inf
 * where there is none.  at: ns entries of scratch.  The band decides only
 * the cost of a selection, never its answer. */
void hd__percentile_band(const hd__pct_sample_t *s, int ns, size_t *at, size_t r1, size_t r2, double *lo2,
                         double *hi2);

/* Where a percentile's exact squared distances come from (percentile.c
 * runs the same selection on either): sample(ctx, d, sel, m, out, err)
 * classifies the points sel[0..m) (increasing) of direction d's asking set
 * (0: A -> B, 1: B -> A) against the band [0, +inf], band(ctx, d, lo2,
 * hi2, out, err) every point of direction d against [lo2, hi2], each as
 * hd__an_band does.  Both return HD_OK or an error with out zeroed. */
typedef struct hd__pct_src {
    int (*sample)(void *ctx, int d, const uint32_t *sel, size_t m, hd__an_band_t *out, hd_error_t *err);
    int (*band)(void *ctx, int d, double lo2, double hi2, hd__an_band_t *out, hd_error_t *err);
    void *ctx;
} hd__pct_src_t;

/* The percentile figures of sets of na and nb points (both at least 1)
 * from src: the same bits as hd_percentile_of on every exact distance
 * whatever src's passes cost.  Returns HD_OK or src's error. */
int hd__percentile_run(const hd__pct_src_t *src, size_t na, size_t nb, double p, hd_percentile_t *out,
                       hd_error_t *err);

/* The percentile figures from a uniform grid's cell bounds (cells.c), for
 * sets whose boxes box_a and box_b lie apart and whose cells' bounds are
 * narrow next to their distances: *done = 1 and out filled, the same bits
 * as hd__percentile_points; else *done = 0 (out untouched) and nothing
 * but the gate's cost spent.  Returns HD_OK, HD_ENOMEM or HD_EOVERFLOW. */
int hd__percentile_cells(const hd_points_t *A, const hd_points_t *B, const hd__box_t *box_a, const hd__box_t *box_b,
                         const hd__box_t *keybox, int threads, double p, hd_percentile_t *out, int *done,
                         hd_error_t *err);

/* ---- histograms (histogram.c) ------------------------------------------- */

/* numpy.histogram's bins on [lo, hi]: the range (widened by half a unit on
 * each side when lo == hi) and norm = bins / (hi - lo). */
typedef struct hd__hist {
    double lo, hi, norm;
    size_t bins;
} hd__hist_t;

/* Checks and widens the range as numpy does.  Errors: HD_EINVAL (bins =
 * 0, lo > hi, a bound not finite), HD_ERANGE (hi - lo overflows). */
int hd__hist_init(hd__hist_t *h, double lo, double hi, size_t bins, hd_error_t *err);
/* Edge k (0..bins) as numpy.linspace computes it; edge bins is hi. */
double hd__hist_edge(const hd__hist_t *h, size_t k);
/* The bin numpy.histogram places x in, or SIZE_MAX for a value outside
 * [lo, hi] (or NaN).  *guess receives the bin before numpy's one-step
 * correction (or the bin itself on a subnormal range): for a fixed guess
 * the bin is a non-decreasing function of x, and the guess is one of x.
 * So every x in [l, u] lies in bin k when l and u have the same guess and
 * both lie in bin k (histogram.c). */
size_t hd__hist_place(const hd__hist_t *h, double x, size_t *guess);
/* 1 when every value of [l, u] (l <= u) is placed alike: in one bin,
 * returned in *bin, or all outside the range (*bin = SIZE_MAX). */
int hd__hist_decided(const hd__hist_t *h, double l, double u, size_t *bin);

/* Adds to counts[0..h->bins) the histogram of the exact nearest distances
 * of asking's points (the structure of P on keybox) to searched, as
 * hd__hist_place places them: an asking bucket whose cheap lower and upper
 * bounds are placed alike (hd__hist_decided) is counted without its
 * distances, the other points get their exact distance (allnearest.c,
 * "histograms from bounds"); partner as hd__an_nearest's, tried only
 * when most points need their distance.  The same counts at any thread
 * count.
 * Returns HD_OK, HD_ENOMEM or HD_EOVERFLOW (counts unspecified, err
 * filled). */
int hd__an_hist(const hd__an_t *asking, const hd__an_t *searched, const hd_points_t *P, const hd_points_t *partner,
                const hd__box_t *keybox, const hd__hist_t *h, int threads, uint64_t *counts, hd_error_t *err);

#endif /* HD_ALLNEAREST_H */
