/*
 * cells.c -- percentiles of far-apart sets from a uniform grid's cell
 * bounds, without the two structures of every point (hd__percentile_cells,
 * which hd_hausdorff_percentile tries first).
 *
 * Each set's points are grouped by the cell of a uniform grid of
 * CELLS_AXIS cubic cells along the longest axis of the key box, each
 * occupied cell keeping the exact box of its points; cells are grouped in
 * superblocks of 2^CELLS_SB cells a side, each keeping the union of its
 * cells' boxes.  For an asking cell c (box q) and the searched cells e:
 *  - U(c) = min over visited e of hd__box_box_ub2(q, e): every cell holds a
 *    point p, and for x in q the computed hd__d2s(x, p) is at most that
 *    bound (settle.c's monotonicity argument), so x's nearest squared
 *    distance is at most U(c) whatever cells are visited;
 *  - L(c) = min over every e of hd__box_box_lb2(q, e), never above any
 *    computed hd__d2s(x, p), p in e.  A superblock's bound is at most each
 *    of its cells' (the union's gap is never wider on an axis), so the
 *    superblocks are visited by increasing bound until one is at least the
 *    L found: the others cannot lower it.
 * Against a band [lo2, hi2]: a cell with U < lo2 counts its points below,
 * one with L > hi2 above; the points of the other (open) cells are
 * classified by hd__an_band on a structure of them alone searching a
 * structure of the searched cells e with hd__box_box_lb2(q, e) <= U(c) for
 * some open c.  Those hold every open point's nearest point: its squared
 * distance d2 is at most U(c), and the cell e* holding a point p* at d2
 * has hd__box_box_lb2(q, e*) <= d2 <= U(c).  So each open point's d2 is
 * its d2 against the whole set, and the counts and the kept values (as a
 * multiset) are hd__an_band's on the whole sets.  The samples take their
 * exact squared distances the same way, with the band [0, +inf] (every
 * sampled cell open).
 *
 * It pays only when most points lie in cells whose range of distances is
 * narrow next to the distances themselves (sets far apart, as issue 39's
 * case b; docs/benchmarks.md, "Sets far apart"): it runs only when the two
 * sets' boxes lie apart, and then only when the probed cells (one in
 * CELLS_PROBE) with U - L at most CELLS_NARROW L hold CELLS_WORTH of the
 * probed points, in both directions.  Only the cost depends on the gate.
 */
#include "nearest/nearest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CELLS_AXIS 32     /* cells along the longest axis of the key box */
#define CELLS_SB 2        /* a superblock holds 2^CELLS_SB cells a side */
#define CELLS_NARROW 0.25 /* a cell is narrow when U - L is at most this share of L */
#define CELLS_WORTH 0.9   /* the share of the points in narrow cells, both directions, the path needs */
#define CELLS_PROBE 16    /* one cell in CELLS_PROBE probed for the gate */

typedef struct {
    size_t n, nc, nsb;
    uint32_t *of;        /* per point: its cell */
    uint32_t *cnt;       /* per cell: its points */
    hd__box_t *box;      /* per cell: the exact box of its points */
    hd__box_t *sbox;     /* per superblock: the union of its cells' boxes */
    uint32_t *sstart;    /* nsb + 1: superblock s holds cells scell[sstart[s] .. sstart[s + 1]) */
    uint32_t *scell;
} cells_t;

typedef struct {
    double lo[3], inv, top[3]; /* top[k] = dim[k] - 1 */
    int dim[3];
} geom_t;

static void cells_free(cells_t *c) {
    free(c->of), free(c->cnt), free(c->box), free(c->sbox), free(c->sstart), free(c->scell);
    memset(c, 0, sizeof *c);
}

/* The cell along axis k of a coordinate v, clamped to the grid (the
 * points lie in the key box; the clamp keeps the conversion defined
 * whatever the rounding). */
static inline uint32_t axis_cell(const geom_t *g, int k, double v) {
    double f = (v - g->lo[k]) * g->inv;
    f = f > 0 ? f : 0;
    f = f < g->top[k] ? f : g->top[k];
    return (uint32_t)f;
}

