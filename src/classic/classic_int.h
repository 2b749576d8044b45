/*
 * classic_int.h -- private to src/classic/: what its files share beside
 * the front header classic.h: the octree that NOHD (on A), OHD (on B) and
 * INC (on both) build (octree.c has its invariants), and the brute-force
 * scans and EARLYBREAK's loop that the paper's algorithms reuse.
 */
#ifndef HD_CLASSIC_INT_H
#define HD_CLASSIC_INT_H

#include "classic/classic.h"

/* ---- the octree (octree.c) ------------------------------------------------ */
typedef struct hd__onode {
    hd__box_t box;          /* tight box of the node's points (exact) */
    double mid[3];          /* the split values of the node's cell */
    size_t begin, count;    /* its points: positions [begin, begin+count) */
    struct hd__onode *kids; /* non-empty children, by increasing octant;
                               NULL at a leaf */
    uint32_t id;            /* 0 .. nodes-1, in creation (depth-first) order */
    uint8_t nkids;
    uint8_t octant;         /* bit k: upper half of the parent's cell on axis k */
    uint8_t depth;          /* the root is at depth 0 */
} hd__onode_t;

typedef struct hd__octree {
    hd__onode_t *root;
    hd__onode_t **node; /* node[id] */
    size_t *idx;        /* idx[p]: original index of the point at position p */
    double *pts;        /* pts[3p .. 3p+2]: its coordinates (a copy) */
    size_t n, nodes, leaves;
    int max_depth;      /* the cap asked for */
    int depth;          /* the deepest node built */
    double lo[3], side; /* the root cell, the cube [lo, lo + side] */
    hd__arena_t arena;
} hd__octree_t;

/* Build an octree over n > 0 packed points.  A node is split into its
 * non-empty octants while its depth is below max_depth (0..60), it holds
 * more than leaf_size points (>= 1) and its points are not all equal.
 * Returns HD_OK or HD_ENOMEM (with err set); on failure nothing is left
 * allocated. */
int hd__octree_build(hd__octree_t *t, const double *xyz, size_t n, int max_depth,
                     size_t leaf_size, hd_error_t *err);
void hd__octree_free(hd__octree_t *t);

/* The leaf whose cell contains p, found by the same split comparisons that
 * placed the tree's points (so a point of the tree finds its own leaf), or
 * NULL when p falls into an empty octant.  Cells on the border of the root
 * cell extend outwards without limit. */
const hd__onode_t *hd__octree_locate(const hd__octree_t *t, const double *p);

/* Octant of p in a node's cell: bit k set when p[k] >= mid[k]. */
HD__INLINE unsigned hd__octant(const double *mid, const double *p) {
    return (unsigned)(p[0] >= mid[0]) | (unsigned)(p[1] >= mid[1]) << 1 |
           (unsigned)(p[2] >= mid[2]) << 2;
}

/* Squared length of a box's diagonal (its size, for INC's choice). */
HD__INLINE double hd__box_size2(const hd__box_t *b) {
    double d[3];
    for (int k = 0; k < 3; k++) d[k] = b->hi[k] - b->lo[k];
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

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

#endif /* HD_CLASSIC_INT_H */
