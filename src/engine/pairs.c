/*
 * pairs.c -- the engine's correspondence path: two sets of the same
 * size listed in the same order.
 *
 * Users very often compare a set with a copy of itself that has been moved,
 * deformed, smoothed, perturbed by noise or re-exported: the same vertices
 * in the same order, each a little displaced.  Then point i of B is a
 * partner of point i of A, and the pair distance p_i = hd__d2(a_i, b_i) is
 * one of the squared distances whose minimum is a_i's nearest distance in
 * B (and b_i's in A: fl(b - a) = -fl(a - b), so the computed value is the
 * same both ways).  Hence, with no rounding argument needed,
 *
 *     nearest2(a_i, B) <= p_i   and   nearest2(b_i, A) <= p_i.
 *
 * That is an upper bound for every point from one streaming pass over both
 * sets, and it settles the Hausdorff distance at once whenever the partners
 * are close: list the points by decreasing p_i (ties by increasing index)
 * and resolve them exactly one after another; as soon as the next p_i is
 * below the maximum found so far, or equal to it at a larger index than
 * the witness, neither it nor any later point can be the witness (its
 * nearest distance is at most p_i, and an equal distance loses the tie to
 * the smaller index).  This is EARLYBREAK's argument (Algorithm 2, lines
 * 8-10) turned around: the bound is known before any search instead of
 * found during one, and the order puts the points that can matter first,
 * as the paper's OHD does with its AHD priming (Algorithm 6, line 1).
 *
 * When is it worth the pass?  Only when a point's partner is closer than
 * its other neighbours.  The gate takes 16 points of A spread over the
 * file and a strided sample of 1024 points of B: when the partner of at
 * least 14 of them is nearer than every sampled point of B, the sets look
 * like a copy and its original.  Two independent clouds fail this at once
 * (a partner is a random point), and so does a copy moved by much more
 * than the spacing of its points; the gate costs some 16,000 distances.
 *
 * The pass keeps, per thread, the PAIR_TOP largest pairs in a heap; the
 * union of the threads' heaps contains the overall top PAIR_TOP, which is a
 * function of the input alone (a total order: p descending, index
 * ascending), so the points resolved, the answer and the witness do not
 * depend on the thread count.
 *
 * The searches.  On a copy the rule usually stops after one or two exact
 * nearest-neighbour searches per direction, so the first searches are plain
 * scans of the other set (stopping at the first point strictly within the
 * maximum, EARLYBREAK's break), which need no index: building the grids
 * would cost more than the whole answer.  After PAIR_SCANS scans' worth of
 * points the engine builds its grids and the rest of the list is searched
 * in them.  If the list is used up before the rule stops, the direction is
 * left to the grid pass or the trees, whose maximum has been raised by
 * every exact search made here; nothing is lost but the pass.
 *
 * The same idea covers a smaller set that is an ordered subset of the
 * larger one (every k-th point kept, a point cloud subsampled by a tool
 * that keeps the order, a mesh simplified by removing vertices): one merge
 * walk finds each point of the small set, in order, as an exact copy in
 * the large one.  Then every nearest distance of the small set is 0, so its
 * directed distance is 0 and its witness is its point 0 with the smallest
 * index at squared distance 0 from it.  The walk gives up as soon as a point
 * is not found, after a first window that keeps unrelated sets from paying
 * more than a few hundred reads.
 */
#include "engine/pairs.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The gate: points of A tested, how many must pass, sampled points of B. */
#define GATE_POINTS 16
#define GATE_PASS 14
#define GATE_SAMPLE 1024
/* Largest pairs kept and resolved at most. */
#define PAIR_TOP 1024
#define PAIR_SLICE 16384
/* Points the scans may read, in whole sets, before the grids are wanted. */
#define PAIR_SCANS 4

struct hd__pair {
    double d2;
    size_t i;
};
typedef struct hd__pair pair_t;

/* a comes before b in the resolution order (larger d2, then smaller i). */
static inline int pair_before(const pair_t *a, const pair_t *b) {
    return a->d2 > b->d2 || (a->d2 == b->d2 && a->i < b->i);
}

/* A heap of at most PAIR_TOP pairs whose root is the last in the order. */
typedef struct {
    pair_t v[PAIR_TOP];
    int n;
} pair_heap_t;

static void heap_push(pair_heap_t *h, pair_t p) {
    if (h->n == PAIR_TOP) {
        if (!pair_before(&p, &h->v[0])) return;
        /* Replace the root and sift it down. */
        int k = 0;
        for (;;) {
            int c = 2 * k + 1;
            if (c >= h->n) break;
            if (c + 1 < h->n && pair_before(&h->v[c], &h->v[c + 1])) c++;
            if (!pair_before(&p, &h->v[c])) break;
            h->v[k] = h->v[c];
            k = c;
        }
        h->v[k] = p;
        return;
    }
    int k = h->n++;
    while (k > 0) {
        int up = (k - 1) / 2;
        if (!pair_before(&h->v[up], &p)) break;
        h->v[k] = h->v[up];
        k = up;
    }
    h->v[k] = p;
}

