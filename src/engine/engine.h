/*
 * engine.h -- the auto engine (layer src/engine/): its spatial index of one
 * point set, the searches, the grid, the partner pairs and the plan.
 *
 * An index does not copy coordinates exactly: it borrows the caller's view
 * and keeps
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

#include <assert.h>
#include <pthread.h>

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
/* Both trees of a call at once, from `pool` (kept blocks are given back
 * first), in the order that holds the least memory at once: both sorts
 * (the larger set first), each leaving only its perm, fkey and room for
 * its boxes, then both quantised copies (one block, the second tree's q
 * borrowed from the first's: free the two together) and boxes.  The pool
 * then holds at most max(16 n0, 7.4 n0 + max(8 n0, 6 (n0 + n1)) + 8 n1,
 * 13.4 (n0 + n1)) bytes, plus pages lost to rounding, with n0 the larger
 * set (docs/engine.md, "Threads and memory"). */
int hd__tree_build_pair(hd__tree_t t[2], const hd__src_t src[2], const size_t n[2],
                        const hd__box_t grid_box[2], int threads, hd__reuse_t *pool, hd_error_t *err);
void hd__tree_free(hd__tree_t *t);
size_t hd__tree_memory(const hd__tree_t *t);

HD__INLINE const hd__box_t *hd__tree_box(const hd__tree_t *t, int level, size_t i) {
    return level == 0 ? &t->bucket[i].box : &t->nodes[t->off[level] + i];
}

HD__INLINE int hd__bucket_size(const hd__tree_t *t, size_t b) {
    assert(b < t->nb); /* so the size is 1 .. HD__BUCKET */
    size_t first = b * HD__BUCKET;
    return (int)(t->n - first < HD__BUCKET ? t->n - first : HD__BUCKET);
}

/* The dequantised (approximate) coordinates of bucket b, in three arrays;
 * returns the bucket's point count.  Point k of the bucket lies within
 * t->bucket[b].err of (x[k], y[k], z[k]). */
HD__INLINE int hd__bucket_decode(const hd__tree_t *t, size_t b, double *x, double *y,
                                 double *z) {
    const hd__bucket_t *bk = &t->bucket[b];
    const uint16_t *q = t->q + b * 3 * HD__BUCKET;
    const double unit = 1.0 / 65535.0;
    double sx = (bk->box.hi[0] - bk->box.lo[0]) * unit;
    double sy = (bk->box.hi[1] - bk->box.lo[1]) * unit;
    double sz = (bk->box.hi[2] - bk->box.lo[2]) * unit;
    int m = hd__bucket_size(t, b);
    for (int k = 0; k < HD__BUCKET; k++) {
        x[k] = bk->box.lo[0] + (double)q[k] * sx;
        y[k] = bk->box.lo[1] + (double)q[HD__BUCKET + k] * sy;
        z[k] = bk->box.lo[2] + (double)q[2 * HD__BUCKET + k] * sz;
    }
#ifndef NDEBUG
    /* A short bucket is padded with copies of its point 0 (hd__min32 and
     * hd__find rely on it: padding never comes before a real point). */
    for (int k = m; k < HD__BUCKET; k++)
        assert(q[k] == q[0] && q[HD__BUCKET + k] == q[HD__BUCKET] &&
               q[2 * HD__BUCKET + k] == q[2 * HD__BUCKET]);
#endif
    return m;
}

/* The smallest of c[0..HD__BUCKET).  A short bucket is padded with copies
 * of its point 0 (build.c), whose values equal c[0], so padding never
 * changes the minimum.  Eight running minima in two vectors of four (GCC
 * vector extensions: one compare and one select per four values, where the
 * scalar loop this replaces compiled to one vminsd per value; callgrind,
 * docs/benchmarks.md, issue 15); each lane keeps m = c < m ? c : m, the
 * same value as that scalar loop for any input. */
typedef double hd__v4d __attribute__((vector_size(32), aligned(8)));
typedef int64_t hd__v4l __attribute__((vector_size(32), aligned(8)));

/* m = c < m ? c : m in each lane (a macro: a function returning a 32-byte
 * vector has a different ABI with and without AVX, which GCC warns about). */
