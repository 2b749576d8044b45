/*
 * kdtree.c -- an exact kd-tree and the "kdtree" algorithm built on it.
 *
 * The "kdtree" algorithm is what the peers do (nanoflann in PDAL and
 * point-cloud-utils, FLANN in Open3D and PCL): build a tree on B, run one
 * exact nearest-neighbour search for every point of A, keep the maximum.  It
 * is NAIVEHDD (paper, Algorithm 1) with line 4's inner loop over B replaced
 * by a tree search, and serves as the peer-equivalent baseline the `auto`
 * engine is measured against (the engine and the public index use their
 * own structures, engine/build.c and engine/grid.c).  Its trees also serve
 * per-point distances (stats.c) for sets beyond the limit of the
 * all-nearest structures (nearest/allnearest.c).
 *
 * Build.  The points are copied into three coordinate arrays plus an array
 * of original indices, and split recursively at the median of the widest
 * axis of the node's exact bounding box until at most HD__KD_LEAF remain.
 * A median split makes the shape of the tree a function of the count alone,
 * so the number of nodes below a node of c points is known in advance
 * (nodes_for) and every subtree has a reserved, preorder range of the one
 * node array: the top levels are split serially, then the subtrees are built
 * by hd__parallel_for into their own ranges, giving the same tree at any
 * thread count.
 *
 * Exactness.  Each node's box is the exact box of its points (min and max of
 * the stored doubles), so the computed lower bound hd__box_lb2 never exceeds
 * the computed hd__d2s to a point inside (points/points.h).  A node is skipped
 * only when its lower bound is strictly greater than the best distance so
 * far; a node whose bound equals it is still visited, because it may hold a
 * point at the same distance with a smaller original index.  Within a leaf a
 * point replaces the best on a smaller distance, or on an equal distance with
 * a smaller original index.  So the search returns the exact nearest squared
 * distance and the smallest original index attaining it, in any visiting
 * order.
 */
#include "classic/classic_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Nodes of a subtree over c points: f(c) = 1 for c <= LEAF, else
 * 1 + f(floor(c/2)) + f(ceil(c/2)).  Computed as the pair (f(c), f(c+1)) from
 * the pair of floor(c/2), so in O(log c). */
static void nodes_pair(size_t c, size_t *fc, size_t *fc1) {
    if (c + 1 <= HD__KD_LEAF) {
        *fc = 1;
        *fc1 = 1;
        return;
    }
    size_t m = c / 2, fm, fm1;
    nodes_pair(m, &fm, &fm1);
    if (c % 2 == 0) {
        *fc = c <= HD__KD_LEAF ? 1 : 1 + 2 * fm;
        *fc1 = 1 + fm + fm1;
    } else {
        *fc = c <= HD__KD_LEAF ? 1 : 1 + fm + fm1;
        *fc1 = 1 + 2 * fm1;
    }
}

static size_t nodes_for(size_t c) {
    size_t f, f1;
    nodes_pair(c, &f, &f1);
    return f;
}

static inline void swap_points(hd__kd_t *kd, size_t a, size_t b) {
    double t;
    t = kd->x[a], kd->x[a] = kd->x[b], kd->x[b] = t;
    t = kd->y[a], kd->y[a] = kd->y[b], kd->y[b] = t;
    t = kd->z[a], kd->z[a] = kd->z[b], kd->z[b] = t;
    size_t u = kd->idx[a];
    kd->idx[a] = kd->idx[b];
    kd->idx[b] = u;
}

/* Rearrange [lo, hi) so that the point of rank `nth` along `key` is at nth,
 * none before it larger and none after it smaller (quickselect with
 * median-of-three pivots and Hoare partitioning, which splits runs of equal
 * keys evenly instead of degrading on them). */
static void select_nth(hd__kd_t *kd, const double *key, size_t lo, size_t hi, size_t nth) {
    while (hi - lo > 1) {
        size_t m = lo + (hi - lo) / 2, l = hi - 1;
        size_t med;
        if (key[lo] < key[m]) med = key[m] < key[l] ? m : (key[lo] < key[l] ? l : lo);
        else med = key[lo] < key[l] ? lo : (key[m] < key[l] ? l : m);
        swap_points(kd, lo, med);
        double pivot = key[lo];
        size_t i = lo - 1, j = hi; /* lo - 1 may wrap; only ++i reads it */
        for (;;) {
            do i++;
            while (key[i] < pivot);
            do j--;
            while (key[j] > pivot);
            if (i >= j) break;
            swap_points(kd, i, j);
        }
        /* [lo, j] <= pivot <= [j+1, hi), with lo <= j < hi - 1. */
        if (nth <= j) hi = j + 1;
        else lo = j + 1;
    }
}

