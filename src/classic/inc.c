/*
 * inc.c -- the incremental Hausdorff distance algorithm of Nutanong, Jacox
 * and Samet (VLDB 2011), the "INC" column of the paper's Table 3.
 *
 * INC traverses an index of A and an index of B at the same time.  Its
 * queue holds entries (e, L): e is a node or a single point of A's tree, L
 * the list of elements (nodes or points) of B's tree that may still hold the
 * nearest neighbour of some point of e.  The key of an entry is an upper
 * bound of the nn distance of every point of e,
 *     U(e, L) = min over c in L of ub(e, c),
 * and the queue is a max-queue on it.  The head is taken; either e is
 * expanded (each child, or each point of a leaf, inherits L), or L is
 * refined (each node of L replaced by its children, or a leaf by its
 * points).  Every new list is filtered: c is dropped when lb(e, c) > U(e, L),
 * because then every point of c is strictly farther from every point of e
 * than some point of another candidate.  An entry whose e is a point and
 * whose L holds only points has U = that point's exact nn distance, and,
 * being the head of a max-queue, it is the largest such value: the answer.
 * The search stops when the head's key is below the best lower bound LB
 * found so far; LB is raised by those exact values and by the box bounds
 * min over c in L of lb(e, c), which bound the nn distance of every point of
 * e from below because L always holds each point's nearest neighbours.
 *
 * Our substitutions and choices:
 *  - Nutanong et al. use R-trees; we use this project's octree (octree.c)
 *    on both sets, split down to INC_LEAF points per leaf (depth capped at
 *    INC_MAX_DEPTH), with each node's tight box as its MBR.  Their bounds
 *    between MBRs become hd__box_box_lb2 / hd__box_box_ub2 (points.h), and
 *    between a point and a box hd__box_lb2 / hd__box_ub2, all evaluated in
 *    hd__d2's operation order, so they bracket the computed distances
 *    exactly (points/points.h); between two points the bound is hd__d2 itself.
 *  - Expand or refine: e is expanded when it is a node at least as large
 *    (squared diagonal of its box) as the largest node of L; otherwise every
 *    node of L is refined.  A point e always refines.
 *  - Ties: the filter keeps c when lb(e, c) == U, so all nearest neighbours
 *    at exactly the nn distance survive and the smallest index among them is
 *    the witness j.  The search stops only when the head's key is strictly
 *    below LB, and entries are queued only when their key is not below LB:
 *    an entry that may hold a point at exactly the answer is always resolved,
 *    so the witness i is the smallest index at the maximum.  (Stopping when
 *    the key is "no larger than" LB would return the right distance but
 *    could miss a tied point of smaller index.)
 *  - Threads: INC's best-first order over one queue is the algorithm; cut
 *    into independent queues it would become a different algorithm, so INC
 *    runs serially whatever the thread count.
 *
 * Counters: distance_evals counts point-to-point hd__d2; nodes_visited the
 * entries taken from the queue.
 */
#include "classic/classic_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define INC_LEAF 8
#define INC_MAX_DEPTH 21

/* An element of a tree: a node (by id) or one point (by position in the
 * tree's order, tagged with the top bit). */
typedef uint64_t ref_t;
#define REF_POINT ((ref_t)1 << 63)

typedef struct {
    ref_t e;    /* element of A's tree */
    ref_t *L;   /* candidate elements of B's tree */
    size_t n;
} entry_t;

typedef struct {
    hd__octree_t ta, tb;
    entry_t *ent;
    size_t n_ent, cap_ent;
    size_t *free_slot;
    size_t n_free;
    hd__heap_t queue;
    double lb; /* LB: the best lower bound of h(A,B)^2 found */
    hd__best_t best;
    uint64_t evals, visited;
    ref_t *scratch; /* refined candidates */
    double *lo, *hi; /* bounds per candidate */
    size_t scratch_cap;
} inc_t;

/* The box of a node, or a point as a degenerate box. */
static const hd__box_t *elem_box(const hd__octree_t *t, ref_t r, hd__box_t *tmp) {
    if (!(r & REF_POINT)) return &t->node[r]->box;
    const double *p = t->pts + 3 * (r & ~REF_POINT);
    for (int k = 0; k < 3; k++) tmp->lo[k] = tmp->hi[k] = p[k];
    return tmp;
}

/* lb and ub of the squared distances between the points of a (in A's tree)
 * and the points of c (in B's tree). */
