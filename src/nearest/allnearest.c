/*
 * allnearest.c -- exact all-nearest-neighbours: for every point of one set,
 * the nearest point of the other, with the smallest index among ties.  This
 * is what hd_distances computes (stats.c), in both directions.
 *
 * A per-point answer needs one complete search per point: no point may be
 * skipped, as the Hausdorff distance's pruning skips the points that cannot
 * be the farthest.  What can be saved is everything around the searches.
 * The exact kd-tree (classic/kdtree.c) that served here before paid for a
 * median selection per node to build, and then walked from its root once
 * per query.  Here:
 *  - Build.  Each set is sorted once along a Morton curve: 30-bit keys on a
 *    grid of 1024 cells per axis over the union of both sets' boxes (so that
 *    the two orders line up), the engine's stable radix sort of key and
 *    index (hd__radix_sort: three counting passes of 10 bits, whose 1024
 *    destinations a pass stream better than the 32768 of two 15-bit
 *    passes), then one gather of the coordinates into
 *    packed arrays
 *    (x[], y[], z[], original indices idx[]).  The sorted keys define an
 *    octree; one pass over them cuts it where a cell holds at most
 *    HD__AN_BUCKET points (the buckets, which are searched) and, coarser,
 *    HD__AN_GROUP points (the groups, in which a set's own points ask).
 *    Octree cells are cubes, so buckets and groups are compact even where
 *    the density changes by orders of magnitude (a Gaussian's core and its
 *    tails), which buckets of a fixed number of consecutive points are not:
 *    those straddle the curve's jumps, and their boxes overlap.  Cells with
 *    a single non-empty child are not stored, so every inner node has two
 *    children or more.  A cell of more than HD__AN_BUCKET points whose keys
 *    are all equal (a dense cluster in a set with far outliers, whose grid
 *    is too coarse for it) is sorted again on a grid over its own box
 *    (refine), up to MAX_REFINE times nested; a bucket whose points are all
 *    copies of one point is scanned as that one point (the sorts are
 *    stable, so its first copy has the smallest index), which keeps
 *    duplicates from costing a scan each.  Every node gets the exact box of
 *    its points.  The two sets are built side by side (stats.c).  A
 *    structure may hold a selection of a set's points, read through the
 *    selection and named as its caller says (hd__an_build_sel: the MPI
 *    layer's slabs, with no copy of the points); the names increase along
 *    the selection, so a stable sort's first copy of a point still has the
 *    smallest name.  The node and bucket arrays grow as the octree is cut
 *    (they were sized for the worst case, n + 1 buckets, and mostly never
 *    touched), and the build keeps an account of every byte it allocates:
 *    its peak (hd__an_t.peak) is what the MPI layer charges.
 *  - Search, a group at a time.  Every query first scans its seeds: the two
 *    searched buckets at its own bucket's place on the curve (the orders
 *    line up, so that is usually close), and the bucket reached from the
 *    root by always taking the child nearest to the group's box (which is
 *    close even when the group is far from the searched set, or the curve
 *    says little).  U, the largest seed distance of the group, lowered to
 *    the upper bounds of the nodes on that path, bounds every answer of the
 *    group.  One traversal of the searched octree then lists every bucket
 *    within U of the group's box: the candidates.  Each query computes its
 *    own bound to every candidate (one vectorised loop), lists without
 *    branches those within its best seed distance, and scans them, each
 *    tested again against the best distance found so far.
 *  - Partners.  Two sets of one size are often a copy and its original in
 *    the same order (a deformed or denoised mesh, a registered scan).  Then
 *    the searched point with a query's own original index, its partner, is
 *    usually its answer or next to it.  Each query of a group starts with
 *    its partner's distance (an actual point's, so the largest over the
 *    group bounds every answer, as U does), and when at most
 *    PAIR_CANDIDATES buckets lie within that bound they are the candidates
 *    and no seed is scanned; otherwise the window path (while it pays)
 *    or the seeds go on from the partners.
 *    The partners are read from the caller's view in its order (a random
 *    access, prefetched a group ahead), or, given by position
 *    (hd__an_nearest_paired: the MPI layer's local parts, of different
 *    sizes, where some partners are on other ranks), from the searched
 *    structure itself; a query without a partner leaves the group's bound
 *    infinite, and the group goes on to the window or the seeds.  A group
 *    counts as a success when
 *    at least half of its answers are the partners themselves; a task stops
 *    trying once most of the groups it tried, PAIR_TRIAL at least, failed,
 *    so unrelated sets pay for eight groups a task.  (Sets of a few
 *    repeated points list few candidates for any partner, but the partner
 *    is seldom the answer there, and reading partners costs a cache miss
 *    each, so trying every group would cost more than it saves.)  This is the engine's correspondence bound (engine/pairs.c)
 *    put to per-point use.
 *  - Window.  When the partners do not help (a copy in another order, or
 *    two sets sampled alike), the two Morton orders still line up: a
 *    query's answer is usually within a few places of the query's own key
 *    on the searched set's curve.  Each set keeps the key of every point
 *    (key32[], 4 bytes a point); a query finds the first searched point
 *    whose key is not below its own (from the searched bucket at its
 *    bucket's key, moving forward as the keys grow) and scans the WINDOW
 *    points around it.  Most queries then hold their answer or a point
 *    as near, and the largest of their bests lists few candidates.  The
 *    few whose answer lies across a jump of the curve have far worse
 *    bests, and one of them would set a bound for the whole group: they
 *    are set apart (best above 16 times, in squares, the geometric mean of
 *    the group's bests, read from the exponents), U is the largest best of
 *    the others, and each query set apart is answered from the group's list
 *    like the others (its answer is usually within U, only its window
 *    was not); when its best is still above U after the list, its answer
 *    is above U, and it lists its own candidates around its own point.
 *    A group fails when more than
 *    a quarter of its queries are set apart or more than WINDOW_CANDIDATES
 *    buckets are listed; a task drops the path as it drops the partners.
 *    How often each route runs is in docs/benchmarks.md, "Issue 15".
 *  - Chunks.  A group's list serves its queries CHUNK at a time: the
 *    chunk's own list keeps the group's candidates within Uc of the
 *    chunk's box, Uc the smaller of U and the chunk's largest best (each
 *    query's answer is at most both), so each query computes fewer
 *    bounds; a list longer than CHUNK_LIST is not filtered but listed
 *    again from the root for the chunk's box.
 *  - Sparse groups (the solo path).  A group of queries whose box
 *    overlaps more of the searched buckets than it has queries (a sparse
 *    set asking a dense one: 10K points asking 1M) shares nothing: its
 *    list would hold thousands of buckets, each bounded for every query.
 *    Each of its queries is searched on its own instead: its window, then
 *    the buckets within that best of the query itself, then the scans.
 *  - Point lists.  A group small next to the distances to its answers (a
 *    dense set asking a sparse one: 1M points asking 10K) has many queries
 *    and few points that can be any of their answers.  When its listed
 *    buckets hold at most POINT_LIST points, those within min(U, V) of the
 *    group's box are kept, V the smallest upper bound from the box to one
 *    of them; each chunk keeps, the same way, those that can be any of its
 *    answers, and while that stays at most 2 CHUNK points its queries scan
 *    just them (no bucket bounds, no per-query lists).
 *  - Shared point lists.  When the asking set is DENSE times as large as
 *    t or more, neighbouring groups have nearly the same candidate points:
 *    RUN consecutive groups list them once, for the run's box, within the
 *    nearest leaf's bound Ub of it (as a far group does, with no window
 *    and no seed), and each group keeps from that list the points that
 *    can be its answers, as a chunk does from its group's.  A run whose box
 *    is not small next to Ub, or whose buckets are too many, leaves its
 *    groups to the paths above.
 *  - Far groups.  A group whose box lies outside the searched set's box
 *    by more than its own diagonal (disjoint sets: the window and the
 *    seeds are far from its answers, and every query scanned the nearest
 *    bucket only to set a bound) takes the nearest leaf's bound Ub (the
 *    least upper bound from the group's box to one of the leaf's points,
 *    far tighter than the bound to the leaf's box: fewer candidates),
 *    which bounds every answer of the group, as U; when at most FAR_CANDIDATES
 *    buckets lie within it, holding at most POINT_LIST points, they are
 *    its candidates, no bucket is scanned first, and its queries are
 *    answered from point lists (the group is small next to Ub).  A group
 *    of the seed path whose box is as far from the nearest leaf is
 *    settled the same way.
 *  - Scans.  A bucket is scanned four points at a time with GCC's vector
 *    extension (each lane evaluates hd__d2s's expression: no fused
 *    multiply-add, -ffp-contract=off), each lane keeping its smallest
 *    distance and the smallest index at it; the scan starts at the group of
 *    four holding the bucket's first point and ends past its last, so it
 *    may read a few points of the neighbouring buckets (and the four copies
 *    of the last point stored after the end), all of them points of the
 *    set.  The lanes' minimum and the smallest index at it are then picked
 *    without a branch per lane: those branches mispredicted.  This file is compiled with
 *    -fno-trapping-math (CMakeLists.txt):
 *    without it GCC does not vectorise the bound loop, and no value
 *    changes.
 *
 * Exactness.  Nothing depends on the Morton order, which only decides
 * locality: every decision compares an exact squared distance or a bound
 * computed from exact boxes.  Every box (buckets, nodes, groups) is the min
 * and max of the stored doubles of its points.  IEEE rounding is monotone
 * (points/points.h): for q in box Q and p in box B, the computed |fl(q - p)| on
 * each axis is at least the computed gap fl(B.lo - Q.hi) (or
 * fl(Q.lo - B.hi)) and at most the computed span max(fl(Q.hi - B.lo),
 * fl(B.hi - Q.lo)), and squaring and the left-to-right sum keep both
 * inequalities.  So node_lb2(Q, B) never exceeds, and node_ub2(Q, B) is
 * never below, the computed hd__d2s of any pair; the same holds for a
 * single query (hd__box_lb2s's expression).
 *  - U is a distance to an actual point (a seed, a partner or a point of
 *    a window) or a node's upper bound (every node holds a point), so each
 *    query of the group has a point within U, and its answer is at most
 *    U; on the window path U is the largest best of the queries not set
 *    apart, so it bounds their answers only.  A query set apart is searched
 *    on the group's list (every bucket within U of a box holding it) with
 *    its bests limited to U: if its answer is at most U, the answer's
 *    bucket has a bound at most the answer, is listed and scanned, and
 *    its best ends at most U; so a best still above U says the answer is
 *    above U, and the query then lists its own candidates within its best
 *    (an actual point's distance, so at least its answer) of its own
 *    point.
 *  - A seed bucket is scanned only when node_lb2 from the group's box to
 *    its box is at most Ub, the nearest leaf's bound; U <= Ub, so a seed
 *    left unscanned is not listed either (the list holds the buckets with
 *    node_lb2 <= U, the same computed value), and no query needs it.
 *  - A node or candidate is dropped only when its bound is strictly above U
 *    or above the query's best distance so far (which is an actual point's
 *    distance): none of its points can be the nearest, nor tie with it.  A
 *    bound equal to the best is not enough: the candidate may hold a point
 *    at the same distance with a smaller original index.
 *  - A chunk's list and a solo query's list are lists of the same kind,
 *    within a bound that is at least the answer of each query using them
 *    (Uc; a solo query's best).  A point list drops a point only when its
 *    bound from the box (node_lb2's expression for a box of one point)
 *    exceeds min(U, V): V is node_ub2's expression from the box to a kept
 *    point, never below that point's computed distance to a query in the
 *    box, so the answer is at most V, and the dropped point is farther.
 *    A run's shared list is such a list for the run's box, within
 *    min(Ub, V): it holds every answer of every query in the box, and
 *    min(Ub, V) bounds each of them, so a group's list taken from it (a
 *    box inside the run's) is one again.
 *    Its scans are the buckets' scans (scan_arrays), over copies of points
 *    of the set only.
 *  - A point replaces the best on a smaller squared distance, or on an
 *    equal one with a smaller original index; reading a point twice (seed
 *    and candidate, overlapping scans) or reading extra points of the set
 *    changes neither, and neither does reading only the first of a
 *    bucket's copies of one point (same distance, smallest index).
 * So each answer is the exact minimum and the smallest index attaining it,
 * whatever the grouping, the order of the candidates or the number of
 * threads; the radix sort is stable with parts in order, so even the
 * structure is the same at any thread count.  The work is split by groups,
 * and every answer is written to the query's original index.
 *
 * Answers are written in the asking set's order, squared, into a buffer
 * (12 bytes per point), and a last parallel pass takes their square roots
 * to the caller's arrays at the original indices: one tight loop of
 * scattered stores overlaps its cache misses, which the same stores
 * between searches did not.
 *
 * Memory: about 36 bytes per point and set (28 for the coordinates and
 * indices, 4 for the keys, the rest for buckets, groups and nodes with their boxes, of
 * which there are far fewer than points), 12 bytes
 * per asking point for the answers in its order, and, per thread, 128
 * bytes per searched bucket for the candidates (the group's list and a
 * chunk's), with about 60 KB of stack for the point lists.  While a set is built it
 * holds up to about 38 bytes per point: 8 of sort keys beside the
 * coordinates and indices (the sort's other buffer is x[]'s memory), and
 * the node and per-bucket arrays, which grow as the octree is cut (sized
 * for the worst case, one point a bucket, they took 24 bytes a point
 * more); the build's account of it is hd__an_t.peak.  What each
 * of these choices was measured to save, and the times, are in
 * docs/journal/benchmarks.md, "Analysis".  Sets of more than HD__AN_MAX_POINTS
 * points are refused with HD_EOVERFLOW (stats.c then uses the kd-trees).
 */
#include "nearest/nearest.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Four lanes of doubles, of 64-bit and of 32-bit integers (GCC's vector
 * extension: the bucket scans, the boxes). */
typedef double v4d __attribute__((vector_size(32)));
typedef int64_t v4l __attribute__((vector_size(32)));
typedef uint32_t v4u __attribute__((vector_size(16)));

/* ---- building ---------------------------------------------------------------- */

#define MAX_PARTS 16
#define GATHER_TASK 16384 /* points per gathering task */
#define BOX_TASK 1024     /* buckets per box task */

