/*
 * engine_grid.c -- the engine's cheap index (a uniform grid in Morton order
 * with an implicit octree over it) and the directed pass that uses it.
 *
 * When the two sets are far apart, or overlap with a Hausdorff distance
 * that is large next to the spacing of the points, almost every point of A
 * has a point of B well within the final maximum, and the work is dominated
 * by reading the input.  This file serves that case with one counting sort
 * per set and one streaming pass over A per direction:
 *  - the grid: 2^bits cubic cells per axis over the set's box (at least 16
 *    points per cell on average, so that the representatives stay in the
 *    caches), numbered along the Morton curve; a counting sort (two
 *    passes) groups the points by cell.  Each cell keeps
 *    a representative, its point with the smallest index.  The octree over
 *    the cells is implicit: the node of level L with prefix p covers cells
 *    [p 8^L, (p+1) 8^L), a contiguous range of points;
 *  - the pass: each point a of A is discarded when the representative of
 *    its cell in B's grid, or the last point of B that discarded something,
 *    lies strictly within cmax of it (the paper's OHD point culling,
 *    Algorithm 6, line 5, with an exact test in place of "inside a leaf
 *    cube"); otherwise an exact nearest-neighbour search in B's octree
 *    (Algorithm 6, line 6) either finds a point within cmax (EARLYBREAK's
 *    break, Algorithm 2, line 8) or gives the exact nearest distance, which
 *    is offered to the maximum (line 7).
 *
 * Exactness.  Discarding uses only exact squared distances to actual points
 * of B (hd__kills: strictly below cmax, or a tie that cannot be the
 * witness).  The octree's node boxes are the nominal cell boxes widened by
 * `margin`, which covers every rounding in assigning a point to its cell
 * and in computing the faces (derived at grid_geometry), so each box
 * encloses its points and hd__box_lb2s never exceeds the distance to any of
 * them; nodes are pruned only when that bound is strictly above the best
 * exact distance.  The search therefore returns the exact nearest distance
 * with the smallest index, as engine_search.c does.
 *
 * The plan (engine.c) primes cmax with hd__grid_prime and decides between
 * this pass and the bucket trees with hd__grid_trial, both here because
 * they run this file's pass on a sample.
 */
#include "index.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- geometry ------------------------------------------------------------------- */

/* Spread the 8 bits of v to every third bit (Morton interleaving), from a
 * table: three table reads per point instead of some thirty operations. */
#define S1(v) ((((v)&1u) | ((v)&2u) << 2 | ((v)&4u) << 4 | ((v)&8u) << 6))
#define S2(v) (S1(v) | S1((v) >> 4) << 12)
#define ROW(b) S2(b), S2(b + 1), S2(b + 2), S2(b + 3), S2(b + 4), S2(b + 5), S2(b + 6), S2(b + 7)
static const uint32_t spread_table[256] = {
    ROW(0),   ROW(8),   ROW(16),  ROW(24),  ROW(32),  ROW(40),  ROW(48),  ROW(56),
    ROW(64),  ROW(72),  ROW(80),  ROW(88),  ROW(96),  ROW(104), ROW(112), ROW(120),
    ROW(128), ROW(136), ROW(144), ROW(152), ROW(160), ROW(168), ROW(176), ROW(184),
    ROW(192), ROW(200), ROW(208), ROW(216), ROW(224), ROW(232), ROW(240), ROW(248),
};
#undef ROW
#undef S2
#undef S1

static inline uint32_t spread8(uint32_t v) { return spread_table[v & 0xff]; }

static inline uint32_t compact8(uint32_t x) {
    x &= 0x249249u;
    x = (x | x >> 2) & 0xc30c3u;
    x = (x | x >> 4) & 0x0f00fu;
    x = (x | x >> 8) & 0xffu;
    return x;
}

