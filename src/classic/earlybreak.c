/*
 * earlybreak.c -- Algorithm 2 (EARLYBREAK, Taha & Hanbury 2015), with the
 * exclusion of the points of A that coincide with points of B.
 *
 * The paper's Algorithm 2, as corrected in Taha and Hanbury's note:
 *   lines 1-3   cmax <- 0; A and B are visited in random orders;
 *   lines 4-15  for each x, scan B keeping cmin, but stop as soon as some
 *               d(x, y) < cmax: then x cannot raise cmax, and line 9
 *               (cmin <- 0) makes sure the partial minimum of the scan so far
 *               is not offered as if it were x's nearest-neighbour distance.
 *               Here a cut-short point simply offers nothing, which is the
 *               same thing.
 * The randomness comes from hd__rng seeded with opt->seed: A's order is
 * drawn first, then B's, so a seed fixes the whole run.
 *
 * Exactness.  Every distance is hd__d2 and every comparison is between such
 * values, so the maximum is the brute force's to the bit.  The witness must
 * not depend on the random order, so the break is strict: a point is cut
 * short when d < cmax (its nn distance is then strictly below the answer)
 * or when d equals a value already found at a smaller index of A (it could
 * tie the answer but not win the tie).  A point that completes its scan
 * keeps the smallest index j of B at its minimum, whatever the order of B.
 *
 * The scan (hd__scan_break, shared with NOHD's Algorithm 5).  Whether a
 * scan is cut short does not depend on the order in which B is read, so it
 * evaluates SCAN_BLOCK distances at a time (a loop the compiler vectorises)
 * and then tests the block: the decision and the minimum are those of the
 * point-by-point loop; only distance_evals, which counts what was
 * evaluated, grows by the rest of the last block.
 *
 * Excluding common points (paper, Section 3.3, Fig. 1).  Taha and Hanbury
 * intersect voxel grids; on general point sets a grid would merge distinct
 * points, so the common points are found exactly: B's points inside A's box
 * go into a hash set keyed by their coordinates' bits (with -0.0 read as
 * 0.0, since hd__d2 puts them at distance 0) and compared with ==, and each
 * point of A inside the box of those points is looked up.  A common point
 * is at distance 0 from B and cannot raise the maximum unless
 * the answer is 0; in that case every point of A is at distance 0 and the
 * witness is A[0] with the first point of B at distance 0 from it, which
 * hd__earlybreak puts back at the end.
 *
 * Threads: the visiting order is cut into slices run by hd__parallel_for;
 * cmax is shared through an hd__bound_t (a stale value is only a weaker
 * bound) and the slices' results merge with hd__best_offer.  Because the
 * breaks are decided by the rules above, the result and the witness are the
 * same at any thread count; only the counters may differ.
 */
#include "classic/classic_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define EB_SLICE 1024

/* The exclusion table: an open-addressing hash set of B's points (those in
 * A's box), keyed by the bits of their coordinates with -0.0 turned into
 * 0.0 (x + 0.0 does that), so that two points hash alike exactly when their
 * coordinates compare equal.  slot[h] is 1 + an index of B, or 0 when empty;
 * the capacity is a power of two at least twice the number of points. */
typedef struct {
    size_t *slot;
    size_t mask;
    const double *b;
} table_t;

static uint64_t mix(uint64_t h, double v) {
    union { double d; uint64_t u; } c;
    c.d = v + 0.0;
    h ^= c.u;
    h *= 0xbf58476d1ce4e5b9ULL;
    return h ^ (h >> 31);
}

static size_t hash_point(const double *p, size_t mask) {
    uint64_t h = mix(mix(mix(0x9e3779b97f4a7c15ULL, p[0]), p[1]), p[2]);
    h *= 0x94d049bb133111ebULL;
    return (size_t)(h ^ (h >> 29)) & mask;
}

/* 1 when p equals (coordinate by coordinate) a point of the table. */
static int in_table(const table_t *t, const double *p) {
    for (size_t h = hash_point(p, t->mask);; h = (h + 1) & t->mask) {
        size_t s = t->slot[h];
        if (!s) return 0;
        const double *q = t->b + 3 * (s - 1);
        if (q[0] == p[0] && q[1] == p[1] && q[2] == p[2]) return 1;
    }
}

