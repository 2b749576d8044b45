/*
 * grid.c -- the engine's cheap index (a uniform grid in Morton order
 * with an implicit octree over it) and the directed pass that uses it.
 *
 * When the two sets are far apart, or overlap with a Hausdorff distance
 * that is large next to the spacing of the points, almost every point of A
 * has a point of B well within the final maximum, and whole regions of A
 * can be dismissed at once.  This file serves that case with one counting
 * sort per set and one pass over A's cells per direction:
 *  - the grid: 2^bits cubic cells per axis over the set's box (at least 16
 *    points per cell on average), numbered along the Morton curve; a
 *    counting sort (one pass counting, one placing) groups the points by
 *    cell.  Each cell keeps a representative, its point with the smallest
 *    index.  The octree over the cells is implicit: the node of level L
 *    with prefix p covers cells [p 8^L, (p+1) 8^L), a contiguous range of
 *    points;
 *  - the pass for h(A,B) walks A's own cells in Morton order (the paper's
 *    CubeToPoints, Algorithm 4, lines 5-7, applied to grid cells).  A cell
 *    is discarded whole, without reading its points, when one point b of B
 *    lies strictly within cmax of every point of its box: b is the
 *    representative of B's cell at the cell's centre, the last point of B
 *    that discarded something, or (for a crowded cell, when cmax is large
 *    next to the cell) the point of B nearest the centre.  The points of a
 *    cell that survives are read through the permutation and tested one by
 *    one against those points of B and the representative of their own
 *    cell in B (the paper's OHD point culling, Algorithm 6, line 5, with an
 *    exact test in place of "inside a leaf cube"); a point none of them
 *    discards gets an exact nearest-neighbour search in B's octree
 *    (Algorithm 6, line 6), which either finds a point within cmax
 *    (EARLYBREAK's break, Algorithm 2, line 8) or gives the exact nearest
 *    distance, offered to the maximum (line 7).  When cmax is below a
 *    cell's diagonal as the pass starts (a translated copy), few cells could
 *    be discarded whole, and the pass tests A's points in input order
 *    instead, as they lie in memory.
 *
 * Exactness.  The octree's node boxes (and so each cell's box) are the
 * nominal boxes widened by `margin`, which covers every rounding in
 * assigning a point to its cell and in computing the faces (derived at
 * grid_geometry): each box encloses its points exactly.  Then, by the
 * monotonicity argument of points/points.h, hd__box_lb2s never exceeds, and
 * hd__box_ub2(box, b) is never below, the computed hd__d2(a, b) of any
 * point a in the box: |fl(a - b)| <= max(|fl(lo - b)|, |fl(hi - b)|) on each
 * axis when lo <= a <= hi, and squaring and adding in the same order are
 * monotone.  So a cell is discarded only when hd__box_ub2 < cmax^2 strictly,
 * which proves hd__d2(a, b) < cmax^2 for each of its points (no slack is
 * needed: b is an exact point, and the bound is computed as the distance
 * is).  Points are discarded only by exact squared distances to actual
 * points of B (hd__kills: strictly below cmax, or a tie that cannot be the
 * witness).  Searches prune a node only when its lower bound is strictly
 * above the best exact distance, so they return the exact nearest distance
 * with the smallest index, as search.c does.  Nothing here depends
 * on the order in which threads take the cells.
 *
 * The plan (engine.c) primes cmax with hd__grid_prime and decides between
 * this pass and the bucket trees with hd__grid_trial, both here because
 * they run this file's point-by-point test on a sample.
 */
#include "engine/grid.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- geometry ------------------------------------------------------------------- */

static inline uint32_t spread8(uint32_t v) { return hd__spread_table[v & 0xff]; }

static inline uint32_t compact8(uint32_t x) {
    x &= 0x249249u;
    x = (x | x >> 2) & 0xc30c3u;
    x = (x | x >> 4) & 0x0f00fu;
    x = (x | x >> 8) & 0xffu;
    return x;
}

/* Cell coordinate of value v on axis k, clamped to the grid (min and max
 * rather than branches: the same values, for finite v). */
static inline uint32_t axis_cell(const hd__grid_t *g, int k, double v) {
    double t = (v - g->lo[k]) * g->inv;
    double top = (double)((1u << g->bits) - 1);
    t = t < top ? t : top;
    t = t > 0 ? t : 0;
    return (uint32_t)t;
}

static inline uint32_t cell_of(const hd__grid_t *g, const double p[3]) {
    return spread8(axis_cell(g, 0, p[0])) | spread8(axis_cell(g, 1, p[1])) << 1 |
           spread8(axis_cell(g, 2, p[2])) << 2;
}