static void bounds(inc_t *s, ref_t a, ref_t c, double *lb, double *ub) {
    int pa = (a & REF_POINT) != 0, pc = (c & REF_POINT) != 0;
    if (pa && pc) {
        double d = hd__d2(s->ta.pts + 3 * (a & ~REF_POINT), s->tb.pts + 3 * (c & ~REF_POINT));
        s->evals++;
        *lb = *ub = d;
    } else if (pa) {
        const double *x = s->ta.pts + 3 * (a & ~REF_POINT);
        const hd__box_t *b = &s->tb.node[c]->box;
        *lb = hd__box_lb2(b, x);
        *ub = hd__box_ub2(b, x);
    } else if (pc) {
        const double *y = s->tb.pts + 3 * (c & ~REF_POINT);
        const hd__box_t *b = &s->ta.node[a]->box;
        *lb = hd__box_lb2(b, y);
        *ub = hd__box_ub2(b, y);
    } else {
        const hd__box_t *x = &s->ta.node[a]->box, *y = &s->tb.node[c]->box;
        *lb = hd__box_box_lb2(x, y);
        *ub = hd__box_box_ub2(x, y);
    }
}

static int grow_scratch(inc_t *s, size_t n) {
    if (n <= s->scratch_cap) return HD_OK;
    size_t cap = s->scratch_cap ? s->scratch_cap : 64;
    while (cap < n) {
        if (hd__mul_overflows(cap, 2)) return HD_ENOMEM;
        cap *= 2;
    }
    ref_t *r = hd__realloc_array(s->scratch, cap, sizeof *r);
    if (r) s->scratch = r;
    double *lo = hd__realloc_array(s->lo, cap, sizeof *lo);
    if (lo) s->lo = lo;
    double *hi = hd__realloc_array(s->hi, cap, sizeof *hi);
    if (hi) s->hi = hi;
    if (!r || !lo || !hi) return HD_ENOMEM;
    s->scratch_cap = cap;
    return HD_OK;
}

/* Filter the n candidates in cand for element e and queue (e, kept) when
 * its key is not below LB.  cand may alias s->scratch. */
static int offer_entry(inc_t *s, ref_t e, const ref_t *cand, size_t n) {
    int rc = grow_scratch(s, n);
    if (rc != HD_OK) return rc;
    double U = INFINITY, lbe = INFINITY;
    for (size_t k = 0; k < n; k++) {
        bounds(s, e, cand[k], &s->lo[k], &s->hi[k]);
        if (s->hi[k] < U) U = s->hi[k];
        if (s->lo[k] < lbe) lbe = s->lo[k];
    }
    /* Every point of e is at least lbe from B (its nearest neighbours are
     * among the candidates): a lower bound of h(A,B)^2. */
    if (lbe > s->lb) s->lb = lbe;
    if (U < s->lb) return HD_OK; /* cannot reach the answer */
    size_t m = 0;
    for (size_t k = 0; k < n; k++) m += s->lo[k] <= U;
    ref_t *L = hd__malloc_array(m, sizeof *L);
    if (!L) return HD_ENOMEM;
    m = 0;
    for (size_t k = 0; k < n; k++)
        if (s->lo[k] <= U) L[m++] = cand[k];
    size_t slot;
    if (s->n_free) {
        slot = s->free_slot[--s->n_free];
    } else {
        if (s->n_ent == s->cap_ent) {
            size_t cap = s->cap_ent ? 2 * s->cap_ent : 1024;
            entry_t *ent = hd__realloc_array(s->ent, cap, sizeof *ent);
            size_t *fs = hd__realloc_array(s->free_slot, cap, sizeof *fs);
            if (ent) s->ent = ent;
            if (fs) s->free_slot = fs;
            if (!ent || !fs) {
                free(L);
                return HD_ENOMEM;
            }
            s->cap_ent = cap;
        }
        slot = s->n_ent++;
    }
    s->ent[slot].e = e;
    s->ent[slot].L = L;
    s->ent[slot].n = m;
    rc = hd__heap_push(&s->queue, U, slot);
    if (rc != HD_OK) {
        /* The slot goes back unused; its list must not be freed again by
         * the final sweep over the slots. */
        free(L);
        s->ent[slot].L = NULL;
        s->free_slot[s->n_free++] = slot;
    }
    return rc;
}

static void release(inc_t *s, size_t slot) {
    free(s->ent[slot].L);
    s->ent[slot].L = NULL;
    s->free_slot[s->n_free++] = slot;
}

