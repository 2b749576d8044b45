/*
 * nohd.c -- Algorithms 3-5 (NOHD): branch and bound over an octree on A,
 * with early breaking, for sets whose boxes do not overlap.
 *
 * Algorithm 3 builds Octree_A (depth opt->depth, 6 by default, the paper's
 * recommendation in Section 6.3) and keeps a decreasing priority queue (DPQ)
 * of entries (N, MinUB), MinUB = UB(B, N) = min over y in B of ub(y, N), an
 * upper bound of the nn distance of every point of N (Definitions 3-5).
 * MaxLB, the best lower bound of h(A,B), starts at 0 (line 4).  The head is
 * dequeued (line 6); an inner node is expanded (lines 8-16): each child C
 * goes through CubeToPoints (Algorithm 4), which returns UB(B, C),
 * LB(B, C) = min over y of lb(y, C) and a flag; a flagged child raises MaxLB
 * to LB(B, C) (every point of C is at least that far from all of B) and is
 * queued.  A leaf's points go through PointToPoints (Algorithm 5), whose
 * exact results raise MaxLB (lines 19-22).
 *
 * Bounds.  lb(y, N) and ub(y, N) are hd__box_lb2 and hd__box_ub2 on the
 * node's tight box (octree.c), so through the monotone-rounding argument of
 * points/points.h they bracket the computed hd__d2 of every point of N: MaxLB
 * never exceeds the true answer, and MinUB is never below the nn distance of
 * any point of N.  CubeToPoints evaluates the same values branch-free, a
 * block of B at a time (see block_bounds), because it is NOHD's hot loop.
 *
 * The paper's tests made exact and tie-safe:
 *  - line 8 (MinUB >= MaxLB: expand) prunes only when MinUB < MaxLB, so a
 *    node that may hold a point whose nn distance equals the answer is never
 *    dropped; we apply it to leaves too (the printed algorithm scans every
 *    dequeued leaf), and since the queue is decreasing, the first entry
 *    below MaxLB ends the search;
 *  - Algorithm 4 line 5 (ub(y, C) <= MaxLB: Flag <- false) becomes
 *    ub(y, C) < MaxLB: then every point of C is strictly nearer to y than the
 *    answer and cannot be the witness;
 *  - Algorithm 5 breaks when d < MaxLB (strictly, as printed) or when d
 *    equals an exact value already found at a smaller index of A.  As printed
 *    it then returns the partial minimum of the scan so far, which can be
 *    larger than MaxLB and would raise it wrongly; the missing "cmin <- 0"
 *    is restored: a point cut short offers nothing;
 *  - MaxLB starts at 0 as printed; with strict tests 0 prunes nothing, so it
 *    needs no witness.  The witness is kept apart (hd__best_t) and only exact
 *    point results enter it, so it is the smallest i at the maximum with the
 *    first j of B at that distance (B is scanned in index order).
 *
 * nNOHD (opt->early_break = 0, the paper's Table 1) removes the two early
 * breaks: CubeToPoints always scans all of B and flags every child, and
 * PointToPoints always scans all of B.  The queue's branch and bound stays.
 *
 * Threads.  With one thread the search is the paper's single queue.  With
 * more, the tree is cut into subtrees (the nodes of the first level that has
 * at least 8 per thread), each searched by its own queue in a task of
 * hd__parallel_for; MaxLB is shared by all (hd__bound_t) and the tasks'
 * witnesses merge with hd__best_offer.  The tests above keep every point at
 * the answer alive whatever MaxLB is, so the result is the same at any
 * thread count; the counters are not.
 *
 * Counters: distance_evals counts point-to-point hd__d2 (PointToPoints);
 * nodes_visited counts CubeToPoints calls, each of which evaluates up to
 * 2|B| box bounds.
 */
#include "classic/classic_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const hd__job_t *job;
    const hd__octree_t *tree;
    const hd__onode_t **task;
    size_t n_tasks;
    int early_break;
    hd__bound_t maxlb;
    hd__best_t *part;  /* one per task */
    hd__heap_t *heap;  /* one per worker */
    uint64_t *evals;   /* one per worker */
    uint64_t *visited; /* one per worker */
} nohd_ctx;

#define CTP_BLOCK 32

/* lb(y, C) and ub(y, C) for the points of a block, written without
 * branches; the values are those of hd__box_lb2 and hd__box_ub2 (for each
 * axis at most one of lo - p and p - hi is positive, and adding 0 to it
 * changes nothing). */