#define SCAN_BLOCK 16

int hd__scan_break(const double *x, const double *pts, const size_t *idx, size_t n,
                   double bound, double tie, double *d2, size_t *j, uint64_t *evals) {
    double cmin = INFINITY, dv[SCAN_BLOCK];
    size_t cj = HD__NONE;
    for (size_t k0 = 0; k0 < n; k0 += SCAN_BLOCK) {
        size_t m = n - k0 < SCAN_BLOCK ? n - k0 : SCAN_BLOCK;
        const double *q = pts + 3 * k0;
        for (size_t k = 0; k < m; k++) dv[k] = hd__d2(x, q + 3 * k);
        *evals += m;
        double bm = INFINITY;
        for (size_t k = 0; k < m; k++) bm = dv[k] < bm ? dv[k] : bm;
        if (bm < bound) return 0;
        if (tie >= bm)
            for (size_t k = 0; k < m; k++)
                if (dv[k] == tie) return 0;
        if (bm <= cmin)
            for (size_t k = 0; k < m; k++) {
                if (dv[k] != bm) continue;
                size_t jj = idx ? idx[k0 + k] : k0 + k;
                if (bm < cmin || jj < cj) {
                    cmin = bm;
                    cj = jj;
                }
            }
    }
    *d2 = cmin;
    *j = cj;
    return 1;
}

static int inside(const hd__box_t *b, const double *p) {
    for (int k = 0; k < 3; k++)
        if (p[k] < b->lo[k] || p[k] > b->hi[k]) return 0;
    return 1;
}

typedef struct {
    const hd__job_t *job;
    const size_t *order;
    size_t n_order;
    const double *br;     /* B in scan order */
    const size_t *bidx;   /* original index of each point of br */
    const table_t *table; /* common-point table, or NULL */
    hd__box_t table_box;  /* box of the points in the table */
    hd__bound_t cmax;
    hd__best_t *part;  /* one per task */
    uint64_t *evals;   /* one per worker */
    uint64_t *culled;  /* one per worker */
} eb_ctx;

static void eb_task(void *vctx, size_t task, int worker) {
    eb_ctx *c = vctx;
    const double *a = c->job->a, *br = c->br;
    const size_t *bidx = c->bidx;
    size_t nb = c->job->nb;
    size_t lo = task * EB_SLICE, hi = lo + EB_SLICE;
    if (hi > c->n_order) hi = c->n_order;
    hd__best_t best;
    hd__best_init(&best);
    uint64_t evals = 0, culled = 0;
    for (size_t t = lo; t < hi; t++) {
        size_t i = c->order[t];
        const double *x = a + 3 * i;
        if (c->table && inside(&c->table_box, x) && in_table(c->table, x)) {
            culled++;
            continue;
        }
        /* Line 8 (d < cmax) with the shared cmax; a tie with a value
         * found at a smaller index cuts short too. */
        double tie = best.i < i ? best.d2 : -1.0, cmin;
        size_t cj;
        if (hd__scan_break(x, br, bidx, nb, hd__bound_get(&c->cmax), tie, &cmin, &cj, &evals)) {
            hd__best_offer(&best, cmin, i, cj); /* line 14 */
            hd__bound_raise(&c->cmax, cmin);
        } /* else line 9: cmin <- 0, the point offers nothing */
    }
    c->part[task] = best;
    c->evals[worker] += evals;
    c->culled[worker] += culled;
}

/* The table of B's points that lie in A's box (only they can equal a point
 * of A); t->slot stays NULL when there are none. */