/* Cell coordinate of value v on axis k, clamped to the grid. */
static inline uint32_t axis_cell(const hd__grid_t *g, int k, double v) {
    double t = (v - g->lo[k]) * g->inv;
    double top = (double)((1u << g->bits) - 1);
    return t >= top ? (uint32_t)top : t > 0 ? (uint32_t)t : 0u;
}

static inline uint32_t cell_of(const hd__grid_t *g, const double p[3]) {
    return spread8(axis_cell(g, 0, p[0])) | spread8(axis_cell(g, 1, p[1])) << 1 |
           spread8(axis_cell(g, 2, p[2])) << 2;
}

/* Points per cell, at least, on average: few enough cells that the
 * representatives stay in the caches while A's points hit them in random
 * order (a cell costs 28 bytes). */
#define GRID_POINTS_PER_CELL 16

/* The grid over a box: cubic cells of side w, a little more than the
 * largest extent over 2^bits, so that the box's top maps inside.  A point x
 * assigned to cell c has t = fl(fl(x - lo) * inv) in [c, c + 1): the true
 * (x - lo) / w differs from t by at most 3u * 2^bits cells (u = 2^-53), and
 * a computed face lo + c * w differs from the true one by at most
 * 2u (|lo| + 2^bits w).  The margin, 1e-12 (2^bits w + max |lo|, |hi|),
 * exceeds the sum of both many times over. */
static void grid_geometry(hd__grid_t *g, const hd__box_t *box, size_t n) {
    int bits = 1;
    while (bits < 8 && (size_t)1 << (3 * (bits + 1)) <= n / GRID_POINTS_PER_CELL) bits++;
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
    uint32_t *cell;             /* n: each point's cell, from the first pass */
    uint32_t *count[MAX_PARTS]; /* per part: counts, then write positions */
    double sum[MAX_PARTS][3];   /* per part: sums of the coordinates */
} build_ctx;

static void count_task(void *vctx, size_t part, int worker) {
    (void)worker;
    build_ctx *c = vctx;
    const hd__grid_t *g = c->g;
    size_t lo = c->n * part / (size_t)c->parts, hi = c->n * (part + 1) / (size_t)c->parts;
    uint32_t *h = c->count[part];
    double sx = 0, sy = 0, sz = 0;
    for (size_t i = lo; i < hi; i++) {
        double p[3];
        hd__src_get(&g->src, i, p);
        uint32_t cell = cell_of(g, p);
        c->cell[i] = cell;
        h[cell]++;
        sx += p[0], sy += p[1], sz += p[2];
    }
    c->sum[part][0] = sx, c->sum[part][1] = sy, c->sum[part][2] = sz;
}

static void scatter_task(void *vctx, size_t part, int worker) {
    (void)worker;
    build_ctx *c = vctx;
    hd__grid_t *g = c->g;
    size_t lo = c->n * part / (size_t)c->parts, hi = c->n * (part + 1) / (size_t)c->parts;
    uint32_t *pos = c->count[part];
    for (size_t i = lo; i < hi; i++) {
        uint32_t cell = c->cell[i];
        uint32_t at = pos[cell]++;
        g->perm[at] = (uint32_t)i;
        if (at == g->start[cell]) hd__src_get(&g->src, i, g->rep + 3 * (size_t)cell);
    }
}

void hd__grid_free(hd__grid_t *g) {
    if (!g) return;
    free(g->perm);
    free(g->start);
    free(g->rep);
    g->perm = NULL;
    g->start = NULL;
    g->rep = NULL;
}

size_t hd__grid_memory(const hd__grid_t *g) {
    size_t cells = (size_t)1 << (3 * g->bits);
    return g->n * sizeof *g->perm + (cells + 1) * sizeof *g->start + cells * 3 * sizeof *g->rep;
}

