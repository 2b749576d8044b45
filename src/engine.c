/*
 * engine.c -- the `auto` engine: exact h(A,B) and H(A,B) over the Morton
 * bucket indexes of engine_build.c.
 *
 * The engine combines three of the paper's ideas with an index that is cheap
 * to build.  Both sets are indexed once (engine_build.c); h(A,B) then walks
 * A's tree in Morton order and searches B's tree:
 *  1. A lower bound cmax is primed from a sample of A whose exact nearest
 *     distances are computed first (the paper's AHD, Algorithm 6, line 1).
 *  2. A whole node of A (a bucket or a run of buckets) is discarded when one
 *     point b of B is proven closer than cmax to every point of the node's
 *     box: hd__box_ub2(box, b) < cmax^2, strictly (the paper's CubeToPoints,
 *     Algorithm 4, lines 5-7, applied to A's nodes).  The b tried is the last
 *     point of B that discarded something, which is usually nearby because
 *     A is walked along its curve.
 *  3. Every remaining point a is first tested against that same b, then
 *     searched in B's tree starting from the bucket where the previous search
 *     ended, stopping as soon as some point of B lies strictly within cmax
 *     (EARLYBREAK, Algorithm 2, lines 8-10).  A search that does not stop is
 *     an exact nearest-neighbour search; its result is a candidate for the
 *     maximum and raises cmax.
 * Threads take subtrees of A from a shared counter and share cmax through
 * an atomic.
 *
 * Exactness and the witness.  cmax is always the exact nearest distance of
 * some point of A, so it never exceeds h(A,B).  A point or node is discarded
 * only on a strict inequality d2(a, b) < cmax^2 (or ub2 < cmax^2, which
 * bounds d2(a, b) from above for every a in the box: internal.h), which
 * proves that its nearest distance is strictly less than h(A,B): it can be
 * neither the maximum nor tied with it.  So every point whose nearest
 * distance equals h(A,B) reaches a search that cannot stop early and gets
 * its exact nearest distance and smallest nearest index (engine_search.c);
 * the per-task maxima merge with hd__best_offer, which keeps the smallest
 * index of A on ties.  The result is the brute force's, bit for bit, at any
 * thread count and in any schedule: timing changes only how much is
 * discarded, never what survives to the end.
 */
#include "index.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- one direction ------------------------------------------------------------ */

typedef struct {
    hd__bcache_t cache;   /* gathered buckets of B */
    hd__counts_t counts;
    uint64_t culled;
    char pad[64];
} worker_t;

typedef struct {
    const hd__tree_t *ta, *tb;
    hd__bound_t cmax;
    int task_level;
    hd__best_t *part;
    worker_t *w;
} dir_ctx;

/* The state of one task's walk. */
typedef struct {
    dir_ctx *c;
    worker_t *w;
    hd__best_t best;
    double bc[3];      /* the last point of B that discarded something */
    int have_bc;
    size_t hint;       /* bucket of B where the last search ended */
} walk_t;

static size_t node_points(const hd__tree_t *t, int level, size_t i) {
    size_t first = (i << level) * HD__BUCKET;
    size_t last = ((i + 1) << level) * HD__BUCKET;
    if (last > t->n) last = t->n;
    return last - first;
}

/* Resolve point a (original index ia): discard it, or find its exact
 * nearest distance and offer it. */
static void resolve_point(walk_t *s, const double a[3], size_t ia) {
    dir_ctx *c = s->c;
    double cmax2 = hd__bound_get(&c->cmax);
    if (s->have_bc) {
        s->w->counts.evals++;
        if (hd__d2(a, s->bc) < cmax2) {
            s->w->culled++;
            return;
        }
    }
    hd__hit_t hit;
    hd__tree_nearest(c->tb, &s->w->cache, a, cmax2, s->hint, &hit, &s->w->counts);
    s->hint = hit.bucket;
    memcpy(s->bc, hit.p, sizeof s->bc);
    s->have_bc = 1;
    if (hit.d2 < cmax2) return;
    hd__best_offer(&s->best, hit.d2, ia, hit.j);
    hd__bound_raise(&c->cmax, hit.d2);
}

