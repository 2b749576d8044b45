/*
 * settle.c -- the band pass with whole nodes settled from bounds
 * (hd__an_band_settled), which percentile.c runs.
 *
 * hd__an_band classifies every asking point against [lo2, hi2] one point at
 * a time.  Here the asking octree is walked from its top: a node whose box
 * q is proven entirely below the band or entirely above it is counted
 * without touching its points; only the leaves (buckets) that no bound
 * settles are open, and their points are classified by hd__an_band on a
 * structure of the open points alone (hd__an_build_sel).  A node is
 *  - below when U < lo2, U the smallest of hd__box_box_ub2(q, n) over the
 *    searched nodes n on the path that always takes the child nearest to
 *    q, and of hd__box_ub2(q, p) over the points p of the searched bucket
 *    that path reaches.  Every node holds a searched point, and for a point
 *    x of q and a searched point p of box n, the computed hd__d2s(x, p) is
 *    at most hd__box_box_ub2(q, n) and, for p itself, at most
 *    hd__box_ub2(q, p): rounded subtraction, the square of a magnitude and
 *    rounded addition are each non-decreasing, and the bounds take on each
 *    axis the largest difference the boxes allow.  So x's nearest squared
 *    distance is at most U < lo2.
 *  - above when no searched point p has hd__box_lb2s(q, p) <= hi2, found
 *    by a search that skips the searched nodes whose hd__box_box_lb2 from q
 *    exceeds hi2: by the same monotonicity, hd__d2s(x, p) is at least
 *    either bound, so every point of q has its nearest squared distance
 *    above hi2.
 * A point is counted once, at the first node of its path (from where the
 * walk starts) that a bound settles, or classified exactly when its bucket
 * stays open, so the counts and the kept values (as a multiset) are
 * hd__an_band's whatever the threads (which only decide where the walk
 * starts).
 *
 * The walk pays off only when bounds settle most points: where a bucket's
 * box is wide next to the distances that decide the band (overlapping
 * sets of similar density) it settles little, and hd__an_band alone is
 * cheaper.  A probe of one asking bucket in SETTLE_PROBE decides: the walk
 * runs when the probed buckets' bounds settle at least SETTLE_WORTH of
 * their points; and when the walk leaves most points open, hd__an_band
 * classifies them all, as a structure of the open points would cost more
 * than it spares.  Only the cost depends on either choice.
 */
#include "nearest/nearest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SETTLE_PROBE 64 /* one asking bucket in SETTLE_PROBE probed */
#define SETTLE_TASKS 8  /* starting nodes per thread, at least, when the walk runs on several */
#define SETTLE_WORTH 0.75 /* the share of the probed points the bounds must settle */

enum { OPEN, BELOW, ABOVE };

static void node_box(const hd__an_t *t, size_t k, hd__box_t *b) {
    for (int d = 0; d < 3; d++) b->lo[d] = t->lo[d][k], b->hi[d] = t->hi[d][k];
}

/* U of the essay: the searched path nearest to q, and its bucket's points. */
static double upper_bound(const hd__an_t *t, const hd__box_t *q) {
    double U = INFINITY;
    size_t k = 0;
    for (;;) {
        hd__box_t b;
        node_box(t, k, &b);
        double u = hd__box_box_ub2(q, &b);
        U = u < U ? u : U;
        if (!t->count[k]) break;
        size_t f = t->first[k], near = f;
        double best = INFINITY;
        for (size_t i = f; i < f + t->count[k]; i++) {
            node_box(t, i, &b);
            double lb = hd__box_box_lb2(q, &b);
            if (lb < best) best = lb, near = i;
        }
        k = near;
    }
    size_t bucket = t->first[k];
    for (size_t i = t->start[bucket]; i < t->stop[bucket]; i++) {
        double p[3] = {t->x[i], t->y[i], t->z[i]};
        double u = hd__box_ub2(q, p);
        U = u < U ? u : U;
    }
    return U;
}

/* 1 when some searched point of node k's subtree has hd__box_lb2s from q
 * at most hi2 (the nearer children first). */