/* Points per cell, at least, on average (a cell costs 28 bytes).  Fewer
 * cells make the counting sort cheaper, but a cell must stay small next to
 * the distance for whole cells to be discarded: where none can be (a copy
 * translated by about a cell), each surviving point's search scans a
 * crowded cell.  The measurements behind 16 are in docs/engine.md, "Step
 * 1: the grid". */
#define GRID_POINTS_PER_CELL 16

/* At most 2^6 cells per axis (2^18 cells, a 1 MB count table per part):
 * beyond that the counting sort's table and its 2^21 write positions miss
 * the caches on every point (measured at 10^8 points: docs/engine.md,
 * "Step 1: the grid"). */
#define GRID_MAX_BITS 6

/* The grid over a box: cubic cells of side w, a little more than the
 * largest extent over 2^bits, so that the box's top maps inside.  A point x
 * assigned to cell c has t = fl(fl(x - lo) * inv) in [c, c + 1): the true
 * (x - lo) / w differs from t by at most 3u * 2^bits cells (u = 2^-53), and
 * a computed face lo + c * w differs from the true one by at most
 * 2u (|lo| + 2^bits w).  The margin, 1e-12 (2^bits w + max |lo|, |hi|),
 * exceeds the sum of both many times over. */
static void grid_geometry(hd__grid_t *g, const hd__box_t *box, size_t n) {
    int bits = 1;
    while (bits < GRID_MAX_BITS && (size_t)1 << (3 * (bits + 1)) <= n / GRID_POINTS_PER_CELL) bits++;
    g->bits = bits;
    double ext = 0, mag = 0;
    for (int k = 0; k < 3; k++) {
        g->lo[k] = box->lo[k];
        double e = box->hi[k] - box->lo[k];
        ext = e > ext ? e : ext;
        mag = fabs(box->lo[k]) > mag ? fabs(box->lo[k]) : mag;
        mag = fabs(box->hi[k]) > mag ? fabs(box->hi[k]) : mag;
    }
    double G = (double)(1u << bits);
    g->w = ext > 0 ? ext / G * (1 + 1e-9) : (mag > 0 ? mag * 1e-9 : 1.0);
    g->inv = 1.0 / g->w;
    g->margin = 1e-12 * (G * g->w + mag);
}

/* The box the grid's cells cover: every point the grid was built over
 * lies in it (grid_geometry rounds the cell width up). */
static hd__box_t grid_extent(const hd__grid_t *g) {
    hd__box_t b;
    for (int k = 0; k < 3; k++) {
        b.lo[k] = g->lo[k];
        b.hi[k] = g->lo[k] + g->w * (double)(1u << g->bits);
    }
    return b;
}

/* The conservative box of the octree node at `level` with Morton prefix p. */
static inline void node_box(const hd__grid_t *g, int level, uint32_t p, hd__box_t *b) {
    uint32_t c[3] = {compact8(p), compact8(p >> 1), compact8(p >> 2)};
    double side = g->w * (double)(1u << level);
    for (int k = 0; k < 3; k++) {
        b->lo[k] = g->lo[k] + (double)c[k] * side - g->margin;
        b->hi[k] = g->lo[k] + (double)(c[k] + 1) * side + g->margin;
    }
}

/* ---- building ------------------------------------------------------------------- */

#define MAX_PARTS 16

typedef struct {
    hd__grid_t *g;
    size_t n;
    int parts;
    uint16_t *cell;             /* n: each point's cell from the first pass, or
                                 * NULL when the second computes it again */
    uint32_t *count[MAX_PARTS]; /* per part: counts, then write positions */
} build_ctx;

/* Point k of a packed double (HD__SRC_F64) or float (HD__SRC_F32) array,
 * or of any source (HD__SRC_ANY); a constant kind lets the compiler
 * specialise the loops below for the packed layouts. */
HD__INLINE void src_point(const hd__src_t *s, hd__src_kind_t kind, size_t k, double p[3]) {
    /* The packed paths read the layout directly and apply no transform. */
    assert(kind == HD__SRC_ANY || (kind == s->kind && !s->T));
    if (kind == HD__SRC_F64) {
        const double *q = (const double *)(const void *)s->base + 3 * k;
        p[0] = q[0], p[1] = q[1], p[2] = q[2];
    } else if (kind == HD__SRC_F32) {
        const float *q = (const float *)(const void *)s->base + 3 * k;
        p[0] = q[0], p[1] = q[1], p[2] = q[2];
    } else {
        hd__src_get(s, k, p);
    }
}

/* The grid's geometry in locals, so that the loops' stores cannot be taken
 * to change it, and the cell of a point as cell_of computes it. */
typedef struct {
    double lo[3], inv, top;
} geom_t;

HD__INLINE geom_t geom_of(const hd__grid_t *g) {
    geom_t q = {{g->lo[0], g->lo[1], g->lo[2]}, g->inv, (double)((1u << g->bits) - 1)};
    return q;
}

