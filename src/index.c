/*
 * index.c -- the public reusable index of B (hd_index_*): build once, query
 * many times, with an optional transform of the query points.
 *
 * The index is the engine's index of B (engine/build.c): a permutation of
 * B in Morton order, buckets with exact boxes and a quantised copy, and a
 * tree of boxes, about 13 bytes per point.  It borrows B's memory (the
 * header says so) and reads exact coordinates from it when an approximation
 * cannot decide.  It is immutable once built, so any number of threads may
 * query it at once.
 *
 * hd_index_directed builds a temporary index of T(A) (the transform applied
 * on the fly, in the documented order) and runs the engine (engine/engine.c): the
 * result is exactly h(T(A), B) with the canonical witness.
 * hd_index_nearest does not search the index's tree once per query: that
 * search is made for the engine's early breaking, and a complete one per
 * query costs several times more, even from a nearby start, than the
 * all-nearest-neighbours structures of nearest/allnearest.c, which answer
 * neighbouring queries a group at a time, their construction included.
 * So it builds those for B and for the transformed queries (36 bytes per
 * point each, freed before it returns) and runs hd__an_nearest, as
 * hd_distances does for one direction; the answers are the same.  Sets beyond that file's limit
 * (2^31 - 9 points), and calls that cannot get the memory for those
 * structures, use the tree: one exact search (engine/search.c) per query,
 * in slices over threads, each starting in the bucket where the previous
 * one ended.  That start is only good when consecutive queries are close,
 * so the queries are first sorted along the Morton curve of the index's
 * grid (their transformed positions; a radix sort of key and index, 16
 * bytes per query while it runs) and searched in that order, each answer
 * written at the query's own index.  (The times of the three ways, tree
 * in file order, tree in Morton order and groups, are in docs/analysis.md
 * and docs/benchmarks.md.)
 *
 * A transform can carry a valid point out of range, so transformed query
 * points are checked (finite, within HD_MAX_COORD) before anything else,
 * once each: HD_ENONFINITE for a NaN or an infinity, HD_ERANGE beyond
 * HD_MAX_COORD, as for untransformed points.  Packed views must be aligned
 * to their element (hd__points_check refuses them otherwise).
 */
#include "engine/engine.h"
#include "index.h"
#include "nearest/nearest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct hd_index {
    hd_points_t view; /* B, borrowed */
    hd__tree_t tree;
};

/* A packed view is read through double or float pointers (hd__src_get's
 * packed kinds, and the packed loops of the builds), which C allows only at
 * addresses aligned to the element; hd__points_check refuses a misaligned
 * one, as hausdorff.h says.  Views with other strides are read with memcpy
 * and may lie at any address. */
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
    idx->view = *B;
    hd__src_t src;
    hd__src_init(&src, &idx->view, NULL);
    int threads = hd__thread_count(opt ? opt->threads : 0, B->count);
    rc = hd__tree_build(&idx->tree, &src, B->count, NULL, threads, NULL, err);
    if (rc) {
        free(idx);
        return rc;
    }
    *out = idx;
    return HD_OK;
}

void hd_index_free(hd_index_t *idx) {
    if (!idx) return;
    hd__tree_free(&idx->tree);
    free(idx);
}

size_t hd_index_count(const hd_index_t *idx) { return idx ? idx->tree.n : 0; }

size_t hd_index_memory(const hd_index_t *idx) {
    return idx ? sizeof *idx + hd__tree_memory(&idx->tree) : 0;
}

/* ---- checking transformed queries ------------------------------------------ */

#define SLICE 4096

typedef struct {
    hd__src_t src;
    size_t n;
    size_t *bad; /* per slice: first point out of range, or NONE */
    /* nearest */
    const hd__tree_t *tree;
    double *dist;
    size_t *nearest;
    hd__counts_t *counts; /* per worker */
    hd__keygrid_t grid;   /* the index's grid, for the order of the queries */
    uint64_t *order;      /* key << 32 | query, sorted; NULL: file order */
    hd__box_t *boxes;     /* per slice: the box of the transformed queries */
    hd__box_t box;        /* the box of the (transformed) queries */
} query_ctx;

