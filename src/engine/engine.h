/*
 * engine.h -- the front header of the auto engine (layer src/engine/): what
 * the layers above use: its entry points (engine.c), the filter they take
 * on a maximum (hd__keep_t), and the spatial index of one point set with
 * its exact search (build.c, search.c), which the public index (index.c)
 * keeps.  The engine's own files share the private headers beside it:
 * tree.h (the buckets' decoding and the proofs from approximations),
 * max.h (the running maximum), grid.h (the grid and its pass), pairs.h
 * (the correspondence path) and walk.h (the walk over two trees).
 *
 * The index of one point set does not copy coordinates exactly: it
 * borrows the caller's view and keeps
 *  - a permutation (4 bytes per point) listing the points in Morton order,
 *    cut into buckets of HD__BUCKET consecutive points;
 *  - per bucket, the exact bounding box of its points and a 16-bit
 *    quantised copy of their coordinates relative to that box (6 bytes per
 *    point), with `err`, a proven upper bound on the Euclidean distance
 *    between any point and its dequantised approximation;
 *  - the exact box of every node of an implicit binary tree over the
 *    buckets.
 * That is about 13 bytes per point (with HD__BUCKET = 32).  Exact
 * coordinates are read through the permutation ("gathered") and widened to
 * double, with an optional transform applied on the fly in the documented
 * order, so every exact distance uses the doubles the brute force uses.
 *
 * The approximations only ever decide what is provably decided: a point p
 * known within E of its approximation p~ satisfies |q - p| <= |q - p~| + E,
 * and hd__kill_below / hd__may_reach turn that into thresholds on the
 * computed squared distance to p~ with every rounding error accounted for.
 *
 * Tree layout: level 0 holds the buckets; node i of level l+1 covers nodes
 * 2i and 2i+1 of level l (the second may not exist); the top level has one
 * node.  Node (l, i) covers buckets [i << l, (i + 1) << l).
 */
#ifndef HD_ENGINE_H
#define HD_ENGINE_H

#include "points/points.h"

#include <stdint.h>

/* ---- the index of one point set (build.c, search.c) ------------------------------ */

/* Points per bucket (at most 32: live points are tracked in 32-bit masks). */
#define HD__BUCKET 32
_Static_assert(HD__BUCKET % 4 == 0 && HD__BUCKET <= 32, "bucket size");
/* Most tree levels (2^40 buckets is far beyond 2^32 points). */
#define HD__MAX_LEVELS 40

/* A bucket: the exact box of its points and the error bound of their
 * quantised copy. */
typedef struct hd__bucket {
    hd__box_t box;
    double err;
} hd__bucket_t;

typedef struct hd__tree {
    size_t n;                       /* points */
    hd__src_t src;
    uint32_t *perm;                 /* n original indices in Morton order */
    uint16_t *q;                    /* per bucket: 32 x, then 32 y, then 32 z */
    int q_borrowed;                 /* q lies in the other tree's block (a pair's second tree) */
    size_t nb;                      /* buckets: ceil(n / HD__BUCKET) */
    hd__bucket_t *bucket;           /* nb buckets */
    int levels;                     /* level 0 .. levels-1; top has 1 node */
    size_t count[HD__MAX_LEVELS];   /* nodes per level */
    size_t off[HD__MAX_LEVELS];     /* first box of level l >= 1 in nodes[] */
    hd__box_t *nodes;               /* exact boxes of the nodes of levels >= 1 */
    hd__box_t box;                  /* the box the Morton grid covers */
    hd__keygrid_t grid;             /* that grid (hd__key30 on it) */
    uint32_t *fkey;                 /* per bucket: the 30-bit key of its first point on
                                     * `grid` (keys along the curve never decrease) */
    hd__reuse_t *pool;              /* where the arrays come from and go back to (or NULL) */
} hd__tree_t;

/* Build the index of n points read from `src` using `threads` threads.
 * The Morton grid covers grid_box, or the set's own box when it is NULL
 * (two sets sorted on the same grid line up along the curve, which is what
 * the walk over nearly identical sets relies on).  The points must be
 * valid (finite, within HD_MAX_COORD, also after the transform).  n must be
 * at most UINT32_MAX (HD_EOVERFLOW otherwise).  Its arrays, and the sort's,
 * come from `pool` (NULL: plain allocations), which must outlive the tree. */