HD__INLINE uint32_t geom_cell(geom_t q, const double p[3]) {
    double t[3];
    for (int k = 0; k < 3; k++) {
        t[k] = (p[k] - q.lo[k]) * q.inv;
        t[k] = t[k] < q.top ? t[k] : q.top;
        t[k] = t[k] > 0 ? t[k] : 0;
    }
    return hd__spread_table[(int32_t)t[0]] | hd__spread_table[(int32_t)t[1]] << 1 |
           hd__spread_table[(int32_t)t[2]] << 2;
}

/* The first pass over points [lo, hi): each point's cell (kept when
 * c->cell is set) and the counts per cell. */
HD__INLINE void count_range(build_ctx *c, size_t part, size_t lo, size_t hi, hd__src_kind_t kind,
                            int keep) {
    const hd__src_t src = c->g->src;
    const geom_t q = geom_of(c->g);
    uint32_t *h = c->count[part];
    uint16_t *cell = c->cell;
    for (size_t i = lo; i < hi; i++) {
        double p[3];
        src_point(&src, kind, i, p);
        uint32_t k = geom_cell(q, p);
        if (keep) cell[i] = (uint16_t)k;
        h[k]++;
    }
}

/* The second pass: each point to its place, in input order within a cell,
 * its cell read from c->cell or computed again. */
HD__INLINE void scatter_range(build_ctx *c, size_t part, size_t lo, size_t hi, hd__src_kind_t kind,
                              int kept) {
    const hd__src_t src = c->g->src;
    const geom_t q = geom_of(c->g);
    uint32_t *perm = c->g->perm, *pos = c->count[part];
    const uint16_t *cell = c->cell;
    for (size_t i = lo; i < hi; i++) {
        uint32_t k;
        if (kept) {
            k = cell[i];
        } else {
            double p[3];
            src_point(&src, kind, i, p);
            k = geom_cell(q, p);
        }
        perm[pos[k]++] = (uint32_t)i;
    }
}

/* Each pass, specialised for the packed layouts and for kept cells. */
HD__HOT static void count_task(void *vctx, size_t part, int worker) {
    (void)worker;
    build_ctx *c = vctx;
    size_t lo = c->n * part / (size_t)c->parts, hi = c->n * (part + 1) / (size_t)c->parts;
    hd__src_kind_t kind = c->g->src.T ? HD__SRC_ANY : c->g->src.kind;
    if (kind == HD__SRC_F64 && c->cell) count_range(c, part, lo, hi, HD__SRC_F64, 1);
    else if (kind == HD__SRC_F64) count_range(c, part, lo, hi, HD__SRC_F64, 0);
    else if (kind == HD__SRC_F32 && c->cell) count_range(c, part, lo, hi, HD__SRC_F32, 1);
    else if (kind == HD__SRC_F32) count_range(c, part, lo, hi, HD__SRC_F32, 0);
    else count_range(c, part, lo, hi, HD__SRC_ANY, c->cell != NULL);
}

static void scatter_task(void *vctx, size_t part, int worker) {
    (void)worker;
    build_ctx *c = vctx;
    size_t lo = c->n * part / (size_t)c->parts, hi = c->n * (part + 1) / (size_t)c->parts;
    hd__src_kind_t kind = c->g->src.T ? HD__SRC_ANY : c->g->src.kind;
    if (c->cell) scatter_range(c, part, lo, hi, HD__SRC_ANY, 1);
    else if (kind == HD__SRC_F64) scatter_range(c, part, lo, hi, HD__SRC_F64, 0);
    else if (kind == HD__SRC_F32) scatter_range(c, part, lo, hi, HD__SRC_F32, 0);
    else scatter_range(c, part, lo, hi, HD__SRC_ANY, 0);
}

/* The representatives: each cell's first point, which has the smallest
 * index since the scatter keeps the input order within a cell. */
static void rep_task(void *vctx, size_t part, int worker) {
    (void)worker;
    build_ctx *c = vctx;
    hd__grid_t *g = c->g;
    size_t cells = (size_t)1 << (3 * g->bits);
    size_t lo = cells * part / (size_t)c->parts, hi = cells * (part + 1) / (size_t)c->parts;
    for (size_t k = lo; k < hi; k++) {
        double *r = g->rep + 3 * k;
        if (g->start[k] == g->start[k + 1]) r[0] = r[1] = r[2] = NAN;
        else hd__src_get(&g->src, g->perm[g->start[k]], r);
    }
}

void hd__grid_free(hd__grid_t *g) {
    if (!g) return;
    hd__reuse_put(g->pool, g->perm);
    hd__reuse_put(g->pool, g->start);
    hd__reuse_put(g->pool, g->rep);
    g->perm = NULL;
    g->start = NULL;
    g->rep = NULL;
}