typedef struct {
    hd__an_t *s;
    hd__src_t src;
    hd__keygrid_t grid;
    size_t n;
    int parts;
    uint64_t *a, *b;     /* key << 32 | index: computed in a, sorted into b */
    const uint32_t *sel; /* point i is the source's point sel[i] (NULL: i) */
    const uint32_t *names; /* and is named names[i] (NULL: its number in the source) */
    size_t bcap, ncap;   /* room in the per-bucket (and per-group) and per-node arrays */
    size_t held, peak;   /* bytes allocated now and at most (hd__an_t.peak) */
} build_ctx;

/* The build's account of what it holds (hd__an_t.peak). */
static void held_add(build_ctx *c, size_t bytes) {
    c->held += bytes;
    if (c->held > c->peak) c->peak = c->held;
}

/* Part p's share of [0, n). */
static void part_range(const build_ctx *c, size_t part, size_t *lo, size_t *hi) {
    *lo = c->n * part / (size_t)c->parts;
    *hi = c->n * (part + 1) / (size_t)c->parts;
}

/* Keys of one part. */
static void key_task(void *vctx, size_t part, int worker) {
    (void)worker;
    build_ctx *c = vctx;
    size_t lo, hi;
    part_range(c, part, &lo, &hi);
    if (!c->sel) {
        hd__src_keys(&c->src, &c->grid, lo, hi, c->a);
        return;
    }
    for (size_t i = lo; i < hi; i++) {
        double p[3];
        hd__src_get(&c->src, c->sel[i], p);
        c->a[i] = (uint64_t)hd__key30(&c->grid, p) << 32 | (uint64_t)i;
    }
}

/* Packed point i of base to position `at` of s. */
HD__INLINE void gather_f64(hd__an_t *s, const double *base, size_t at, uint32_t i) {
    const double *q = base + 3 * (size_t)i;
    s->x[at] = q[0], s->y[at] = q[1], s->z[at] = q[2];
    s->idx[at] = i;
}

/* Gather the points [task * GATHER_TASK, ...) in sorted order (positions
 * n .. n + 3 repeat the last point, so that scans may read whole groups of
 * four). */
static void gather_task(void *vctx, size_t task, int worker) {
    (void)worker;
    build_ctx *c = vctx;
    hd__an_t *s = c->s;
    size_t lo = task * GATHER_TASK, hi = lo + GATHER_TASK < s->n + 4 ? lo + GATHER_TASK : s->n + 4;
    const uint32_t *sel = c->sel, *names = c->names;
    if (sel) { /* a selection (hd__an_build_sel): its own loop, the other is hot */
        for (size_t at = lo; at < hi; at++) {
            if (at + 16 < s->n && c->src.kind != HD__SRC_ANY)
                __builtin_prefetch(c->src.base + (ptrdiff_t)sel[(uint32_t)c->b[at + 16]] *
                                                     hd__src_packed_stride(&c->src));
            uint32_t i = (uint32_t)c->b[at < s->n ? at : s->n - 1];
            double p[3];
            hd__src_get(&c->src, sel[i], p);
            s->x[at] = p[0], s->y[at] = p[1], s->z[at] = p[2];
            s->idx[at] = names ? names[i] : sel[i];
        }
        return;
    }
    if (c->src.kind == HD__SRC_F64 && !c->src.T) {
        /* Packed doubles, the layout most callers pass: the same reads as
         * hd__src_get's, without its tests per point. */
        const double *base = (const double *)(const void *)c->src.base;
        size_t mid = s->n > 16 ? s->n - 16 : 0; /* below it, a point 16 ahead exists */
        mid = mid < lo ? lo : mid > hi ? hi : mid;
        for (size_t at = lo; at < mid; at++) {
            __builtin_prefetch(base + 3 * (size_t)(uint32_t)c->b[at + 16]);
            gather_f64(s, base, at, (uint32_t)c->b[at]);
        }
        for (size_t at = mid; at < hi; at++) gather_f64(s, base, at, (uint32_t)c->b[at < s->n ? at : s->n - 1]);
        return;
    }
    for (size_t at = lo; at < hi; at++) {
        if (at + 16 < s->n && c->src.kind != HD__SRC_ANY)
            __builtin_prefetch(c->src.base + (ptrdiff_t)(uint32_t)c->b[at + 16] * hd__src_packed_stride(&c->src));
        uint32_t i = (uint32_t)c->b[at < s->n ? at : s->n - 1];
        double p[3];
        hd__src_get(&c->src, i, p);
        s->x[at] = p[0], s->y[at] = p[1], s->z[at] = p[2];
        s->idx[at] = i;
    }
}

/* The smallest and the largest of v[b], ..., v[e - 1] (b < e) into *lo
 * and *hi: four lanes at a time, then the lanes' (each lane's, and so
 * the whole set's, are values of v: the box is exact). */
HD__INLINE void span_minmax(const double *v, size_t b, size_t e, double *lo, double *hi) {
    double l = v[b], h = l;
    size_t i = b + 1;
    if (e - b >= 8) {
        v4d l4, h4, w;
        __builtin_memcpy(&l4, v + b, sizeof l4);
        h4 = l4;
        for (i = b + 4; i + 4 <= e; i += 4) {
            __builtin_memcpy(&w, v + i, sizeof w);
            v4l lt = w < l4, gt = w > h4;
            l4 = (v4d)(((v4l)w & lt) | ((v4l)l4 & ~lt));
            h4 = (v4d)(((v4l)w & gt) | ((v4l)h4 & ~gt));
        }
        for (int k = 0; k < 4; k++) {
            l = l4[k] < l ? l4[k] : l;
            h = h4[k] > h ? h4[k] : h;
        }
    }
    for (; i < e; i++) {
        l = v[i] < l ? v[i] : l;
        h = v[i] > h ? v[i] : h;
    }
    *lo = l, *hi = h;
}

/* The exact box of the points [b, e) into node k's box. */
HD__INLINE void points_box(hd__an_t *s, size_t b, size_t e, size_t k) {
    const double *v[3] = {s->x, s->y, s->z};
    for (int d = 0; d < 3; d++) span_minmax(v[d], b, e, &s->lo[d][k], &s->hi[d][k]);
}

/* The exact boxes of the leaves of buckets [task * BOX_TASK, ...). */
HD__HOT static void box_task(void *vctx, size_t task, int worker) {
    (void)worker;
    build_ctx *c = vctx;
    hd__an_t *s = c->s;
    size_t b0 = task * BOX_TASK, b1 = b0 + BOX_TASK < s->nb ? b0 + BOX_TASK : s->nb;
    for (size_t b = b0; b < b1; b++) {
        size_t k = s->leaf[b];
        points_box(s, s->start[b], s->start[b + 1], k);
        /* Copies of one point are in index order (the sorts are stable):
         * the first one answers for all of them. */
        int same = 1;
        for (int d = 0; d < 3; d++) same = same && s->lo[d][k] == s->hi[d][k];
        s->stop[b] = same ? s->start[b] + 1 : s->start[b + 1];
    }
}

/* The end of the run of keys from e (below hi) with e's digit at `shift`:
 * within a cell the digits grow, so a galloping search then a bisection
 * find it in a logarithm of the run's length (a linear scan read every
 * key once per level of the octree). */
static size_t digit_end(const uint64_t *keys, size_t e, size_t hi, int shift) {
    uint64_t digit = keys[e] >> shift & 7;
    size_t step = 1, in = e; /* keys[in] has the digit; the end is in (in, out] */
    while (in + step < hi && (keys[in + step] >> shift & 7) == digit) in += step, step *= 2;
    size_t out = in + step < hi ? in + step : hi;
    while (out - in > 1) {
        size_t mid = in + (out - in) / 2;
        if ((keys[mid] >> shift & 7) == digit) in = mid;
        else out = mid;
    }
    return out;
}

/* The children of the octree cell [lo, hi) of the sorted keys at `shift`
 * (the cell's keys agree above it): the ends of its non-empty sub-cells,
 * in order.  Cells with one sub-cell are split further at once, so every
 * returned cell has at least two children, unless its keys are all equal
 * (then it has one, and *shift is below 32). */
static int split_cell(const uint64_t *keys, size_t lo, size_t hi, int *shift, size_t ends[8]) {
    for (;;) {
        int nc = 0;
        for (size_t e = lo; e < hi;) ends[nc++] = e = digit_end(keys, e, hi, *shift);
        *shift -= 3;
        if (nc > 1 || *shift < 32) return nc;
    }
}

static int cmp_u64(const void *x, const void *y) {
    uint64_t a = *(const uint64_t *)x, b = *(const uint64_t *)y;
    return (a > b) - (a < b);
}

/* A cell of more than HD__AN_BUCKET points whose keys are all equal (the
 * grid is too coarse there: a dense cluster in a set with far outliers):
 * sort its points again on a grid over their own box and put the new keys
 * in keys[lo, hi), so that the octree can split it further.  Returns 0
 * when the points are all equal (nothing to split) or memory is short
 * (the cell then stays one large bucket: slower, still exact). */
static int refine(build_ctx *c, hd__an_t *s, uint64_t *keys, size_t lo, size_t hi) {
    size_t m = hi - lo;
    hd__box_t box;
    double *v[3] = {s->x, s->y, s->z};
    for (int d = 0; d < 3; d++) {
        box.lo[d] = box.hi[d] = v[d][lo];
        for (size_t i = lo + 1; i < hi; i++) {
            box.lo[d] = v[d][i] < box.lo[d] ? v[d][i] : box.lo[d];
            box.hi[d] = v[d][i] > box.hi[d] ? v[d][i] : box.hi[d];
        }
    }
    hd__keygrid_t g;
    hd__keygrid_init(&g, &box);
    if (g.scale == 0.0) return 0;
    uint64_t *k2 = hd__malloc_array(m, sizeof *k2);
    double *t = hd__malloc_array(m, 3 * sizeof *t);
    uint32_t *ti = hd__malloc_array(m, sizeof *ti);
    int ok = k2 && t && ti;
    size_t temp = m * (sizeof *k2 + 3 * sizeof *t + sizeof *ti); /* m < n: no overflow */
    held_add(c, temp);
    c->held -= temp;
    if (ok) {
        for (size_t i = 0; i < m; i++) {
            double p[3] = {s->x[lo + i], s->y[lo + i], s->z[lo + i]};
            k2[i] = (uint64_t)hd__key30(&g, p) << 32 | (uint64_t)i;
            t[3 * i] = p[0], t[3 * i + 1] = p[1], t[3 * i + 2] = p[2];
            ti[i] = s->idx[lo + i];
        }
        qsort(k2, m, sizeof *k2, cmp_u64);
        for (size_t r = 0; r < m; r++) {
            size_t i = (uint32_t)k2[r];
            s->x[lo + r] = t[3 * i], s->y[lo + r] = t[3 * i + 1], s->z[lo + r] = t[3 * i + 2];
            s->idx[lo + r] = ti[i];
            keys[lo + r] = (k2[r] >> 32) << 32 | ti[i];
        }
    }
    free(k2);
    free(t);
    free(ti);
    return ok;
}

/* Nested refinements followed, at most (each one splits its cell). */
#define MAX_REFINE 6

/* Array *p of `cap` elements of `size` bytes made `want` long, in the
 * build's account (both blocks at once, as a copying realloc holds them). */
static int grow(build_ctx *c, void **p, size_t cap, size_t want, size_t size) {
    void *q = hd__realloc_array(*p, want, size);
    if (!q) return HD_ENOMEM;
    *p = q;
    held_add(c, want * size); /* want * size: checked by hd__realloc_array */
    c->held -= cap * size;
    return HD_OK;
}

/* Half as much room again, or `need` if more. */
static size_t grown(size_t cap, size_t need) {
    return cap + cap / 2 > need ? cap + cap / 2 : need;
}

/* The node arrays with room for `need`. */
static int grow_nodes(build_ctx *c, size_t need) {
    hd__an_t *s = c->s;
    size_t want = grown(c->ncap, need), cap = c->ncap;
    if (grow(c, (void **)&s->first, cap, want, sizeof *s->first) ||
        grow(c, (void **)&s->count, cap, want, sizeof *s->count))
        return HD_ENOMEM;
    c->ncap = want;
    return HD_OK;
}

/* The per-bucket and per-group arrays (a group holds a bucket or more, so
 * there are never more groups than buckets) with room for `need`. */
static int grow_buckets(build_ctx *c, size_t need) {
    hd__an_t *s = c->s;
    size_t want = grown(c->bcap, need), cap = c->bcap;
    uint32_t **a[6] = {&s->start, &s->key, &s->stop, &s->leaf, &s->gstart, &s->glead};
    for (int k = 0; k < 6; k++)
        if (grow(c, (void **)a[k], cap, want, sizeof(uint32_t))) return HD_ENOMEM;
    c->bcap = want;
    return HD_OK;
}

/* The octree of the sorted keys, cells split until at most HD__AN_BUCKET
 * points remain (or their points are equal): node 0 is the root, the
 * children of a node are consecutive nodes, and the leaves are the buckets,
 * numbered in key order (start[], leaf[], and key[]: the key of each
 * bucket's first point on the grid of both sets).  The groups are the
 * largest nodes of at most HD__AN_GROUP points (or leaves): unions of whole
 * buckets (gstart[], glead[]). */