static int reaches(const hd__an_t *t, size_t k, const hd__box_t *q, double hi2) {
    if (!t->count[k]) {
        size_t bucket = t->first[k];
        for (size_t i = t->start[bucket]; i < t->stop[bucket]; i++)
            if (hd__box_lb2s(q, t->x[i], t->y[i], t->z[i]) <= hi2) return 1;
        return 0;
    }
    size_t f = t->first[k];
    int nc = t->count[k], order[8];
    double lb[8];
    for (int i = 0; i < nc; i++) {
        hd__box_t b;
        node_box(t, f + (size_t)i, &b);
        lb[i] = hd__box_box_lb2(q, &b);
        int j = i;
        for (; j > 0 && lb[order[j - 1]] > lb[i]; j--) order[j] = order[j - 1];
        order[j] = i;
    }
    for (int r = 0; r < nc && lb[order[r]] <= hi2; r++)
        if (reaches(t, f + (size_t)order[r], q, hi2)) return 1;
    return 0;
}

/* The class of the asking box q: below, above, or open. */
static int classify(const hd__an_t *t, const hd__box_t *q, double lo2, double hi2) {
    double U = lo2 > 0 || hi2 < INFINITY ? upper_bound(t, q) : INFINITY;
    if (U < lo2) return BELOW;
    if (U <= hi2 || reaches(t, 0, q, hi2)) return OPEN; /* a point within U <= hi2: not above */
    return ABOVE;
}

/* The points of asking node k (its buckets are consecutive). */
static size_t node_points(const hd__an_t *q, size_t k) {
    size_t a = k, b = k;
    while (q->count[a]) a = q->first[a];
    while (q->count[b]) b = q->first[b] + q->count[b] - 1u;
    return q->start[q->first[b] + 1] - q->start[q->first[a]];
}

typedef struct {
    const hd__an_t *q, *t;
    double lo2, hi2;
    const uint32_t *roots; /* the walk's starting nodes */
    uint8_t *open;         /* per asking bucket: 1 when no bound settled it */
    size_t (*count)[2];    /* per worker: points below, above */
} settle_ctx;

static void walk(const settle_ctx *c, size_t k, size_t count[2]) {
    const hd__an_t *q = c->q;
    hd__box_t box;
    node_box(q, k, &box);
    int cls = classify(c->t, &box, c->lo2, c->hi2);
    if (cls != OPEN) count[cls == ABOVE] += node_points(q, k);
    else if (!q->count[k]) c->open[q->first[k]] = 1;
    else
        for (size_t i = q->first[k]; i < q->first[k] + q->count[k]; i++) walk(c, i, count);
}

static void walk_task(void *vctx, size_t task, int worker) {
    const settle_ctx *c = vctx;
    walk(c, c->roots[task], c->count[worker]);
}

/* 1 when the bounds of one asking bucket in SETTLE_PROBE settle at least
 * SETTLE_WORTH of their points. */
static int settle_worth(const settle_ctx *c) {
    const hd__an_t *q = c->q;
    size_t seen = 0, settled = 0;
    for (size_t b = 0; b < q->nb; b += SETTLE_PROBE) {
        size_t m = q->start[b + 1] - q->start[b];
        hd__box_t box;
        node_box(q, q->leaf[b], &box);
        seen += m;
        if (classify(c->t, &box, c->lo2, c->hi2) != OPEN) settled += m;
    }
    return (double)settled >= SETTLE_WORTH * (double)seen;
}

/* The walk's starting nodes: the root, or, for several threads, the
 * nodes of the shallowest levels until there are enough of them (a leaf
 * stays as it is).  *roots is malloc'd; returns their number, 0 when out
 * of memory. */
static size_t walk_roots(const hd__an_t *q, int threads, uint32_t **roots) {
    size_t want = threads > 1 ? (size_t)threads * SETTLE_TASKS : 1, n = 1, cap = want + 8 * want + 8;
    uint32_t *r = hd__malloc_array(cap, sizeof *r), *next = hd__malloc_array(cap, sizeof *next);
    if (!r || !next) {
        free(r), free(next);
        return 0;
    }
    r[0] = 0;
    for (int grew = 1; n < want && grew;) {
        size_t m = 0;
        grew = 0;
        for (size_t i = 0; i < n; i++) {
            if (!q->count[r[i]] || m + 8 > cap) {
                next[m++] = r[i];
                continue;
            }
            for (uint32_t j = q->first[r[i]]; j < q->first[r[i]] + q->count[r[i]]; j++) next[m++] = j;
            grew = 1;
        }
        uint32_t *s = r;
        r = next, next = s, n = m;
    }
    free(next);
    *roots = r;
    return n;
}