static void range_box(const hd__kd_t *kd, size_t b, size_t e, hd__box_t *box) {
    const double *c[3] = {kd->x, kd->y, kd->z};
    for (int k = 0; k < 3; k++) {
        double lo = c[k][b], hi = c[k][b];
        for (size_t i = b + 1; i < e; i++) {
            double v = c[k][i];
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
        box->lo[k] = lo;
        box->hi[k] = hi;
    }
}

/* Make node k over [b, e); when it is split, return 1 and the split point. */
static int make_node(hd__kd_t *kd, size_t k, size_t b, size_t e, size_t *mid) {
    hd__kdnode_t *nd = &kd->nodes[k];
    range_box(kd, b, e, &nd->box);
    nd->begin = b;
    nd->end = e;
    nd->right = 0;
    if (e - b <= HD__KD_LEAF) return 0;
    int axis = 0;
    double w = nd->box.hi[0] - nd->box.lo[0];
    for (int c = 1; c < 3; c++) {
        double wc = nd->box.hi[c] - nd->box.lo[c];
        if (wc > w) {
            w = wc;
            axis = c;
        }
    }
    const double *key = axis == 0 ? kd->x : axis == 1 ? kd->y : kd->z;
    size_t m = b + (e - b) / 2;
    select_nth(kd, key, b, e, m);
    nd->right = k + 1 + nodes_for(m - b);
    *mid = m;
    return 1;
}

static void build_subtree(hd__kd_t *kd, size_t k, size_t b, size_t e) {
    size_t m;
    while (make_node(kd, k, b, e, &m)) {
        build_subtree(kd, k + 1, b, m);
        k = kd->nodes[k].right;
        b = m;
    }
}

typedef struct {
    size_t node, begin, end;
} subtree_t;

typedef struct {
    hd__kd_t *kd;
    subtree_t *tasks;
    size_t n_tasks, cap;
} build_ctx;

/* Split serially down to subtrees of at most `limit` points, listing them. */
static void build_top(build_ctx *c, size_t k, size_t b, size_t e, size_t limit) {
    size_t m;
    if (e - b <= limit) {
        c->tasks[c->n_tasks].node = k;
        c->tasks[c->n_tasks].begin = b;
        c->tasks[c->n_tasks].end = e;
        c->n_tasks++;
        return;
    }
    if (!make_node(c->kd, k, b, e, &m)) return;
    build_top(c, k + 1, b, m, limit);
    build_top(c, c->kd->nodes[k].right, m, e, limit);
}

static void build_task(void *vctx, size_t task, int worker) {
    (void)worker;
    build_ctx *c = vctx;
    const subtree_t *s = &c->tasks[task];
    build_subtree(c->kd, s->node, s->begin, s->end);
}

void hd__kd_free(hd__kd_t *kd) {
    if (!kd) return;
    free(kd->x);
    free(kd->y);
    free(kd->z);
    free(kd->idx);
    free(kd->nodes);
    memset(kd, 0, sizeof *kd);
}

int hd__kd_build(hd__kd_t *kd, const hd_points_t *p, int threads, hd_error_t *err) {
    memset(kd, 0, sizeof *kd);
    size_t n = p->count;
    kd->n = n;
    kd->n_nodes = nodes_for(n);
    kd->x = hd__malloc_array(n, sizeof(double));
    kd->y = hd__malloc_array(n, sizeof(double));
    kd->z = hd__malloc_array(n, sizeof(double));
    kd->idx = hd__malloc_array(n, sizeof(size_t));
    kd->nodes = hd__malloc_array(kd->n_nodes, sizeof(hd__kdnode_t));
    if (!kd->x || !kd->y || !kd->z || !kd->idx || !kd->nodes) {
        hd__kd_free(kd);
        return hd__err(err, HD_ENOMEM, "cannot allocate a kd-tree of %zu points", n);
    }
    for (size_t k = 0; k < n; k++) {
        double q[3];
        hd_points_get(p, k, q);
        kd->x[k] = q[0];
        kd->y[k] = q[1];
        kd->z[k] = q[2];
        kd->idx[k] = k;
    }
    if (threads < 1) threads = 1;
    /* Subtrees of about n / (8 * threads) points balance the load; the
     * serial top costs a few passes over the points. */
    size_t limit = threads == 1 ? n : n / (8 * (size_t)threads);
    if (limit < 4096) limit = 4096;
    build_ctx c;
    c.kd = kd;
    c.cap = 2 * (n / limit + 1) + 2;
    c.n_tasks = 0;
    c.tasks = hd__malloc_array(c.cap, sizeof *c.tasks);
    if (!c.tasks) {
        hd__kd_free(kd);
        return hd__err(err, HD_ENOMEM, "cannot allocate a kd-tree of %zu points", n);
    }
    build_top(&c, 0, 0, n, limit);
    hd__parallel_for(threads, c.n_tasks, build_task, &c);
    free(c.tasks);
    return HD_OK;
}

double hd__kd_nearest(const hd__kd_t *kd, const double q[3], double stop2, size_t *j,
                      hd__kdcount_t *count) {
    struct {
        size_t node;
        double lb2;
    } stack[128];
    int sp = 0;
    double best = INFINITY;
    size_t bj = HD__NONE;
    uint64_t evals = 0, visited = 0;
    const double qx = q[0], qy = q[1], qz = q[2];
    stack[sp].node = 0;
    stack[sp].lb2 = 0.0;
    sp++;
    while (sp > 0) {
        sp--;
        if (stack[sp].lb2 > best) continue;
        size_t k = stack[sp].node;
        const hd__kdnode_t *nd = &kd->nodes[k];
        visited++;
        if (nd->right == 0) {
            for (size_t i = nd->begin; i < nd->end; i++) {
                double d = hd__d2s(qx, qy, qz, kd->x[i], kd->y[i], kd->z[i]);
                if (d < best || (d == best && kd->idx[i] < bj)) {
                    best = d;
                    bj = kd->idx[i];
                }
            }
            evals += nd->end - nd->begin;
            if (best < stop2) break;
            continue;
        }
        size_t l = k + 1, r = nd->right;
        double dl = hd__box_lb2(&kd->nodes[l].box, q);
        double dr = hd__box_lb2(&kd->nodes[r].box, q);
        /* Push the farther child first so the nearer one is searched first. */
        if (dl <= dr) {
            if (dr <= best) stack[sp].node = r, stack[sp].lb2 = dr, sp++;
            if (dl <= best) stack[sp].node = l, stack[sp].lb2 = dl, sp++;
        } else {
            if (dl <= best) stack[sp].node = l, stack[sp].lb2 = dl, sp++;
            if (dr <= best) stack[sp].node = r, stack[sp].lb2 = dr, sp++;
        }
    }
    if (count) {
        count->evals += evals;
        count->nodes += visited;
    }
    *j = bj;
    return best;
}

/* ---- the "kdtree" algorithm: one full search per point of A ------------- */

#define KD_SLICE 1024

typedef struct {
    const hd__job_t *job;
    const hd__kd_t *kd;
    hd__best_t *part;
    hd__kdcount_t *count; /* per worker */
} kdalg_ctx;

static void kdalg_task(void *vctx, size_t task, int worker) {
    kdalg_ctx *c = vctx;
    size_t lo = task * KD_SLICE, hi = lo + KD_SLICE;
    if (hi > c->job->na) hi = c->job->na;
    hd__best_t best;
    hd__best_init(&best);
    for (size_t i = lo; i < hi; i++) {
        size_t j;
        double d = hd__kd_nearest(c->kd, c->job->a + 3 * i, 0.0, &j, &c->count[worker]);
        hd__best_offer(&best, d, i, j);
    }
    c->part[task] = best;
}

int hd__kdtree(const hd__job_t *job, hd_result_t *out, hd_error_t *err) {
    hd__kd_t kd;
    hd_points_t B = hd_points_f64(job->b, job->nb);
    int rc = hd__kd_build(&kd, &B, job->threads, err);
    if (rc) return rc;
    size_t tasks = (job->na + KD_SLICE - 1) / KD_SLICE;
    kdalg_ctx c;
    c.job = job;
    c.kd = &kd;
    c.part = hd__malloc_array(tasks, sizeof *c.part);
    c.count = hd__calloc_array((size_t)job->threads, sizeof *c.count);
    if (!c.part || !c.count) {
        rc = hd__err(err, HD_ENOMEM, "out of memory");
    } else {
        hd__parallel_for(job->threads, tasks, kdalg_task, &c);
    }
    if (rc == HD_OK) {
        hd__best_t best;
        hd__best_init(&best);
        hd__best_merge(&best, c.part, tasks);
        hd__best_store(&best, out);
        for (int w = 0; w < job->threads; w++) {
            out->stats.distance_evals += c.count[w].evals;
            out->stats.nodes_visited += c.count[w].nodes;
        }
        out->algorithm = HD_ALG_KDTREE;
    }
    free(c.part);
    free(c.count);
    hd__kd_free(&kd);
    return rc;
}