static int build_octree(build_ctx *c) {
    hd__an_t *s = c->s;
    uint64_t *keys = c->b;
    struct {
        size_t lo, hi, node;
        int shift, grouped, refined;
    } stack[7 * 10 * (MAX_REFINE + 1) + 8];
    int sp = 1;
    size_t n = s->n, nb = 0, nn = 1, ng = 0;
    stack[0].lo = 0, stack[0].hi = n, stack[0].node = 0, stack[0].shift = 27 + 32;
    stack[0].grouped = 0, stack[0].refined = 0;
    while (sp > 0) {
        sp--;
        size_t lo = stack[sp].lo, hi = stack[sp].hi, node = stack[sp].node;
        int shift = stack[sp].shift, grouped = stack[sp].grouped, refined = stack[sp].refined;
        /* Room for a leaf at nb, a group at ng <= nb, and start[nb + 1]. */
        if (nb + 2 > c->bcap && grow_buckets(c, nb + 2)) return HD_ENOMEM;
        size_t ends[8];
        int nc = hi - lo <= HD__AN_BUCKET || shift < 32 ? 1 : split_cell(keys, lo, hi, &shift, ends);
        if (nc == 1 && hi - lo > HD__AN_BUCKET && refined < MAX_REFINE && refine(c, s, keys, lo, hi)) {
            /* The new keys differ (the cell's extreme points on its widest
             * axis get cells 0 and 1023), so the cell now splits. */
            shift = 27 + 32, refined++;
            nc = split_cell(keys, lo, hi, &shift, ends);
        }
        if (!grouped && (hi - lo <= HD__AN_GROUP || nc == 1)) {
            s->gstart[ng] = (uint32_t)lo;
            s->glead[ng++] = (uint32_t)nb;
            grouped = 1;
        }
        if (nc == 1) {
            double p[3] = {s->x[lo], s->y[lo], s->z[lo]};
            s->first[node] = (uint32_t)nb;
            s->count[node] = 0;
            s->leaf[nb] = (uint32_t)node;
            s->key[nb] = hd__key30(&c->grid, p);
            s->start[nb++] = (uint32_t)lo;
            continue;
        }
        if (nn + (size_t)nc > c->ncap && grow_nodes(c, nn + (size_t)nc)) return HD_ENOMEM;
        s->first[node] = (uint32_t)nn;
        s->count[node] = (uint8_t)nc;
        for (int k = nc - 1; k >= 0; k--) {
            stack[sp].lo = k ? ends[k - 1] : lo;
            stack[sp].hi = ends[k];
            stack[sp].node = nn + (size_t)k;
            stack[sp].shift = shift;
            stack[sp].grouped = grouped;
            stack[sp].refined = refined;
            sp++;
        }
        nn += (size_t)nc;
    }
    s->start[nb] = s->gstart[ng] = (uint32_t)n;
    s->nb = nb, s->ng = ng, s->nn = nn;
    return HD_OK;
}

static void shrink(void **p, size_t n, size_t size) {
    void *q = hd__realloc_array(*p, n, size);
    if (q) *p = q;
}

void hd__an_free(hd__an_t *s) {
    if (!s) return;
    free(s->x);
    free(s->y);
    free(s->z);
    free(s->idx);
    free(s->key32);
    free(s->start);
    free(s->key);
    free(s->stop);
    free(s->leaf);
    free(s->gstart);
    free(s->glead);
    free(s->first);
    free(s->count);
    for (int d = 0; d < 3; d++) free(s->lo[d]), free(s->hi[d]);
    memset(s, 0, sizeof *s);
}

/* The upper halves of keys[0, n) moved down to the first 4 n bytes of
 * the same memory, in order: four keys read, then their halves written
 * over bytes of keys read already. */
HD__HOT static void keys_upper(uint64_t *keys, size_t n) {
    unsigned char *k32 = (unsigned char *)keys;
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        uint64_t w[4];
        uint32_t k[4];
        memcpy(w, keys + i, sizeof w);
        for (int j = 0; j < 4; j++) k[j] = (uint32_t)(w[j] >> 32);
        memcpy(k32 + 4 * i, k, sizeof k);
    }
    for (; i < n; i++) {
        uint32_t k = (uint32_t)(keys[i] >> 32);
        memcpy(k32 + 4 * i, &k, sizeof k);
    }
}

/* The structure of the points p[sel[i]], i < n (sel NULL: p's first n),
 * each named names[i] (names NULL: by its number in p). */
static int build(hd__an_t *s, const hd_points_t *p, const uint32_t *sel, const uint32_t *names, size_t n,
                 const hd_transform_t *T, const hd__box_t *keybox, int threads, hd_error_t *err) {
    memset(s, 0, sizeof *s);
    if (n > HD__AN_MAX_POINTS)
        return hd__err(err, HD_EOVERFLOW, "at most %zu points per set, not %zu", (size_t)HD__AN_MAX_POINTS, n);
    s->n = n;
    threads = threads < 1 ? 1 : threads;
    build_ctx c;
    memset(&c, 0, sizeof c);
    c.s = s;
    c.n = n;
    c.sel = sel;
    c.names = names;
#ifndef NDEBUG
    for (size_t t = 1; t < n && (sel || names); t++) /* names increase (the essay) */
        assert(names ? names[t - 1] < names[t] : sel[t - 1] < sel[t]);
#endif
    hd__src_init(&c.src, p, T);
    hd__keygrid_init(&c.grid, keybox);
    c.parts = threads > MAX_PARTS ? MAX_PARTS : threads;
    c.parts = hd__parts_for(n, c.parts);
    /* Node and bucket arrays grow as the octree is cut (a bucket usually
     * holds a few dozen points; at worst there are fewer than 2n nodes,
     * since every inner node has two children or more). */
    c.ncap = n / 8 + 64;
    c.bcap = n / 16 + 64;
    s->x = hd__malloc_array(n + 4, sizeof *s->x);
    s->y = hd__malloc_array(n + 4, sizeof *s->y);
    s->z = hd__malloc_array(n + 4, sizeof *s->z);
    s->idx = hd__malloc_array(n + 4, sizeof *s->idx);
    s->start = hd__malloc_array(c.bcap, sizeof *s->start);
    s->key = hd__malloc_array(c.bcap, sizeof *s->key);
    s->stop = hd__malloc_array(c.bcap, sizeof *s->stop);
    s->leaf = hd__malloc_array(c.bcap, sizeof *s->leaf);
    s->gstart = hd__malloc_array(c.bcap, sizeof *s->gstart);
    s->glead = hd__malloc_array(c.bcap, sizeof *s->glead);
    s->first = hd__malloc_array(c.ncap, sizeof *s->first);
    s->count = hd__malloc_array(c.ncap, sizeof *s->count);
    /* The keys are computed in x[]'s memory, which the gather fills only
     * after the sort; hd__radix_sort makes three passes, an odd number, so
     * the sorted keys end in the other buffer.  Fresh memory costs a page
     * fault per 4 KiB on first touch, a tenth of the build on some
     * machines. */
    uint64_t *first_buffer = s->x ? (uint64_t *)(void *)s->x : NULL;
    c.a = first_buffer;
    c.b = hd__malloc_array(n, sizeof *c.b);
    /* These are written whole (keys, then the gathered coordinates): map
     * their pages at once rather than a fault per page. */
    hd__prefault(s->x, (n + 4) * sizeof *s->x);
    hd__prefault(s->y, (n + 4) * sizeof *s->y);
    hd__prefault(s->z, (n + 4) * sizeof *s->z);
    hd__prefault(s->idx, (n + 4) * sizeof *s->idx);
    hd__prefault(c.b, n * sizeof *c.b);
    int ok = s->x && s->y && s->z && s->idx && s->start && s->key && s->stop && s->leaf && s->gstart &&
             s->glead && s->first && s->count && c.a && c.b;
    /* Every count is below 2^31 and every size a few bytes: no overflow. */
    held_add(&c, (n + 4) * (3 * sizeof(double) + sizeof(uint32_t)) + 6 * c.bcap * sizeof(uint32_t) +
                     c.ncap * (sizeof *s->first + sizeof *s->count) + n * sizeof *c.b);
    int rc = HD_OK;
    if (ok) {
        hd__parallel_for(c.parts, (size_t)c.parts, key_task, &c);
        rc = hd__radix_sort(&c.a, &c.b, n, c.parts);
        /* Now c.a holds the sorted keys and c.b is x[]'s memory. */
        uint64_t *t = c.a;
        c.a = c.b, c.b = t;
        if (rc == HD_OK) hd__parallel_for(threads, (n + 4 + GATHER_TASK - 1) / GATHER_TASK, gather_task, &c);
    }
    if (ok && rc == HD_OK) {
        ok = build_octree(&c) == HD_OK;
        /* The keys' upper halves are kept (key32[]), moved down in their
         * own memory, which is touched already (a fresh array costs a page
         * fault per 4 KiB); the rest is given back before the boxes.  In
         * a refined cell they are the keys on the cell's own grid: the
         * window there is a guess like any other. */
        if (c.b) keys_upper(c.b, n);
        s->key32 = (uint32_t *)(void *)c.b;
        shrink((void **)&s->key32, n ? n : 1, sizeof *s->key32);
        c.a = c.b = NULL;
        /* Give back what the bounds reserved (keeping a block if the
         * system cannot shrink it) before the boxes are allocated. */
        if (ok) {
            shrink((void **)&s->start, s->nb + 1, sizeof *s->start);
            shrink((void **)&s->leaf, s->nb, sizeof *s->leaf);
            shrink((void **)&s->key, s->nb, sizeof *s->key);
            shrink((void **)&s->stop, s->nb, sizeof *s->stop);
            shrink((void **)&s->gstart, s->ng + 1, sizeof *s->gstart);
            shrink((void **)&s->glead, s->ng, sizeof *s->glead);
            shrink((void **)&s->first, s->nn, sizeof *s->first);
            shrink((void **)&s->count, s->nn, sizeof *s->count);
            /* From here on the structure holds what it keeps, the boxes
             * allocated next among it. */
            c.held = 0;
            held_add(&c, hd__an_bytes(s));
        }
        for (int d = 0; d < 3 && ok; d++) {
            s->lo[d] = hd__malloc_array(s->nn, sizeof(double));
            s->hi[d] = hd__malloc_array(s->nn, sizeof(double));
            ok = s->lo[d] && s->hi[d];
        }
    }
    if (ok && rc == HD_OK) {
        hd__parallel_for(threads, (s->nb + BOX_TASK - 1) / BOX_TASK, box_task, &c);
        /* Children come after their parent: boxes bottom-up. */
        for (size_t k = s->nn; k-- > 0;) {
            if (!s->count[k]) continue;
            size_t f = s->first[k], e = f + s->count[k];
            for (int d = 0; d < 3; d++) {
                double lo = s->lo[d][f], hi = s->hi[d][f];
                for (size_t i = f + 1; i < e; i++) {
                    lo = s->lo[d][i] < lo ? s->lo[d][i] : lo;
                    hi = s->hi[d][i] > hi ? s->hi[d][i] : hi;
                }
                s->lo[d][k] = lo;
                s->hi[d][k] = hi;
            }
        }
    }
    if (c.a != first_buffer) free(c.a);
    if (c.b != first_buffer) free(c.b);
    if (!ok) {
        hd__an_free(s);
        return hd__err(err, HD_ENOMEM, "cannot allocate the search structure of %zu points", n);
    }
    if (rc != HD_OK) {
        hd__an_free(s);
        return hd__err(err, rc, "%s", hd_strerror(rc));
    }
    s->peak = c.peak;
    return HD_OK;
}

int hd__an_build(hd__an_t *s, const hd_points_t *p, const hd_transform_t *T, const hd__box_t *keybox,
                 int threads, hd_error_t *err) {
    return build(s, p, NULL, NULL, p->count, T, keybox, threads, err);
}

int hd__an_build_sel(hd__an_t *s, const hd_points_t *p, const uint32_t *sel, const uint32_t *names, size_t m,
                     const hd__box_t *keybox, int threads, hd_error_t *err) {
    return build(s, p, sel, names, m, NULL, keybox, threads, err);
}

size_t hd__an_bytes(const hd__an_t *s) {
    size_t n = s->n;
    return (n + 4) * (3 * sizeof(double) + sizeof(uint32_t)) + n * sizeof(uint32_t) +
           s->nb * 4 * sizeof(uint32_t) + s->ng * 2 * sizeof(uint32_t) + 2 * sizeof(uint32_t) +
           s->nn * (sizeof *s->first + sizeof *s->count + 6 * sizeof(double));
}

/* ---- searching --------------------------------------------------------------- */

/* Candidate buckets of one group, their boxes in structure of arrays. */
typedef struct {
    size_t n;
    uint32_t *bucket, *keep;
    double *lo[3], *hi[3];
    double *lb2;   /* per query: the bound of each candidate */
    hd__an_counts_t counts; /* what this worker's groups and queries took */
} cands_t;

/* The smallest computed squared distance between a point of box q and a
 * point of node k's box (see the essay). */
HD__INLINE double node_lb2(const hd__box_t *q, const hd__an_t *t, size_t k) {
    double g[3];
    for (int d = 0; d < 3; d++) {
        double u = t->lo[d][k] - q->hi[d], v = q->lo[d] - t->hi[d][k];
        g[d] = u > v ? u : v;
        g[d] = g[d] > 0 ? g[d] : 0;
    }
    return g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
}

/* The largest computed squared distance between a point of box q and a
 * point of node k's box (see the essay). */
HD__INLINE double node_ub2(const hd__box_t *q, const hd__an_t *t, size_t k) {
    double g[3];
    for (int d = 0; d < 3; d++) {
        double u = q->hi[d] - t->lo[d][k], v = t->hi[d][k] - q->lo[d];
        g[d] = u > v ? u : v;
    }
    return g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
}

/* node_lb2's expression from box q to each of the boxes f, ..., f + n - 1
 * of the arrays lo[], hi[] (a node's children, or a candidate list, q
 * then a query's point) into out: without branches, so that it
 * vectorises. */
HD__INLINE void boxes_lb2(double *const lo[3], double *const hi[3], size_t f, size_t n, const hd__box_t *q,
                          double *restrict out) {
    const double *restrict lx = lo[0] + f, *restrict ly = lo[1] + f, *restrict lz = lo[2] + f;
    const double *restrict hx = hi[0] + f, *restrict hy = hi[1] + f, *restrict hz = hi[2] + f;
    double ax = q->lo[0], ay = q->lo[1], az = q->lo[2], bx = q->hi[0], by = q->hi[1], bz = q->hi[2];
    for (size_t i = 0; i < n; i++) {
        double u, v, gx, gy, gz;
        u = lx[i] - bx, v = ax - hx[i], gx = u > v ? u : v, gx = gx > 0 ? gx : 0;
        u = ly[i] - by, v = ay - hy[i], gy = u > v ? u : v, gy = gy > 0 ? gy : 0;
        u = lz[i] - bz, v = az - hz[i], gz = u > v ? u : v, gz = gz > 0 ? gz : 0;
        out[i] = gx * gx + gy * gy + gz * gz;
    }
}