/* The m points of the open buckets classified by hd__an_band on a
 * structure of them alone, added to out (whose counts hold the settled
 * points). */
static int band_open(const hd__an_t *q, const hd__an_t *t, const hd_points_t *P, const hd__box_t *keybox,
                     const uint8_t *open, size_t m, double lo2, double hi2, int threads, hd__an_band_t *out,
                     hd_error_t *err) {
    if (!m) return (out->v = hd__malloc_array(1, sizeof *out->v)) ? HD_OK
                                                                    : hd__err(err, HD_ENOMEM, "cannot allocate");
    uint8_t *mark = hd__calloc_array(P->count, 1);
    uint32_t *sel = hd__malloc_array(m, sizeof *sel);
    int rc = mark && sel ? HD_OK : hd__err(err, HD_ENOMEM, "cannot allocate %zu indices", m);
    for (size_t b = 0; rc == HD_OK && b < q->nb; b++)
        if (open[b])
            for (size_t k = q->start[b]; k < q->start[b + 1]; k++) mark[q->idx[k]] = 1;
    size_t k = 0;
    for (size_t i = 0; rc == HD_OK && i < P->count; i++)
        if (mark[i]) sel[k++] = (uint32_t)i;
    hd__an_t one;
    if (rc == HD_OK && (rc = hd__an_build_sel(&one, P, sel, NULL, m, keybox, threads, err)) == HD_OK) {
        hd__an_band_t part;
        rc = hd__an_band(&one, t, lo2, hi2, threads, &part, err);
        hd__an_free(&one);
        if (rc == HD_OK) {
            out->below += part.below, out->above += part.above, out->solo += part.solo;
            out->n = part.n, out->v = part.v;
        }
    }
    free(mark);
    free(sel);
    return rc;
}

int hd__an_band_settled(const hd__an_t *asking, const hd__an_t *searched, const hd_points_t *P,
                        const hd__box_t *keybox, double lo2, double hi2, int threads, hd__an_band_t *out,
                        size_t *settled, hd_error_t *err) {
    memset(out, 0, sizeof *out);
    if (settled) *settled = 0;
    if (asking->n == 0) return hd__an_band(asking, searched, lo2, hi2, threads, out, err);
    settle_ctx c = {asking, searched, lo2, hi2, NULL, NULL, NULL};
    uint32_t *roots = NULL;
    size_t nr = walk_roots(asking, threads, &roots);
    int workers = hd__thread_count(threads, nr ? nr : 1);
    c.roots = roots;
    c.open = hd__calloc_array(asking->nb, 1);
    c.count = hd__calloc_array((size_t)workers, sizeof *c.count);
    int rc = nr && c.open && c.count ? HD_OK : HD_ENOMEM;
    if (rc != HD_OK) {
        rc = hd__err(err, rc, "cannot allocate the settled band's walk");
    } else if (!settle_worth(&c)) {
        rc = hd__an_band(asking, searched, lo2, hi2, threads, out, err);
    } else {
        hd__parallel_for(workers, nr, walk_task, &c);
        size_t m = 0; /* the open points; when they are most, every point by hd__an_band */
        for (size_t b = 0; b < asking->nb; b++)
            if (c.open[b]) m += asking->start[b + 1] - asking->start[b];
        if (2 * m > asking->n) {
            rc = hd__an_band(asking, searched, lo2, hi2, threads, out, err);
        } else {
            for (int w = 0; w < workers; w++) out->below += c.count[w][0], out->above += c.count[w][1];
            if (settled) *settled = out->below + out->above;
            rc = band_open(asking, searched, P, keybox, c.open, m, lo2, hi2, threads, out, err);
        }
    }
    free(roots);
    free(c.open);
    free(c.count);
    if (rc != HD_OK) {
        memset(out, 0, sizeof *out);
        if (settled) *settled = 0;
    }
    return rc;
}
