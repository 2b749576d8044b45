/*
 * index.c -- the public reusable index of B (hd_index_*): build once, query
 * many times, with an optional transform of the query points.
 *
 * The index is the exact kd-tree of kdtree.c over a copy of B, so it keeps
 * no pointer into the caller's memory after hd_index_build returns (the
 * header allows borrowing; this version does not need to).  It is immutable
 * once built: queries only read it, so any number of threads may query it at
 * once.
 *
 * Queries transform each point of A (or Q) with hd__transform_apply, in the
 * documented order, and check that the transformed point is finite and
 * within HD_MAX_COORD, since a transform can carry a valid point out of
 * range.  Work over A is cut into slices run by hd__parallel_for.
 *
 * hd_index_directed computes h(T(A), B) as NAIVEHDD (paper, Algorithm 1)
 * does, with EARLYBREAK's observation (Algorithm 2, line 7: break as soon as
 * cmin < cmax) moved into the tree search: the search for a point a stops as
 * soon as it meets a point of B strictly closer than the current maximum
 * cmax, which all threads share through an atomic.  That is exact and keeps
 * the canonical witness at any thread count: cmax never exceeds the final
 * maximum, so a point whose nearest distance equals or exceeds the final
 * maximum never meets a point strictly closer than cmax, and its search
 * always completes with the exact distance and the smallest nearest index;
 * the slices then merge with hd__best_offer (larger distance, then smaller
 * i).
 */
#include "kdtree.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

struct hd_index {
    hd__kd_t kd;
};

#define INDEX_SLICE 1024

int hd_index_build(const hd_points_t *B, const hd_options_t *opt, hd_index_t **out,
                   hd_error_t *err) {
    hd__err_clear(err);
    if (!out) return hd__err(err, HD_EINVAL, "index pointer is NULL");
    *out = NULL;
    if (opt && opt->threads < 0)
        return hd__err(err, HD_EINVAL, "threads must be 0 (every core) or positive, not %d",
                       opt->threads);
    int rc = hd__points_check(B, "B", NULL, err);
    if (rc) return rc;
    hd_index_t *idx = calloc(1, sizeof *idx);
    if (!idx) return hd__err(err, HD_ENOMEM, "cannot allocate an index");
    int threads = hd__thread_count(opt ? opt->threads : 0, B->count);
    rc = hd__kd_build(&idx->kd, B, threads, err);
    if (rc) {
        free(idx);
        return rc;
    }
    *out = idx;
    return HD_OK;
}

void hd_index_free(hd_index_t *idx) {
    if (!idx) return;
    hd__kd_free(&idx->kd);
    free(idx);
}

size_t hd_index_count(const hd_index_t *idx) { return idx ? idx->kd.n : 0; }

size_t hd_index_memory(const hd_index_t *idx) {
    return idx ? sizeof *idx + hd__kd_memory(&idx->kd) : 0;
}

/* ---- shared by both queries -------------------------------------------- */

typedef struct {
    const hd_index_t *idx;
    const hd_points_t *q;
    const hd_transform_t *T;
    size_t n;
    /* directed */
    _Atomic uint64_t cmax_bits; /* bits of a non-negative double */
    hd__best_t *part;
    /* nearest */
    double *dist;
    size_t *nearest;
    /* both */
    size_t *bad;            /* per slice: first point out of range, or NONE */
    hd__kdcount_t *count;   /* per worker */
    int threads;
} query_ctx;

/* Point k of the query, transformed; 0 when the result is not a valid
 * coordinate triple (non-finite or beyond HD_MAX_COORD). */
static int query_point(const query_ctx *c, size_t k, double p[3]) {
    if (!c->T) {
        hd_points_get(c->q, k, p);
        return 1;
    }
    double raw[3];
    hd_points_get(c->q, k, raw);
    hd__transform_apply(c->T, raw, p);
    for (int d = 0; d < 3; d++)
        if (!(fabs(p[d]) <= HD_MAX_COORD)) return 0;
    return 1;
}

