/*
 * ohd.c -- Algorithms 6-7 (OHD): an approximate distance from a sample, an
 * octree on B at a resolution derived from it, point culling, and a
 * best-first nearest-neighbour search with early exit, for overlapping sets.
 *
 * Algorithm 6.
 *   line 1  AHD: the paper runs EARLYBREAK's outer loop for lambda * |A|
 *           iterations (Section 4.4.1; lambda = opt->lambda, 1/100 by
 *           default).  We draw ceil(lambda * |A|) distinct points of A with
 *           the seeded generator and run hd__eb_loop on them (earlybreak.c),
 *           so AHD is the exact nn distance of a real point of A, a lower
 *           bound of h(A,B) that comes with its witness.
 *   line 2  Octree_B "with the given resolution (AHD)": leaves whose cells
 *           are small enough that a point of A inside a non-empty leaf cell
 *           is within AHD of a point of B.  A cell of side s only bounds
 *           distances inside it by its diagonal s*sqrt(3), so the depth is
 *           the smallest k with 3 * (side * 2^-k)^2 <= AHD^2, capped at
 *           OHD_MAX_DEPTH; the cap is what keeps AHD = 0 (identical points)
 *           from asking for an endless subdivision.  Nodes holding a single
 *           point or only equal points are not split further (octree.c).
 *   lines 3-9  Maxlb <- AHD; each point x of A is culled (line 5) or gets
 *           Minlb <- NNDist(x, Octree_B) and Maxlb <- max(Maxlb, Minlb).
 *
 * Point culling (Section 4.4.2, Fig. 6), made safe.  The paper culls the
 * points of A lying in a leaf cell of Octree_B, claiming their distance
 * "cannot be over AHD".  Whether the cell's diagonal is <= AHD depends on
 * rounding, and a point exactly at AHD could still be the witness, so we
 * keep the paper's choice of candidates (the leaf whose cell contains x,
 * found by hd__octree_locate with the tree's own split values; the cells on
 * the border of the root reach outwards, so points of A outside B's box are
 * candidates too) but cull x only on a proof that some point of B is
 * strictly nearer than the current Maxlb: the leaf's tight-box upper bound
 * hd__box_ub2 < Maxlb, or else the exact hd__d2 to the leaf's first point
 * < Maxlb.  A culled point's nn
 * distance is then strictly below the answer.  opt->culling = 0 gives the
 * paper's nOHD (Table 2): every point goes through NNDist.
 *
 * Algorithm 7 (NNDist).  An ascending priority queue (APQ) of (N, lb(x, N))
 * starts with the root at 0 (line 3).  An inner node with lb <= Minlb has
 * its children queued when their lb <= Minlb (lines 7-13); a leaf's points
 * are measured (lines 17-23).  Since the queue is ascending, the first entry
 * with lb > Minlb ends the search (the paper pops and discards the rest one
 * by one, which is the same).  The <= keeps every node that may hold a point
 * at exactly Minlb, so the smallest index of B at the nn distance is found.
 * The early exit of lines 19-20, "if d <= Maxlb then APQ <- empty", is
 * exact only for the distance: a point whose nn distance equals Maxlb may
 * still be the witness if its index is smaller.  We exit when d < Maxlb, or
 * when d equals an exact value already found at a smaller index of A; an
 * exited point offers nothing.
 *
 * Threads: A is cut into slices in index order (hd__parallel_for); Maxlb is
 * shared (hd__bound_t, starting at AHD), each slice's witness starts as
 * AHD's and slices merge with hd__best_offer.  All tests above keep every
 * point whose nn distance is the answer, so result and witness do not depend
 * on the thread count; the counters do.
 *
 * Counters: distance_evals counts hd__d2 calls (sample, culling, NNDist);
 * nodes_visited counts APQ entries processed; points_culled the culled
 * points of A.
 */
#include "classic/classic_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define OHD_SLICE 512
#define OHD_MAX_DEPTH 16