#define HD__V4_MIN(m, c)                                                           \
    do {                                                                           \
        hd__v4l lt_ = (c) < (m);                                                   \
        (m) = (hd__v4d)(((hd__v4l)(c) & lt_) | ((hd__v4l)(m) & ~lt_));             \
    } while (0)

/* m = c > m ? c : m in each lane. */
#define HD__V4_MAX(m, c)                                                           \
    do {                                                                           \
        hd__v4l gt_ = (c) > (m);                                                   \
        (m) = (hd__v4d)(((hd__v4l)(c) & gt_) | ((hd__v4l)(m) & ~gt_));             \
    } while (0)

HD__INLINE double hd__min32(const double *c) {
    hd__v4d m0, m1, a, b;
    __builtin_memcpy(&m0, c, sizeof m0);
    __builtin_memcpy(&m1, c + 4, sizeof m1);
    for (int k = 8; k < HD__BUCKET; k += 8) {
        __builtin_memcpy(&a, c + k, sizeof a);
        __builtin_memcpy(&b, c + k + 4, sizeof b);
        HD__V4_MIN(m0, a);
        HD__V4_MIN(m1, b);
    }
    HD__V4_MIN(m0, m1);
    double x = m0[0] < m0[1] ? m0[0] : m0[1], y = m0[2] < m0[3] ? m0[2] : m0[3];
    return x < y ? x : y;
}

/* The first position of value v in c (v occurs, and is a real point) --
 * unless the caller's points changed during the call (hausdorff.h forbids
 * it, but a Python thread can do it): a NaN written after validation makes
 * v NaN, found nowhere, and then position 0 (always a real point) keeps
 * the search in bounds.  The answer is then meaningless, but nothing is
 * read out of bounds. */
HD__INLINE int hd__find(const double *c, double v) {
    /* A mask of the equal values, without an early exit: the loop
     * vectorises (compare, move mask), where a search loop does not. */
    uint32_t m = 0;
    for (int k = 0; k < HD__BUCKET; k++) m |= (uint32_t)(c[k] == v) << k;
    assert(m != 0 || __builtin_isnan(v)); /* some c[k] == v unless v is NaN */
    return m ? __builtin_ctz(m) : 0;
}

/* Keep the k items with the largest scores, in decreasing order of score,
 * in score[0..*n) and item[0..*n) (*n grows to k). */
HD__INLINE void hd__top_insert(double *score, size_t *item, int *n, int k, double sc, size_t it) {
    if (*n == k && !(sc > score[k - 1])) return;
    int at = *n < k ? (*n)++ : k - 1;
    while (at > 0 && score[at - 1] < sc) {
        score[at] = score[at - 1];
        item[at] = item[at - 1];
        at--;
    }
    score[at] = sc;
    item[at] = it;
}

/* ---- proofs from approximations -------------------------------------------- */
/* Relative slack that covers every rounding in the computed squared
 * distances (a few units of 2^-53) and in these thresholds, many times over;
 * and an absolute floor below which squared distances may have underflowed. */
#define HD__SLACK 1e-12
#define HD__TINY 1e-280

/* A computed squared distance c~ = hd__d2s(q, p~) < hd__kill_below(lim, E),
 * where the true point p lies within E of p~ (and q is exact, or E includes
 * q's own error), proves that the computed hd__d2s(q, p) < lim.  Returns 0
 * (nothing is proven, c~ >= 0) when lim is too small. */
HD__INLINE double hd__kill_below(double lim, double E) {
    if (!(lim > HD__TINY)) return 0.0;
    double r = __builtin_sqrt(lim) * (1 - HD__SLACK) - E * (1 + HD__SLACK);
    if (r <= 0) return 0.0;
    double t = r * r * (1 - HD__SLACK);
    /* With an error bound E >= 0, the threshold never exceeds lim. */
    assert(!(E >= 0) || !(t > lim));
    return t > HD__TINY ? t : 0.0;
}

/* A computed c~ > hd__may_reach(best, E) proves hd__d2s(q, p) > best. */
HD__INLINE double hd__may_reach(double best, double E) {
    double r = __builtin_sqrt(best) * (1 + HD__SLACK) + E * (1 + HD__SLACK);
    double t = r * r * (1 + HD__SLACK) + HD__TINY;
    assert(!(E >= 0) || !(t < best)); /* with E >= 0, a point beyond it is beyond best */
    return t;
}