int hd__grid_build(hd__grid_t *g, const hd__src_t *src, size_t n, const hd__box_t *box,
                   int threads, hd__reuse_t *pool, hd_error_t *err) {
    return hd__grid_build_as(g, src, n, n, box, threads, pool, err);
}

int hd__grid_build_as(hd__grid_t *g, const hd__src_t *src, size_t n, size_t n_cells,
                      const hd__box_t *box, int threads, hd__reuse_t *pool, hd_error_t *err) {
    memset(g, 0, sizeof *g);
    g->pool = pool;
    if (n > UINT32_MAX)
        return hd__err(err, HD_EOVERFLOW,
                       "the auto engine indexes at most 4294967295 points per set, not %zu", n);
    g->n = n;
    g->src = *src;
    grid_geometry(g, box, n_cells);
    size_t cells = (size_t)1 << (3 * g->bits);
    build_ctx c;
    memset(&c, 0, sizeof c);
    c.g = g;
    c.n = n;
    c.parts = threads < 1 ? 1 : threads > MAX_PARTS ? MAX_PARTS : threads;
    if ((size_t)c.parts > n / 4096 + 1) c.parts = (int)(n / 4096 + 1);
    g->perm = hd__reuse_get(pool, n, sizeof *g->perm);
    g->start = hd__reuse_get(pool, cells + 1, sizeof *g->start);
    g->rep = hd__reuse_get(pool, cells, 3 * sizeof *g->rep);
    /* Cell numbers are kept between the passes when they fit in 16 bits;
     * otherwise (more than 4 million points) the second pass computes them
     * again, which costs less than first touching 4 more bytes per point. */
    int keep = cells <= 65536;
    c.cell = keep ? hd__reuse_get(pool, n, sizeof *c.cell) : NULL;
    int ok = g->perm && g->start && g->rep && (c.cell || !keep);
    for (int p = 0; p < c.parts && ok; p++) {
        ok = (c.count[p] = hd__reuse_get(pool, cells, sizeof(uint32_t))) != NULL;
        if (ok) memset(c.count[p], 0, cells * sizeof(uint32_t));
    }
    if (ok) {
        hd__parallel_for(c.parts, (size_t)c.parts, count_task, &c);
        /* Cell starts, and each part's first write position in each cell
         * (parts in order, so the order within a cell is the input order). */
        uint32_t sum = 0;
        for (size_t k = 0; k < cells; k++) {
            g->start[k] = sum;
            for (int p = 0; p < c.parts; p++) {
                uint32_t v = c.count[p][k];
                c.count[p][k] = sum;
                sum += v;
            }
        }
        g->start[cells] = sum;
        assert(sum == n); /* every point counted in exactly one cell */
        hd__parallel_for(c.parts, (size_t)c.parts, scatter_task, &c);
        hd__parallel_for(c.parts, (size_t)c.parts, rep_task, &c);
    }
    for (int p = c.parts - 1; p >= 0; p--) hd__reuse_put(pool, c.count[p]);
    hd__reuse_put(pool, c.cell);
    if (!ok) {
        hd__grid_free(g);
        return hd__err(err, HD_ENOMEM, "cannot allocate the grid of %zu points", n);
    }
    return HD_OK;
}

/* ---- searching ------------------------------------------------------------------ */

typedef struct {
    const hd__grid_t *g;
    const double *q;
    double stop2, tie2;
    hd__hit_t *hit;
    hd__counts_t *n;
} gsearch_t;

/* Scan the points of cell `cell`; returns 1 when the search may stop. */
static int scan_cell(gsearch_t *s, uint32_t cell) {
    const hd__grid_t *g = s->g;
    hd__hit_t *hit = s->hit;
    uint32_t b = g->start[cell], e = g->start[cell + 1];
    for (uint32_t k = b; k < e; k++) {
        size_t j = g->perm[k];
        double p[3];
        hd__src_get(&g->src, j, p);
        double d = hd__d2(s->q, p);
        if (d < hit->d2 || (d == hit->d2 && j < hit->j)) {
            hit->d2 = d;
            hit->j = j;
            memcpy(hit->p, p, sizeof p);
            /* A proof is all the caller wants: stop at the first one (a
             * crowded cell is not read to its end for nothing). */
            if (hit->d2 < s->stop2 || hit->d2 <= s->tie2) {
                s->n->exact += k - b + 1;
                return 1;
            }
        }
    }
    s->n->exact += e - b;
    return 0;
}