typedef struct {
    const hd__src_t *a, *b;
    size_t n;
    pair_heap_t *heap; /* per worker */
} pass_ctx;

static void pass_task(void *vctx, size_t task, int worker) {
    pass_ctx *c = vctx;
    pair_heap_t *h = &c->heap[worker];
    size_t lo = task * PAIR_SLICE, hi = lo + PAIR_SLICE < c->n ? lo + PAIR_SLICE : c->n;
    for (size_t i = lo; i < hi; i++) {
        double p[3], q[3];
        hd__src_get(c->a, i, p);
        hd__src_get(c->b, i, q);
        pair_t e = {hd__d2(p, q), i};
        if (h->n == PAIR_TOP && !pair_before(&e, &h->v[0])) continue;
        heap_push(h, e);
    }
}

static int cmp_pairs(const void *x, const void *y) {
    const pair_t *a = x, *b = y;
    return pair_before(a, b) ? -1 : pair_before(b, a) ? 1 : 0;
}

/* Whether the partners of a few points of A are nearer than every sampled
 * point of B. */
static int gate(const hd__src_t src[2], size_t n) {
    size_t ns = n < GATE_SAMPLE ? n : GATE_SAMPLE;
    int pass = 0, tested = n < GATE_POINTS ? (int)n : GATE_POINTS;
    for (int t = 0; t < tested; t++) {
        size_t i = (size_t)t * n / (size_t)tested;
        double p[3], q[3];
        hd__src_get(&src[0], i, p);
        hd__src_get(&src[1], i, q);
        double partner = hd__d2(p, q);
        int nearer = 1;
        for (size_t s = 0; s < ns && nearer; s++) {
            size_t j = s * n / ns;
            if (j == i) continue;
            hd__src_get(&src[1], j, q);
            nearer = partner < hd__d2(p, q);
        }
        pass += nearer;
    }
    return pass >= (tested < GATE_PASS ? tested : GATE_PASS);
}

void hd__pairs_free(hd__pairs_t *P) {
    free(P->list);
    memset(P, 0, sizeof *P);
}

int hd__pairs_begin(hd__pairs_t *P, const hd__src_t src[2], size_t n, int threads,
                    hd__counts_t *counts, hd_error_t *err) {
    memset(P, 0, sizeof *P);
    P->n = n;
    if (!gate(src, n)) return HD_OK;
    counts->evals += (uint64_t)GATE_POINTS * GATE_SAMPLE;

    /* The pass: each worker's largest pairs, then the overall top. */
    size_t tasks = (n + PAIR_SLICE - 1) / PAIR_SLICE;
    threads = hd__thread_count(threads, tasks);
    pass_ctx c = {&src[0], &src[1], n, hd__calloc_array((size_t)threads, sizeof(pair_heap_t))};
    pair_t *all = hd__calloc_array((size_t)threads * PAIR_TOP, sizeof *all);
    if (!c.heap || !all) {
        free(c.heap);
        free(all);
        return hd__err(err, HD_ENOMEM, "out of memory");
    }
    hd__parallel_for(threads, tasks, pass_task, &c);
    counts->evals += n;
    size_t m = 0;
    for (int w = 0; w < threads; w++) {
        memcpy(all + m, c.heap[w].v, (size_t)c.heap[w].n * sizeof *all);
        m += (size_t)c.heap[w].n;
    }
    free(c.heap);
    qsort(all, m, sizeof *all, cmp_pairs);
    P->list = all;
    P->m = m < PAIR_TOP ? m : PAIR_TOP;
    P->active = 1;
    return HD_OK;
}

/* Exact nearest neighbour of q among the n points of src by a scan in index
 * order, with the early stop of hd__grid_nearest (stop2, tie2). */
static void scan_nearest(const hd__src_t *src, size_t n, const double q[3], double stop2,
                         double tie2, hd__hit_t *hit, hd__counts_t *counts) {
    hit->d2 = INFINITY;
    hit->killed = 0;
    hit->j = HD__NONE;
    hit->bucket = HD__NONE;
    hit->perr = 0.0;
    double d[64];
    for (size_t lo = 0; lo < n; lo += 64) {
        size_t m = n - lo < 64 ? n - lo : 64;
        double low = INFINITY;
        for (size_t k = 0; k < m; k++) {
            double p[3];
            hd__src_get(src, lo + k, p);
            d[k] = hd__d2(q, p);
            low = d[k] < low ? d[k] : low;
        }
        counts->exact += m;
        if (!(low < hit->d2)) continue;
        size_t k = 0;
        while (d[k] != low) k++;
        hit->d2 = low;
        hit->j = lo + k;
        hd__src_get(src, lo + k, hit->p);
        if (low < stop2 || low <= tie2) {
            hit->killed = 1;
            return;
        }
    }
}

