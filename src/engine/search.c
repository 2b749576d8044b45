/*
 * search.c -- exact nearest-neighbour search in the engine's index,
 * with early break and a starting bucket, reading exact coordinates only
 * where the quantised copy cannot decide.
 *
 * The search is the branch-and-bound of OHD (paper, Algorithm 6, line 6:
 * NNDist(x, Octree_B)) over the implicit tree of engine.h, visiting the
 * nearer child first, combined with EARLYBREAK's break (Algorithm 2, lines
 * 8-10; PointToPoints, Algorithm 5, lines 4-6): when the caller only needs
 * to know whether some point lies strictly within a bound, the search stops
 * at the first proof of one.
 *
 * In a bucket, the squared distance c~ from q to every dequantised point is
 * computed first (a short loop the compiler vectorises; no fused
 * multiply-add, the build passes -ffp-contract=off).  Then:
 *  - c~ < hd__kill_below(stop2, err) proves that the exact squared distance
 *    is < stop2: the search stops (early break) without reading the point;
 *  - a point with c~ > hd__may_reach(best, err) provably lies farther than
 *    the best exact distance so far and is skipped;
 *  - every other point is read exactly (through the permutation) and its
 *    exact squared distance hd__d2 is compared, the smallest original index
 *    winning ties.  The point with the smallest c~ is read first, so `best`
 *    tightens before the others are judged.
 * Nodes are pruned with the exact lower bound hd__box_lb2 of their exact
 * boxes, only when it is strictly greater than the best exact distance (a
 * node at equal distance may hold a tie with a smaller index).
 *
 * So the result is the exact nearest squared distance with the smallest
 * index attaining it, or a proof that some point is strictly within stop2
 * (or within tie2), whatever the visiting order and the starting bucket.
 */
#include "engine/tree.h"

#include <assert.h>
#include <math.h>

typedef struct {
    const hd__tree_t *t;
    const double *q;
    double stop2, tie2, kill2; /* kill2 = max(stop2, tie2): what a proof needs */
    hd__hit_t *hit;
    hd__counts_t *n;
} search_t;

/* Read point k of bucket b exactly and offer it; returns 1 when the search
 * may stop. */
static inline int exact_point(search_t *s, size_t b, int k) {
    const hd__tree_t *t = s->t;
    hd__hit_t *hit = s->hit;
    assert(k < hd__bucket_size(t, b));
    size_t j = t->perm[b * HD__BUCKET + (size_t)k];
    assert(j < t->n);
    double p[3];
    hd__src_get(&t->src, j, p);
    double d = hd__d2(s->q, p);
    s->n->exact++;
    if (d < hit->d2 || (d == hit->d2 && j < hit->j)) {
        hit->d2 = d;
        hit->j = j;
        hit->bucket = b;
        hit->p[0] = p[0], hit->p[1] = p[1], hit->p[2] = p[2];
        hit->perr = 0.0;
    }
    return hit->d2 < s->stop2 || hit->d2 <= s->tie2;
}

/* Scan bucket b; returns 1 when the search may stop. */
HD__HOT static int scan_bucket(search_t *s, size_t b) {
    const hd__tree_t *t = s->t;
    double x[HD__BUCKET], y[HD__BUCKET], z[HD__BUCKET], c[HD__BUCKET];
    int m = hd__bucket_decode(t, b, x, y, z);
    const double qx = s->q[0], qy = s->q[1], qz = s->q[2];
    for (int k = 0; k < HD__BUCKET; k++) c[k] = hd__d2s(qx, qy, qz, x[k], y[k], z[k]);
    s->n->evals += (uint64_t)m;
    int arg = hd__find(c, hd__min32(c));
    assert(arg < m); /* the padding repeats point 0, so a real point comes first */
    double err = t->bucket[b].err;
    if (c[arg] < hd__kill_below(s->kill2, err)) {
#ifndef NDEBUG
        /* The early break's proof: the point, read exactly, lies strictly
         * within kill2 (NaN only if the caller broke the contract). */
        double e[3];
        hd__src_get(&t->src, t->perm[b * HD__BUCKET + (size_t)arg], e);
        assert(!(hd__d2(s->q, e) >= s->kill2));
#endif
        hd__hit_t *hit = s->hit;
        hit->killed = 1;
        hit->bucket = b;
        hit->p[0] = x[arg], hit->p[1] = y[arg], hit->p[2] = z[arg];
        hit->perr = err;
        return 1;
    }
    if (c[arg] > hd__may_reach(s->hit->d2, err)) return 0;
    if (exact_point(s, b, arg)) return 1;
    double reach = hd__may_reach(s->hit->d2, err);
    for (int k = 0; k < m; k++) {
        if (k == arg || c[k] > reach) continue;
        if (exact_point(s, b, k)) return 1;
        reach = hd__may_reach(s->hit->d2, err);
    }
    return 0;
}

/* Squared distance from q to the centre of box b (a visiting-order hint). */
static inline double centre2(const hd__box_t *b, const double q[3]) {
    double d = 0;
    for (int k = 0; k < 3; k++) {
        double u = 0.5 * (b->lo[k] + b->hi[k]) - q[k];
        d += u * u;
    }
    return d;
}

void hd__tree_nearest(const hd__tree_t *t, const double q[3], double stop2, double tie2,
                      size_t hint, hd__hit_t *hit, hd__counts_t *n) {
    search_t s;
    s.t = t;
    s.q = q;
    s.stop2 = stop2;
    s.tie2 = tie2;
    s.kill2 = stop2 > tie2 ? stop2 : tie2;
    s.hit = hit;
    s.n = n;
    hit->d2 = INFINITY;
    hit->killed = 0;
    hit->j = HD__NONE;
    hit->bucket = HD__NONE;
    if (hint != HD__NONE && scan_bucket(&s, hint)) return;
    struct {
        int level;
        size_t i;
        double lb2;
    } stack[2 * HD__MAX_LEVELS + 2];
    int sp = 0;
    stack[0].level = t->levels - 1;
    stack[0].i = 0;
    stack[0].lb2 = 0.0;
    sp = 1;
    uint64_t visited = 0;
    while (sp > 0) {
        sp--;
        if (stack[sp].lb2 > hit->d2) continue;
        int l = stack[sp].level;
        size_t i = stack[sp].i;
        assert(l >= 0 && l < t->levels && i < t->count[l]);
        visited++;
        if (l == 0) {
            if (i != hint && scan_bucket(&s, i)) break;
            continue;
        }
        size_t a = 2 * i, b = 2 * i + 1;
        double da = hd__box_lb2(hd__tree_box(t, l - 1, a), q);
        if (b >= t->count[l - 1]) {
            if (da <= hit->d2) stack[sp].level = l - 1, stack[sp].i = a, stack[sp].lb2 = da, sp++;
            continue;
        }
        double db = hd__box_lb2(hd__tree_box(t, l - 1, b), q);
        /* Push the farther child first so the nearer one is searched first;
         * when both bounds are equal (typically 0: q lies in both boxes),
         * the child whose centre is nearer goes first. */
        if (da > db || (da == db && centre2(hd__tree_box(t, l - 1, a), q) >
                                        centre2(hd__tree_box(t, l - 1, b), q))) {
            size_t u = a;
            a = b;
            b = u;
            double v = da;
            da = db;
            db = v;
        }
        if (db <= hit->d2) stack[sp].level = l - 1, stack[sp].i = b, stack[sp].lb2 = db, sp++;
        if (da <= hit->d2) stack[sp].level = l - 1, stack[sp].i = a, stack[sp].lb2 = da, sp++;
    }
    n->nodes += visited;
}
