/*
 * tree.h -- private to src/engine/: the bucket trees' inner workings that
 * build.c, search.c, walk.c and engine.c share (engine.h has the tree and
 * its search for the layers above): the pair build, node boxes, the
 * quantised buckets' decoding, the vector kernels over a bucket, and the
 * proofs from approximations.
 */
#ifndef HD_ENGINE_TREE_H
#define HD_ENGINE_TREE_H

#include "engine/engine.h"

#include <assert.h>

/* Both trees of a call at once, from `pool` (kept blocks are given back
 * first), in the order that holds the least memory at once: both sorts
 * (the larger set first), each leaving only its perm, fkey and room for
 * its boxes, then both quantised copies (one block, the second tree's q
 * borrowed from the first's: free the two together) and boxes.  The pool
 * then holds at most max(16 n0, 7.4 n0 + max(8 n0, 6 (n0 + n1)) + 8 n1,
 * 13.4 (n0 + n1)) bytes, plus pages lost to rounding, with n0 the larger
 * set (docs/engine.md, "Threads and memory"). */
int hd__tree_build_pair(hd__tree_t t[2], const hd__src_t src[2], const size_t n[2],
                        const hd__box_t grid_box[2], int threads, hd__reuse_t *pool, hd_error_t *err);

HD__INLINE const hd__box_t *hd__tree_box(const hd__tree_t *t, int level, size_t i) {
    return level == 0 ? &t->bucket[i].box : &t->nodes[t->off[level] + i];
}

HD__INLINE int hd__bucket_size(const hd__tree_t *t, size_t b) {
    assert(b < t->nb); /* so the size is 1 .. HD__BUCKET */
    size_t first = b * HD__BUCKET;
    return (int)(t->n - first < HD__BUCKET ? t->n - first : HD__BUCKET);
}

/* The dequantised (approximate) coordinates of bucket b, in three arrays;
 * returns the bucket's point count.  Point k of the bucket lies within
 * t->bucket[b].err of (x[k], y[k], z[k]). */
HD__INLINE int hd__bucket_decode(const hd__tree_t *t, size_t b, double *x, double *y,
                                 double *z) {
    const hd__bucket_t *bk = &t->bucket[b];
    const uint16_t *q = t->q + b * 3 * HD__BUCKET;
    const double unit = 1.0 / 65535.0;
    double sx = (bk->box.hi[0] - bk->box.lo[0]) * unit;
    double sy = (bk->box.hi[1] - bk->box.lo[1]) * unit;
    double sz = (bk->box.hi[2] - bk->box.lo[2]) * unit;
    int m = hd__bucket_size(t, b);
    for (int k = 0; k < HD__BUCKET; k++) {
        x[k] = bk->box.lo[0] + (double)q[k] * sx;
        y[k] = bk->box.lo[1] + (double)q[HD__BUCKET + k] * sy;
        z[k] = bk->box.lo[2] + (double)q[2 * HD__BUCKET + k] * sz;
    }
#ifndef NDEBUG
    /* A short bucket is padded with copies of its point 0 (hd__min32 and
     * hd__find rely on it: padding never comes before a real point). */
    for (int k = m; k < HD__BUCKET; k++)
        assert(q[k] == q[0] && q[HD__BUCKET + k] == q[HD__BUCKET] &&
               q[2 * HD__BUCKET + k] == q[2 * HD__BUCKET]);
#endif
    return m;
}

/* The smallest of c[0..HD__BUCKET).  A short bucket is padded with copies
 * of its point 0 (build.c), whose values equal c[0], so padding never
 * changes the minimum.  Eight running minima in two vectors of four (GCC
 * vector extensions: one compare and one select per four values, where a
 * scalar loop compiles to one vminsd per value; callgrind on hd_bench
 * counts both, docs/benchmarks.md); each lane keeps m = c < m ? c : m, the
 * same value as the scalar loop for any input. */
typedef double hd__v4d __attribute__((vector_size(32), aligned(8)));
typedef int64_t hd__v4l __attribute__((vector_size(32), aligned(8)));