typedef struct {
    const hd__job_t *job;
    const hd__octree_t *tree;
    int culling;
    hd__best_t ahd;    /* the sample's result: AHD with its witness */
    hd__bound_t maxlb;
    hd__best_t *part;  /* one per task */
    hd__heap_t *heap;  /* one per worker */
    uint64_t *evals, *visited, *culled; /* one per worker */
} ohd_ctx;

/* Algorithm 7.  Returns 1 with x's exact nn distance in *d2 and the
 * smallest index of B at that distance in *j, or 0 on the early exit. */
static int nn_dist(const hd__octree_t *t, hd__heap_t *h, const double *x, double maxlb,
                   double tie, double *d2, size_t *j, uint64_t *evals, uint64_t *visited) {
    double minlb = INFINITY; /* line 1 */
    size_t bj = HD__NONE;
    hd__heap_clear(h);
    (void)hd__heap_push(h, 0.0, t->root->id); /* line 3; room for every node */
    while (hd__heap_size(h)) {
        hd__heap_item_t it = hd__heap_pop(h); /* line 5 */
        if (it.key > minlb) break;             /* lines 7, 10: nothing nearer left */
        const hd__onode_t *N = t->node[it.val];
        (*visited)++;
        if (N->kids) {
            for (int k = 0; k < N->nkids; k++) { /* lines 8-13 */
                const hd__onode_t *C = &N->kids[k];
                double lb = hd__box_lb2(&C->box, x);
                if (lb <= minlb) (void)hd__heap_push(h, lb, C->id);
            }
        } else {
            for (size_t p = N->begin; p < N->begin + N->count; p++) { /* lines 17-23 */
                double d = hd__d2(x, t->pts + 3 * p);
                (*evals)++;
                if (d < maxlb || d == tie) return 0; /* lines 19-20, tie-safe */
                size_t jj = t->idx[p];
                if (d < minlb || (d == minlb && jj < bj)) {
                    minlb = d;
                    bj = jj;
                }
            }
        }
    }
    *d2 = minlb;
    *j = bj;
    return 1;
}

/* Line 5: 1 when x is proven strictly nearer to B than maxlb through the leaf
 * of Octree_B whose cell contains it. */
static int culled(const hd__octree_t *t, const double *x, double maxlb, uint64_t *evals) {
    const hd__onode_t *leaf = hd__octree_locate(t, x);
    if (!leaf) return 0;
    if (hd__box_ub2(&leaf->box, x) < maxlb) return 1;
    (*evals)++;
    return hd__d2(x, t->pts + 3 * leaf->begin) < maxlb;
}

static void ohd_task(void *vctx, size_t task, int worker) {
    ohd_ctx *c = vctx;
    const double *a = c->job->a;
    size_t lo = task * OHD_SLICE, hi = lo + OHD_SLICE;
    if (hi > c->job->na) hi = c->job->na;
    hd__best_t best = c->ahd;
    uint64_t evals = 0, visited = 0, cull = 0;
    for (size_t i = lo; i < hi; i++) { /* line 4 */
        const double *x = a + 3 * i;
        double maxlb = hd__bound_get(&c->maxlb);
        if (c->culling && culled(c->tree, x, maxlb, &evals)) {
            cull++;
            continue;
        }
        double tie = best.i < i ? best.d2 : -1.0, d2;
        size_t j;
        if (nn_dist(c->tree, &c->heap[worker], x, maxlb, tie, &d2, &j, &evals, &visited)) {
            hd__best_offer(&best, d2, i, j); /* line 7 */
            hd__bound_raise(&c->maxlb, d2);
        }
    }
    c->part[task] = best;
    c->evals[worker] += evals;
    c->visited[worker] += visited;
    c->culled[worker] += cull;
}