static void check_task(void *vctx, size_t task, int worker) {
    (void)worker;
    query_ctx *c = vctx;
    size_t lo = task * SLICE, hi = lo + SLICE < c->n ? lo + SLICE : c->n;
    c->bad[task] = HD__NONE;
    hd__box_t *b = &c->boxes[task];
    for (size_t k = lo; k < hi; k++) {
        double p[3];
        hd__src_get(&c->src, k, p);
        if (!(fabs(p[0]) <= HD_MAX_COORD && fabs(p[1]) <= HD_MAX_COORD &&
              fabs(p[2]) <= HD_MAX_COORD)) {
            c->bad[task] = k;
            return;
        }
        for (int d = 0; d < 3; d++) {
            b->lo[d] = k == lo || p[d] < b->lo[d] ? p[d] : b->lo[d];
            b->hi[d] = k == lo || p[d] > b->hi[d] ? p[d] : b->hi[d];
        }
    }
}

/* Validate the view and, with a transform, every transformed point; c->box
 * gets the box of the points the queries are (transformed, if T is set). */
static int query_begin(const hd_index_t *idx, const hd_points_t *q, const char *what,
                       const hd_transform_t *T, const hd_options_t *opt, query_ctx *c,
                       int *threads, hd_error_t *err) {
    memset(c, 0, sizeof *c);
    if (!idx) return hd__err(err, HD_EINVAL, "index is NULL");
    if (opt && opt->threads < 0)
        return hd__err(err, HD_EINVAL, "threads must be 0 (every core) or positive, not %d",
                       opt->threads);
    int rc = hd__points_check(q, what, &c->box, err);
    if (rc) return rc;
    hd__src_init(&c->src, q, T);
    c->n = q->count;
    size_t slices = (c->n + SLICE - 1) / SLICE;
    *threads = hd__thread_count(opt ? opt->threads : 0, slices);
    if (!T) return HD_OK;
    c->bad = hd__malloc_array(slices, sizeof *c->bad);
    c->boxes = hd__malloc_array(slices, sizeof *c->boxes);
    if (!c->bad || !c->boxes) rc = hd__err(err, HD_ENOMEM, "out of memory");
    if (rc == HD_OK) hd__parallel_for(*threads, slices, check_task, c);
    for (size_t t = 0; t < slices && rc == HD_OK; t++)
        if (c->bad[t] != HD__NONE) {
            /* The first such point, read again to say what is wrong, with
             * the codes hd__points_check gives untransformed points. */
            double p[3];
            hd__src_get(&c->src, c->bad[t], p);
            int finite = isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
            rc = hd__err(err, finite ? HD_ERANGE : HD_ENONFINITE,
                         finite ? "point %zu of %s is beyond 1e153 after the transform"
                                : "point %zu of %s is NaN or infinite after the transform",
                         c->bad[t], what);
        }
    for (size_t t = 0; t < slices && rc == HD_OK; t++) {
        if (t == 0) c->box = c->boxes[0];
        else hd__box_merge(&c->box, &c->boxes[t]);
    }
    free(c->bad);
    free(c->boxes);
    c->bad = NULL;
    c->boxes = NULL;
    return rc;
}

/* ---- queries ----------------------------------------------------------------- */

int hd_index_directed(const hd_index_t *idx, const hd_points_t *A, const hd_transform_t *T,
                      const hd_options_t *opt, hd_result_t *out, hd_error_t *err) {
    hd__err_clear(err);
    if (!out) return hd__err(err, HD_EINVAL, "result pointer is NULL");
    memset(out, 0, sizeof *out);
    double t0 = hd__now();
    query_ctx c;
    int threads = 1;
    int rc = query_begin(idx, A, "A", T, opt, &c, &threads, err);
    if (rc) return rc;
    threads = hd__thread_count(opt ? opt->threads : 0, A->count > idx->tree.n ? A->count : idx->tree.n);
    hd__tree_t ta;
    rc = hd__tree_build(&ta, &c.src, A->count, &idx->tree.box, threads, NULL, err);
    if (rc) return rc;
    rc = hd__engine_trees(&ta, &idx->tree, threads, out, err);
    hd__tree_free(&ta);
    out->seconds = hd__now() - t0;
    return rc;
}

/* Per-point answers by nearest/allnearest.c (see the essay): the structures of B
 * and of T(Q) on a grid over both boxes, then one group of neighbouring
 * queries at a time. */
static int nearest_by_groups(const hd_index_t *idx, const hd_points_t *Q, const hd_transform_t *T,
                             query_ctx *c, int threads, double *dist, size_t *nearest, hd_error_t *err) {
    hd__box_t keybox = idx->tree.box;
    hd__box_merge(&keybox, &c->box);
    hd__an_t sb, sq;
    int rc;
    if ((rc = hd__an_build(&sb, &idx->view, NULL, &keybox, threads, err))) return rc;
    if ((rc = hd__an_build(&sq, Q, T, &keybox, threads, err)) == HD_OK) {
        /* A copy of B in B's order has its partners at the same indices
         * (nearest/allnearest.c, "Partners"). */
        const hd_points_t *partner = Q->count == idx->view.count ? &idx->view : NULL;
        rc = hd__an_nearest(&sq, &sb, partner, threads, dist, nearest, NULL, err);
        hd__an_free(&sq);
    }
    hd__an_free(&sb);
    return rc;
}