void hd__grid_nearest(const hd__grid_t *g, const double q[3], double stop2, double tie2,
                      hd__hit_t *hit, hd__counts_t *n) {
    gsearch_t s = {g, q, stop2, tie2, hit, n};
    hit->d2 = INFINITY;
    hit->killed = 0;
    hit->j = HD__NONE;
    hit->bucket = HD__NONE;
    hit->perr = 0.0;
    /* The query's own cell first: often it settles the search. */
    uint32_t own = cell_of(g, q);
    if (scan_cell(&s, own)) return;
    struct {
        int level;
        uint32_t p;
        double lb2;
    } stack[8 * 9 + 8];
    int sp = 1;
    stack[0].level = g->bits;
    stack[0].p = 0;
    stack[0].lb2 = 0.0;
    uint64_t visited = 0;
    while (sp > 0) {
        sp--;
        if (stack[sp].lb2 > hit->d2) continue;
        int l = stack[sp].level;
        uint32_t p = stack[sp].p;
        visited++;
        if (l == 0) {
            if (p != own && scan_cell(&s, p)) break;
            continue;
        }
        /* The non-empty children, nearest first. */
        int nc = 0;
        size_t cp[8];
        double cl[8];
        uint32_t span = 1u << (3 * (l - 1));
        for (uint32_t k = 0; k < 8; k++) {
            uint32_t q8 = 8 * p + k;
            if (g->start[q8 * span] == g->start[(q8 + 1) * span]) continue;
            hd__box_t b;
            node_box(g, l - 1, q8, &b);
            double lb = hd__box_lb2s(&b, q[0], q[1], q[2]);
            if (lb > hit->d2) continue;
            hd__top_insert(cl, cp, &nc, 8, lb, q8);
        }
        /* cl is in decreasing order: push so the nearest is popped first. */
        for (int k = 0; k < nc; k++) {
            stack[sp].level = l - 1;
            stack[sp].p = (uint32_t)cp[k];
            stack[sp].lb2 = cl[k];
            sp++;
        }
    }
    n->nodes += visited;
}

/* ---- the directed pass ------------------------------------------------------------ */

#define PASS_SLICE 8192

/* Point i of A (source a): discard it or resolve it exactly, against B's
 * grid gb.  near is a point of B found close to i's cell (or NULL); *bc is
 * the last point of B that discarded something (bc_ok says whether there
 * is one). */
static inline void pass_point(const hd__src_t *src, const hd__grid_t *gb, hd__max_t *m, size_t i,
                              const double *near, double cmax2, hd__best_t *snap, double bc[3],
                              int *bc_ok, hd__counts_t *n, uint64_t *culled) {
    double a[3];
    hd__src_get(src, i, a);
    if (near) {
        n->evals++;
        if (hd__kills(cmax2, snap, hd__d2(a, near), i)) {
            (*culled)++;
            return;
        }
    }
    const double *rep = gb->rep + 3 * (size_t)cell_of(gb, a);
    n->evals++;
    if (hd__kills(cmax2, snap, hd__d2(a, rep), i)) {
        (*culled)++;
        return;
    }
    if (*bc_ok) {
        n->evals++;
        if (hd__kills(cmax2, snap, hd__d2(a, bc), i)) {
            (*culled)++;
            return;
        }
    }
    double tie2 = i > snap->i ? snap->d2 : -1.0;
    hd__hit_t hit;
    hd__grid_nearest(gb, a, cmax2, tie2, &hit, n);
    memcpy(bc, hit.p, 3 * sizeof *bc);
    *bc_ok = 1;
    if (hit.d2 < cmax2 || hit.d2 <= tie2) return;
    hd__max_offer(m, hit.d2, i, hit.j, snap);
}

typedef struct {
    const hd__grid_t *ga, *gb;
    hd__max_t *m;
    int by_cells;           /* 1: walk A's cells; 0: A's points in input order */
    size_t cells, per_task; /* A's cells (or points), and how many each task takes */
    hd__counts_t *counts;   /* per worker */
    uint64_t *culled;       /* per worker */
} pass_ctx;

/* Whether the point b of B discards every point of a cell of A with box
 * `box`: the box's computed upper bound is strictly below cmax2 (a strict
 * proof only; see the essay for why it covers every rounding). */
static inline int cell_killed(const hd__box_t *box, const double *b, double cmax2,
                              hd__counts_t *n) {
    n->evals++;
    return hd__box_ub2(box, b) < cmax2;
}

#ifndef NDEBUG
/* What discarding a cell whole claims: each of its points (perm[s..e) of
 * g), read exactly, lies strictly within cmax2 of b (NaN only when the
 * caller's points broke the contract). */
static int cell_within(const hd__grid_t *g, uint32_t s, uint32_t e, const double *b,
                       double cmax2) {
    for (uint32_t k = s; k < e; k++) {
        double a[3];
        hd__src_get(&g->src, g->perm[k], a);
        if (hd__d2(a, b) >= cmax2) return 0;
    }
    return 1;
}
#endif

/* Points read this far ahead in a cell are prefetched. */
#define PREFETCH 16

