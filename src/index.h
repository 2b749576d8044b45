/*
 * index.h -- the engine's spatial index of one point set (internal).
 *
 * An index never copies coordinates: it borrows the caller's view and keeps
 * a permutation (4 bytes per point) that lists the points in Morton order,
 * cut into buckets of HD__BUCKET consecutive points, plus the exact bounding
 * box of every bucket and of every node of an implicit binary tree over the
 * buckets (about 6 bytes per point).  Coordinates are read through the
 * permutation ("gathered") and widened to double, with an optional transform
 * applied on the fly in the documented order, so every distance is computed
 * from exactly the doubles the brute force uses.
 *
 * Tree layout: level 0 holds the buckets; node i of level l+1 covers nodes
 * 2i and 2i+1 of level l (the second may not exist); the top level has one
 * node.  Node (l, i) covers buckets [i << l, (i + 1) << l) and points
 * [(i << l) * HD__BUCKET, ...) of the Morton order.
 */
#ifndef HD_INDEX_H
#define HD_INDEX_H

#include "internal.h"

/* Points per bucket. */
#define HD__BUCKET 16
/* Most tree levels (2^40 buckets is far beyond 2^32 points). */
#define HD__MAX_LEVELS 40

/* Where the coordinates of a set come from. */
typedef struct hd__src {
    const char *base;
    ptrdiff_t ps, cs;           /* point and coordinate strides in bytes */
    int kind;                   /* 0: packed double, 1: packed float, 2: any */
    hd_dtype_t dtype;
    const hd_transform_t *T;    /* applied to every point read, or NULL */
} hd__src_t;

void hd__src_init(hd__src_t *s, const hd_points_t *p, const hd_transform_t *T);

/* Point k of the source (original numbering), transformed if T is set. */
HD__INLINE void hd__src_get(const hd__src_t *s, size_t k, double out[3]) {
    double p[3];
    if (s->kind == 0) {
        const double *q = (const double *)(const void *)(s->base + (ptrdiff_t)k * 24);
        p[0] = q[0], p[1] = q[1], p[2] = q[2];
    } else if (s->kind == 1) {
        const float *q = (const float *)(const void *)(s->base + (ptrdiff_t)k * 12);
        p[0] = q[0], p[1] = q[1], p[2] = q[2];
    } else {
        const char *b = s->base + (ptrdiff_t)k * s->ps;
        for (int c = 0; c < 3; c++) {
            if (s->dtype == HD_FLOAT32) {
                float v;
                __builtin_memcpy(&v, b + c * s->cs, sizeof v);
                p[c] = v;
            } else {
                __builtin_memcpy(&p[c], b + c * s->cs, sizeof(double));
            }
        }
    }
    if (s->T) hd__transform_apply(s->T, p, out);
    else out[0] = p[0], out[1] = p[1], out[2] = p[2];
}

typedef struct hd__tree {
    size_t n;                       /* points */
    hd__src_t src;
    uint32_t *perm;                 /* n original indices in Morton order */
    size_t nb;                      /* buckets: ceil(n / HD__BUCKET) */
    int levels;                     /* level 0 .. levels-1; top has 1 node */
    size_t count[HD__MAX_LEVELS];   /* nodes per level */
    size_t off[HD__MAX_LEVELS];     /* first box of each level in boxes[] */
    hd__box_t *boxes;               /* exact boxes of all nodes */
    hd__box_t box;                  /* the set's box (= the top node's) */
} hd__tree_t;

/* Build the index of n points read from `src` using `threads` threads.
 * The points must be valid (finite, within HD_MAX_COORD, also after the
 * transform).  n must be at most UINT32_MAX (HD_EOVERFLOW otherwise). */
int hd__tree_build(hd__tree_t *t, const hd__src_t *src, size_t n, int threads,
                   hd_error_t *err);
void hd__tree_free(hd__tree_t *t);
size_t hd__tree_memory(const hd__tree_t *t);

HD__INLINE const hd__box_t *hd__tree_box(const hd__tree_t *t, int level, size_t i) {
    return &t->boxes[t->off[level] + i];
}

/* ---- searching ----------------------------------------------------------- */

/* A small per-thread cache of gathered buckets (structure of arrays), so
 * that the searches of nearby query points read each bucket's scattered
 * coordinates once. */
#define HD__CACHE_SLOTS 32
typedef struct hd__bcache {
    size_t tag[HD__CACHE_SLOTS];
    double x[HD__CACHE_SLOTS][HD__BUCKET];
    double y[HD__CACHE_SLOTS][HD__BUCKET];
    double z[HD__CACHE_SLOTS][HD__BUCKET];
} hd__bcache_t;

void hd__bcache_init(hd__bcache_t *c);

/* The gathered coordinates of bucket b of t; returns its point count. */
int hd__bucket_get(const hd__tree_t *t, hd__bcache_t *c, size_t b, const double **x,
                   const double **y, const double **z);

/* What a nearest-neighbour search found. */
typedef struct hd__hit {
    double d2;       /* squared distance */
    size_t j;        /* original index in the searched set */
    size_t bucket;   /* bucket holding it (a hint for the next search) */
    double p[3];     /* its coordinates */
} hd__hit_t;

typedef struct hd__counts {
    uint64_t evals, nodes;
} hd__counts_t;

/* Exact nearest neighbour of q in t: *hit gets the smallest squared distance
 * and the smallest original index attaining it.  Bucket `hint` (or HD__NONE)
 * is searched first.  With stop2 > 0 the search may stop as soon as it has
 * found a point at squared distance < stop2 (strictly); then hit->d2 < stop2
 * and the hit is that point.  A result >= stop2 is always exact. */
void hd__tree_nearest(const hd__tree_t *t, hd__bcache_t *c, const double q[3], double stop2,
                      size_t hint, hd__hit_t *hit, hd__counts_t *n);

/* ---- the engine ---------------------------------------------------------------- */

/* h(A,B) over built indexes of A and B (engine.c), with `threads` threads. */
int hd__engine_trees(const hd__tree_t *ta, const hd__tree_t *tb, int threads,
                     hd_result_t *out, hd_error_t *err);

#endif /* HD_INDEX_H */