/* The least of V and the largest computed squared distance between a
 * point of box q and each of the points [b, e) of the arrays x, y, z
 * (node_ub2's expression with a box of one point: each of those points
 * is within it of every point of q). */
HD__INLINE double points_ub2(const hd__box_t *q, const double *restrict x, const double *restrict y,
                             const double *restrict z, size_t b, size_t e, double V) {
    double l0 = q->lo[0], l1 = q->lo[1], l2 = q->lo[2], h0 = q->hi[0], h1 = q->hi[1], h2 = q->hi[2];
    for (size_t k = b; k < e; k++) {
        double u, v, ex, ey, ez;
        u = h0 - x[k], v = x[k] - l0, ex = u > v ? u : v;
        u = h1 - y[k], v = y[k] - l1, ey = u > v ? u : v;
        u = h2 - z[k], v = z[k] - l2, ez = u > v ? u : v;
        double ub = ex * ex + ey * ey + ez * ez;
        V = ub < V ? ub : V;
    }
    return V;
}

/* The bucket reached from the root by always taking the child whose box
 * is nearest to the box q; *U is lowered to the upper bounds of the nodes
 * on the way (each holds a point, so every query in q has a point within
 * them), and at the leaf to each of its points' upper bounds (each is
 * within it of every query in q).  When the group is far from t, or the
 * curve's order says little (refined cells), this is a better first
 * bucket than the seeds. */
HD__HOT static size_t nearest_leaf(const hd__an_t *t, const hd__box_t *q, double *U) {
    for (size_t k = 0;;) {
        double u = node_ub2(q, t, k);
        *U = u < *U ? u : *U;
        if (!t->count[k]) {
            size_t b = t->first[k];
            *U = points_ub2(q, t->x, t->y, t->z, t->start[b], t->stop[b], *U);
            return b;
        }
        size_t f = t->first[k], near = f;
        int nc = t->count[k];
        double best = INFINITY, lb[8];
        boxes_lb2(t->lo, t->hi, f, (size_t)nc, q, lb);
        for (int i = 0; i < nc; i++)
            if (lb[i] < best) best = lb[i], near = f + (size_t)i;
        k = near;
    }
}

/* List in c every bucket of t whose box is within U of the box q (box
 * bound <= U), U bounding the answer of every query in q: the buckets left
 * out hold no point that any of them could have as its nearest.  Returns 0,
 * with the list unfinished, as soon as it would hold more than `limit`. */
HD__HOT static int candidates(const hd__an_t *t, const hd__box_t *q, double U, size_t limit, cands_t *c) {
    uint32_t stack[8 * 11 + 8];
    double slb[8 * 11 + 8];
    int sp = 0;
    size_t m = 0;
    stack[sp] = 0, slb[sp] = node_lb2(q, t, 0), sp++;
    while (sp > 0) {
        sp--;
        if (slb[sp] > U) continue;
        size_t k = stack[sp];
        if (!t->count[k]) {
            if (m == limit) return 0;
            c->bucket[m] = t->first[k];
            for (int d = 0; d < 3; d++) c->lo[d][m] = t->lo[d][k], c->hi[d][m] = t->hi[d][k];
            m++;
            continue;
        }
        size_t f = t->first[k];
        int nc = t->count[k];
        double lb[8];
        boxes_lb2(t->lo, t->hi, f, (size_t)nc, q, lb);
        for (int i = nc - 1; i >= 0; i--)
            if (lb[i] <= U) stack[sp] = (uint32_t)(f + (size_t)i), slb[sp] = lb[i], sp++;
    }
    c->n = m;
    return 1;
}

/* The bound hd__box_lb2s of every candidate for the query (qx, qy, qz)
 * into c->lb2 (branch-free, so that it vectorises). */
HD__INLINE void candidate_bounds(cands_t *c, size_t nc, double qx, double qy, double qz) {
    hd__box_t p = {{qx, qy, qz}, {qx, qy, qz}};
    boxes_lb2(c->lo, c->hi, 0, nc, &p, c->lb2);
}

/* One query against one bucket: the squared distances four lanes at a time
 * (GCC's vector extension; each lane evaluates the expression of hd__d2s),
 * their minimum, and the smallest original index at the minimum. */

/* The distances of (vx, vy, vz) to the four points from position k of
 * the arrays x, y, z. */
#define D4(x, y, z, k, vx, vy, vz, out)                                   \
    do {                                                                  \
        v4d x_, y_, z_;                                                   \
        __builtin_memcpy(&x_, (x) + (k), sizeof x_);                      \
        __builtin_memcpy(&y_, (y) + (k), sizeof y_);                      \
        __builtin_memcpy(&z_, (z) + (k), sizeof z_);                      \
        x_ = (vx)-x_, y_ = (vy)-y_, z_ = (vz)-z_;                         \
        (out) = x_ * x_ + y_ * y_ + z_ * z_;                              \
    } while (0)

/* The points [0, n) of the arrays x, y, z (names idx), n > 0, read four
 * at a time (the last four may run past n: the caller makes sure those are
 * points of the set too): each lane keeps its smallest distance and the
 * smallest index at it, then the lanes' minimum and its smallest index
 * replace *best and *bj when smaller, or equal with a smaller index. */
HD__INLINE void scan_arrays(const double *x, const double *y, const double *z, const uint32_t *idx, size_t n,
                            double qx, double qy, double qz, double *best, uint32_t *bj) {
    v4d vx = {qx, qx, qx, qx}, vy = {qy, qy, qy, qy}, vz = {qz, qz, qz, qz}, mv, d;
    v4u iu;
    D4(x, y, z, 0, vx, vy, vz, mv);
    __builtin_memcpy(&iu, idx, sizeof iu);
    v4l jv = __builtin_convertvector(iu, v4l);
    for (size_t k = 4; k < n; k += 4) {
        D4(x, y, z, k, vx, vy, vz, d);
        __builtin_memcpy(&iu, idx + k, sizeof iu);
        v4l jl = __builtin_convertvector(iu, v4l);
        v4l take = (d < mv) | ((d == mv) & (jl < jv));
        mv = (v4d)(((v4l)d & take) | ((v4l)mv & ~take));
        jv = (jl & take) | (jv & ~take);
    }
    double m = mv[0] < mv[1] ? mv[0] : mv[1], m2 = mv[2] < mv[3] ? mv[2] : mv[3];
    m = m < m2 ? m : m2;
    if (m > *best) return;
    /* The smallest index among the lanes at m, without a branch per lane
     * (those mispredict: they cost more than the scan). */
    v4d mm = {m, m, m, m};
    v4l at = mv == mm, none = {INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX};
    v4l jm = (jv & at) | (none & ~at);
    int64_t j01 = jm[0] < jm[1] ? jm[0] : jm[1], j23 = jm[2] < jm[3] ? jm[2] : jm[3];
    uint32_t j = (uint32_t)(j01 < j23 ? j01 : j23);
    if (m < *best || j < *bj) {
        *best = m;
        *bj = j;
    }
}

/* The points [k0, e) of t, k0 a multiple of four, e at most n + 1 (the
 * last group of four read may run past e, into the copies of the last
 * point stored after the end). */
HD__INLINE void scan_span(const hd__an_t *t, size_t k0, size_t e, double qx, double qy, double qz,
                          double *best, uint32_t *bj) {
    scan_arrays(t->x + k0, t->y + k0, t->z + k0, t->idx + k0, e - k0, qx, qy, qz, best, bj);
}

/* One bucket: from the group of four that holds its first point to the
 * one that holds its last.  The points read before and after the bucket
 * are points of the set too, so reading them changes no answer. */
HD__INLINE void scan_bucket(const hd__an_t *t, size_t b, double qx, double qy, double qz,
                            double *best, uint32_t *bj) {
    scan_span(t, t->start[b] & ~(size_t)3, t->stop[b], qx, qy, qz, best, bj);
}

/* The last bucket of t whose first key is at most `key` (or bucket 0),
 * searching up from bucket `from`, the answer for a smaller key (the keys
 * grow: a few steps usually do; doubling steps then bisection). */
static size_t bucket_at(const hd__an_t *t, uint32_t key, size_t from) {
    size_t lo = from, step = 1;
    while (lo + step < t->nb && t->key[lo + step] <= key) lo += step, step *= 2;
    size_t hi = lo + step < t->nb ? lo + step : t->nb; /* the answer is in [lo, hi) */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (t->key[mid] <= key) lo = mid;
        else hi = mid;
    }
    return lo;
}

#define GROUPS_PER_TASK 128 /* groups of queries per task */
#define SEEDS 2             /* buckets scanned first for each query */

#define PAIR_CANDIDATES 32 /* most candidates of a group for the partner path */
#define PAIR_TRIAL 8        /* groups of a task tried before the partner path may be dropped */
#define WINDOW_CANDIDATES 64 /* most candidates of a group for the window path */
#define WINDOW 8            /* points of t scanned around a query's key (a multiple of 8) */
#define CHUNK 16            /* queries answered from one chunk list */
#define WINDOW_CHUNK 12     /* the same on the window path */
#define CHUNK_LIST 256      /* a group list longer than this is not filtered but listed again per chunk */
#define POINT_LIST 512      /* most points of a group's candidate buckets for a point list */
#define DENSE 8             /* a set this many times as large as t tries point lists in every group */
#define FAR_CANDIDATES 64   /* most candidates of a far group answered without seeds */
#define RUN 3               /* groups of a dense set sharing one point list */

/* The rest of one query's search, on the candidate list cd (the buckets
 * within U of a box holding the query, U at least its answer): every
 * candidate's bound for it, then the scans it cannot skip, those within
 * its best so far and U, listed without branches and each tested again
 * against the best found so far.  The buckets [s0, s1) and `near` were
 * scanned already. */
HD__INLINE void finish_query(const hd__an_t *t, cands_t *cd, double qx, double qy, double qz, double U,
                             size_t s0, size_t s1, size_t near, double *best, uint32_t *bj) {
    size_t nc = cd->n;
    double b2 = *best;
    uint32_t j = *bj;
    candidate_bounds(cd, nc, qx, qy, qz);
    double lim = b2 < U ? b2 : U;
    size_t ns = 0;
    for (size_t r = 0; r < nc; r++) {
        cd->keep[ns] = (uint32_t)r;
        ns += cd->lb2[r] <= lim;
    }
    for (size_t r = 0; r < ns; r++) {
        size_t at = cd->keep[r], b = cd->bucket[at];
        lim = b2 < U ? b2 : U;
        if (cd->lb2[at] > lim) continue;
        if ((b >= s0 && b < s1) || b == near) continue;
        scan_bucket(t, b, qx, qy, qz, &b2, &j);
    }
    *best = b2;
    *bj = j;
}

typedef struct {
    const hd__an_t *q, *t;
    const hd_points_t *partner; /* t's view: query i's partner is its point i (or NULL) */
    const uint32_t *pair_at;    /* or per query, in q's order: its partner's position in t
                                 * (HD__AN_NO_PARTNER: none), or NULL */
    double *dist;
    size_t *nearest;
    cands_t *cand; /* per worker w: cand[w] the group's list, cand[workers + w] a chunk's,
                    * each with room for every bucket of t */
    int workers;
    double *sd;    /* answers in q's order: squared distances */
    uint32_t *sj;  /* and nearest original indices */
} query_ctx;

#define SCATTER_TASK 65536 /* answers per scattering task */

/* The answers [task * SCATTER_TASK, ...) in q's order to the caller's
 * arrays, at their original indices. */
static void scatter_answers(void *vctx, size_t task, int worker) {
    (void)worker;
    query_ctx *c = vctx;
    const uint32_t *idx = c->q->idx;
    size_t lo = task * SCATTER_TASK, hi = lo + SCATTER_TASK < c->q->n ? lo + SCATTER_TASK : c->q->n;
    if (c->dist)
        for (size_t k = lo; k < hi; k++) c->dist[idx[k]] = sqrt(c->sd[k]);
    if (c->nearest)
        for (size_t k = lo; k < hi; k++) c->nearest[idx[k]] = c->sj[k];
}

/* Queries first .. first + m - 1 of q (at most HD__AN_GROUP, one key
 * group or a piece of it) while query_task answers them: their box, each
 * one's best answer so far (a real point's squared distance) and its name,
 * its partner's name, and its seed bucket on t's curve. */
typedef struct {
    size_t first, m;
    hd__box_t box;
    double best[HD__AN_GROUP];
    uint32_t bj[HD__AN_GROUP], pj[HD__AN_GROUP];
    size_t seed[HD__AN_GROUP];
} qgroup_t;

/* The box of q's points [first, first + m), m > 0. */
HD__INLINE void span_box(const hd__an_t *q, size_t first, size_t m, hd__box_t *box) {
    const double *v[3] = {q->x, q->y, q->z};
    for (int d = 0; d < 3; d++) {
        box->lo[d] = box->hi[d] = v[d][first];
        for (size_t k = first + 1; k < first + m; k++) {
            box->lo[d] = v[d][k] < box->lo[d] ? v[d][k] : box->lo[d];
            box->hi[d] = v[d][k] > box->hi[d] ? v[d][k] : box->hi[d];
        }
    }
}

HD__INLINE void qgroup_box(const hd__an_t *q, qgroup_t *G) { span_box(q, G->first, G->m, &G->box); }

/* Each query's place on t's curve: the searched bucket at its own
 * bucket's key (h: the query's bucket, s0: the last seed, both carried
 * from query to query of a key group). */
HD__INLINE void qgroup_seeds(const hd__an_t *q, const hd__an_t *t, qgroup_t *G, size_t *h, size_t *s0) {
    for (size_t k = 0; k < G->m; k++) {
        while (q->start[*h + 1] <= G->first + k) ++*h;
        if (k == 0 || q->start[*h] == G->first + k) *s0 = bucket_at(t, q->key[*h], *s0);
        G->seed[k] = *s0;
    }
}

/* The partner path's first answers: each query's partner (a point of the
 * caller's partner set at the query's own index, read there, or a point
 * of t named by pair_at) and its distance.  Returns the largest, which
 * bounds every answer of the group (infinite when a query has no
 * partner). */