static inline void src_prefetch(const hd__src_t *s, size_t k) {
#if defined(__GNUC__)
    /* A point may straddle two cache lines. */
    const char *p = s->base + (ptrdiff_t)k * s->ps;
    __builtin_prefetch(p);
    __builtin_prefetch(p + 2 * s->cs);
#else
    (void)s, (void)k;
#endif
}

/* A cell holding fewer points than this is not worth a search from its
 * centre: its points are tested one by one. */
#define CELL_SEARCH_MIN 8

static void pass_task(void *vctx, size_t task, int worker) {
    pass_ctx *c = vctx;
    const hd__grid_t *ga = c->ga, *gb = c->gb;
    size_t lo = task * c->per_task, hi = lo + c->per_task < c->cells ? lo + c->per_task : c->cells;
    hd__best_t snap;
    hd__max_snapshot(c->m, &snap);
    double bc[3] = {0, 0, 0};
    int bc_ok = 0;
    hd__counts_t *n = &c->counts[worker];
    uint64_t *culled = &c->culled[worker];
    if (!c->by_cells) {
        for (size_t i = lo; i < hi; i++)
            pass_point(&ga->src, gb, c->m, i, NULL, hd__bound_get(&c->m->cmax), &snap, bc, &bc_ok,
                       n, culled);
        return;
    }
    /* Half the cell's diagonal, rounded up generously (a heuristic only:
     * it sets where the centre's search may stop, never what is proven). */
    double half = 0.87 * (ga->w + 2 * ga->margin) * (1 + 1e-9);
    for (size_t cell = lo; cell < hi; cell++) {
        uint32_t s = ga->start[cell], e = ga->start[cell + 1];
        if (s == e) continue;
        double cmax2 = hd__bound_get(&c->m->cmax);
        hd__box_t box;
        node_box(ga, 0, (uint32_t)cell, &box);
        double mid[3];
        for (int k = 0; k < 3; k++) mid[k] = 0.5 * (box.lo[k] + box.hi[k]);
        /* The representative of B's cell at the centre, then the last
         * point of B that discarded something. */
        const double *rep = gb->rep + 3 * (size_t)cell_of(gb, mid);
        if (cell_killed(&box, rep, cmax2, n)) {
            assert(cell_within(ga, s, e, rep, cmax2));
            memcpy(bc, rep, sizeof bc);
            bc_ok = 1;
            *culled += e - s;
            continue;
        }
        if (bc_ok && cell_killed(&box, bc, cmax2, n)) {
            assert(cell_within(ga, s, e, bc, cmax2));
            *culled += e - s;
            continue;
        }
        /* A crowded cell: the point of B nearest its centre is the best
         * candidate to discard it whole, and otherwise a good first test
         * for each of its points. */
        const double *near = NULL;
        hd__hit_t hit;
        double r = sqrt(cmax2) - half;
        if (e - s >= CELL_SEARCH_MIN && r > 0.5 * ga->w) {
            hd__grid_nearest(gb, mid, r * r, -1.0, &hit, n);
            if (cell_killed(&box, hit.p, cmax2, n)) {
                assert(cell_within(ga, s, e, hit.p, cmax2));
                memcpy(bc, hit.p, sizeof bc);
                bc_ok = 1;
                *culled += e - s;
                continue;
            }
            near = hit.p;
        }
        /* The points are scattered over the input: ask for them ahead. */
        for (uint32_t k = s; k < e && k < s + PREFETCH; k++) src_prefetch(&ga->src, ga->perm[k]);
        for (uint32_t k = s; k < e; k++) {
            if (k + PREFETCH < e) src_prefetch(&ga->src, ga->perm[k + PREFETCH]);
            pass_point(&ga->src, gb, c->m, ga->perm[k], near, hd__bound_get(&c->m->cmax), &snap,
                       bc, &bc_ok, n, culled);
        }
    }
}

int hd__grid_directed(const hd__grid_t *ga, const hd__grid_t *gb, hd__max_t *m, int threads,
                      hd__counts_t *counts, uint64_t *culled, hd_error_t *err) {
    pass_ctx c;
    c.ga = ga;
    c.gb = gb;
    c.m = m;
    /* When cmax is below a cell's diagonal few cells can be discarded
     * whole (none below half the diagonal; a translated copy, say): then
     * the points are better read in input order, as they lie in memory,
     * than cell by cell through the permutation. */
    double diag = 1.74 * ga->w;
    c.by_cells = hd__bound_get(&m->cmax) > diag * diag;
    if (c.by_cells) {
        c.cells = (size_t)1 << (3 * ga->bits);
        /* About PASS_SLICE points per task on average. */
        c.per_task = ga->n ? c.cells * PASS_SLICE / ga->n : c.cells;
        if (c.per_task < 1) c.per_task = 1;
    } else {
        c.cells = ga->n;
        c.per_task = PASS_SLICE;
    }
    size_t tasks = (c.cells + c.per_task - 1) / c.per_task;
    threads = hd__thread_count(threads, tasks);
    c.counts = hd__calloc_array((size_t)threads, sizeof *c.counts);
    c.culled = hd__calloc_array((size_t)threads, sizeof *c.culled);
    if (!c.counts || !c.culled) {
        free(c.counts);
        free(c.culled);
        return hd__err(err, HD_ENOMEM, "out of memory");
    }
    hd__parallel_for(threads, tasks, pass_task, &c);
    for (int k = 0; k < threads; k++) {
        counts->evals += c.counts[k].evals;
        counts->exact += c.counts[k].exact;
        counts->nodes += c.counts[k].nodes;
        *culled += c.culled[k];
    }
    free(c.counts);
    free(c.culled);
    return HD_OK;
}