/* The Morton keys of the queries [task * SLICE, ...) on the index's grid. */
static void key_task(void *vctx, size_t task, int worker) {
    (void)worker;
    query_ctx *c = vctx;
    size_t lo = task * SLICE, hi = lo + SLICE < c->n ? lo + SLICE : c->n;
    hd__src_keys(&c->src, &c->grid, lo, hi, c->order);
}

static void nearest_task(void *vctx, size_t task, int worker) {
    query_ctx *c = vctx;
    size_t lo = task * SLICE, hi = lo + SLICE < c->n ? lo + SLICE : c->n;
    size_t hint = HD__NONE;
    for (size_t r = lo; r < hi; r++) {
        size_t k = c->order ? (size_t)(uint32_t)c->order[r] : r;
        double p[3];
        hd__src_get(&c->src, k, p);
        hd__hit_t hit;
        hd__tree_nearest(c->tree, p, 0.0, -1.0, hint, &hit, &c->counts[worker]);
        hint = hit.bucket;
        if (c->dist) c->dist[k] = sqrt(hit.d2);
        if (c->nearest) c->nearest[k] = hit.j;
    }
}

/* One exact search of the tree per query, in Morton order (see the essay). */
static int nearest_by_tree(const hd_index_t *idx, query_ctx *c, int threads, double *dist, size_t *nearest,
                           hd_error_t *err) {
    c->tree = &idx->tree;
    c->dist = dist;
    c->nearest = nearest;
    c->counts = hd__calloc_array((size_t)threads, sizeof *c->counts);
    if (!c->counts) return hd__err(err, HD_ENOMEM, "out of memory");
    size_t slices = (c->n + SLICE - 1) / SLICE;
    if (c->n > 1 && c->n <= UINT32_MAX) {
        /* Without memory for the order, the file order is still exact. */
        uint64_t *tmp = hd__malloc_array(c->n, sizeof *tmp);
        c->order = tmp ? hd__malloc_array(c->n, sizeof *c->order) : NULL;
        if (c->order) {
            hd__keygrid_init(&c->grid, &idx->tree.box);
            hd__parallel_for(threads, slices, key_task, c);
            if (hd__radix_sort(&c->order, &tmp, c->n, threads) != HD_OK) {
                free(c->order);
                c->order = NULL;
            }
        }
        free(tmp);
    }
    hd__parallel_for(threads, slices, nearest_task, c);
    free(c->order);
    free(c->counts);
    c->order = NULL;
    c->counts = NULL;
    return HD_OK;
}

int hd__index_nearest_by(const hd_index_t *idx, const hd_points_t *Q, const hd_transform_t *T,
                         const hd_options_t *opt, double *dist, size_t *nearest, hd__nearest_path_t path,
                         hd_error_t *err) {
    hd__err_clear(err);
    query_ctx c;
    int threads = 1;
    int rc = query_begin(idx, Q, "Q", T, opt, &c, &threads, err);
    if (rc) return rc;
    if (!dist && !nearest) return HD_OK;
    int groups = c.n <= HD__AN_MAX_POINTS && idx->tree.n <= HD__AN_MAX_POINTS;
    if (path == HD__NEAREST_TREE || !groups) return nearest_by_tree(idx, &c, threads, dist, nearest, err);
    int gthreads = hd__thread_count(opt ? opt->threads : 0, c.n > idx->tree.n ? c.n : idx->tree.n);
    rc = nearest_by_groups(idx, Q, T, &c, gthreads, dist, nearest, err);
    if (rc != HD_ENOMEM) return rc;
    /* Without memory for the groups' structures (about 36 bytes per point
     * of each set), the tree answers the same, in more time. */
    hd__err_clear(err);
    return nearest_by_tree(idx, &c, threads, dist, nearest, err);
}

int hd_index_nearest(const hd_index_t *idx, const hd_points_t *Q, const hd_transform_t *T,
                     const hd_options_t *opt, double *dist, size_t *nearest, hd_error_t *err) {
    return hd__index_nearest_by(idx, Q, T, opt, dist, nearest, HD__NEAREST_AUTO, err);
}