int hd__tree_build(hd__tree_t *t, const hd__src_t *src, size_t n, const hd__box_t *grid_box,
                   int threads, hd__reuse_t *pool, hd_error_t *err);
void hd__tree_free(hd__tree_t *t);
size_t hd__tree_memory(const hd__tree_t *t);

/* What a nearest-neighbour search found. */
typedef struct hd__hit {
    double d2;       /* exact squared distance (when exact) */
    int killed;      /* 1: the search stopped early, proving d2 < stop2 (or
                      * <= tie2) for the point below; d2 is then meaningless */
    size_t j;        /* original index in the searched set (exact hits) */
    size_t bucket;   /* bucket of the point found (a hint for the next search) */
    double p[3];     /* its coordinates, known within perr */
    double perr;     /* 0 for exact coordinates, else the bucket's err */
} hd__hit_t;

typedef struct hd__counts {
    uint64_t evals, exact, nodes;
} hd__counts_t;

/* Exact nearest neighbour of the exact point q in t: hit->d2 is the
 * smallest squared distance and hit->j the smallest original index
 * attaining it.  Bucket `hint` (or HD__NONE) is searched first.  The search
 * may stop as soon as it proves that some point lies at squared distance
 * < stop2, or <= tie2; it then sets hit->killed.  Pass stop2 = 0 and
 * tie2 = -1 for a full search. */
void hd__tree_nearest(const hd__tree_t *t, const double q[3], double stop2, double tie2,
                      size_t hint, hd__hit_t *hit, hd__counts_t *n);

/* ---- the filter on a direction's maximum -------------------------------------- */

/* A filter on a direction's maximum: keep(ctx, i, d2, j) says whether
 * point i of A, whose exact squared nearest distance is d2 and nearest
 * point of B j (the smallest index at d2), may be the maximum.
 * A point it refuses is left out of the maximum and of the bound that
 * prunes the others, as if it were not in A; every path offers each point
 * that may beat the maximum (hd__max_offer), so the answer is the maximum
 * over the points kept, with its smallest index, and every point not
 * offered has a nearest distance no larger than it.  Called under the
 * maximum's lock, so it may record what it refuses. */
typedef struct {
    int (*keep)(void *ctx, size_t i, double d2, size_t j); /* NULL: every point */
    void *ctx;
} hd__keep_t;

/* ---- the engine ---------------------------------------------------------------- */

/* What the engine runs (engine.c): its plan's choice, or one path forced. */
typedef enum hd__engine_force {
    /* The plan chooses: the shortcuts of pairs.c (a copy in the same order,
     * an ordered subset), else the grid pass or the trees by the grid trial. */
    HD__ENGINE_PLANNED = 0,
    /* No shortcut: the grid pass for every direction. */
    HD__ENGINE_FORCE_GRID = 1,
    /* No shortcut: the bucket trees for every direction. */
    HD__ENGINE_FORCE_TREES = 2
} hd__engine_force_t;

/* H(A,B) by the engine with its choice overridden by `force`
 * (HD__ENGINE_FORCE_GRID or HD__ENGINE_FORCE_TREES; HD__ENGINE_PLANNED
 * lets the plan choose).  For tests. */
int hd__engine_forced(const hd_points_t *A, const hd_points_t *B, const hd_options_t *opt,
                      hd__engine_force_t force, hd_symmetric_t *out, hd_error_t *err);

/* h(A,B) over built indexes of A and B (engine.c), with `threads` threads. */
int hd__engine_trees(const hd__tree_t *ta, const hd__tree_t *tb, int threads,
                     hd_result_t *out, hd_error_t *err);