/* ---- searching ----------------------------------------------------------- */

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

/* How hd__index_nearest_by answers (index.c). */
typedef enum hd__nearest_path {
    /* As hd_index_nearest: the groups of nearest/allnearest.c, or the tree
     * for sets beyond that file's limit or without memory for the groups. */
    HD__NEAREST_AUTO = 0,
    /* For the tests: one search of the index's tree per query, the path
     * that only those sets take otherwise. */
    HD__NEAREST_TREE = 1
} hd__nearest_path_t;

/* hd_index_nearest by the given path. */
int hd__index_nearest_by(const hd_index_t *idx, const hd_points_t *Q, const hd_transform_t *T,
                         const hd_options_t *opt, double *dist, size_t *nearest,
                         hd__nearest_path_t path, hd_error_t *err);

/* Exact nearest neighbour of the exact point q in t: hit->d2 is the
 * smallest squared distance and hit->j the smallest original index
 * attaining it.  Bucket `hint` (or HD__NONE) is searched first.  The search
 * may stop as soon as it proves that some point lies at squared distance
 * < stop2, or <= tie2; it then sets hit->killed.  Pass stop2 = 0 and
 * tie2 = -1 for a full search. */
void hd__tree_nearest(const hd__tree_t *t, const double q[3], double stop2, double tie2,
                      size_t hint, hd__hit_t *hit, hd__counts_t *n);

/* ---- the grid: a cheap index for sparse queries (grid.c) --------------------- */

/* Points grouped by the cell of a uniform grid of 2^bits cubic cells per
 * axis over the set's box; cells are numbered along the Morton curve, so
 * the cells below any node of the implicit octree over them are a
 * contiguous range, and so are their points.  Each cell keeps a
 * representative, its point with the smallest original index. */
typedef struct hd__grid {
    size_t n;
    hd__src_t src;
    int bits;             /* cells per axis: 1 << bits (at most 6) */
    double lo[3], w, inv; /* cell (cx, cy, cz) spans lo + c * w .. lo + (c + 1) * w */
    double margin;        /* widening of every face that covers all rounding */
    uint32_t *perm;       /* n original indices grouped by cell */
    uint32_t *start;      /* 8^bits + 1 offsets into perm */
    double *rep;          /* per cell x, y, z of its representative; NaN if empty */
    hd__reuse_t *pool;     /* where the arrays come from and go back to (or NULL) */
} hd__grid_t;

/* The grid's arrays come from `pool` (NULL: plain allocations). */
int hd__grid_build(hd__grid_t *g, const hd__src_t *src, size_t n, const hd__box_t *box,
                   int threads, hd__reuse_t *pool, hd_error_t *err);
/* The same with the cells a set of n_cells points would get (a sample's
 * grid as fine as its set's). */
int hd__grid_build_as(hd__grid_t *g, const hd__src_t *src, size_t n, size_t n_cells,
                      const hd__box_t *box, int threads, hd__reuse_t *pool, hd_error_t *err);
void hd__grid_free(hd__grid_t *g);

/* Exact nearest neighbour of q in g, with the early stop of hd__tree_nearest
 * (stop2, tie2).  hit->bucket is unused. */
void hd__grid_nearest(const hd__grid_t *g, const double q[3], double stop2, double tie2,
                      hd__hit_t *hit, hd__counts_t *n);

/* ---- the running maximum shared by the threads of one direction --------------- */

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

/* cmax (the bound all threads raise), and under a lock the maximum so far
 * with its canonical witness. */
typedef struct hd__max {
    hd__bound_t cmax;
    pthread_mutex_t lock;
    hd__best_t best;
    hd__keep_t keep;
} hd__max_t;

int hd__max_init(hd__max_t *m);
void hd__max_destroy(hd__max_t *m);
/* Record an exact nearest distance d2 of point i (nearest j), unless the
 * maximum's filter refuses it; *snap gets a consistent copy of the maximum
 * so far. */
void hd__max_offer(hd__max_t *m, double d2, size_t i, size_t j, hd__best_t *snap);
void hd__max_snapshot(hd__max_t *m, hd__best_t *snap);