static void walk_bucket(walk_t *s, size_t bk) {
    const hd__tree_t *ta = s->c->ta;
    size_t first = bk * HD__BUCKET;
    size_t m = ta->n - first < HD__BUCKET ? ta->n - first : HD__BUCKET;
    for (size_t k = 0; k < m; k++) {
        double a[3];
        size_t ia = ta->perm[first + k];
        hd__src_get(&ta->src, ia, a);
        resolve_point(s, a, ia);
    }
}

static void walk_node(walk_t *s, int level, size_t i) {
    const hd__tree_t *ta = s->c->ta;
    if (s->have_bc) {
        double cmax2 = hd__bound_get(&s->c->cmax);
        if (hd__box_ub2(hd__tree_box(ta, level, i), s->bc) < cmax2) {
            s->w->culled += node_points(ta, level, i);
            return;
        }
    }
    s->w->counts.nodes++;
    if (level == 0) {
        walk_bucket(s, i);
        return;
    }
    walk_node(s, level - 1, 2 * i);
    if (2 * i + 1 < ta->count[level - 1]) walk_node(s, level - 1, 2 * i + 1);
}

static void walk_task(void *vctx, size_t task, int worker) {
    dir_ctx *c = vctx;
    walk_t s;
    s.c = c;
    s.w = &c->w[worker];
    hd__best_init(&s.best);
    s.have_bc = 0;
    s.hint = HD__NONE;
    walk_node(&s, c->task_level, task);
    c->part[task] = s.best;
}

/* Prime cmax with the exact nearest distances of a sample of A: points
 * evenly spread along A's curve, and every point of the buckets of A with
 * the largest boxes (sparse regions, where the maximum tends to be). */
#define PRIME_SPREAD 64
#define PRIME_BUCKETS 16

static void prime(dir_ctx *c, hd__best_t *best) {
    const hd__tree_t *ta = c->ta;
    walk_t s;
    s.c = c;
    s.w = &c->w[0];
    hd__best_init(&s.best);
    s.have_bc = 0;
    s.hint = HD__NONE;
    size_t step = ta->n / PRIME_SPREAD + 1;
    for (size_t k = step / 2; k < ta->n; k += step) {
        double a[3];
        size_t ia = ta->perm[k];
        hd__src_get(&ta->src, ia, a);
        s.have_bc = 0;
        resolve_point(&s, a, ia);
    }
    /* The buckets with the largest box diagonals (a small selection). */
    size_t top[PRIME_BUCKETS];
    double size[PRIME_BUCKETS];
    int nt = 0;
    for (size_t b = 0; b < ta->nb; b++) {
        const hd__box_t *x = hd__tree_box(ta, 0, b);
        double d = 0;
        for (int k = 0; k < 3; k++) d += (x->hi[k] - x->lo[k]) * (x->hi[k] - x->lo[k]);
        if (nt < PRIME_BUCKETS || d > size[nt - 1]) {
            int p = nt < PRIME_BUCKETS ? nt++ : PRIME_BUCKETS - 1;
            while (p > 0 && size[p - 1] < d) {
                size[p] = size[p - 1];
                top[p] = top[p - 1];
                p--;
            }
            size[p] = d;
            top[p] = b;
        }
    }
    for (int k = 0; k < nt; k++) {
        s.have_bc = 0;
        walk_bucket(&s, top[k]);
    }
    *best = s.best;
}