static void block_bounds(const hd__box_t *box, const double *y, size_t n, double *bu,
                         double *bl) {
    double lv[CTP_BLOCK], uv[CTP_BLOCK];
    const double lo0 = box->lo[0], lo1 = box->lo[1], lo2 = box->lo[2];
    const double hi0 = box->hi[0], hi1 = box->hi[1], hi2 = box->hi[2];
    for (size_t j = 0; j < n; j++) {
        const double x = y[3 * j], yy = y[3 * j + 1], z = y[3 * j + 2];
        double b0 = lo0 - x, a0 = x - hi0, b1 = lo1 - yy, a1 = yy - hi1, b2 = lo2 - z, a2 = z - hi2;
        double l0 = (b0 > 0.0 ? b0 : 0.0) + (a0 > 0.0 ? a0 : 0.0);
        double l1 = (b1 > 0.0 ? b1 : 0.0) + (a1 > 0.0 ? a1 : 0.0);
        double l2 = (b2 > 0.0 ? b2 : 0.0) + (a2 > 0.0 ? a2 : 0.0);
        double f0 = fabs(x - lo0), g0 = fabs(hi0 - x), u0 = f0 > g0 ? f0 : g0;
        double f1 = fabs(yy - lo1), g1 = fabs(hi1 - yy), u1 = f1 > g1 ? f1 : g1;
        double f2 = fabs(z - lo2), g2 = fabs(hi2 - z), u2 = f2 > g2 ? f2 : g2;
        lv[j] = l0 * l0 + l1 * l1 + l2 * l2;
        uv[j] = u0 * u0 + u1 * u1 + u2 * u2;
    }
    double U = INFINITY, L = INFINITY;
    for (size_t j = 0; j < n; j++) {
        L = lv[j] < L ? lv[j] : L;
        U = uv[j] < U ? uv[j] : U;
    }
    *bu = U;
    *bl = L;
}

/* Algorithm 4.  Returns the flag; *ub and *lb are set when it is 1.  The
 * flag and both minima do not depend on the order in which B is scanned, so
 * the test of line 5 is made once per block of CTP_BLOCK points, which keeps
 * the loop free of unpredictable branches; the answer is the one the
 * point-by-point loop gives. */
static int cube_to_points(const hd__onode_t *C, const double *b, size_t nb, double maxlb,
                          int early_break, double *ub, double *lb) {
    double UB = INFINITY, LB = INFINITY;
    for (size_t j0 = 0; j0 < nb; j0 += CTP_BLOCK) {
        size_t n = nb - j0 < CTP_BLOCK ? nb - j0 : CTP_BLOCK;
        double bu, bl;
        block_bounds(&C->box, b + 3 * j0, n, &bu, &bl);
        if (early_break && bu < maxlb) return 0; /* lines 5-7 */
        UB = bu < UB ? bu : UB;
        LB = bl < LB ? bl : LB;
    }
    *ub = UB;
    *lb = LB;
    return 1;
}

/* Algorithm 5.  Returns 1 with the exact nn distance of x in *d2 and the
 * smallest index at that distance in *j, or 0 when the scan was cut short
 * (d < MaxLB, lines 4-5, or d equal to a value found at a smaller index of
 * A).  nNOHD never cuts short. */
static int point_to_points(const double *x, const double *b, size_t nb, double maxlb,
                           double tie, int early_break, double *d2, size_t *j,
                           uint64_t *evals) {
    if (!early_break) maxlb = tie = -1.0;
    return hd__scan_break(x, b, NULL, nb, maxlb, tie, d2, j, evals);
}