HD__INLINE double partner_bests(const query_ctx *c, const hd__src_t *psrc, qgroup_t *G) {
    const hd__an_t *q = c->q, *t = c->t;
    size_t first = G->first, m = G->m;
    double U = 0;
    if (c->partner) {
        /* The partners are read in the original order, far apart: ask for
         * the next chunk's while this one is worked on. */
        for (size_t k = first + m; k < first + 2 * m && k < q->n; k++)
            __builtin_prefetch(psrc->base + (ptrdiff_t)q->idx[k] * psrc->ps);
        for (size_t k = 0; k < m; k++) {
            double p[3];
            uint32_t i = q->idx[first + k];
            hd__src_get(psrc, i, p);
            G->best[k] = hd__d2s(q->x[first + k], q->y[first + k], q->z[first + k], p[0], p[1], p[2]);
            G->pj[k] = G->bj[k] = i;
            U = G->best[k] > U ? G->best[k] : U;
        }
        return U;
    }
    /* The partners are points of t, near in its order when near in space;
     * a query without one has no bound (U infinite: the seeds go on from
     * the others). */
    for (size_t k = 0; k < m; k++) {
        uint32_t at = c->pair_at[first + k];
        G->pj[k] = UINT32_MAX;
        if (at == HD__AN_NO_PARTNER) {
            U = INFINITY;
            continue;
        }
        assert(at < t->n);
        G->best[k] = hd__d2s(q->x[first + k], q->y[first + k], q->z[first + k], t->x[at], t->y[at], t->z[at]);
        G->pj[k] = G->bj[k] = t->idx[at];
        U = G->best[k] > U ? G->best[k] : U;
    }
    return U;
}

/* Query k of q against the WINDOW points of t around its own key on t's
 * curve, into *best and *bj.  *b and *p carry the bucket and the point of
 * t reached by the previous query (keys grow along q: start both at 0, or
 * *b at a bucket whose key is at most the query's). */
HD__INLINE void window_best(const hd__an_t *q, const hd__an_t *t, size_t k, size_t *b, size_t *p, double *best,
                            uint32_t *bj) {
    uint32_t kq = q->key32[k];
    *b = bucket_at(t, kq, *b);
    *p = *p > t->start[*b] ? *p : t->start[*b];
    while (*p < t->start[*b + 1] && t->key32[*p] < kq) ++*p;
    size_t k0 = *p & ~(size_t)3;
    k0 = k0 >= WINDOW / 2 ? k0 - WINDOW / 2 : 0;
    size_t e = k0 + WINDOW < t->n ? k0 + WINDOW : t->n;
    scan_span(t, k0, e, q->x[k], q->y[k], q->z[k], best, bj);
}

/* The window path's first answers (query_task's essay): each query's best
 * among the WINDOW points of t around its own place on t's curve (the
 * seeds must be set).  Returns U, the largest best of the queries not set
 * apart (those above 16 times, in squares, the geometric mean of the
 * group's bests, from their exponents), with their number in *apart. */
HD__INLINE double window_bests(const hd__an_t *q, const hd__an_t *t, qgroup_t *G, size_t *apart) {
    size_t first = G->first, m = G->m;
    int64_t esum = 0;
    for (size_t k = 0, p = 0, b = 0; k < m; k++) {
        b = b > G->seed[k] ? b : G->seed[k];
        window_best(q, t, first + k, &b, &p, &G->best[k], &G->bj[k]);
        esum += (int64_t)(hd__bits_of(G->best[k]) >> 52);
    }
    int64_t ecut = esum / (int64_t)m + 4;
    uint64_t ucut = (uint64_t)(ecut < 2047 ? ecut : 2047) << 52;
    double cut, U = 0;
    __builtin_memcpy(&cut, &ucut, sizeof cut);
    *apart = 0;
    for (size_t k = 0; k < m; k++) {
        int far = G->best[k] > cut;
        *apart += (size_t)far;
        U = !far && G->best[k] > U ? G->best[k] : U;
    }
    return U;
}

/* The points of t in the buckets listed in cd. */
HD__INLINE size_t listed_points(const hd__an_t *t, const cands_t *cd) {
    size_t total = 0;
    for (size_t r = 0; r < cd->n; r++) total += t->stop[cd->bucket[r]] - t->start[cd->bucket[r]];
    return total;
}

/* The squared diagonal of a group's box. */
HD__INLINE double qgroup_diag2(const qgroup_t *G) {
    double diag2 = 0;
    for (int d = 0; d < 3; d++) diag2 += (G->box.hi[d] - G->box.lo[d]) * (G->box.hi[d] - G->box.lo[d]);
    return diag2;
}

/* A far group: its box's squared diagonal at most lb2, a bound from its
 * box to every point of t (disjoint sets, where the curve's seeds and the
 * window are far), and, Ub bounding every answer of the group (a bound
 * from the nearest leaf's path, which holds a point within Ub of each
 * query), at most FAR_CANDIDATES buckets within Ub holding at most
 * POINT_LIST points: they are listed into cd and returns 1.  Such a group
 * scans nothing first: U = Ub, no query has a best yet, and qgroup_finish
 * answers it from point lists (it is small next to Ub). */
HD__INLINE int far_group(const hd__an_t *t, const qgroup_t *G, double lb2, double Ub, cands_t *cd) {
    return qgroup_diag2(G) <= lb2 && candidates(t, &G->box, Ub, FAR_CANDIDATES, cd) &&
           listed_points(t, cd) <= POINT_LIST;
}

/* The seeds' answers, when no path listed the candidates: the searched
 * buckets at each query's place on the curve (the seeds must be set), and
 * the bucket nearest to the group's box, give every query a real point;
 * U, the largest of these distances (or the nearest bucket's bound Ub,
 * when smaller), bounds every answer of the group and lists its
 * candidates into cd.  Returns the nearest bucket, and *scanned = 1;
 * for a far group (far_group) *scanned = 0 and U = Ub. */
HD__INLINE size_t seed_bests(const hd__an_t *q, const hd__an_t *t, qgroup_t *G, cands_t *cd, double *U,
                             int *scanned) {
    double Ub = INFINITY;
    size_t near = nearest_leaf(t, &G->box, &Ub);
    *U = Ub;
    *scanned = !far_group(t, G, node_lb2(&G->box, t, t->leaf[near]), Ub, cd);
    if (!*scanned) return near;
    *U = 0;
    /* A seed bucket whose box is farther from the group's than Ub holds no
     * answer of the group and is not listed (U <= Ub below): it is not
     * scanned either (disjoint sets, where the curve's seeds are far and
     * the nearest leaf is near). */
    size_t last = SIZE_MAX;
    int useful[SEEDS] = {0};
    for (size_t k = 0; k < G->m; k++) {
        double qx = q->x[G->first + k], qy = q->y[G->first + k], qz = q->z[G->first + k];
        if (G->seed[k] != last) {
            last = G->seed[k];
            for (size_t b = last; b < last + SEEDS; b++)
                useful[b - last] = b < t->nb && node_lb2(&G->box, t, t->leaf[b]) <= Ub;
        }
        for (size_t b = G->seed[k]; b < G->seed[k] + SEEDS; b++)
            if (useful[b - G->seed[k]]) scan_bucket(t, b, qx, qy, qz, &G->best[k], &G->bj[k]);
        if (near < G->seed[k] || near >= G->seed[k] + SEEDS) scan_bucket(t, near, qx, qy, qz, &G->best[k], &G->bj[k]);
        *U = G->best[k] > *U ? G->best[k] : *U;
    }
    *U = Ub < *U ? Ub : *U;
    candidates(t, &G->box, *U, SIZE_MAX, cd);
    return near;
}

/* The candidates of cd within Uc of the box q, into ck: filtered from
 * cd, or listed afresh from t's root when cd is long (a group spread
 * over many of t's buckets, a sparse set asking a dense one).  A bucket
 * left out has node_lb2 above Uc from the box, so above the answer of
 * every query in it whose answer is at most Uc. */
HD__INLINE void chunk_candidates(const hd__an_t *t, const cands_t *cd, const hd__box_t *q, double Uc, cands_t *ck) {
    if (cd->n > CHUNK_LIST) {
        candidates(t, q, Uc, SIZE_MAX, ck);
        return;
    }
    size_t m = 0;
    for (size_t r = 0; r < cd->n; r++) {
        double g[3];
        for (int d = 0; d < 3; d++) {
            double u = cd->lo[d][r] - q->hi[d], v = q->lo[d] - cd->hi[d][r];
            g[d] = u > v ? u : v;
            g[d] = g[d] > 0 ? g[d] : 0;
        }
        double lb = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        ck->bucket[m] = cd->bucket[r];
        for (int d = 0; d < 3; d++) ck->lo[d][m] = cd->lo[d][r], ck->hi[d][m] = cd->hi[d][r];
        m += lb <= Uc;
    }
    ck->n = m;
}

/* Candidate points, shared by queries whose box is small next to the
 * distances to their answers (a dense set asking a sparse one): many
 * queries, few points that can be any of their answers.  x, y, z, idx in
 * structure of arrays, n of them, padded to a multiple of four with
 * copies of the last (a copy changes no minimum and no smallest index). */
typedef struct {
    size_t n;
    double x[POINT_LIST + 4], y[POINT_LIST + 4], z[POINT_LIST + 4];
    uint32_t idx[POINT_LIST + 4];
} plist_t;

HD__INLINE void plist_pad(plist_t *l) {
    for (size_t k = l->n; l->n && k < ((l->n + 3) & ~(size_t)3); k++)
        l->x[k] = l->x[l->n - 1], l->y[k] = l->y[l->n - 1], l->z[k] = l->z[l->n - 1], l->idx[k] = l->idx[l->n - 1];
}

/* span_bounds's gap g (at least 0) and span e on one axis for the four
 * coordinates from p, the box's side [lo, hi]. */
HD__INLINE void gap_span4(const double *p, v4d lo, v4d hi, v4d *g, v4d *e) {
    v4d c_, zero = {0, 0, 0, 0};
    __builtin_memcpy(&c_, p, sizeof c_);
    v4d u = c_ - hi, v = lo - c_;
    v4l c = u > v;
    *g = (v4d)(((v4l)u & c) | ((v4l)v & ~c));
    *g = (v4d)((v4l)*g & (*g > zero));
    *e = (v4d)(((v4l)-v & c) | ((v4l)-u & ~c));
}

/* The n points at positions at[] of the arrays x, y, z, idx into l
 * (the positions of the points kept are listed first, without a branch
 * per point, and only those are copied). */
HD__INLINE void plist_take(plist_t *l, const double *x, const double *y, const double *z, const uint32_t *idx,
                           const uint32_t *at, size_t n) {
    for (size_t k = 0; k < n; k++) l->x[k] = x[at[k]], l->y[k] = y[at[k]], l->z[k] = z[at[k]], l->idx[k] = idx[at[k]];
    l->n = n;
}

/* The smallest and the largest computed squared distance between each of
 * the n points (x[k], y[k], z[k]) and a point of box q (node_lb2's and
 * node_ub2's expressions with a box of one point; see the essay; the
 * span's max(hi - p, p - lo) is the larger of the negated gaps, as IEEE
 * subtraction is exact under negation): the smallest into lb[k], and
 * returns the least of the largest, or V when smaller.  Four points at a
 * time with GCC's vector extension (each lane evaluates the scalar
 * expressions, selections by masks: GCC left the scalar loop unvectorised),
 * the rest one by one; the least of the lanes is the same minimum in any
 * order (the bounds are sums of squares, never -0 nor NaN). */
HD__INLINE double span_bounds(const hd__box_t *q, const double *restrict x, const double *restrict y,
                              const double *restrict z, size_t n, double *restrict lb, double V) {
    double l0 = q->lo[0], l1 = q->lo[1], l2 = q->lo[2], h0 = q->hi[0], h1 = q->hi[1], h2 = q->hi[2];
    v4d L0 = {l0, l0, l0, l0}, L1 = {l1, l1, l1, l1}, L2 = {l2, l2, l2, l2};
    v4d H0 = {h0, h0, h0, h0}, H1 = {h1, h1, h1, h1}, H2 = {h2, h2, h2, h2};
    v4d Vv = {V, V, V, V};
    size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        v4d gx, gy, gz, ex, ey, ez;
        gap_span4(x + k, L0, H0, &gx, &ex);
        gap_span4(y + k, L1, H1, &gy, &ey);
        gap_span4(z + k, L2, H2, &gz, &ez);
        v4d l = gx * gx + gy * gy + gz * gz, ub = ex * ex + ey * ey + ez * ez;
        __builtin_memcpy(lb + k, &l, sizeof l);
        v4l c = ub < Vv;
        Vv = (v4d)(((v4l)ub & c) | ((v4l)Vv & ~c));
    }
    double m = Vv[0] < Vv[1] ? Vv[0] : Vv[1], m2 = Vv[2] < Vv[3] ? Vv[2] : Vv[3];
    V = m < m2 ? m : m2;
    for (; k < n; k++) {
        double u, v, gx, gy, gz, ex, ey, ez;
        u = x[k] - h0, v = l0 - x[k], gx = u > v ? u : v, gx = gx > 0 ? gx : 0, ex = u > v ? -v : -u;
        u = y[k] - h1, v = l1 - y[k], gy = u > v ? u : v, gy = gy > 0 ? gy : 0, ey = u > v ? -v : -u;
        u = z[k] - h2, v = l2 - z[k], gz = u > v ? u : v, gz = gz > 0 ? gz : 0, ez = u > v ? -v : -u;
        lb[k] = gx * gx + gy * gy + gz * gz;
        double ub = ex * ex + ey * ey + ez * ez;
        V = ub < V ? ub : V;
    }
    return V;
}

/* The points of the buckets listed in cd that can be the answer of a
 * query in box q whose answer is at most U, into out: V, the smallest
 * node_ub2 of a listed point from the box, bounds every such answer too
 * (the point is within V of each query), and a point whose bound from
 * the box is above min(U, V) is farther than that answer.  Returns 0 when
 * the buckets hold more than POINT_LIST points (then nothing is listed).
 * The bounds are taken first, over each bucket's points where t stores
 * them, and only the points kept are copied. */