/* Offer point i of a to m with its exact nearest distance in B's grid
 * gb; *hit gets the search's answer. */
static void offer_nearest(const hd__src_t *a, size_t i, const hd__grid_t *gb, hd__max_t *m,
                          hd__counts_t *counts, hd__hit_t *hit) {
    double p[3];
    hd__src_get(a, i, p);
    hd__grid_nearest(gb, p, 0.0, -1.0, hit, counts);
    hd__max_offer(m, hit->d2, i, hit->j, NULL);
}

/* How empty B's grid gb is at p, higher being emptier: the inverse of
 * the points in p's cell of B, or for an empty cell 2 plus p's squared
 * distance to the box gb covers (gbox = grid_extent(gb)). */
static double emptiness(const hd__grid_t *gb, const hd__box_t *gbox, const double p[3]) {
    uint32_t cb = cell_of(gb, p);
    uint32_t count = gb->start[cb + 1] - gb->start[cb];
    return count ? 1.0 / (double)count : 2.0 + hd__box_lb2(gbox, p);
}

/* Prime m for h(A,B) from A's own grid: the representatives of A's cells
 * cover the space A occupies evenly, whatever its density, so the ones
 * lying where B is emptiest (B's cells there empty, or nearly) are where
 * the maximum is likely; the HD__PRIME_CELLS of them with the fewest
 * points of B around get exact nearest-neighbour searches in B. */

void hd__grid_prime(const hd__grid_t *ga, const hd__grid_t *gb, hd__max_t *m,
                    hd__counts_t *counts) {
    size_t cells = (size_t)1 << (3 * ga->bits);
    size_t pick[HD__PRIME_CELLS];
    double score[HD__PRIME_CELLS];
    int np = 0;
    const hd__box_t gbox = grid_extent(gb);
    for (size_t c = 0; c < cells; c++) {
        if (ga->start[c] == ga->start[c + 1]) continue;
        hd__top_insert(score, pick, &np, HD__PRIME_CELLS, emptiness(gb, &gbox, ga->rep + 3 * c), c);
    }
    for (int k = 0; k < np; k++) { /* the cell's representative: its first point */
        hd__hit_t hit;
        offer_nearest(&ga->src, ga->perm[ga->start[pick[k]]], gb, m, counts, &hit);
    }
}

/* The HD__PRIME_CELLS representatives of A's cells (ga) farthest from a
 * sample of B (gs, a grid of every few points of B): their distance to
 * the nearest sampled point bounds their nearest distance in B from above,
 * and is large only where B is sparse or absent, which is where
 * hd__grid_prime looks.  A search stops as soon as it finds a sampled
 * point nearer than the 32nd-largest distance so far (that representative
 * is not among them), so most end in the first cell they read.  For the
 * plan's early decision (engine.c), which has no grid of B to count in. */
int hd__grid_prime_picks_far(const hd__grid_t *ga, const hd__grid_t *gs, size_t out[HD__PRIME_CELLS]) {
    size_t cells = (size_t)1 << (3 * ga->bits);
    size_t pick[HD__PRIME_CELLS];
    double score[HD__PRIME_CELLS];
    int np = 0;
    hd__counts_t work = {0, 0, 0};
    for (size_t c = 0; c < cells; c++) {
        if (ga->start[c] == ga->start[c + 1]) continue;
        double bar = np == HD__PRIME_CELLS ? score[np - 1] : 0.0;
        hd__hit_t hit;
        hd__grid_nearest(gs, ga->rep + 3 * c, bar, -1.0, &hit, &work);
        if (!hit.killed) hd__top_insert(score, pick, &np, HD__PRIME_CELLS, hit.d2, c);
    }
    for (int k = 0; k < np; k++) out[k] = ga->perm[ga->start[pick[k]]];
    return np;
}