/* m = c < m ? c : m in each lane (a macro: a function returning a 32-byte
 * vector has a different ABI with and without AVX, which GCC warns about). */
#define HD__V4_MIN(m, c)                                                           \
    do {                                                                           \
        hd__v4l lt_ = (c) < (m);                                                   \
        (m) = (hd__v4d)(((hd__v4l)(c) & lt_) | ((hd__v4l)(m) & ~lt_));             \
    } while (0)

/* m = c > m ? c : m in each lane. */
#define HD__V4_MAX(m, c)                                                           \
    do {                                                                           \
        hd__v4l gt_ = (c) > (m);                                                   \
        (m) = (hd__v4d)(((hd__v4l)(c) & gt_) | ((hd__v4l)(m) & ~gt_));             \
    } while (0)

HD__INLINE double hd__min32(const double *c) {
    hd__v4d m0, m1, a, b;
    __builtin_memcpy(&m0, c, sizeof m0);
    __builtin_memcpy(&m1, c + 4, sizeof m1);
    for (int k = 8; k < HD__BUCKET; k += 8) {
        __builtin_memcpy(&a, c + k, sizeof a);
        __builtin_memcpy(&b, c + k + 4, sizeof b);
        HD__V4_MIN(m0, a);
        HD__V4_MIN(m1, b);
    }
    HD__V4_MIN(m0, m1);
    double x = m0[0] < m0[1] ? m0[0] : m0[1], y = m0[2] < m0[3] ? m0[2] : m0[3];
    return x < y ? x : y;
}

/* The first position of value v in c (v occurs, and is a real point) --
 * unless the caller's points changed during the call (hausdorff.h forbids
 * it, but a Python thread can do it): a NaN written after validation makes
 * v NaN, found nowhere, and then position 0 (always a real point) keeps
 * the search in bounds.  The answer is then meaningless, but nothing is
 * read out of bounds. */
HD__INLINE int hd__find(const double *c, double v) {
    /* A mask of the equal values, without an early exit: the loop
     * vectorises (compare, move mask), where a search loop does not. */
    uint32_t m = 0;
    for (int k = 0; k < HD__BUCKET; k++) m |= (uint32_t)(c[k] == v) << k;
    assert(m != 0 || __builtin_isnan(v)); /* some c[k] == v unless v is NaN */
    return m ? __builtin_ctz(m) : 0;
}

/* ---- proofs from approximations -------------------------------------------- */
/* Relative slack that covers every rounding in the computed squared
 * distances (a few units of 2^-53) and in these thresholds, many times over;
 * and an absolute floor below which squared distances may have underflowed. */
#define HD__SLACK 1e-12
#define HD__TINY 1e-280

/* A computed squared distance c~ = hd__d2s(q, p~) < hd__kill_below(lim, E),
 * where the true point p lies within E of p~ (and q is exact, or E includes
 * q's own error), proves that the computed hd__d2s(q, p) < lim.  Returns 0
 * (nothing is proven, c~ >= 0) when lim is too small. */
HD__INLINE double hd__kill_below(double lim, double E) {
    if (!(lim > HD__TINY)) return 0.0;
    double r = __builtin_sqrt(lim) * (1 - HD__SLACK) - E * (1 + HD__SLACK);
    if (r <= 0) return 0.0;
    double t = r * r * (1 - HD__SLACK);
    /* With an error bound E >= 0, the threshold never exceeds lim. */
    assert(!(E >= 0) || !(t > lim));
    return t > HD__TINY ? t : 0.0;
}

/* A computed c~ > hd__may_reach(best, E) proves hd__d2s(q, p) > best. */
HD__INLINE double hd__may_reach(double best, double E) {
    double r = __builtin_sqrt(best) * (1 + HD__SLACK) + E * (1 + HD__SLACK);
    double t = r * r * (1 + HD__SLACK) + HD__TINY;
    assert(!(E >= 0) || !(t < best)); /* with E >= 0, a point beyond it is beyond best */
    return t;
}

#endif /* HD_ENGINE_TREE_H */