/* The cells of P on g: numbered by first occupation, boxes exact. */
static int cells_build(cells_t *c, const hd_points_t *P, const geom_t *g, hd_error_t *err) {
    hd__src_t src;
    hd__src_init(&src, P, NULL);
    size_t dense = (size_t)g->dim[0] * (size_t)g->dim[1] * (size_t)g->dim[2];
    int sd[3];
    for (int k = 0; k < 3; k++) sd[k] = ((g->dim[k] - 1) >> CELLS_SB) + 1;
    size_t sdense = (size_t)sd[0] * (size_t)sd[1] * (size_t)sd[2];
    memset(c, 0, sizeof *c);
    c->n = P->count;
    size_t cap = P->count < dense ? P->count : dense; /* occupied cells at most */
    uint32_t *map = hd__malloc_array(dense, sizeof *map), *smap = hd__malloc_array(sdense, sizeof *smap);
    uint32_t *csb = hd__malloc_array(cap, sizeof *csb);
    c->of = hd__malloc_array(P->count, sizeof *c->of);
    c->box = hd__malloc_array(cap, sizeof *c->box);
    c->cnt = hd__calloc_array(cap, sizeof *c->cnt);
    c->sbox = hd__malloc_array(cap < sdense ? cap : sdense, sizeof *c->sbox);
    int rc = map && smap && csb && c->of && c->box && c->cnt && c->sbox ? HD_OK : HD_ENOMEM;
    if (rc == HD_OK) {
        memset(map, 0xff, dense * sizeof *map);
        memset(smap, 0xff, sdense * sizeof *smap);
        const double *f64 = src.kind == HD__SRC_F64 ? (const double *)(const void *)src.base : NULL;
        uint32_t *of = c->of, *cnt = c->cnt, *sb = csb;
        hd__box_t *box = c->box;
        size_t nc = 0, nsb = 0, d1 = (size_t)g->dim[1], d2 = (size_t)g->dim[2];
        for (size_t i = 0; i < P->count; i++) {
            double p[3];
            if (f64) p[0] = f64[3 * i], p[1] = f64[3 * i + 1], p[2] = f64[3 * i + 2];
            else hd__src_get(&src, i, p);
            uint32_t x = axis_cell(g, 0, p[0]), y = axis_cell(g, 1, p[1]), z = axis_cell(g, 2, p[2]);
            size_t at = ((size_t)x * d1 + y) * d2 + z;
            uint32_t k = map[at];
            if (k == UINT32_MAX) {
                k = map[at] = (uint32_t)nc++;
                size_t sat = ((size_t)(x >> CELLS_SB) * (size_t)sd[1] + (y >> CELLS_SB)) * (size_t)sd[2] +
                             (z >> CELLS_SB);
                if (smap[sat] == UINT32_MAX) smap[sat] = (uint32_t)nsb++;
                sb[k] = smap[sat];
                for (int d = 0; d < 3; d++) box[k].lo[d] = box[k].hi[d] = p[d];
            }
            of[i] = k;
            cnt[k]++;
            hd__box_t *b = &box[k];
            for (int d = 0; d < 3; d++) {
                b->lo[d] = p[d] < b->lo[d] ? p[d] : b->lo[d];
                b->hi[d] = p[d] > b->hi[d] ? p[d] : b->hi[d];
            }
        }
        c->nc = nc, c->nsb = nsb;
        c->sstart = hd__calloc_array(c->nsb + 1, sizeof *c->sstart);
        c->scell = hd__malloc_array(c->nc ? c->nc : 1, sizeof *c->scell);
        rc = c->sstart && c->scell ? HD_OK : HD_ENOMEM;
    }
    if (rc == HD_OK) { /* the superblocks' cells, by a counting sort */
        for (size_t k = 0; k < c->nc; k++) c->sstart[csb[k] + 1]++;
        for (size_t s = 0; s < c->nsb; s++) c->sstart[s + 1] += c->sstart[s];
        for (size_t s = 0; s < c->nsb; s++) c->sbox[s] = c->box[0], c->sbox[s].lo[0] = INFINITY;
        uint32_t *fill = map; /* reused: dense >= nsb */
        memcpy(fill, c->sstart, c->nsb * sizeof *fill);
        for (size_t k = 0; k < c->nc; k++) {
            uint32_t s = csb[k];
            c->scell[fill[s]++] = (uint32_t)k;
            if (c->sbox[s].lo[0] == INFINITY) c->sbox[s] = c->box[k];
            else hd__box_merge(&c->sbox[s], &c->box[k]);
        }
    }
    free(map), free(smap), free(csb);
    if (rc != HD_OK) {
        cells_free(c);
        return hd__err(err, rc, "cannot allocate the cells of %zu points", P->count);
    }
    return HD_OK;
}

/* U and L of the essay for the box q against the searched cells t; sb:
 * t->nsb entries of scratch.  The superblocks are taken by increasing
 * bound, the smallest left each time (they are few). */