int hd__grid_build(hd__grid_t *g, const hd__src_t *src, size_t n, const hd__box_t *box,
                   int threads, hd_error_t *err) {
    memset(g, 0, sizeof *g);
    if (n > UINT32_MAX)
        return hd__err(err, HD_EOVERFLOW,
                       "the auto engine indexes at most 4294967295 points per set, not %zu", n);
    g->n = n;
    g->src = *src;
    grid_geometry(g, box, n);
    size_t cells = (size_t)1 << (3 * g->bits);
    build_ctx c;
    memset(&c, 0, sizeof c);
    c.g = g;
    c.n = n;
    c.parts = threads < 1 ? 1 : threads > MAX_PARTS ? MAX_PARTS : threads;
    if ((size_t)c.parts > n / 4096 + 1) c.parts = (int)(n / 4096 + 1);
    g->perm = hd__malloc_array(n, sizeof *g->perm);
    g->start = hd__malloc_array(cells + 1, sizeof *g->start);
    g->rep = hd__malloc_array(cells, 3 * sizeof *g->rep);
    c.cell = hd__malloc_array(n, sizeof *c.cell);
    int ok = g->perm && g->start && g->rep && c.cell;
    for (int p = 0; p < c.parts && ok; p++) ok = (c.count[p] = hd__calloc_array(cells, sizeof(uint32_t))) != NULL;
    if (ok) {
        hd__parallel_for(c.parts, (size_t)c.parts, count_task, &c);
        for (int k = 0; k < 3; k++) {
            double t = 0;
            for (int p = 0; p < c.parts; p++) t += c.sum[p][k];
            g->centroid[k] = t / (double)n;
        }
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
            double nan = NAN;
            g->rep[3 * k] = g->rep[3 * k + 1] = g->rep[3 * k + 2] = nan;
        }
        g->start[cells] = sum;
        hd__parallel_for(c.parts, (size_t)c.parts, scatter_task, &c);
    }
    for (int p = 0; p < c.parts; p++) free(c.count[p]);
    free(c.cell);
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

typedef struct {
    const hd__src_t *a;
    size_t na;
    const hd__grid_t *gb;
    hd__max_t *m;
    hd__counts_t *counts; /* per worker */
    uint64_t *culled;     /* per worker */
} pass_ctx;

/* Point i of A: discard it or resolve it exactly.  *bc is the last point of
 * B that discarded something (bc_ok says whether there is one). */
static inline void pass_point(pass_ctx *c, size_t i, double cmax2, const hd__best_t *snap,
                              double bc[3], int *bc_ok, hd__counts_t *n, uint64_t *culled,
                              hd__best_t *snap_out) {
    double a[3];
    hd__src_get(c->a, i, a);
    const double *rep = c->gb->rep + 3 * (size_t)cell_of(c->gb, a);
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
    hd__grid_nearest(c->gb, a, cmax2, tie2, &hit, n);
    memcpy(bc, hit.p, 3 * sizeof *bc);
    *bc_ok = 1;
    if (hit.d2 < cmax2 || hit.d2 <= tie2) return;
    hd__max_offer(c->m, hit.d2, i, hit.j, snap_out);
}

static void pass_task(void *vctx, size_t task, int worker) {
    pass_ctx *c = vctx;
    size_t lo = task * PASS_SLICE, hi = lo + PASS_SLICE < c->na ? lo + PASS_SLICE : c->na;
    hd__best_t snap;
    hd__max_snapshot(c->m, &snap);
    double bc[3] = {0, 0, 0};
    int bc_ok = 0;
    hd__counts_t *n = &c->counts[worker];
    uint64_t *culled = &c->culled[worker];
    for (size_t i = lo; i < hi; i++) {
        double cmax2 = hd__bound_get(&c->m->cmax);
        pass_point(c, i, cmax2, &snap, bc, &bc_ok, n, culled, &snap);
    }
}