/* As hd__grid_prime, from every step-th point of A instead of A's
 * representatives: what the plan can prime with before A's grid exists.
 * A sample follows A's density rather than its extent, so it finds fewer
 * of the far, sparse places where the maximum tends to be.  The trial
 * after it may then come out higher or lower than with hd__grid_prime
 * (hd_bench prints both; the figures are in docs/engine.md, "Step 2: the
 * plan"), so the plan decides on it only far from GRID_COST (engine.c,
 * EARLY_COST). */
void hd__grid_prime_sampled(const hd__src_t *a, size_t na, size_t step, const hd__grid_t *gb,
                            hd__max_t *m, hd__counts_t *counts) {
    size_t pick[HD__PRIME_CELLS];
    double score[HD__PRIME_CELLS];
    int np = 0;
    const hd__box_t gbox = grid_extent(gb);
    for (size_t i = 0; i < na; i += step) {
        double p[3];
        hd__src_get(a, i, p);
        hd__top_insert(score, pick, &np, HD__PRIME_CELLS, emptiness(gb, &gbox, p), i);
    }
    for (int k = 0; k < np; k++) {
        hd__hit_t hit;
        offer_nearest(a, pick[k], gb, m, counts, &hit);
    }
}

/* Prime m for h(A,B) and measure what the grid pass costs: take a strided
 * sample of A; in a few rounds, resolve exactly the sampled points that
 * neither the representative of their cell nor any point found so far
 * discards, farthest from their representative (or from B's box when their
 * cell is empty) first, since far-away points are where the maximum lies;
 * then run the pass itself over the sample.  Returns the pass's work per
 * sampled point (distances evaluated plus octree nodes visited), or an
 * estimate above `limit` as soon as the work passes limit per point. */
#define RATE_SAMPLE 2048
#define RATE_ROUNDS 3
#define RATE_RESOLVE 16

double hd__grid_trial(const hd__src_t *a, size_t na, const hd__grid_t *gb, hd__max_t *m,
                      double limit, hd__counts_t *counts) {
    size_t ns = na < RATE_SAMPLE ? na : RATE_SAMPLE;
    double found[RATE_ROUNDS * RATE_RESOLVE][3];
    int nf = 0;
    const hd__box_t gbox = grid_extent(gb);
    for (int round = 0; round <= RATE_ROUNDS; round++) {
        hd__best_t snap;
        hd__max_snapshot(m, &snap);
        double cmax2 = hd__bound_get(&m->cmax);
        /* The RATE_RESOLVE sampled survivors with the largest score. */
        size_t pick[RATE_RESOLVE];
        double score[RATE_RESOLVE];
        int np = 0;
        for (size_t s = 0; s < ns; s++) {
            size_t i = s * na / ns;
            double p[3];
            hd__src_get(a, i, p);
            uint32_t cell = cell_of(gb, p);
            double d = hd__d2(p, gb->rep + 3 * (size_t)cell);
            int gone = hd__kills(cmax2, &snap, d, i);
            for (int f = 0; f < nf && !gone; f++) gone = hd__kills(cmax2, &snap, hd__d2(p, found[f]), i);
            counts->evals += 1 + (uint64_t)nf;
            if (gone) continue;
            /* Sparse cells of B first (empty ones by their distance to B's
             * box), then the representative's distance. */
            uint32_t count = gb->start[cell + 1] - gb->start[cell];
            double sc = count ? d / (double)count : 1e300 + hd__box_lb2(&gbox, p);
            hd__top_insert(score, pick, &np, RATE_RESOLVE, sc, i);
        }
        if (round == RATE_ROUNDS || np == 0) break;
        for (int k = 0; k < np; k++) {
            hd__hit_t hit;
            offer_nearest(a, pick[k], gb, m, counts, &hit);
            memcpy(found[nf++], hit.p, sizeof found[0]);
        }
    }
    /* The point-by-point pass over the sample (hd__grid_directed runs it
     * on the points of the cells it cannot discard whole). */
    hd__counts_t n = {0, 0, 0};
    uint64_t culled = 0;
    hd__best_t snap;
    hd__max_snapshot(m, &snap);
    double bc[3] = {0, 0, 0};
    int bc_ok = 0;
    size_t done = 0;
    for (size_t s = 0; s < ns; s++, done++) {
        double cmax2 = hd__bound_get(&m->cmax);
        pass_point(a, gb, m, s * na / ns, NULL, cmax2, &snap, bc, &bc_ok, &n, &culled);
        /* Far too costly already: the answer is clear, stop paying. */
        if (n.evals + n.exact + n.nodes > (uint64_t)(limit * (double)ns)) {
            done++;
            break;
        }
    }
    counts->evals += n.evals;
    counts->exact += n.exact;
    counts->nodes += n.nodes;
    return done ? (double)(n.evals + n.exact + n.nodes) / (double)done : 0.0;
}