HD__HOT static int group_points(const hd__an_t *t, const cands_t *cd, const hd__box_t *q, double U, plist_t *out,
                                double *Vout) {
    if (listed_points(t, cd) > POINT_LIST) return 0;
    double lb[POINT_LIST], V = U;
    size_t m = 0;
    for (size_t r = 0; r < cd->n; r++) {
        size_t k0 = t->start[cd->bucket[r]], e = t->stop[cd->bucket[r]];
        V = span_bounds(q, t->x + k0, t->y + k0, t->z + k0, e - k0, lb + m, V);
        m += e - k0;
    }
    uint32_t at[POINT_LIST];
    size_t n = 0;
    m = 0;
    for (size_t r = 0; r < cd->n; r++)
        for (size_t k = t->start[cd->bucket[r]]; k < t->stop[cd->bucket[r]]; k++, m++) {
            at[n] = (uint32_t)k;
            n += lb[m] <= V;
        }
    plist_take(out, t->x, t->y, t->z, t->idx, at, n);
    *Vout = V;
    return 1;
}

/* The points of `from` that can be the answer of a query in the box q
 * (a chunk of the group's, answers at most U), the same way, into out. */
HD__HOT static void chunk_points(const plist_t *from, const hd__box_t *q, double U, plist_t *out) {
    double lb[POINT_LIST];
    double V = span_bounds(q, from->x, from->y, from->z, from->n, lb, U);
    uint32_t at[POINT_LIST];
    size_t n = 0;
    for (size_t k = 0; k < from->n; k++) {
        at[n] = (uint32_t)k;
        n += lb[k] <= V;
    }
    plist_take(out, from->x, from->y, from->z, from->idx, at, n);
    plist_pad(out);
}

/* One query against every point of l (padded: the reads past l->n are
 * copies of its last point), into *best and *bj. */
HD__INLINE void scan_points(const plist_t *l, double qx, double qy, double qz, double *best, uint32_t *bj) {
    if (l->n) scan_arrays(l->x, l->y, l->z, l->idx, l->n, qx, qy, qz, best, bj);
}

/* Every query of the group answered exactly from the candidates listed
 * within U, into c->sd and c->sj.  A windowed query set apart (best above
 * U) goes through the list with the others; if its best is still above U
 * then, its answer is above U (an answer within U is listed) and it gets
 * candidates of its own, within its best.  The queries are answered CHUNK
 * (on the window path WINDOW_CHUNK) at a time (consecutive on the curve, so close): the
 * chunk's own list holds the group's candidates within Uc of the chunk's
 * box, Uc = min(U, the chunk's largest best), which bounds the answer of
 * each of its queries (each answer is at most U and at most its best);
 * a short group list is used as it is.  `scanned` says whether the
 * seed buckets and `near` were scanned for every query (the seed path;
 * not for a far group, seed_bests).  Returns how many answers were the
 * partners (for the partner path's upkeep). */
HD__INLINE size_t qgroup_finish(query_ctx *c, cands_t *cd, cands_t *ck, qgroup_t *G, double U, int paired,
                                int windowed, size_t near, int scanned, const plist_t *shared) {
    const hd__an_t *q = c->q, *t = c->t;
    size_t first = G->first, kept = 0, napart = 0, nlisted = 0;
    uint32_t apart[HD__AN_GROUP], listed[HD__AN_GROUP];
    uint8_t seeded[HD__AN_GROUP];
    for (size_t k = 0; k < G->m; k++) {
        /* Set apart: the list within U holds its answer when that is at
         * most U; a best still above U after the list says it is not. */
        seeded[k] = windowed && G->best[k] > U;
        listed[nlisted++] = (uint32_t)k;
    }
    /* A group small next to its answers' distances (its box's diagonal
     * at most twice the bound U on them) shares its candidate points,
     * chunk by chunk, while the chunks' lists stay short: a far group
     * (nothing scanned yet, seed_bests) or a group of a set DENSE times
     * as large as t or more (few points of t per group) at any size,
     * another when it has two chunks of queries or more.  (Which groups
     * try decides only the cost.) */
    plist_t gp, cp;
    double V;
    int points = (nlisted >= 2 * CHUNK || !scanned || q->n / DENSE >= t->n) && qgroup_diag2(G) <= 4 * U &&
                 (shared ? (chunk_points(shared, &G->box, U, &gp), 1) : group_points(t, cd, &G->box, U, &gp, &V));
    size_t chunk = windowed ? WINDOW_CHUNK : CHUNK;
    for (size_t r0 = 0; r0 < nlisted; r0 += chunk) {
        size_t r1 = r0 + chunk < nlisted ? r0 + chunk : nlisted;
        const cands_t *list = cd;
        hd__box_t box;
        double Uc = 0;
        for (size_t r = r0; r < r1 && (points || cd->n > CHUNK); r++) {
            size_t k = first + listed[r];
            double p[3] = {q->x[k], q->y[k], q->z[k]};
            for (int d = 0; d < 3; d++) {
                box.lo[d] = r == r0 || p[d] < box.lo[d] ? p[d] : box.lo[d];
                box.hi[d] = r == r0 || p[d] > box.hi[d] ? p[d] : box.hi[d];
            }
            Uc = G->best[listed[r]] > Uc ? G->best[listed[r]] : Uc;
        }
        Uc = Uc < U ? Uc : U;
        /* A far group of one chunk: its box and bound are the group's
         * (no query has a best yet), so its list is the group's. */
        const plist_t *pl = &cp;
        if (points && !scanned && nlisted <= chunk) {
            plist_pad(&gp);
            pl = &gp;
        } else if (points) {
            chunk_points(&gp, &box, Uc, &cp);
        }
        points = points && pl->n <= 2 * CHUNK;
        if (points) {
            for (size_t r = r0; r < r1; r++) {
                size_t k = listed[r];
                scan_points(pl, q->x[first + k], q->y[first + k], q->z[first + k], &G->best[k], &G->bj[k]);
                if (seeded[k] && G->best[k] > U) apart[napart++] = (uint32_t)k;
                c->sd[first + k] = G->best[k];
                c->sj[first + k] = G->bj[k];
                kept += paired && !windowed && G->bj[k] == G->pj[k];
            }
            cd->counts.pointed += r1 - r0;
            continue;
        }
        if (cd->n > CHUNK) {
            chunk_candidates(t, cd, &box, Uc, ck);
            list = ck;
        }
        for (size_t r = r0; r < r1; r++) {
            size_t k = listed[r];
            double qx = q->x[first + k], qy = q->y[first + k], qz = q->z[first + k];
            cands_t *l = (cands_t *)list;
            if (paired || !scanned) finish_query(t, l, qx, qy, qz, U, 0, 0, SIZE_MAX, &G->best[k], &G->bj[k]);
            else finish_query(t, l, qx, qy, qz, U, G->seed[k], G->seed[k] + SEEDS, near, &G->best[k], &G->bj[k]);
            if (seeded[k] && G->best[k] > U) apart[napart++] = (uint32_t)k;
            c->sd[first + k] = G->best[k];
            c->sj[first + k] = G->bj[k];
            kept += paired && !windowed && G->bj[k] == G->pj[k];
        }
    }
    /* The queries set apart: each one's own candidates, the buckets within
     * its best so far (a real point's distance, so at least its answer) of
     * the query itself. */
    cd->counts.apart += napart;
    for (size_t r = 0; r < napart; r++) {
        size_t k = apart[r];
        double qx = q->x[first + k], qy = q->y[first + k], qz = q->z[first + k];
        hd__box_t pb = {{qx, qy, qz}, {qx, qy, qz}};
        candidates(t, &pb, G->best[k], SIZE_MAX, cd);
        finish_query(t, cd, qx, qy, qz, G->best[k], 0, 0, SIZE_MAX, &G->best[k], &G->bj[k]);
        c->sd[first + k] = G->best[k];
        c->sj[first + k] = G->bj[k];
    }
    return kept;
}

/* The solo path: a group of queries spread over more of t's buckets than
 * it has queries (a sparse set asking a dense one) shares no work, and
 * each of its queries is searched on its own: its WINDOW points on t's
 * curve (an actual point's distance, so a bound on its answer), then the
 * buckets within that bound of the query itself (candidates), then
 * finish_query on them.  *b and *p carry the window's place (the keys
 * grow along q). */
HD__INLINE void solo_query(query_ctx *c, cands_t *cd, size_t k, size_t *b, size_t *p) {
    const hd__an_t *q = c->q, *t = c->t;
    double qx = q->x[k], qy = q->y[k], qz = q->z[k], best = INFINITY;
    uint32_t j = UINT32_MAX;
    window_best(q, t, k, b, p, &best, &j);
    hd__box_t pb = {{qx, qy, qz}, {qx, qy, qz}};
    candidates(t, &pb, best, SIZE_MAX, cd);
    finish_query(t, cd, qx, qy, qz, best, 0, 0, SIZE_MAX, &best, &j);
    c->sd[k] = best;
    c->sj[k] = j;
}

/* Runs of RUN consecutive groups of a set DENSE times as large as t or
 * more (a dense set asking a sparse one: the run's box is small next to
 * the distances to its answers, and its groups have nearly the same
 * candidates) share one point list, listed once for the run's box Q: the
 * nearest leaf's bound Ub bounds every answer in Q (nearest_leaf), the
 * buckets within Ub of Q (at most FAR_CANDIDATES, holding at most
 * POINT_LIST points) hold them all, and their points within min(Ub, V)
 * of Q (group_points) still do; *U = min(Ub, V) bounds every answer in Q.
 * Each group of the run then keeps from that list the points that can be
 * its answers (chunk_points, within U of its own box) and goes on as a
 * far group does.  Returns 0 (the groups go their own ways) when Q is not
 * small next to Ub, or the buckets are too many.  The groups g, ..., g +
 * ng - 1 of q; cd is left holding the run's candidates (within Ub of Q,
 * so of each group's box: the groups' bucket lists may use it). */
static int run_points(const hd__an_t *q, const hd__an_t *t, size_t g, size_t ng, cands_t *cd, plist_t *S,
                      double *U) {
    hd__box_t box;
    span_box(q, q->gstart[g], q->gstart[g + ng] - q->gstart[g], &box);
    double Ub = INFINITY, diag2 = 0;
    nearest_leaf(t, &box, &Ub);
    for (int d = 0; d < 3; d++) diag2 += (box.hi[d] - box.lo[d]) * (box.hi[d] - box.lo[d]);
    return diag2 <= 4 * Ub && candidates(t, &box, Ub, FAR_CANDIDATES, cd) && group_points(t, cd, &box, Ub, S, U);
}

/* The groups of a task, each answered in phases: its box; first answers
 * by the partner path or the window path while they pay, each listing the
 * group's candidates when its bound lists few; else, when the group's box
 * overlaps more of t's buckets than it has queries, the solo path; else
 * the seeds' answers and their candidates; then every query exactly
 * (qgroup_finish).
 *
 * The partner path: when the sets are a copy and its original in the same
 * order, each query's partner (the searched point of its own original
 * index) is usually at or next to its answer.  Its distance is a real
 * point's, so the largest over the group bounds every answer; if few
 * buckets lie within it, they are the candidates and no seed is scanned.
 * Otherwise the partners still stand as first answers for the window (or
 * the seeds) to improve on.
 *
 * The window path: a near-copy in another order (or two sets sampled
 * alike) puts each query's answer at about its own place on t's curve,
 * the two orders being taken on one grid: p, the first point of t whose
 * key is not below the query's (found from its seed bucket's start, the
 * queries' keys growing).  The WINDOW points of t around it are real
 * points, so each query's best among them bounds its answer.  A few
 * queries whose answer lies across a jump of the curve get a far worse
 * best than the others; U, the largest best of the rest, bounds their
 * answers and lists few candidates, and those few (best above U) are
 * searched on their own afterwards.
 *
 * A task drops either path once most of the groups it tried, PAIR_TRIAL
 * at least, failed (for the partners: did not find most answers at the
 * partners; for the window: more than a quarter of the queries apart, or
 * too many candidates); no answer depends on any of this. */
HD__HOT static void query_task(void *vctx, size_t task, int worker) {
    query_ctx *c = vctx;
    const hd__an_t *q = c->q, *t = c->t;
    cands_t *cd = &c->cand[worker], *ck = &c->cand[c->workers + worker];
    size_t g0 = task * GROUPS_PER_TASK, g1 = g0 + GROUPS_PER_TASK < q->ng ? g0 + GROUPS_PER_TASK : q->ng;
    qgroup_t G;
    size_t at0 = g0 < g1 ? bucket_at(t, q->key[q->glead[g0]], 0) : 0;
    hd__src_t psrc;
    if (c->partner) hd__src_init(&psrc, c->partner, NULL);
    size_t tried = 0, kept_groups = 0, wtried = 0, wkept = 0;
    int dense = q->n / DENSE >= t->n, shared = 0;
    plist_t S;
    double US = 0;
    for (size_t g = g0; g < g1; g++) {
        if (dense && (g - g0) % RUN == 0) shared = run_points(q, t, g, g1 - g < RUN ? g1 - g : RUN, cd, &S, &US);
        /* A group of equal keys may hold more than HD__AN_GROUP points:
         * its queries are then taken HD__AN_GROUP at a time. */
        size_t h = q->glead[g], s0 = at0;
        at0 = bucket_at(t, q->key[h], at0);
        for (size_t first = q->gstart[g]; first < q->gstart[g + 1]; first += HD__AN_GROUP) {
            G.first = first;
            G.m = q->gstart[g + 1] - first < HD__AN_GROUP ? q->gstart[g + 1] - first : HD__AN_GROUP;
            qgroup_box(q, &G);
            double U = 0, lb0 = node_lb2(&G.box, t, 0);
            int paired = 0, windowed = 0, seeded = 0, scanned = 1;
            size_t near = SIZE_MAX;
            for (size_t k = 0; k < G.m; k++) G.best[k] = INFINITY, G.bj[k] = UINT32_MAX;
            if (shared) {
                /* Its run's list holds every answer of the group, within
                 * US: no path below runs (nothing scanned). */
                U = US, scanned = 0;
                cd->counts.shared++;
            } else if (lb0 >= qgroup_diag2(&G)) {
                /* Outside t's box by its own diagonal: maybe a far group. */
                U = INFINITY;
                near = nearest_leaf(t, &G.box, &U);
                scanned = !far_group(t, &G, lb0, U, cd);
            }
            if (scanned && (c->partner || c->pair_at) && (tried < PAIR_TRIAL || 2 * kept_groups >= tried)) {
                U = partner_bests(c, &psrc, &G);
                paired = candidates(t, &G.box, U, PAIR_CANDIDATES, cd);
                tried++;
                cd->counts.paired += (size_t)paired;
            }
            /* The partners' distances are real points': the window improves
             * on them when they listed too many candidates. */
            if (scanned && !paired && (wtried < PAIR_TRIAL || 2 * wkept >= wtried)) {
                qgroup_seeds(q, t, &G, &h, &s0);
                seeded = 1;
                size_t apart;
                U = window_bests(q, t, &G, &apart);
                if (4 * apart <= G.m) paired = candidates(t, &G.box, U, WINDOW_CANDIDATES, cd);
                windowed = paired;
                wtried++;
                wkept += (size_t)paired;
                cd->counts.windowed += (size_t)paired;
            }
            if (!paired && scanned && !candidates(t, &G.box, 0, G.m, cd)) {
                /* Spread over more of t's buckets than it has queries. */
                for (size_t k = first, wb = 0, wp = 0; k < first + G.m; k++) solo_query(c, cd, k, &wb, &wp);
                cd->counts.solo += G.m;
                continue;
            }
            if (!paired && scanned) {
                if (!seeded) qgroup_seeds(q, t, &G, &h, &s0);
                near = seed_bests(q, t, &G, cd, &U, &scanned);
            }
            cd->counts.far += (size_t)(!scanned && !shared);
            size_t kept = qgroup_finish(c, cd, ck, &G, U, paired, windowed, near, scanned, shared ? &S : NULL);
            /* The path pays when the partners are the answers (a copy), not
             * merely near enough to list few candidates (a few buckets of
             * repeated points): it is kept on while at least half of the
             * groups tried had half of their answers there. */
            kept_groups += !windowed && 2 * kept >= G.m;
        }
    }
}