/* h(A,B) over built indexes of A and B. */
static int engine_directed(const hd__tree_t *ta, const hd__tree_t *tb, int threads,
                           hd_result_t *out, hd_error_t *err) {
    dir_ctx c;
    memset(&c, 0, sizeof c);
    c.ta = ta;
    c.tb = tb;
    hd__bound_init(&c.cmax, 0.0);
    /* Tasks are subtrees of about 64 buckets (1024 points). */
    c.task_level = ta->levels - 1 < 6 ? ta->levels - 1 : 6;
    size_t tasks = ta->count[c.task_level];
    if (threads < 1) threads = 1;
    c.part = hd__malloc_array(tasks, sizeof *c.part);
    c.w = hd__malloc_array((size_t)threads, sizeof *c.w);
    if (!c.part || !c.w) {
        free(c.part);
        free(c.w);
        return hd__err(err, HD_ENOMEM, "out of memory");
    }
    for (int k = 0; k < threads; k++) {
        hd__bcache_init(&c.w[k].cache);
        memset(&c.w[k].counts, 0, sizeof c.w[k].counts);
        c.w[k].culled = 0;
    }
    hd__best_t best;
    prime(&c, &best);
    int rc = hd__parallel_for(threads, tasks, walk_task, &c);
    if (rc != HD_OK) {
        free(c.part);
        free(c.w);
        return hd__err(err, rc, "%s", hd_strerror(rc));
    }
    for (size_t t = 0; t < tasks; t++) hd__best_offer(&best, c.part[t].d2, c.part[t].i, c.part[t].j);
    memset(&out->stats, 0, sizeof out->stats);
    for (int k = 0; k < threads; k++) {
        out->stats.distance_evals += c.w[k].counts.evals;
        out->stats.nodes_visited += c.w[k].counts.nodes;
        out->stats.points_culled += c.w[k].culled;
    }
    out->distance2 = best.d2;
    out->distance = sqrt(best.d2);
    out->i = best.i;
    out->j = best.j;
    out->algorithm = HD_ALG_AUTO;
    free(c.part);
    free(c.w);
    return HD_OK;
}

/* ---- entry points ---------------------------------------------------------------- */

int hd__engine_trees(const hd__tree_t *ta, const hd__tree_t *tb, int threads, hd_result_t *out,
                     hd_error_t *err) {
    return engine_directed(ta, tb, threads, out, err);
}

static int build_pair(const hd_points_t *A, const hd_points_t *B, int threads, hd__tree_t *ta,
                      hd__tree_t *tb, double *build_seconds, hd_error_t *err) {
    hd__src_t sa, sb;
    hd__src_init(&sa, A, NULL);
    hd__src_init(&sb, B, NULL);
    double t0 = hd__now();
    int rc = hd__tree_build(ta, &sa, A->count, threads, err);
    if (rc) return rc;
    rc = hd__tree_build(tb, &sb, B->count, threads, err);
    if (rc) {
        hd__tree_free(ta);
        return rc;
    }
    *build_seconds = hd__now() - t0;
    return HD_OK;
}

int hd__engine_directed(const hd_points_t *A, const hd_points_t *B, const hd_options_t *opt,
                        hd_result_t *out, hd_error_t *err) {
    size_t n = A->count > B->count ? A->count : B->count;
    int threads = hd__thread_count(opt->threads, n);
    hd__tree_t ta, tb;
    double tbuild;
    double t0 = hd__now();
    int rc = build_pair(A, B, threads, &ta, &tb, &tbuild, err);
    if (rc) return rc;
    rc = engine_directed(&ta, &tb, threads, out, err);
    hd__tree_free(&ta);
    hd__tree_free(&tb);
    out->seconds = hd__now() - t0;
    return rc;
}

int hd__engine_hausdorff(const hd_points_t *A, const hd_points_t *B, const hd_options_t *opt,
                         hd_symmetric_t *out, hd_error_t *err) {
    size_t n = A->count > B->count ? A->count : B->count;
    int threads = hd__thread_count(opt->threads, n);
    hd__tree_t ta, tb;
    double tbuild;
    int rc = build_pair(A, B, threads, &ta, &tb, &tbuild, err);
    if (rc) return rc;
    double t0 = hd__now();
    rc = engine_directed(&ta, &tb, threads, &out->ab, err);
    double t1 = hd__now();
    if (rc == HD_OK) rc = engine_directed(&tb, &ta, threads, &out->ba, err);
    double t2 = hd__now();
    /* Each direction reports its own walk plus half of the shared build. */
    out->ab.seconds = (t1 - t0) + tbuild / 2;
    out->ba.seconds = (t2 - t1) + tbuild / 2;
    hd__tree_free(&ta);
    hd__tree_free(&tb);
    return rc;
}

/* The packed-doubles form used by hd__run_directed (hd_directed with the
 * packed job, e.g. from other modules). */
int hd__engine(const hd__job_t *job, hd_result_t *out, hd_error_t *err) {
    hd_points_t A = hd_points_f64(job->a, job->na), B = hd_points_f64(job->b, job->nb);
    return hd__engine_directed(&A, &B, job->opt, out, err);
}