static void nohd_task(void *vctx, size_t task, int worker) {
    nohd_ctx *c = vctx;
    const hd__octree_t *t = c->tree;
    const double *b = c->job->b;
    size_t nb = c->job->nb;
    hd__heap_t *h = &c->heap[worker];
    uint64_t evals = 0, visited = 0;
    hd__best_t best;
    hd__best_init(&best);
    hd__heap_clear(h);
    /* Line 3: the (sub)tree's root with MinUB = infinity.  The heap holds
     * room for every node, so pushes cannot fail. */
    (void)hd__heap_push(h, INFINITY, c->task[task]->id);
    while (hd__heap_size(h)) {
        hd__heap_item_t it = hd__heap_pop(h); /* line 6 */
        const hd__onode_t *N = t->node[it.val];
        if (it.key < hd__bound_get(&c->maxlb)) break; /* line 8, strict */
        if (N->kids) {
            for (int k = 0; k < N->nkids; k++) { /* lines 9-15 */
                const hd__onode_t *C = &N->kids[k];
                double ub, lb;
                visited++;
                if (cube_to_points(C, b, nb, hd__bound_get(&c->maxlb), c->early_break, &ub, &lb)) {
                    hd__bound_raise(&c->maxlb, lb);
                    (void)hd__heap_push(h, ub, C->id);
                }
            }
        } else {
            for (size_t p = N->begin; p < N->begin + N->count; p++) { /* lines 19-22 */
                size_t i = t->idx[p];
                double tie = best.i < i ? best.d2 : -1.0, d2;
                size_t j;
                if (point_to_points(t->pts + 3 * p, b, nb, hd__bound_get(&c->maxlb), tie,
                                    c->early_break, &d2, &j, &evals)) {
                    hd__best_offer(&best, d2, i, j);
                    hd__bound_raise(&c->maxlb, d2);
                }
            }
        }
    }
    c->part[task] = best;
    c->evals[worker] += evals;
    c->visited[worker] += visited;
}

/* The subtrees the tasks search: the root alone for one thread, else the
 * first level of the tree with at least 8 nodes per thread (leaves above it
 * stay whole).  Returns a malloc'd array or NULL. */
static const hd__onode_t **cut_tree(const hd__octree_t *t, int threads, size_t *n) {
    size_t want = threads > 1 ? 8 * (size_t)threads : 1;
    const hd__onode_t **cur = hd__malloc_array(1, sizeof *cur);
    if (!cur) return NULL;
    cur[0] = t->root;
    *n = 1;
    while (*n < want) {
        size_t m = 0, inner = 0;
        for (size_t k = 0; k < *n; k++) {
            m += cur[k]->kids ? cur[k]->nkids : 1;
            inner += cur[k]->kids != NULL;
        }
        if (!inner) break;
        const hd__onode_t **next = hd__malloc_array(m, sizeof *next);
        if (!next) {
            free(cur);
            return NULL;
        }
        size_t q = 0;
        for (size_t k = 0; k < *n; k++) {
            if (!cur[k]->kids) next[q++] = cur[k];
            else
                for (int e = 0; e < cur[k]->nkids; e++) next[q++] = &cur[k]->kids[e];
        }
        free(cur);
        cur = next;
        *n = m;
    }
    return cur;
}

int hd__nohd(const hd__job_t *job, hd_result_t *out, hd_error_t *err) {
    hd__octree_t tree;
    int rc = hd__octree_build(&tree, job->a, job->na, job->opt->depth, 1, err); /* line 1 */
    if (rc != HD_OK) return rc;
    nohd_ctx c;
    memset(&c, 0, sizeof c);
    c.job = job;
    c.tree = &tree;
    c.early_break = job->opt->early_break != 0;
    int threads = job->threads;
    c.task = cut_tree(&tree, threads, &c.n_tasks);
    c.part = c.task ? hd__malloc_array(c.n_tasks, sizeof *c.part) : NULL;
    c.heap = hd__calloc_array((size_t)threads, sizeof *c.heap);
    c.evals = hd__calloc_array((size_t)threads, sizeof *c.evals);
    c.visited = hd__calloc_array((size_t)threads, sizeof *c.visited);
    rc = (c.task && c.part && c.heap && c.evals && c.visited) ? HD_OK : HD_ENOMEM;
    for (int w = 0; c.heap && w < threads; w++) {
        hd__heap_init(&c.heap[w], 1); /* line 2: a "descending order" queue */
        if (rc == HD_OK) rc = hd__heap_reserve(&c.heap[w], tree.nodes);
    }
    if (rc == HD_OK) {
        hd__bound_init(&c.maxlb, 0.0); /* line 4 */
        hd__parallel_for(threads, c.n_tasks, nohd_task, &c);
    }
    if (rc == HD_OK) {
        hd__best_t best;
        hd__best_init(&best);
        hd__best_merge(&best, c.part, c.n_tasks);
        hd__best_store(&best, out);
        for (int w = 0; w < threads; w++) {
            out->stats.distance_evals += c.evals[w];
            out->stats.nodes_visited += c.visited[w];
        }
    } else {
        hd__err(err, rc, "nohd: %s", hd_strerror(rc));
    }
    for (int w = 0; c.heap && w < threads; w++) hd__heap_free(&c.heap[w]);
    free(c.heap);
    free(c.task);
    free(c.part);
    free(c.evals);
    free(c.visited);
    hd__octree_free(&tree);
    return rc;
}