static void cell_bounds(const cells_t *t, const hd__box_t *q, double *sb, double *U, double *L) {
    for (size_t s = 0; s < t->nsb; s++) sb[s] = hd__box_box_lb2(q, &t->sbox[s]);
    double u = INFINITY, l = INFINITY;
    for (;;) {
        size_t at = 0;
        for (size_t s = 1; s < t->nsb; s++) at = sb[s] < sb[at] ? s : at;
        if (!(sb[at] < l)) break; /* the rest cannot lower L (a visited one is +inf) */
        sb[at] = INFINITY;
        for (uint32_t j = t->sstart[at]; j < t->sstart[at + 1]; j++) {
            double lb = hd__box_box_lb2(q, &t->box[t->scell[j]]), ub = hd__box_box_ub2(q, &t->box[t->scell[j]]);
            l = lb < l ? lb : l;
            u = ub < u ? ub : u;
        }
    }
    *U = u, *L = l;
}

/* Marks (need[e] = 1) the searched cells e with hd__box_box_lb2(q, e) <= U. */
static void mark_near(const cells_t *t, const hd__box_t *q, double U, uint8_t *need) {
    for (size_t s = 0; s < t->nsb; s++) {
        if (hd__box_box_lb2(q, &t->sbox[s]) > U) continue;
        for (uint32_t j = t->sstart[s]; j < t->sstart[s + 1]; j++)
            if (hd__box_box_lb2(q, &t->box[t->scell[j]]) <= U) need[t->scell[j]] = 1;
    }
}

/* One direction: the asking cells q, their bounds against t. */
typedef struct {
    const cells_t *q, *t;
    const hd_points_t *P, *Q;
    double *U, *L;
} dir_t;

static int dir_bounds(dir_t *d, hd_error_t *err) {
    d->U = hd__malloc_array(d->q->nc ? d->q->nc : 1, sizeof *d->U);
    d->L = hd__malloc_array(d->q->nc ? d->q->nc : 1, sizeof *d->L);
    double *sb = hd__malloc_array(d->t->nsb ? d->t->nsb : 1, sizeof *sb);
    if (!d->U || !d->L || !sb) {
        free(sb);
        return hd__err(err, HD_ENOMEM, "cannot allocate the bounds of %zu cells", d->q->nc);
    }
    for (size_t k = 0; k < d->q->nc; k++) cell_bounds(d->t, &d->q->box[k], sb, &d->U[k], &d->L[k]);
    free(sb);
    return HD_OK;
}

/* 1 when the probed cells (one in CELLS_PROBE) that are narrow (U - L at
 * most CELLS_NARROW L) hold CELLS_WORTH of the probed points. */
static int narrow_enough(const cells_t *q, const cells_t *t) {
    double *sb = hd__malloc_array(t->nsb ? t->nsb : 1, sizeof *sb);
    if (!sb) return 0;
    size_t seen = 0, narrow = 0;
    for (size_t k = 0; k < q->nc; k += CELLS_PROBE) {
        double U, L;
        cell_bounds(t, &q->box[k], sb, &U, &L);
        seen += q->cnt[k];
        narrow += U - L <= CELLS_NARROW * L ? q->cnt[k] : 0;
    }
    free(sb);
    return (double)narrow >= CELLS_WORTH * (double)seen;
}

/* The band pass of direction d over the points sel[0..m) of P (all when
 * sel is NULL): counts from the cells' bounds, the open points by
 * hd__an_band (the essay). */