/* Refine every node of L into its children (or a leaf into its points). */
static int refine(inc_t *s, const entry_t *en) {
    size_t n = 0;
    for (size_t k = 0; k < en->n; k++) {
        ref_t c = en->L[k];
        if (c & REF_POINT) n++;
        else {
            const hd__onode_t *N = s->tb.node[c];
            n += N->kids ? N->nkids : N->count;
        }
    }
    int rc = grow_scratch(s, n);
    if (rc != HD_OK) return rc;
    ref_t *out = s->scratch;
    n = 0;
    for (size_t k = 0; k < en->n; k++) {
        ref_t c = en->L[k];
        const hd__onode_t *N = (c & REF_POINT) ? NULL : s->tb.node[c];
        if (!N) out[n++] = c;
        else if (N->kids)
            for (int q = 0; q < N->nkids; q++) out[n++] = N->kids[q].id;
        else
            for (size_t p = N->begin; p < N->begin + N->count; p++) out[n++] = p | REF_POINT;
    }
    return offer_entry(s, en->e, out, n);
}

/* Expand e into its children (or a leaf into its points), each inheriting L. */
static int expand(inc_t *s, const entry_t *en) {
    const hd__onode_t *N = s->ta.node[en->e];
    int rc = HD_OK;
    if (N->kids) {
        for (int q = 0; q < N->nkids && rc == HD_OK; q++)
            rc = offer_entry(s, N->kids[q].id, en->L, en->n);
    } else {
        for (size_t p = N->begin; p < N->begin + N->count && rc == HD_OK; p++)
            rc = offer_entry(s, p | REF_POINT, en->L, en->n);
    }
    return rc;
}

static int run(inc_t *s) {
    int rc = offer_entry(s, s->ta.root->id, &(ref_t){s->tb.root->id}, 1);
    while (rc == HD_OK && hd__heap_size(&s->queue)) {
        hd__heap_item_t it = hd__heap_pop(&s->queue);
        if (it.key < s->lb) break; /* nothing left can reach LB */
        s->visited++;
        entry_t en = s->ent[it.val];
        int resolved = (en.e & REF_POINT) != 0;
        double biggest = 0.0; /* largest candidate node */
        hd__box_t tmp;
        for (size_t k = 0; k < en.n; k++) {
            if (en.L[k] & REF_POINT) continue;
            resolved = 0;
            double sz = hd__box_size2(elem_box(&s->tb, en.L[k], &tmp));
            if (sz > biggest) biggest = sz;
        }
        if (resolved) {
            /* A point whose candidates are points: the key is its exact nn
             * distance, and every candidate kept is at that distance. */
            size_t j = HD__NONE;
            for (size_t k = 0; k < en.n; k++) {
                size_t jj = s->tb.idx[en.L[k] & ~REF_POINT];
                if (jj < j) j = jj;
            }
            hd__best_offer(&s->best, it.key, s->ta.idx[en.e & ~REF_POINT], j);
            if (it.key > s->lb) s->lb = it.key;
        } else if (!(en.e & REF_POINT) && !(hd__box_size2(&s->ta.node[en.e]->box) < biggest)) {
            /* written as !(<) so that a NaN box (points changed during the
             * call, which hausdorff.h forbids) expands e: refining a list of
             * points alone would queue the same entry again, for ever */
            rc = expand(s, &en);
        } else {
            rc = refine(s, &en);
        }
        release(s, it.val);
    }
    return rc;
}

int hd__inc(const hd__job_t *job, hd_result_t *out, hd_error_t *err) {
    inc_t s;
    memset(&s, 0, sizeof s);
    hd__heap_init(&s.queue, 1);
    hd__best_init(&s.best);
    s.lb = 0.0;
    int rc = hd__octree_build(&s.ta, job->a, job->na, INC_MAX_DEPTH, INC_LEAF, err);
    if (rc != HD_OK) return rc;
    rc = hd__octree_build(&s.tb, job->b, job->nb, INC_MAX_DEPTH, INC_LEAF, err);
    if (rc != HD_OK) {
        hd__octree_free(&s.ta);
        return rc;
    }
    rc = run(&s);
    if (rc == HD_OK) {
        hd__best_store(&s.best, out);
        out->stats.distance_evals = s.evals;
        out->stats.nodes_visited = s.visited;
    } else {
        hd__err(err, rc, "inc: %s", hd_strerror(rc));
    }
    for (size_t k = 0; k < s.n_ent; k++) free(s.ent[k].L);
    free(s.ent);
    free(s.free_slot);
    free(s.scratch);
    free(s.lo);
    free(s.hi);
    hd__heap_free(&s.queue);
    hd__octree_free(&s.ta);
    hd__octree_free(&s.tb);
    return rc;
}