static double bits_to_double(uint64_t u) {
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

/* Raise the shared bound to d2 (>= 0): non-negative doubles order as their
 * bit patterns do, so an integer compare-and-swap maximum suffices. */
static void raise_bound(_Atomic uint64_t *bits, double d2) {
    uint64_t want;
    memcpy(&want, &d2, sizeof want);
    uint64_t cur = atomic_load_explicit(bits, memory_order_relaxed);
    while (want > cur &&
           !atomic_compare_exchange_weak_explicit(bits, &cur, want, memory_order_relaxed,
                                                  memory_order_relaxed)) {
    }
}

static void directed_task(void *vctx, size_t task, int worker) {
    query_ctx *c = vctx;
    size_t lo = task * INDEX_SLICE, hi = lo + INDEX_SLICE;
    if (hi > c->n) hi = c->n;
    hd__best_t best;
    hd__best_init(&best);
    c->bad[task] = HD__NONE;
    for (size_t i = lo; i < hi; i++) {
        double p[3];
        if (!query_point(c, i, p)) {
            c->bad[task] = i;
            break;
        }
        double cmax = bits_to_double(atomic_load_explicit(&c->cmax_bits, memory_order_relaxed));
        size_t j;
        double d = hd__kd_nearest(&c->idx->kd, p, cmax, &j, &c->count[worker]);
        if (d < cmax) continue; /* some point of B is strictly closer than cmax */
        hd__best_offer(&best, d, i, j);
        raise_bound(&c->cmax_bits, d);
    }
    c->part[task] = best;
}

static void nearest_task(void *vctx, size_t task, int worker) {
    query_ctx *c = vctx;
    size_t lo = task * INDEX_SLICE, hi = lo + INDEX_SLICE;
    if (hi > c->n) hi = c->n;
    c->bad[task] = HD__NONE;
    for (size_t k = lo; k < hi; k++) {
        double p[3];
        if (!query_point(c, k, p)) {
            c->bad[task] = k;
            break;
        }
        size_t j;
        double d = hd__kd_nearest(&c->idx->kd, p, 0.0, &j, &c->count[worker]);
        if (c->dist) c->dist[k] = sqrt(d);
        if (c->nearest) c->nearest[k] = j;
    }
}

static int run_query(query_ctx *c, const hd_options_t *opt, hd__task_fn fn, hd_error_t *err) {
    size_t tasks = (c->n + INDEX_SLICE - 1) / INDEX_SLICE;
    int threads = hd__thread_count(opt ? opt->threads : 0, tasks);
    c->threads = threads;
    c->bad = hd__malloc_array(tasks, sizeof *c->bad);
    c->count = hd__calloc_array((size_t)threads, sizeof *c->count);
    int rc = HD_OK;
    if (!c->bad || !c->count || (fn == directed_task && !c->part)) {
        rc = hd__err(err, HD_ENOMEM, "out of memory");
    } else {
        rc = hd__parallel_for(threads, tasks, fn, c);
        if (rc != HD_OK) hd__err(err, rc, "%s", hd_strerror(rc));
    }
    for (size_t t = 0; rc == HD_OK && t < tasks; t++)
        if (c->bad[t] != HD__NONE)
            rc = hd__err(err, HD_ERANGE,
                         "point %zu of the query is NaN, infinite or beyond 1e153 after "
                         "the transform",
                         c->bad[t]);
    return rc;
}

static int query_begin(const hd_index_t *idx, const hd_points_t *q, const char *what,
                       const hd_transform_t *T, const hd_options_t *opt, query_ctx *c,
                       hd_error_t *err) {
    memset(c, 0, sizeof *c);
    if (!idx) return hd__err(err, HD_EINVAL, "index is NULL");
    if (opt && opt->threads < 0)
        return hd__err(err, HD_EINVAL, "threads must be 0 (every core) or positive, not %d",
                       opt->threads);
    int rc = hd__points_check(q, what, NULL, err);
    if (rc) return rc;
    c->idx = idx;
    c->q = q;
    c->T = T;
    c->n = q->count;
    atomic_init(&c->cmax_bits, 0);
    return HD_OK;
}

static void query_end(query_ctx *c, hd_stats_t *stats) {
    if (stats && c->count) {
        for (int w = 0; w < c->threads; w++) {
            stats->distance_evals += c->count[w].evals;
            stats->nodes_visited += c->count[w].nodes;
        }
    }
    free(c->bad);
    free(c->count);
    free(c->part);
}

int hd_index_directed(const hd_index_t *idx, const hd_points_t *A, const hd_transform_t *T,
                      const hd_options_t *opt, hd_result_t *out, hd_error_t *err) {
    hd__err_clear(err);
    if (!out) return hd__err(err, HD_EINVAL, "result pointer is NULL");
    memset(out, 0, sizeof *out);
    double t0 = hd__now();
    query_ctx c;
    int rc = query_begin(idx, A, "A", T, opt, &c, err);
    if (rc) return rc;
    size_t tasks = (c.n + INDEX_SLICE - 1) / INDEX_SLICE;
    c.part = hd__malloc_array(tasks, sizeof *c.part);
    rc = run_query(&c, opt, directed_task, err);
    if (rc == HD_OK) {
        hd__best_t best;
        hd__best_init(&best);
        for (size_t t = 0; t < tasks; t++) hd__best_offer(&best, c.part[t].d2, c.part[t].i, c.part[t].j);
        out->distance2 = best.d2;
        out->distance = sqrt(best.d2);
        out->i = best.i;
        out->j = best.j;
        out->algorithm = HD_ALG_KDTREE;
    }
    query_end(&c, &out->stats);
    out->seconds = hd__now() - t0;
    return rc;
}

int hd_index_nearest(const hd_index_t *idx, const hd_points_t *Q, const hd_transform_t *T,
                     const hd_options_t *opt, double *dist, size_t *nearest, hd_error_t *err) {
    hd__err_clear(err);
    query_ctx c;
    int rc = query_begin(idx, Q, "Q", T, opt, &c, err);
    if (rc) return rc;
    c.dist = dist;
    c.nearest = nearest;
    rc = run_query(&c, opt, nearest_task, err);
    query_end(&c, NULL);
    return rc;
}