static int dir_band(const dir_t *d, const uint32_t *sel, size_t m, const hd__box_t *keybox, double lo2, double hi2,
                    int threads, hd__an_band_t *out, hd_error_t *err) {
    const cells_t *q = d->q, *t = d->t;
    memset(out, 0, sizeof *out);
    size_t count = sel ? m : q->n, nopen = 0, nneed = 0;
    uint8_t *cls = hd__malloc_array(q->nc ? q->nc : 1, 1), *need = hd__calloc_array(t->nc ? t->nc : 1, 1);
    uint32_t *open = hd__malloc_array(count ? count : 1, sizeof *open);
    uint32_t *tsel = hd__malloc_array(t->n ? t->n : 1, sizeof *tsel);
    int rc = cls && need && open && tsel ? HD_OK : hd__err(err, HD_ENOMEM, "cannot allocate a cells pass");
    for (size_t k = 0; rc == HD_OK && k < q->nc; k++) cls[k] = d->U[k] < lo2 ? 1 : d->L[k] > hi2 ? 2 : 0;
    for (size_t r = 0; rc == HD_OK && r < count; r++) {
        uint32_t i = sel ? sel[r] : (uint32_t)r, k = q->of[i];
        if (cls[k] == 1) out->below++;
        else if (cls[k] == 2) out->above++;
        else {
            open[nopen++] = i;
            if (cls[k] == 0) mark_near(t, &q->box[k], d->U[k], need), cls[k] = 3; /* marked once */
        }
    }
    for (size_t j = 0; rc == HD_OK && j < t->n; j++)
        if (need[t->of[j]]) tsel[nneed++] = (uint32_t)j;
    if (nopen && !nneed) /* not reached (the cell giving U is marked); the whole set is always right */
        for (size_t j = 0; j < t->n; j++) tsel[nneed++] = (uint32_t)j;
    if (rc == HD_OK && nopen) {
        hd__an_t a, b;
        hd__an_band_t part;
        if ((rc = hd__an_build_sel(&a, d->P, open, NULL, nopen, keybox, threads, err)) == HD_OK) {
            if ((rc = hd__an_build_sel(&b, d->Q, tsel, NULL, nneed, keybox, threads, err)) == HD_OK) {
                rc = hd__an_band(&a, &b, lo2, hi2, threads, &part, err);
                hd__an_free(&b);
            }
            hd__an_free(&a);
        }
        if (rc == HD_OK) out->below += part.below, out->above += part.above, out->n = part.n, out->v = part.v;
    } else if (rc == HD_OK && !(out->v = hd__malloc_array(1, sizeof *out->v))) {
        rc = hd__err(err, HD_ENOMEM, "cannot allocate");
    }
    free(cls), free(need), free(open), free(tsel);
    if (rc != HD_OK) memset(out, 0, sizeof *out);
    return rc;
}

typedef struct {
    dir_t dir[2];
    const hd__box_t *keybox;
    int threads;
} cells_src_t;

static int src_band(void *ctx, int d, double lo2, double hi2, hd__an_band_t *out, hd_error_t *err) {
    cells_src_t *c = ctx;
    return dir_band(&c->dir[d], NULL, 0, c->keybox, lo2, hi2, c->threads, out, err);
}

static int src_sample(void *ctx, int d, const uint32_t *sel, size_t m, hd__an_band_t *out, hd_error_t *err) {
    cells_src_t *c = ctx;
    return dir_band(&c->dir[d], sel, m, c->keybox, 0.0, INFINITY, c->threads, out, err);
}

int hd__percentile_cells(const hd_points_t *A, const hd_points_t *B, const hd__box_t *box_a, const hd__box_t *box_b,
                         const hd__box_t *keybox, int threads, double p, hd_percentile_t *out, int *done,
                         hd_error_t *err) {
    *done = 0;
    if (!(hd__box_box_lb2(box_a, box_b) > 0)) return HD_OK; /* the sets' boxes overlap or touch */
    double ext = 0;
    for (int k = 0; k < 3; k++) ext = keybox->hi[k] - keybox->lo[k] > ext ? keybox->hi[k] - keybox->lo[k] : ext;
    if (!(ext > 0) || !isfinite(ext) || A->count < 2 || B->count < 2) return HD_OK;
    geom_t g;
    g.inv = CELLS_AXIS / ext;
    if (!isfinite(g.inv)) return HD_OK;
    for (int k = 0; k < 3; k++) {
        double n = floor((keybox->hi[k] - keybox->lo[k]) * g.inv) + 1;
        g.dim[k] = n < CELLS_AXIS ? (int)n : CELLS_AXIS;
        g.lo[k] = keybox->lo[k], g.top[k] = (double)(g.dim[k] - 1);
    }
    cells_t ca, cb;
    int rc = cells_build(&ca, A, &g, err);
    if (rc) return rc;
    if ((rc = cells_build(&cb, B, &g, err))) {
        cells_free(&ca);
        return rc;
    }
    cells_src_t c = {{{&ca, &cb, A, B, NULL, NULL}, {&cb, &ca, B, A, NULL, NULL}}, keybox, threads};
    if (narrow_enough(&ca, &cb) && narrow_enough(&cb, &ca)) {
        for (int d = 0; d < 2 && rc == HD_OK; d++) rc = dir_bounds(&c.dir[d], err);
        hd__pct_src_t src = {src_sample, src_band, &c};
        if (rc == HD_OK) rc = hd__percentile_run(&src, A->count, B->count, p, out, err);
        *done = rc == HD_OK;
    }
    for (int d = 0; d < 2; d++) free(c.dir[d].U), free(c.dir[d].L);
    cells_free(&ca);
    cells_free(&cb);
    return rc;
}