/* Whether a point of B at squared distance d2 from point i of A proves that
 * i is not the witness: its nearest distance is then below the maximum
 * (d2 < cmax2), or at most a maximum already attained at a smaller index
 * (snap, a consistent copy of the maximum so far). */
HD__INLINE int hd__kills(double cmax2, const hd__best_t *snap, double d2, size_t i) {
    return d2 < cmax2 || (d2 <= snap->d2 && i > snap->i);
}

/* h(A,B) by the grid: A's cells (ga) are visited in Morton order, and a
 * cell is discarded whole when one point of B is proven strictly within
 * cmax of its whole box; the points of the other cells are tested against
 * nearby points of B and searched exactly when none discards them (when
 * cmax is below a cell's diagonal, all of A's points in input order
 * instead).  On return m holds the maximum; counts and culled are added
 * to. */
int hd__grid_directed(const hd__grid_t *ga, const hd__grid_t *gb, hd__max_t *m, int threads,
                      hd__counts_t *counts, uint64_t *culled, hd_error_t *err);

/* Prime m with the exact nearest distances of the HD__PRIME_CELLS
 * representatives of A's cells (ga) that lie where B is emptiest. */
#define HD__PRIME_CELLS 32
void hd__grid_prime(const hd__grid_t *ga, const hd__grid_t *gb, hd__max_t *m,
                    hd__counts_t *counts);
/* The representatives of A's cells farthest from a grid gs of a sample of
 * B, for when B has no grid of its own yet: their indices into A (out),
 * their number returned. */
int hd__grid_prime_picks_far(const hd__grid_t *ga, const hd__grid_t *gs, size_t out[HD__PRIME_CELLS]);

/* The same from A's points alone, before A has a grid: of every
 * `step`-th point of A, the HD__PRIME_CELLS lying where B is emptiest. */
void hd__grid_prime_sampled(const hd__src_t *a, size_t na, size_t step, const hd__grid_t *gb,
                            hd__max_t *m, hd__counts_t *counts);

/* Prime m with the exact nearest distances of points of a sample of A
 * chosen where the maximum is likely, then run the grid pass over the
 * sample; returns its work (distances and nodes) per sampled point, or
 * stops early with some value above `limit`. */
double hd__grid_trial(const hd__src_t *a, size_t na, const hd__grid_t *gb, hd__max_t *m,
                      double limit, hd__counts_t *counts);

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

/* The correspondence path (pairs.c), for two sets of n points each
 * listed in the same order (a copy and its original).  hd__pairs_begin
 * tests a sample and, when the partners (a_i, b_i) look closer than other
 * neighbours, lists the pairs with the largest distances (P->active).
 * hd__pairs_resolve then resolves, for each direction d < directions, the
 * listed points of set d exactly, in decreasing order of pair distance,
 * until the rest provably cannot hold the witness (P->resolved[d]; max[d]
 * then holds h exactly): by scans of the other set while grid is NULL
 * (and a budget lasts), in grid[1 - d] otherwise.  It returns 1 when every
 * direction is resolved.  Otherwise max[d] has only been raised. */
struct hd__pair;
typedef struct hd__pairs {
    struct hd__pair *list; /* m pairs in resolution order */
    size_t m, n, pos[2];
    uint64_t scanned; /* points read by scans */
    int active, resolved[2];
} hd__pairs_t;

int hd__pairs_begin(hd__pairs_t *P, const hd__src_t src[2], size_t n, int threads,
                    hd__counts_t *counts, hd_error_t *err);
int hd__pairs_resolve(hd__pairs_t *P, const hd__src_t src[2], const hd__grid_t *grid,
                      hd__max_t *max, int directions, hd__counts_t *counts);
void hd__pairs_free(hd__pairs_t *P);

/* When the ns points of `small` appear, in order, as exact copies among the
 * nl > ns points of `large` (an ordered subset), h(small, large) = 0: offer
 * it to max with its witness and return 1; otherwise return 0 (after
 * reading at most a short window of `large` when the sets are unrelated). */
int hd__subset_resolve(const hd__src_t *small, size_t ns, const hd__src_t *large, size_t nl,
                       hd__max_t *max, hd__counts_t *counts);

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