/* The workers hd__an_nearest runs. */
static int query_threads(const hd__an_t *asking, int threads) {
    return hd__thread_count(threads, (asking->ng + GROUPS_PER_TASK - 1) / GROUPS_PER_TASK);
}

size_t hd__an_nearest_bytes(const hd__an_t *asking, const hd__an_t *searched, int threads) {
    size_t w = (size_t)query_threads(asking, threads);
    return 2 * w * (sizeof(cands_t) + searched->nb * (2 * sizeof(uint32_t) + 7 * sizeof(double))) +
           asking->n * (sizeof(double) + sizeof(uint32_t));
}

/* Room for a candidate list of every bucket of a structure of nb buckets
 * in each of the `workers` lists cand[] (zeroed); HD_OK or HD_ENOMEM. */
static int cands_alloc(cands_t *cand, int workers, size_t nb) {
    for (int w = 0; w < workers; w++) {
        cands_t *cd = &cand[w];
        cd->bucket = hd__malloc_array(nb, sizeof *cd->bucket);
        cd->keep = hd__malloc_array(nb, sizeof *cd->keep);
        cd->lb2 = hd__malloc_array(nb, sizeof *cd->lb2);
        int ok = cd->bucket && cd->keep && cd->lb2;
        for (int d = 0; d < 3; d++) {
            cd->lo[d] = hd__malloc_array(nb, sizeof(double));
            cd->hi[d] = hd__malloc_array(nb, sizeof(double));
            ok = ok && cd->lo[d] && cd->hi[d];
        }
        if (!ok) return HD_ENOMEM;
    }
    return HD_OK;
}

/* Frees what cands_alloc allocated, and the array cand itself (NULL is
 * allowed). */
static void cands_free(cands_t *cand, int workers) {
    for (int w = 0; cand && w < workers; w++) {
        cands_t *cd = &cand[w];
        free(cd->bucket);
        free(cd->keep);
        free(cd->lb2);
        for (int d = 0; d < 3; d++) free(cd->lo[d]), free(cd->hi[d]);
    }
    free(cand);
}

/* hd__an_nearest with the partners of a view (partner) or at positions
 * of searched (pair_at), at most one of them. */
static int nearest_run(const hd__an_t *asking, const hd__an_t *searched, const hd_points_t *partner,
                       const uint32_t *pair_at, int threads, double *dist, size_t *nearest, hd__an_counts_t *counts,
                       hd_error_t *err) {
    size_t tasks = (asking->ng + GROUPS_PER_TASK - 1) / GROUPS_PER_TASK;
    threads = query_threads(asking, threads);
    assert(!partner || !pair_at);
    query_ctx c = {asking, searched, partner && partner->count == asking->n ? partner : NULL, pair_at, dist, nearest,
                   NULL, threads, NULL, NULL};
    c.cand = hd__calloc_array(2 * (size_t)threads, sizeof *c.cand);
    c.sd = hd__malloc_array(asking->n, sizeof *c.sd);
    c.sj = hd__malloc_array(asking->n, sizeof *c.sj);
    int rc = c.cand && c.sd && c.sj ? HD_OK : HD_ENOMEM;
    /* Every answer is written: their pages mapped at once. */
    hd__prefault(c.sd, asking->n * sizeof *c.sd);
    hd__prefault(c.sj, asking->n * sizeof *c.sj);
    if (rc == HD_OK) rc = cands_alloc(c.cand, 2 * threads, searched->nb);
    if (rc == HD_OK) {
        hd__parallel_for(threads, tasks, query_task, &c);
        hd__parallel_for(threads, (asking->n + SCATTER_TASK - 1) / SCATTER_TASK, scatter_answers, &c);
    }
    if (counts) memset(counts, 0, sizeof *counts);
    for (int w = 0; counts && c.cand && w < threads; w++) {
        counts->paired += c.cand[w].counts.paired;
        counts->windowed += c.cand[w].counts.windowed;
        counts->apart += c.cand[w].counts.apart;
        counts->solo += c.cand[w].counts.solo;
        counts->pointed += c.cand[w].counts.pointed;
        counts->far += c.cand[w].counts.far;
        counts->shared += c.cand[w].counts.shared;
    }
    cands_free(c.cand, 2 * threads);
    free(c.sd);
    free(c.sj);
    if (rc != HD_OK) return hd__err(err, rc, "cannot allocate the candidate lists");
    return HD_OK;
}

int hd__an_nearest(const hd__an_t *asking, const hd__an_t *searched, const hd_points_t *partner,
                   int threads, double *dist, size_t *nearest, hd__an_counts_t *counts, hd_error_t *err) {
    return nearest_run(asking, searched, partner, NULL, threads, dist, nearest, counts, err);
}

int hd__an_nearest_paired(const hd__an_t *asking, const hd__an_t *searched, const uint32_t *pair_at, int threads,
                          double *dist, size_t *nearest, hd__an_counts_t *counts, hd_error_t *err) {
    return nearest_run(asking, searched, NULL, pair_at, threads, dist, nearest, counts, err);
}

/* ---- within a band: ranks without every distance ------------------------------ */

/*
 * hd__an_band classifies every asking point by its exact nearest squared
 * distance d2 against a band [lo2, hi2]: below (d2 < lo2) and above
 * (d2 > hi2) are only counted, and d2 itself is kept only for the points
 * within the band.  A point is settled below as soon as any searched point
 * lies at a computed squared distance under lo2 (the nearest is at most
 * that), and above when no bucket's bound is at most hi2 (a bound never
 * exceeds the computed distance of a point it holds).  Only the points
 * within the band need their complete search; when the band brackets a
 * percentile closely, those are few, which is what makes a percentile
 * cheaper than every distance.
 *
 * The search of one point: the WINDOW points of the searched set around
 * its own key on the searched set's curve (window_best), which settle most
 * points below; for the others, the searched bucket nearest to the box of
 * its asking bucket (nearest_leaf), then the candidate buckets within
 * min(hi2, U) of that box, U the smaller of the path's node bounds and the
 * largest best of the bucket's open points (each an actual point's
 * distance, so U bounds each of their answers, and a band with hi2 = +inf
 * stays a local search).  Candidates whose box holds the point are scanned
 * first (they usually settle it below), then the others within
 * min(best, hi2).  The minimiser of a point whose d2 is at most hi2 lies in
 * a bucket whose bound is at most d2, at most its best and at most hi2: it
 * is scanned, so a point kept in the band has its exact d2.  An asking
 * bucket that would list more than BAND_SHARED candidates per open point
 * (a sparse set asking a dense one) lists them per point instead, around
 * the point within its best and hi2: the same argument.  Copies of
 * one point (a bucket whose stop is start + 1) are settled once for all of
 * them.  The counts and the
 * kept values (as a multiset) depend on nothing but the two sets and the
 * band, whatever the threads.
 */

#define BAND_TASK 64   /* asking buckets per task */
#define BAND_SHARED 16 /* most candidates per open point of a bucket for one shared list */

typedef struct {
    double *v;
    size_t n, cap;
    size_t below, above, solo;
    int nomem;
} band_out_t;

typedef struct {
    const hd__an_t *q, *t;
    double lo2, hi2;
    cands_t *cand;
    band_out_t *out; /* per worker */
    double *each;    /* NULL, or each point's class by its name (hd__an_band_each) */
} band_ctx;

/* The class of `times` points from position k of q in each (NULL: not
 * kept; the passes without it are compiled without the stores): -1 below,
 * +inf above, else d2. */
HD__INLINE void band_each(const band_ctx *c, double *each, size_t k, size_t times, double d2) {
    if (!each) return;
    double v = d2 < c->lo2 ? -1.0 : d2 > c->hi2 ? INFINITY : d2;
    for (size_t t = 0; t < times; t++) each[c->q->idx[k + t]] = v;
}

/* Settles one value, of `times` points from position k, into o. */
HD__INLINE void band_settle(const band_ctx *c, band_out_t *o, double *each, double d2, size_t times, size_t k) {
    band_each(c, each, k, times, d2);
    if (d2 < c->lo2) {
        o->below += times;
        return;
    }
    if (d2 > c->hi2) {
        o->above += times;
        return;
    }
    if (o->n + times > o->cap) {
        size_t cap = o->cap ? 2 * o->cap : 1024;
        while (cap < o->n + times) cap *= 2;
        double *v = hd__realloc_array(o->v, cap, sizeof *v);
        if (!v) {
            o->nomem = 1;
            return;
        }
        o->v = v, o->cap = cap;
    }
    for (size_t k = 0; k < times; k++) o->v[o->n++] = d2;
}

/* The rest of one point's search on the candidate list cd (seed buckets
 * [s0, s1) scanned already, best their smallest distance): its best
 * distance, exact when at most hi2, or some distance under lo2. */
HD__INLINE double band_finish(const band_ctx *c, cands_t *cd, double qx, double qy, double qz, double best,
                          size_t near) {
    const hd__an_t *t = c->t;
    uint32_t j = UINT32_MAX;
    candidate_bounds(cd, cd->n, qx, qy, qz);
    for (int pass = 0; pass < 2; pass++)
        for (size_t r = 0; r < cd->n && !(best < c->lo2); r++) {
            double lb = cd->lb2[r], lim = best < c->hi2 ? best : c->hi2;
            size_t b = cd->bucket[r];
            if ((pass == 0) != (lb <= 0) || lb > lim || b == near) continue;
            scan_bucket(t, b, qx, qy, qz, &best, &j);
        }
    return best;
}

/* Points [first, end) of asking bucket b (at most HD__AN_BUCKET), each
 * standing for `times` copies: all below at once when a node on the path
 * to the searched bucket nearest to b's box is within lo2 of every point
 * of the box (node_ub2 is never below the computed distance of a pair
 * drawn from the two boxes, and a node holds a point); else the window of
 * each point on t's curve, then, for those it left open, that nearest
 * bucket, then the candidates.  *wb and *wp carry the window's place (window_best). */
HD__INLINE void band_points(const band_ctx *c, cands_t *cd, band_out_t *o, double *each, size_t b, size_t first,
                            size_t end, size_t times, size_t *wb, size_t *wp) {
    const hd__an_t *q = c->q, *t = c->t;
    double best[HD__AN_BUCKET], U = INFINITY, V = 0;
    size_t open = 0, node = q->leaf[b];
    hd__box_t box;
    for (int d = 0; d < 3; d++) box.lo[d] = q->lo[d][node], box.hi[d] = q->hi[d][node];
    size_t near = nearest_leaf(t, &box, &U);
    if (U < c->lo2) { /* every point of the box has a point of t within U */
        o->below += (end - first) * times;
        band_each(c, each, first, (end - first) * times, -1.0);
        return;
    }
    for (size_t k = first; k < end; k++) {
        uint32_t j = UINT32_MAX;
        double *bk = &best[k - first];
        *bk = INFINITY;
        window_best(q, t, k, wb, wp, bk, &j);
        if (!(*bk < c->lo2)) scan_bucket(t, near, q->x[k], q->y[k], q->z[k], bk, &j);
        if (*bk < c->lo2) {
            band_settle(c, o, each, *bk, times, k);
            *bk = -1; /* settled */
            continue;
        }
        open++;
        V = *bk > V ? *bk : V;
    }
    if (!open) return;
    U = U < V ? U : V;
    double lim = U < c->hi2 ? U : c->hi2;
    if (candidates(t, &box, lim, open * BAND_SHARED, cd)) {
        for (size_t k = first; k < end; k++)
            if (best[k - first] >= 0)
                band_settle(c, o, each, band_finish(c, cd, q->x[k], q->y[k], q->z[k], best[k - first], near), times,
                            k);
        return;
    }
    /* A bucket spread over more of t's buckets than BAND_SHARED per open
     * point (a sparse set asking a dense one): each open point lists its
     * own candidates, within its best and hi2 of the point itself. */
    for (size_t k = first; k < end; k++) {
        double bk = best[k - first];
        if (bk < 0) continue;
        hd__box_t pb = {{q->x[k], q->y[k], q->z[k]}, {q->x[k], q->y[k], q->z[k]}};
        candidates(t, &pb, bk < c->hi2 ? bk : c->hi2, SIZE_MAX, cd);
        o->solo += times;
        band_settle(c, o, each, band_finish(c, cd, q->x[k], q->y[k], q->z[k], bk, near), times, k);
    }
}

/* Asking bucket b, HD__AN_BUCKET points at a time (a bucket of equal keys
 * may hold more). */