int hd__grid_directed(const hd__src_t *a, size_t na, const hd__grid_t *gb, hd__max_t *m,
                      int threads, hd__counts_t *counts, uint64_t *culled, hd_error_t *err) {
    pass_ctx c;
    c.a = a;
    c.na = na;
    c.gb = gb;
    c.m = m;
    size_t tasks = (na + PASS_SLICE - 1) / PASS_SLICE;
    threads = hd__thread_count(threads, tasks);
    c.counts = hd__calloc_array((size_t)threads, sizeof *c.counts);
    c.culled = hd__calloc_array((size_t)threads, sizeof *c.culled);
    if (!c.counts || !c.culled) {
        free(c.counts);
        free(c.culled);
        return hd__err(err, HD_ENOMEM, "out of memory");
    }
    int rc = hd__parallel_for(threads, tasks, pass_task, &c);
    for (int k = 0; k < threads; k++) {
        counts->evals += c.counts[k].evals;
        counts->exact += c.counts[k].exact;
        counts->nodes += c.counts[k].nodes;
        *culled += c.culled[k];
    }
    free(c.counts);
    free(c.culled);
    if (rc != HD_OK) return hd__err(err, rc, "%s", hd_strerror(rc));
    return HD_OK;
}

/* Prime m for h(A,B) from A's own grid: the representatives of A's cells
 * cover the space A occupies evenly, whatever its density, so the ones
 * lying where B is emptiest (B's cells there empty, or nearly) are where
 * the maximum is likely; the PRIME_CELLS of them with the fewest points of
 * B around get exact nearest-neighbour searches in B. */
#define PRIME_CELLS 32

void hd__grid_prime(const hd__grid_t *ga, const hd__grid_t *gb, hd__max_t *m,
                    hd__counts_t *counts) {
    size_t cells = (size_t)1 << (3 * ga->bits);
    size_t pick[PRIME_CELLS];
    double score[PRIME_CELLS];
    int np = 0;
    hd__box_t gbox;
    for (int k = 0; k < 3; k++) {
        gbox.lo[k] = gb->lo[k];
        gbox.hi[k] = gb->lo[k] + gb->w * (double)(1u << gb->bits);
    }
    for (size_t c = 0; c < cells; c++) {
        if (ga->start[c] == ga->start[c + 1]) continue;
        const double *p = ga->rep + 3 * c;
        uint32_t cb = cell_of(gb, p);
        uint32_t count = gb->start[cb + 1] - gb->start[cb];
        /* Higher is emptier: empty cells by their distance to B's box. */
        double sc = count ? 1.0 / (double)count : 2.0 + hd__box_lb2(&gbox, p);
        hd__top_insert(score, pick, &np, PRIME_CELLS, sc, c);
    }
    for (int k = 0; k < np; k++) {
        size_t i = ga->perm[ga->start[pick[k]]];
        hd__hit_t hit;
        hd__grid_nearest(gb, ga->rep + 3 * (size_t)pick[k], 0.0, -1.0, &hit, counts);
        hd__max_offer(m, hit.d2, i, hit.j, NULL);
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
    hd__box_t gbox;
    for (int k = 0; k < 3; k++) {
        gbox.lo[k] = gb->lo[k];
        gbox.hi[k] = gb->lo[k] + gb->w * (double)(1u << gb->bits);
    }
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
            double p[3];
            hd__src_get(a, pick[k], p);
            hd__hit_t hit;
            hd__grid_nearest(gb, p, 0.0, -1.0, &hit, counts);
            hd__max_offer(m, hit.d2, pick[k], hit.j, NULL);
            memcpy(found[nf++], hit.p, sizeof found[0]);
        }
    }
    /* The pass over the sample, as hd__grid_directed runs it. */
    pass_ctx c;
    c.a = a;
    c.na = na;
    c.gb = gb;
    c.m = m;
    hd__counts_t n = {0, 0, 0};
    uint64_t culled = 0;
    hd__best_t snap;
    hd__max_snapshot(m, &snap);
    double bc[3] = {0, 0, 0};
    int bc_ok = 0;
    size_t done = 0;
    for (size_t s = 0; s < ns; s++, done++) {
        double cmax2 = hd__bound_get(&m->cmax);
        pass_point(&c, s * na / ns, cmax2, &snap, bc, &bc_ok, &n, &culled, &snap);
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