/* Line 1: AHD from ceil(lambda * |A|) distinct random points of A. */
static int approximate(const hd__job_t *job, hd__rng_t *rng, hd__best_t *ahd, hd_stats_t *stats,
                       hd_error_t *err) {
    size_t na = job->na;
    double want = ceil(job->opt->lambda * (double)na);
    size_t m = want < 1.0 ? 1 : want >= (double)na ? na : (size_t)want;
    size_t *perm = hd__malloc_array(na, sizeof *perm);
    if (!perm) return hd__err(err, HD_ENOMEM, "ohd: out of memory for %zu points", na);
    for (size_t k = 0; k < na; k++) perm[k] = k;
    for (size_t k = 0; k < m; k++) { /* the first m steps of a Fisher-Yates shuffle */
        size_t r = k + (size_t)hd__rng_below(rng, na - k);
        size_t tmp = perm[k];
        perm[k] = perm[r];
        perm[r] = tmp;
    }
    int rc = hd__eb_loop(job, perm, m, 0, rng, ahd, stats, err);
    free(perm);
    return rc;
}

/* Line 2: the depth whose cells have a diagonal of at most AHD. */
static int resolution_depth(const hd__box_t *box, double ahd2) {
    double s = 0.0;
    for (int k = 0; k < 3; k++)
        if (box->hi[k] - box->lo[k] > s) s = box->hi[k] - box->lo[k];
    int depth = 0;
    while (depth < OHD_MAX_DEPTH && 3.0 * (s * s) > ahd2) {
        s *= 0.5;
        depth++;
    }
    return depth;
}

int hd__ohd(const hd__job_t *job, hd_result_t *out, hd_error_t *err) {
    hd__rng_t rng;
    hd__rng_seed(&rng, job->opt->seed);
    ohd_ctx c;
    memset(&c, 0, sizeof c);
    int rc = approximate(job, &rng, &c.ahd, &out->stats, err);
    if (rc != HD_OK) return rc;
    hd__octree_t tree;
    rc = hd__octree_build(&tree, job->b, job->nb, resolution_depth(&job->box_b, c.ahd.d2), 1, err);
    if (rc != HD_OK) return rc;
    int threads = job->threads;
    size_t tasks = (job->na + OHD_SLICE - 1) / OHD_SLICE;
    c.job = job;
    c.tree = &tree;
    c.culling = job->opt->culling != 0;
    c.part = hd__malloc_array(tasks, sizeof *c.part);
    c.heap = hd__calloc_array((size_t)threads, sizeof *c.heap);
    c.evals = hd__calloc_array((size_t)threads, sizeof *c.evals);
    c.visited = hd__calloc_array((size_t)threads, sizeof *c.visited);
    c.culled = hd__calloc_array((size_t)threads, sizeof *c.culled);
    rc = (c.part && c.heap && c.evals && c.visited && c.culled) ? HD_OK : HD_ENOMEM;
    for (int w = 0; c.heap && w < threads; w++) {
        hd__heap_init(&c.heap[w], 0); /* an "ascending order" queue */
        if (rc == HD_OK) rc = hd__heap_reserve(&c.heap[w], tree.nodes);
    }
    if (rc == HD_OK) {
        hd__bound_init(&c.maxlb, c.ahd.d2); /* line 3: Maxlb <- AHD */
        hd__parallel_for(threads, tasks, ohd_task, &c);
    }
    if (rc == HD_OK) {
        hd__best_t best = c.ahd;
        hd__best_merge(&best, c.part, tasks);
        hd__best_store(&best, out);
        for (int w = 0; w < threads; w++) {
            out->stats.distance_evals += c.evals[w];
            out->stats.nodes_visited += c.visited[w];
            out->stats.points_culled += c.culled[w];
        }
    } else {
        hd__err(err, rc, "ohd: %s", hd_strerror(rc));
    }
    for (int w = 0; c.heap && w < threads; w++) hd__heap_free(&c.heap[w]);
    free(c.heap);
    free(c.part);
    free(c.evals);
    free(c.visited);
    free(c.culled);
    hd__octree_free(&tree);
    return rc;
}
