/*
 * engine_search.c -- exact nearest-neighbour search in the engine's index,
 * with early break, a starting bucket, and a cache of gathered buckets.
 *
 * The search is the branch-and-bound of OHD (paper, Algorithm 6, line 6:
 * NNDist(x, Octree_B)) over the implicit tree of index.h, visiting the
 * nearer child first, combined with EARLYBREAK's break (Algorithm 2, lines
 * 8-10; PointToPoints, Algorithm 5, lines 4-6): when the caller only needs
 * to know whether some point of B lies strictly within a bound, the search
 * stops at the first such point.
 *
 * Exactness.  Boxes enclose their points exactly, so a node whose computed
 * lower bound hd__box_lb2 is strictly greater than the best squared distance
 * found cannot hold a nearer point, nor one at the same distance; a node
 * whose bound equals the best is still visited, because it may hold a point
 * at the same distance with a smaller original index.  Within a bucket the
 * minimum is taken over the exact hd__d2s values and ties go to the smallest
 * original index.  The result is therefore the exact nearest squared
 * distance and the smallest index attaining it, whatever the visiting order,
 * the starting bucket or the cache contents.
 *
 * Speed.  The index keeps no copy of the coordinates; a bucket's points are
 * gathered through the permutation into a small direct-mapped cache (per
 * thread) as three arrays, and the distance loop over a bucket is a plain
 * loop over those arrays that the compiler vectorises (without fused
 * multiply-add: the build passes -ffp-contract=off).
 */
#include "index.h"

#include <math.h>

void hd__bcache_init(hd__bcache_t *c) {
    for (int s = 0; s < HD__CACHE_SLOTS; s++) c->tag[s] = HD__NONE;
}

int hd__bucket_get(const hd__tree_t *t, hd__bcache_t *c, size_t b, const double **x,
                   const double **y, const double **z) {
    size_t s = b % HD__CACHE_SLOTS;
    size_t first = b * HD__BUCKET;
    size_t m = t->n - first < HD__BUCKET ? t->n - first : HD__BUCKET;
    if (c->tag[s] != b) {
        for (size_t k = 0; k < m; k++) {
            double p[3];
            hd__src_get(&t->src, t->perm[first + k], p);
            c->x[s][k] = p[0];
            c->y[s][k] = p[1];
            c->z[s][k] = p[2];
        }
        c->tag[s] = b;
    }
    *x = c->x[s];
    *y = c->y[s];
    *z = c->z[s];
    return (int)m;
}

/* Scan bucket b: update *hit (smaller distance, or equal distance with a
 * smaller original index). */
static inline void scan_bucket(const hd__tree_t *t, hd__bcache_t *c, size_t b, const double q[3],
                               hd__hit_t *hit, hd__counts_t *n) {
    const double *x, *y, *z;
    int m = hd__bucket_get(t, c, b, &x, &y, &z);
    double d[HD__BUCKET];
    const double qx = q[0], qy = q[1], qz = q[2];
    for (int k = 0; k < m; k++) d[k] = hd__d2s(qx, qy, qz, x[k], y[k], z[k]);
    double dmin = INFINITY;
    for (int k = 0; k < m; k++) dmin = d[k] < dmin ? d[k] : dmin;
    n->evals += (uint64_t)m;
    if (dmin > hit->d2) return;
    const uint32_t *perm = t->perm + b * HD__BUCKET;
    for (int k = 0; k < m; k++) {
        if (d[k] == dmin && (dmin < hit->d2 || perm[k] < hit->j)) {
            hit->d2 = dmin;
            hit->j = perm[k];
            hit->bucket = b;
            hit->p[0] = x[k];
            hit->p[1] = y[k];
            hit->p[2] = z[k];
        }
    }
}

void hd__tree_nearest(const hd__tree_t *t, hd__bcache_t *c, const double q[3], double stop2,
                      size_t hint, hd__hit_t *hit, hd__counts_t *n) {
    hit->d2 = INFINITY;
    hit->j = HD__NONE;
    hit->bucket = HD__NONE;
    if (hint != HD__NONE) {
        scan_bucket(t, c, hint, q, hit, n);
        if (hit->d2 < stop2) return;
    }
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
        visited++;
        if (l == 0) {
            if (i != hint) {
                scan_bucket(t, c, i, q, hit, n);
                if (hit->d2 < stop2) break;
            }
            continue;
        }
        size_t a = 2 * i, b = 2 * i + 1;
        double da = hd__box_lb2(hd__tree_box(t, l - 1, a), q);
        if (b >= t->count[l - 1]) {
            if (da <= hit->d2) stack[sp].level = l - 1, stack[sp].i = a, stack[sp].lb2 = da, sp++;
            continue;
        }
        double db = hd__box_lb2(hd__tree_box(t, l - 1, b), q);
        /* Push the farther child first so the nearer one is searched first. */
        if (da > db) {
            size_t s = a;
            a = b;
            b = s;
            double u = da;
            da = db;
            db = u;
        }
        if (db <= hit->d2) stack[sp].level = l - 1, stack[sp].i = b, stack[sp].lb2 = db, sp++;
        if (da <= hit->d2) stack[sp].level = l - 1, stack[sp].i = a, stack[sp].lb2 = da, sp++;
    }
    n->nodes += visited;
}