HD__INLINE void band_bucket(const band_ctx *c, cands_t *cd, band_out_t *o, double *each, size_t b, size_t *wb,
                            size_t *wp) {
    const hd__an_t *q = c->q;
    size_t first = q->start[b], end = q->stop[b], times = end == first + 1 ? q->start[b + 1] - first : 1;
    for (size_t k = first; k < end; k += HD__AN_BUCKET)
        band_points(c, cd, o, each, b, k, end - k < HD__AN_BUCKET ? end : k + HD__AN_BUCKET, times, wb, wp);
}

/* One task's asking buckets; each as band_each's (NULL: the stores are
 * compiled out of band_task). */
HD__INLINE void band_range(const band_ctx *c, size_t task, int worker, double *each) {
    size_t b0 = task * BAND_TASK, b1 = b0 + BAND_TASK < c->q->nb ? b0 + BAND_TASK : c->q->nb;
    size_t wb = 0, wp = 0;
    for (size_t b = b0; b < b1; b++) band_bucket(c, &c->cand[worker], &c->out[worker], each, b, &wb, &wp);
}

static HD__HOT void band_task(void *vctx, size_t task, int worker) { band_range(vctx, task, worker, NULL); }

/* band_task keeping each point's class (hd__an_band_each). */
static HD__HOT void band_task_each(void *vctx, size_t task, int worker) {
    const band_ctx *c = vctx;
    band_range(c, task, worker, c->each);
}

int hd__an_band(const hd__an_t *asking, const hd__an_t *searched, double lo2, double hi2, int threads,
                hd__an_band_t *out, hd_error_t *err) {
    return hd__an_band_each(asking, searched, lo2, hi2, threads, out, NULL, err);
}

int hd__an_band_each(const hd__an_t *asking, const hd__an_t *searched, double lo2, double hi2, int threads,
                     hd__an_band_t *out, double *each, hd_error_t *err) {
    memset(out, 0, sizeof *out);
    size_t tasks = (asking->nb + BAND_TASK - 1) / BAND_TASK;
    threads = hd__thread_count(threads, tasks);
    band_ctx c = {asking, searched, lo2, hi2, NULL, NULL, each};
    c.cand = hd__calloc_array((size_t)threads, sizeof *c.cand);
    c.out = hd__calloc_array((size_t)threads, sizeof *c.out);
    int rc = c.cand && c.out ? HD_OK : HD_ENOMEM;
    if (rc == HD_OK) rc = cands_alloc(c.cand, threads, searched->nb);
    if (rc == HD_OK) hd__parallel_for(threads, tasks, each ? band_task_each : band_task, &c);
    size_t kept = 0;
    for (int w = 0; c.out && w < threads; w++) {
        out->below += c.out[w].below, out->above += c.out[w].above, kept += c.out[w].n;
        out->solo += c.out[w].solo;
        if (c.out[w].nomem) rc = HD_ENOMEM;
    }
    if (rc == HD_OK && !(out->v = hd__malloc_array(kept ? kept : 1, sizeof *out->v))) rc = HD_ENOMEM;
    for (int w = 0; rc == HD_OK && w < threads; w++) {
        if (c.out[w].n) memcpy(out->v + out->n, c.out[w].v, c.out[w].n * sizeof *out->v);
        out->n += c.out[w].n;
    }
    for (int w = 0; c.out && w < threads; w++) free(c.out[w].v);
    free(c.out);
    cands_free(c.cand, threads);
    if (rc != HD_OK) {
        free(out->v);
        memset(out, 0, sizeof *out);
        return hd__err(err, rc, "cannot allocate the distances within the band");
    }
    return HD_OK;
}

/* ---- histograms from bounds ------------------------------------------------- */

/*
 * hd__an_hist counts every asking point's exact nearest distance sqrt(d2)
 * in numpy's bins (histogram.c), computing it only for the points of the
 * asking buckets whose bounds do not decide the bin.  Bounds on the d2 of
 * every point of an asking bucket's box, rounding included:
 *  - above: U, the smallest node_ub2 on the path to the searched bucket
 *    nearest to the box (a node holds a point, so every point of the box
 *    has one within U);
 *  - below: L, the smallest node_lb2 from the box to a searched bucket
 *    (the minimiser of each point lies in one), found by a descent that
 *    skips the nodes whose bound is not below the smallest so far.
 * sqrt is monotone, so sqrt(L) and sqrt(U) bound the distances.  When they
 * are placed alike (hd__hist_decided), so is every value between them: the
 * bucket's points are counted at once.  (When the bounds of a sample of
 * the buckets decide few points, no bucket is tried.)  The points of the other buckets
 * get their exact distances from hd__an_nearest (on a structure of those
 * points alone when they are at most half, else on all of asking, with
 * the partners hd_distances gives it) and are placed by the same rule.
 */

#define HIST_TASK 64  /* asking buckets per task of the bound pass */
#define HIST_PROBE 16 /* one bucket in HIST_PROBE tried before the bound pass */

typedef struct {
    const hd__an_t *q, *t;
    const hd__hist_t *h;
    uint8_t *open;      /* per asking bucket: 1 when its bounds did not decide */
    uint64_t **counts;  /* per worker */
} hist_ctx;

/* The smallest node_lb2 from box q to a bucket of t, or some bound below
 * `enough` as soon as one is found (a lower bound that small decides
 * nothing). */
static double tree_lb2(const hd__an_t *t, const hd__box_t *q, double enough) {
    uint32_t stack[8 * 11 + 8];
    double slb[8 * 11 + 8], least = INFINITY;
    int sp = 0;
    stack[sp] = 0, slb[sp] = node_lb2(q, t, 0), sp++;
    while (sp > 0 && !(least < enough)) {
        sp--;
        if (slb[sp] >= least) continue;
        size_t k = stack[sp];
        if (!t->count[k]) {
            least = slb[sp];
            continue;
        }
        size_t f = t->first[k];
        int top = sp;
        for (int i = 0; i < t->count[k]; i++) {
            double lb = node_lb2(q, t, f + (size_t)i);
            if (lb >= least) continue;
            stack[sp] = (uint32_t)(f + (size_t)i), slb[sp] = lb, sp++;
            if (lb < slb[top]) { /* the nearest child at top */
                uint32_t ks = stack[top];
                double ls = slb[top];
                stack[top] = stack[sp - 1], slb[top] = slb[sp - 1];
                stack[sp - 1] = ks, slb[sp - 1] = ls;
            }
        }
        if (sp > top + 1) { /* then on the stack's top, searched first */
            uint32_t ks = stack[top];
            double ls = slb[top];
            stack[top] = stack[sp - 1], slb[top] = slb[sp - 1];
            stack[sp - 1] = ks, slb[sp - 1] = ls;
        }
    }
    return least;
}

/* Below this squared distance a lower bound cannot place an interval
 * ending at u = sqrt(U) in u's bin (or above hi): just under the square
 * of that bin's lower edge.  It only spares work: the decision is
 * hd__hist_decided's. */
static double useful_lb2(const hd__hist_t *h, double U) {
    size_t guess, b = hd__hist_place(h, sqrt(U), &guess);
    double e = b == SIZE_MAX ? h->hi : hd__hist_edge(h, b);
    return e > 0 ? 0.999 * e * e : 0.0;
}

/* 1 when the bounds of asking bucket b decide its bin, in *bin. */
static int hist_bucket(const hist_ctx *c, size_t b, size_t *bin) {
    const hd__an_t *q = c->q, *t = c->t;
    size_t node = q->leaf[b];
    hd__box_t box;
    for (int d = 0; d < 3; d++) box.lo[d] = q->lo[d][node], box.hi[d] = q->hi[d][node];
    double U = INFINITY;
    nearest_leaf(t, &box, &U);
    double L = hd__hist_decided(c->h, 0.0, sqrt(U), bin) ? 0.0 : tree_lb2(t, &box, useful_lb2(c->h, U));
    return hd__hist_decided(c->h, sqrt(L), sqrt(U), bin);
}

static HD__HOT void hist_task(void *vctx, size_t task, int worker) {
    hist_ctx *c = vctx;
    const hd__an_t *q = c->q;
    size_t b0 = task * HIST_TASK, b1 = b0 + HIST_TASK < q->nb ? b0 + HIST_TASK : q->nb, bin;
    for (size_t b = b0; b < b1; b++) {
        c->open[b] = !hist_bucket(c, b, &bin);
        if (!c->open[b] && bin != SIZE_MAX) c->counts[worker][bin] += q->start[b + 1] - q->start[b];
    }
}

/* 1 when the bounds of every HIST_PROBE-th bucket decide at least a
 * quarter of their points: the bound pass then spares more than it costs.
 * Only the cost depends on it. */
static int hist_worth(const hist_ctx *c) {
    const hd__an_t *q = c->q;
    size_t seen = 0, decided = 0, bin;
    for (size_t b = 0; b < q->nb; b += HIST_PROBE) {
        size_t m = q->start[b + 1] - q->start[b];
        seen += m;
        if (hist_bucket(c, b, &bin)) decided += m;
    }
    return 4 * decided >= seen;
}

/* The exact distances of the open buckets' points, placed. */
static int hist_open(const hist_ctx *c, const hd_points_t *P, const hd_points_t *partner, const hd__box_t *keybox,
                     int threads, uint64_t *counts, hd_error_t *err) {
    const hd__an_t *q = c->q;
    size_t m = 0, n = q->start[q->nb];
    for (size_t b = 0; b < q->nb; b++)
        if (c->open[b]) m += q->start[b + 1] - q->start[b];
    if (!m) return HD_OK;
    double *dist = hd__malloc_array(P->count, sizeof *dist);
    uint8_t *mark = hd__calloc_array(P->count, 1);
    uint32_t *sel = NULL;
    int rc = dist && mark ? HD_OK : hd__err(err, HD_ENOMEM, "cannot allocate %zu distances", P->count);
    for (size_t b = 0; rc == HD_OK && b < q->nb; b++)
        if (c->open[b])
            for (size_t k = q->start[b]; k < q->start[b + 1]; k++) mark[q->idx[k]] = 1;
    if (rc == HD_OK && 2 * m > n) { /* most points: the structure of them all */
        rc = hd__an_nearest(q, c->t, partner, threads, dist, NULL, NULL, err);
    } else if (rc == HD_OK) { /* a structure of the open points (increasing names) */
        if (!(sel = hd__malloc_array(m, sizeof *sel))) rc = hd__err(err, HD_ENOMEM, "cannot allocate %zu indices", m);
        size_t k = 0;
        for (size_t i = 0; rc == HD_OK && i < P->count; i++)
            if (mark[i]) sel[k++] = (uint32_t)i;
        hd__an_t one;
        if (rc == HD_OK && (rc = hd__an_build_sel(&one, P, sel, NULL, m, keybox, threads, err)) == HD_OK) {
            rc = hd__an_nearest(&one, c->t, NULL, threads, dist, NULL, NULL, err);
            hd__an_free(&one);
        }
    }
    for (size_t i = 0; rc == HD_OK && i < P->count; i++)
        if (mark[i]) {
            size_t guess, b = hd__hist_place(c->h, dist[i], &guess);
            if (b != SIZE_MAX) counts[b]++;
        }
    free(dist);
    free(mark);
    free(sel);
    return rc;
}

int hd__an_hist(const hd__an_t *asking, const hd__an_t *searched, const hd_points_t *P, const hd_points_t *partner,
                const hd__box_t *keybox, const hd__hist_t *h, int threads, uint64_t *counts, hd_error_t *err) {
    size_t tasks = (asking->nb + HIST_TASK - 1) / HIST_TASK;
    int workers = hd__thread_count(threads, tasks ? tasks : 1);
    hist_ctx c = {asking, searched, h, NULL, NULL};
    c.open = hd__malloc_array(asking->nb ? asking->nb : 1, 1);
    c.counts = hd__calloc_array((size_t)workers, sizeof *c.counts);
    int rc = c.open && c.counts ? HD_OK : HD_ENOMEM;
    for (int w = 0; rc == HD_OK && w < workers; w++)
        if (!(c.counts[w] = hd__calloc_array(h->bins, sizeof *counts))) rc = HD_ENOMEM;
    if (rc != HD_OK) {
        rc = hd__err(err, rc, "cannot allocate the histogram's counts");
    } else {
        if (hist_worth(&c)) hd__parallel_for(workers, tasks, hist_task, &c);
        else memset(c.open, 1, asking->nb);
        uint64_t *sum = c.counts[0];
        for (int w = 1; w < workers; w++)
            for (size_t k = 0; k < h->bins; k++) sum[k] += c.counts[w][k];
        rc = hist_open(&c, P, partner, keybox, threads, sum, err);
        for (size_t k = 0; rc == HD_OK && k < h->bins; k++) counts[k] += sum[k];
    }
    for (int w = 0; c.counts && w < workers; w++) free(c.counts[w]);
    free(c.counts);
    free(c.open);
    return rc;
}

/* ---- both sets side by side --------------------------------------------------- */

typedef struct {
    const hd_points_t *set[2];
    const hd__box_t *keybox;
    int threads; /* for each build */
    int rc[2];
    hd_error_t err[2];
    hd__an_t *s;
} pair_ctx;

static void pair_task(void *vctx, size_t task, int worker) {
    (void)worker;
    pair_ctx *c = vctx;
    c->rc[task] = hd__an_build(&c->s[task], c->set[task], NULL, c->keybox, c->threads, &c->err[task]);
}

int hd__an_build_pair(const hd_points_t *A, const hd_points_t *B, const hd__box_t *keybox, int threads,
                      hd__an_t s[2], hd_error_t *err) {
    /* Part of each build is serial (the octree), so two builds on half the
     * threads each finish sooner than one after the other on all of them. */
    pair_ctx c = {{A, B}, keybox, threads < 2 ? 1 : threads / 2, {HD_OK, HD_OK}, {{0}, {0}}, s};
    memset(s, 0, 2 * sizeof *s);
    hd__parallel_for(threads < 2 ? 1 : 2, 2, pair_task, &c);
    for (int k = 0; k < 2; k++)
        if (c.rc[k]) {
            if (err) *err = c.err[k];
            hd__an_free(&s[0]);
            hd__an_free(&s[1]);
            return c.rc[k];
        }
    return HD_OK;
}