/* The rule: pair e, and every pair after it in the order, cannot hold the
 * witness of the maximum snap (its nearest distance is at most e->d2). */
static inline int cannot_be_witness(const pair_t *e, const hd__best_t *snap) {
    return snap->d2 >= 0 && (e->d2 < snap->d2 || (e->d2 == snap->d2 && e->i > snap->i));
}

int hd__pairs_resolve(hd__pairs_t *P, const hd__src_t src[2], const hd__grid_t *grid,
                      hd__max_t *max, int directions, hd__counts_t *counts) {
    int all = 1;
    for (int d = 0; d < directions; d++) {
        if (!P->active || P->resolved[d]) continue;
        hd__best_t snap;
        hd__max_snapshot(&max[d], &snap);
        size_t k = P->pos[d];
        for (; k < P->m; k++) {
            const pair_t *e = &P->list[k];
            /* The rule covers the pairs after e only if they come in order. */
            assert(k == 0 || !pair_before(e, &P->list[k - 1]));
            assert(e->i < P->n);
            if (cannot_be_witness(e, &snap)) break;
            if (!grid && P->scanned >= (uint64_t)PAIR_SCANS * P->n) break; /* grids wanted */
            double q[3];
            hd__src_get(&src[d], e->i, q);
            double cmax2 = hd__bound_get(&max[d].cmax);
            double tie2 = e->i > snap.i ? snap.d2 : -1.0;
            hd__hit_t hit;
            uint64_t before = counts[d].exact;
            if (grid) {
                hd__grid_nearest(&grid[1 - d], q, cmax2, tie2, &hit, &counts[d]);
            } else {
                scan_nearest(&src[1 - d], P->n, q, cmax2, tie2, &hit, &counts[d]);
                P->scanned += counts[d].exact - before;
            }
            if (hit.d2 < cmax2 || hit.d2 <= tie2) continue; /* not the witness */
            /* A full search: the nearest distance is at most the pair's. */
            assert(!(hit.d2 > e->d2));
            hd__max_offer(&max[d], hit.d2, e->i, hit.j, &snap);
        }
        P->pos[d] = k;
        /* Settled when the rule stopped the walk, or every point was listed. */
        P->resolved[d] = k < P->m ? cannot_be_witness(&P->list[k], &snap) : P->m == P->n;
        all &= P->resolved[d];
    }
    return P->active && all;
}

/* ---- ordered subsets ---------------------------------------------------------- */

/* Points of the small set the first window must find, and how far into the
 * large set (in multiples of the size ratio) it may look for them. */
#define SUBSET_WINDOW 64
#define SUBSET_SLACK 4

static int same_point(const double p[3], const double q[3]) {
    return p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
}

int hd__subset_resolve(const hd__src_t *small, size_t ns, const hd__src_t *large, size_t nl,
                       hd__max_t *max, hd__counts_t *counts) {
    if (ns == 0 || ns >= nl) return 0;
    size_t ratio = (nl + ns - 1) / ns;
    size_t win = SUBSET_WINDOW < ns ? SUBSET_WINDOW : ns;
    size_t limit = win * ratio * SUBSET_SLACK + SUBSET_WINDOW;
    size_t i = 0, first = 0;
    for (size_t j = 0; j < ns; j++) {
        double p[3], q[3];
        hd__src_get(small, j, p);
        for (;; i++) {
            if (i == nl || (j < win && i >= limit)) {
                counts->evals += i;
                return 0;
            }
            hd__src_get(large, i, q);
            if (same_point(p, q)) break;
        }
        if (j == 0) first = i;
        i++;
    }
    counts->evals += i;
    /* Every point of the small set has a copy: h = 0.  The witness is its
     * point 0 and the smallest index at squared distance 0 from it (an
     * earlier point than its copy may differ by less than the square root
     * of the smallest double). */
    double p[3];
    hd__src_get(small, 0, p);
    size_t j0 = first;
    for (size_t k = 0; k < first; k++) {
        double q[3];
        hd__src_get(large, k, q);
        if (hd__d2(p, q) == 0.0) {
            j0 = k;
            break;
        }
    }
    counts->evals += j0;
#ifndef NDEBUG
    /* The witness: point 0 of the small set is at squared distance 0 from j0. */
    double w[3];
    hd__src_get(large, j0, w);
    assert(hd__d2(p, w) == 0.0);
#endif
    hd__max_offer(max, 0.0, 0, j0, NULL);
    return 1;
}