/* ---- entry points for the layers above (engine.c) ------------------------------ */
/* Each entry that runs the engine (hd__engine_directed,
 * hd__engine_hausdorff, hd__engine_directed_above, hd__engine_forced)
 * reports in its results' stats.peak_bytes the most memory the call held
 * at once: its pool's high-water mark (hd__reuse_t.peak: every array
 * proportional to a set, mapped and touched), which excludes only arrays
 * of O(threads + n / 16384) bytes (the plan's pairs, the threads' counts);
 * 0 for a call settled before any index.  The layers that account for
 * memory (the MPI library's peak) read it there. */
/* The auto engine on validated views, without packed copies (engine.c):
 * h(A,B), and H(A,B) with each set indexed once for both directions. */
int hd__engine_directed(const hd_points_t *A, const hd_points_t *B,
                        const hd__box_t *box_a, const hd__box_t *box_b,
                        const hd_options_t *opt, hd_result_t *out,
                        hd_error_t *err);
int hd__engine_hausdorff(const hd_points_t *A, const hd_points_t *B,
                         const hd__box_t *box_a, const hd__box_t *box_b,
                         const hd_options_t *opt, hd_symmetric_t *out,
                         hd_error_t *err);
/* hd__engine_hausdorff with a filter on each direction's maximum (keep[0]
 * on h(A,B)'s points of A, keep[1] on h(B,A)'s points of B; see
 * hd__keep_t): each answer is the maximum over the points kept.  The
 * correspondence and subset paths, which settle a direction from its
 * pairs, do not run.  For the MPI library's pass over a rank's local sets,
 * whose points near a face of the rank's region have a nearest distance
 * that is only local. */
int hd__engine_hausdorff_kept(const hd_points_t *A, const hd_points_t *B,
                              const hd__box_t *box_a, const hd__box_t *box_b,
                              const hd_options_t *opt, const hd__keep_t keep[2],
                              hd_symmetric_t *out, hd_error_t *err);
/* h(A,B) alone, its maximum filtered by *keep (as above). */
int hd__engine_directed_kept(const hd_points_t *A, const hd_points_t *B,
                             const hd__box_t *box_a, const hd__box_t *box_b,
                             const hd_options_t *opt, const hd__keep_t *keep,
                             hd_result_t *out, hd_error_t *err);
/* h(A,B) where only an answer above a floor matters: the maximum starts
 * at (floor2, floor_i) as if point floor_i of A had that squared nearest
 * distance, so every point that cannot beat it (u^2 < floor2, or u^2 =
 * floor2 and an index above floor_i) is pruned as soon as one point of B
 * shows it.  out is the exact h(A,B) with its witness when that beats the
 * floor (a larger distance, or the same at an index below floor_i); else
 * out->distance2 = floor2 and out->i = floor_i, which the caller reads as
 * "nothing above" (out->j is then HD__NONE, or a real nearest point of a
 * point floor_i at exactly floor2).  floor2 < 0: no floor (what
 * hd__engine_directed runs).  For the MPI library's second pass
 * over a rank's interior, which matters only where it beats the best of
 * every rank. */
int hd__engine_directed_above(const hd_points_t *A, const hd_points_t *B,
                              const hd__box_t *box_a, const hd__box_t *box_b,
                              const hd_options_t *opt, double floor2, size_t floor_i,
                              hd_result_t *out, hd_error_t *err);
/* The engine's plan for H(A,B), for tests and benchmarks: which path
 * answers (the correspondence path settles both directions exactly when
 * path is HD__PLAN_PAIRS), whether the pairs were listed, which directions
 * they resolved, and each direction's grid trial cost (distances and nodes
 * per point).  plan may be NULL; buf (may be NULL when len is 0) gets the
 * same as one sentence, for people. */
typedef enum { HD__PLAN_PAIRS = 1, HD__PLAN_GRID, HD__PLAN_TREES } hd__plan_path_t;
typedef struct {
    hd__plan_path_t path;
    int pairs_listed;  /* 1: pairs listed, 0: not tried */
    int resolved[2];   /* per direction, 0 or 1 */
    double grid_cost[2];
} hd__engine_plan_t;
int hd__engine_explain(const hd_points_t *A, const hd_points_t *B,
                       const hd_options_t *opt, hd__engine_plan_t *plan,
                       char *buf, size_t len, hd_error_t *err);

#endif /* HD_ENGINE_H */