static int common_table(const hd__job_t *job, table_t *t, hd__box_t *box) {
    t->slot = NULL;
    t->b = job->b;
    size_t m = 0;
    for (size_t j = 0; j < job->nb; j++) {
        const double *q = job->b + 3 * j;
        if (!inside(&job->box_a, q)) continue;
        if (m == 0) {
            for (int c = 0; c < 3; c++) box->lo[c] = box->hi[c] = q[c];
        } else {
            for (int c = 0; c < 3; c++) {
                if (q[c] < box->lo[c]) box->lo[c] = q[c];
                if (q[c] > box->hi[c]) box->hi[c] = q[c];
            }
        }
        m++;
    }
    if (m == 0) return HD_OK;
    size_t cap = 16;
    while (cap < 2 * m) {
        if (hd__mul_overflows(cap, 2)) return HD_ENOMEM;
        cap *= 2;
    }
    t->slot = hd__calloc_array(cap, sizeof *t->slot);
    if (!t->slot) return HD_ENOMEM;
    t->mask = cap - 1;
    for (size_t j = 0; j < job->nb; j++) {
        const double *q = job->b + 3 * j;
        if (!inside(&job->box_a, q) || in_table(t, q)) continue;
        size_t h = hash_point(q, t->mask);
        while (t->slot[h]) h = (h + 1) & t->mask;
        t->slot[h] = j + 1;
    }
    return HD_OK;
}

int hd__eb_loop(const hd__job_t *job, const size_t *order, size_t n_order,
                int exclude_common, hd__rng_t *rng, hd__best_t *best,
                hd_stats_t *stats, hd_error_t *err) {
    hd__best_init(best);
    size_t nb = job->nb, tasks = (n_order + EB_SLICE - 1) / EB_SLICE;
    eb_ctx c;
    memset(&c, 0, sizeof c);
    c.job = job;
    c.order = order;
    c.n_order = n_order;
    size_t *bidx = hd__malloc_array(nb, sizeof *bidx);
    double *br = hd__malloc_array(nb, 3 * sizeof(double));
    c.part = hd__malloc_array(tasks, sizeof *c.part);
    c.evals = hd__calloc_array((size_t)job->threads, sizeof *c.evals);
    c.culled = hd__calloc_array((size_t)job->threads, sizeof *c.culled);
    table_t table = {NULL, 0, NULL};
    int rc = HD_ENOMEM;
    if (bidx && br && c.part && c.evals && c.culled) {
        /* Line 3: B_r <- randomize(B). */
        hd__rng_permute(rng, bidx, nb);
        for (size_t k = 0; k < nb; k++) memcpy(br + 3 * k, job->b + 3 * bidx[k], 3 * sizeof(double));
        c.br = br;
        c.bidx = bidx;
        rc = exclude_common ? common_table(job, &table, &c.table_box) : HD_OK;
    }
    if (rc == HD_OK) {
        c.table = table.slot ? &table : NULL;
        hd__bound_init(&c.cmax, 0.0); /* line 1: cmax <- 0 */
        hd__parallel_for(job->threads, tasks, eb_task, &c);
    }
    if (rc == HD_OK) {
        hd__best_merge(best, c.part, tasks);
        for (int w = 0; w < job->threads; w++) {
            stats->distance_evals += c.evals[w];
            stats->points_culled += c.culled[w];
        }
    } else {
        hd__err(err, rc, "earlybreak: %s", hd_strerror(rc));
    }
    free(table.slot);
    free(bidx);
    free(br);
    free(c.part);
    free(c.evals);
    free(c.culled);
    return rc;
}

int hd__earlybreak(const hd__job_t *job, hd_result_t *out, hd_error_t *err) {
    hd__rng_t rng;
    hd__rng_seed(&rng, job->opt->seed);
    size_t *order = hd__malloc_array(job->na, sizeof *order);
    if (!order) return hd__err(err, HD_ENOMEM, "earlybreak: out of memory for %zu points", job->na);
    hd__rng_permute(&rng, order, job->na); /* line 2: A_r <- randomize(A) */
    hd__best_t best;
    int rc = hd__eb_loop(job, order, job->na, job->opt->exclude_common, &rng, &best, &out->stats, err);
    free(order);
    if (rc != HD_OK) return rc;
    if (best.i == HD__NONE || best.d2 <= 0.0) {
        /* Every point of A is at distance 0 from B (all were common, or the
         * largest distance found is 0): the witness is A[0]. */
        best.d2 = 0.0;
        best.i = 0;
        best.j = hd__first_at(job->a, job->b, job->nb, 0.0, &out->stats.distance_evals);
    }
    hd__best_store(&best, out);
    return HD_OK;
}
