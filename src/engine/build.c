/*
 * build.c -- building the engine's index of one point set: points
 * sorted along a Morton (Z-order) curve, cut into buckets, with exact boxes.
 *
 * Why Morton order.  The engine's work is dominated by reading points, and
 * a set whose points are listed along a space-filling curve has spatially
 * coherent buckets: consecutive query points are near each other, so a
 * search can start where the previous one ended, and the boxes of buckets
 * and of runs of buckets are small.  Sorting costs a few linear passes (a
 * radix sort), far less than the median splits of a kd-tree, and needs no
 * copy of the coordinates, only a permutation.
 *
 * Keys.  Each point gets a 30-bit Morton key from a 1024^3 grid of cubic
 * cells laid over the set's box (or over the box the caller gives, so that
 * two sets can share a cell size and line up); the key is packed above the
 * point's 32-bit original index, so sorting the 64-bit words sorts by
 * (key, index) and the order is a function of the input alone, at any
 * thread count.  The keys only decide the order: nothing exact depends on
 * them.  A cell holding more than a bucket of points (a dense cluster,
 * duplicates) is refined: its points are re-keyed on a grid over their own exact box and sorted again,
 * recursively, until every run of equal keys fits in a bucket or consists of
 * identical points.
 *
 * Boxes.  Every bucket's box is the exact box of its points, read as the
 * doubles the distance computations read (after the transform, if any);
 * every tree node's box is the union of its children's.  Boxes therefore
 * enclose their points exactly, which is what makes the pruning tests of
 * the searches exact without an epsilon (see points/points.h).
 *
 * Quantised copy.  Each bucket also keeps its points' coordinates as 16-bit
 * fractions of its box and `err`, a proven bound on the distance between a
 * point and its dequantised approximation (make_bucket), so that searches
 * can decide most questions without reading the scattered input.
 *
 * Memory.  The sort uses two arrays of 8 bytes per point; the result keeps
 * 4 bytes per point for the permutation, 6 for the quantised copy, 56 per
 * bucket of 32 for its box and err, 4 per bucket for its first key, and 48
 * per tree node (about one per bucket): 13.375 bytes per point, in two
 * blocks.  The permutation, the first keys and the boxes (7.4 bytes per
 * point) are written into the sort buffer the sort leaves spare, whose
 * pages past them go back to the system (hd__reuse_shrink; 2 MiB pages
 * only whole, so up to 2 MiB a block stays); the quantised
 * copy takes a kept sort buffer when one fits, shrunk the same way.  The
 * engine builds its two trees in two halves (hd__tree_build_pair): both
 * sorts first, the larger set's first, each leaving only its 7.4 bytes per
 * point, then both quantised copies, in one block, and boxes.  That block
 * is the buffer the first sort's keys end in (its tmp: the radix sort
 * makes three passes), given back after it and asked for at max(8 n0,
 * 6 (n0 + n1)) bytes so that it can take both copies: two blocks would
 * each keep a last 2 MiB page whole.  So at no time are more
 * than max(16 n0, 7.4 n0 + max(8 n0, 6 (n0 + n1)) + 8 n1, 13.375 (n0 + n1))
 * bytes held (n0 the larger set), at most 16 bytes per point of both sets,
 * plus pages lost to rounding and the pool's chunks; on sets of one size
 * 13.7.  The second tree's q lies in the first's block (q_borrowed): the
 * pair is freed together.
 */
#include "engine/tree.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- keys ------------------------------------------------------------------ */

#define SLICE 16384

typedef struct {
    const hd__src_t *src;
    size_t n;
    hd__keygrid_t grid;
    uint64_t *keys;
    hd__box_t *part_box;
} key_ctx;

static void box_task(void *vctx, size_t task, int worker) {
    (void)worker;
    key_ctx *c = vctx;
    size_t lo = task * SLICE, hi = lo + SLICE < c->n ? lo + SLICE : c->n;
    hd__box_t b;
    double p[3];
    hd__src_get(c->src, lo, p);
    for (int k = 0; k < 3; k++) b.lo[k] = b.hi[k] = p[k];
    for (size_t i = lo + 1; i < hi; i++) {
        hd__src_get(c->src, i, p);
        for (int k = 0; k < 3; k++) {
            b.lo[k] = p[k] < b.lo[k] ? p[k] : b.lo[k];
            b.hi[k] = p[k] > b.hi[k] ? p[k] : b.hi[k];
        }
    }
    c->part_box[task] = b;
}

HD__HOT static void key_task(void *vctx, size_t task, int worker) {
    (void)worker;
    key_ctx *c = vctx;
    size_t lo = task * SLICE, hi = lo + SLICE < c->n ? lo + SLICE : c->n;
    hd__src_keys(c->src, &c->grid, lo, hi, c->keys);
}

/* ---- refinement of crowded cells ------------------------------------------- */

static void insertion_sort(uint64_t *a, size_t n) {
    for (size_t i = 1; i < n; i++) {
        uint64_t v = a[i];
        size_t j = i;
        while (j > 0 && a[j - 1] > v) {
            a[j] = a[j - 1];
            j--;
        }
        a[j] = v;
    }
}

/* Re-key and sort the run a[0..m) (all with equal keys) on a grid over its
 * own box, then refine its crowded sub-runs.  tmp has room for m words. */
static int refine(const hd__src_t *src, uint64_t *a, uint64_t *tmp, size_t m, int depth) {
    hd__box_t b;
    double p[3];
    hd__src_get(src, (uint32_t)a[0], p);
    for (int k = 0; k < 3; k++) b.lo[k] = b.hi[k] = p[k];
    for (size_t i = 1; i < m; i++) {
        hd__src_get(src, (uint32_t)a[i], p);
        for (int k = 0; k < 3; k++) {
            b.lo[k] = p[k] < b.lo[k] ? p[k] : b.lo[k];
            b.hi[k] = p[k] > b.hi[k] ? p[k] : b.hi[k];
        }
    }
    hd__keygrid_t g;
    hd__keygrid_init(&g, &b);
    if (g.scale == 0.0 || depth > 200) return HD_OK; /* identical points */
    for (size_t i = 0; i < m; i++) {
        hd__src_get(src, (uint32_t)a[i], p);
        a[i] = (uint64_t)hd__key30(&g, p) << 32 | (a[i] & 0xffffffffu);
    }
    if (m <= 64) {
        insertion_sort(a, m);
    } else {
        uint64_t *x = a, *y = tmp;
        int rc = hd__radix_sort(&x, &y, m, 1);
        if (rc) return rc;
        if (x != a) memcpy(a, x, m * sizeof *a);
    }
    for (size_t s = 0; s < m;) {
        size_t e = s + 1;
        while (e < m && a[e] >> 32 == a[s] >> 32) e++;
        if (e - s > HD__BUCKET) {
            int rc = refine(src, a + s, tmp + s, e - s, depth + 1);
            if (rc) return rc;
        }
        s = e;
    }
    return HD_OK;
}

/* ---- buckets and boxes ------------------------------------------------------ */

typedef struct {
    hd__tree_t *t;
    int level;
} boxes_ctx;

#define BOX_TASK 512 /* buckets (or nodes) per task */

/* Bucket b: gather its points, take their exact box, quantise each
 * coordinate to 16 bits over the box, and measure the error of the
 * dequantised points (hd__bucket_decode) against the exact ones.  The
 * computed difference fl(x - x~) is within a factor (1 + 2^-53) of the true
 * one, so err = sqrt(3) * max |fl(x - x~)| * (1 + slack) bounds the true
 * Euclidean distance between a point and its approximation. */
HD__HOT static void make_bucket(hd__tree_t *t, size_t b) {
    size_t s = b * HD__BUCKET;
    int m = hd__bucket_size(t, b);
    double p[3][HD__BUCKET];
    if (t->src.kind != HD__SRC_ANY && b + 1 < t->nb) {
        /* The points are scattered in memory: ask for the next bucket's
         * points early so their loads overlap with this bucket's work. */
        ptrdiff_t el = hd__src_packed_stride(&t->src);
        size_t e = s + HD__BUCKET, pe = e + HD__BUCKET < t->n ? e + HD__BUCKET : t->n;
        for (size_t i = e; i < pe; i++) __builtin_prefetch(t->src.base + (ptrdiff_t)t->perm[i] * el);
    }
    for (int k = 0; k < m; k++) {
        double v[3];
        hd__src_get(&t->src, t->perm[s + (size_t)k], v);
        p[0][k] = v[0], p[1][k] = v[1], p[2][k] = v[2];
    }
    /* Pad a short bucket with copies of its first point, so that the loops
     * below run over whole buckets (and vectorise). */
    for (int k = m; k < HD__BUCKET; k++) p[0][k] = p[0][0], p[1][k] = p[1][0], p[2][k] = p[2][0];
    hd__bucket_t *bk = &t->bucket[b];
    uint16_t *q = t->q + b * 3 * HD__BUCKET;
    double err = 0;
    for (int c = 0; c < 3; c++) {
        const double *v = p[c];
        /* Four running extremes in a vector each (HD__V4_MIN/MAX: a compare
         * and a select per four values; GCC leaves the scalar ternaries of
         * these loops scalar): the same values as the scalar loops. */
        hd__v4d l4, h4, a;
        __builtin_memcpy(&l4, v, sizeof l4);
        h4 = l4;
        for (int k = 4; k < HD__BUCKET; k += 4) {
            __builtin_memcpy(&a, v + k, sizeof a);
            HD__V4_MIN(l4, a);
            HD__V4_MAX(h4, a);
        }
        double lo = l4[0], hi = h4[0];
        for (int r = 1; r < 4; r++) {
            lo = l4[r] < lo ? l4[r] : lo;
            hi = h4[r] > hi ? h4[r] : hi;
        }
        bk->box.lo[c] = lo;
        bk->box.hi[c] = hi;
        double step = (hi - lo) * (1.0 / 65535.0);
        double inv = step > 0 ? 1.0 / step : 0.0;
        /* Quantise, dequantise and measure four values at a time, with the
         * scalar code's operations in its order (a - lo, times inv, plus
         * 0.5, the smaller of that and 65535, truncated; lo + q * step, as
         * hd__bucket_decode computes it): the same values.  The largest |d|
         * is the larger of the largest d and the largest -d (both start
         * at 0). */
        typedef int32_t v4i __attribute__((vector_size(16), aligned(4)));
        const hd__v4d lo4 = {lo, lo, lo, lo}, step4 = {step, step, step, step},
                      inv4 = {inv, inv, inv, inv}, half4 = {0.5, 0.5, 0.5, 0.5},
                      top4 = {65535.0, 65535.0, 65535.0, 65535.0};
        int32_t qi[HD__BUCKET];
        hd__v4d dh = {0, 0, 0, 0}, dl = {0, 0, 0, 0};
        for (int k = 0; k < HD__BUCKET; k += 4) {
            __builtin_memcpy(&a, v + k, sizeof a);
            hd__v4d u = (a - lo4) * inv4 + half4, m = top4; /* u >= 0.5: v[k] >= lo */
            HD__V4_MIN(m, u);
            v4i qk = __builtin_convertvector(m, v4i);
            __builtin_memcpy(qi + k, &qk, sizeof qk);
            hd__v4d d = a - (lo4 + __builtin_convertvector(qk, hd__v4d) * step4);
            HD__V4_MAX(dh, d);
            HD__V4_MIN(dl, d);
        }
        for (int r = 0; r < 4; r++) {
            err = dh[r] > err ? dh[r] : err;
            err = -dl[r] > err ? -dl[r] : err;
        }
        for (int k = 0; k < HD__BUCKET; k++) q[c * HD__BUCKET + k] = (uint16_t)qi[k];
    }
    /* sqrt(3) rounded up, and slack for the rounding of this product. */
    bk->err = err * 1.7320508075688776 * (1 + 1e-12);
#ifndef NDEBUG
    /* What the searches' proofs rest on, for valid (finite) points: the box
     * encloses the bucket's points exactly, and each coordinate lies within
     * err / sqrt(3) of its dequantised copy (hd__bucket_decode), so each
     * point within err of it. */
    double x[HD__BUCKET], y[HD__BUCKET], z[HD__BUCKET];
    hd__bucket_decode(t, b, x, y, z);
    int finite = 1;
    for (int k = 0; k < m; k++)
        finite &= isfinite(p[0][k]) && isfinite(p[1][k]) && isfinite(p[2][k]);
    for (int k = 0; k < m && finite; k++) {
        const double a[3] = {x[k], y[k], z[k]};
        for (int c = 0; c < 3; c++) {
            assert(p[c][k] >= bk->box.lo[c] && p[c][k] <= bk->box.hi[c]);
            assert(fabs(p[c][k] - a[c]) * 1.7320508075688776 <= bk->err);
        }
    }
#endif
}

static void bucket_task(void *vctx, size_t task, int worker) {
    (void)worker;
    boxes_ctx *c = vctx;
    hd__tree_t *t = c->t;
    size_t lo = task * BOX_TASK, hi = lo + BOX_TASK < t->nb ? lo + BOX_TASK : t->nb;
    for (size_t b = lo; b < hi; b++) make_bucket(t, b);
}

static void node_boxes(void *vctx, size_t task, int worker) {
    (void)worker;
    boxes_ctx *c = vctx;
    hd__tree_t *t = c->t;
    int l = c->level;
    size_t lo = task * BOX_TASK, hi = lo + BOX_TASK < t->count[l] ? lo + BOX_TASK : t->count[l];
    for (size_t i = lo; i < hi; i++) {
        hd__box_t b = *hd__tree_box(t, l - 1, 2 * i);
        if (2 * i + 1 < t->count[l - 1]) hd__box_merge(&b, hd__tree_box(t, l - 1, 2 * i + 1));
        t->nodes[t->off[l] + i] = b;
    }
}

/* ---- the build ---------------------------------------------------------------- */

/* A tree's arrays live in two blocks: perm, then fkey, bucket and nodes
 * (written into the buffer the sort left spare, offsets rounded up to 64
 * bytes), and q alone. */
#define ALIGN64(x) (((x) + 63) & ~(size_t)63)

static size_t node_count(const hd__tree_t *t) {
    return t->levels > 1 ? t->off[t->levels - 1] + 1 : 0;
}

static size_t fkey_at(const hd__tree_t *t) { return ALIGN64(t->n * sizeof *t->perm); }
static size_t bucket_at(const hd__tree_t *t) { return ALIGN64(fkey_at(t) + t->nb * sizeof *t->fkey); }
static size_t nodes_at(const hd__tree_t *t) { return ALIGN64(bucket_at(t) + t->nb * sizeof *t->bucket); }
static size_t perm_bytes(const hd__tree_t *t) { return nodes_at(t) + node_count(t) * sizeof *t->nodes; }
static size_t q_bytes_of(size_t n) { return (n + HD__BUCKET - 1) / HD__BUCKET * 3 * HD__BUCKET * sizeof(uint16_t); }
static size_t q_bytes(const hd__tree_t *t) { return q_bytes_of(t->n); }

void hd__tree_free(hd__tree_t *t) {
    if (!t) return;
    hd__reuse_put(t->pool, t->perm); /* and fkey, bucket, nodes */
    if (!t->q_borrowed) hd__reuse_put(t->pool, t->q);
    t->fkey = NULL;
    t->perm = NULL;
    t->q = NULL;
    t->bucket = NULL;
    t->nodes = NULL;
}

size_t hd__tree_memory(const hd__tree_t *t) {
    return t->n * sizeof *t->perm +
           t->nb * (3 * HD__BUCKET * sizeof *t->q + sizeof *t->bucket + sizeof *t->fkey) +
           node_count(t) * sizeof *t->nodes;
}

/* The first half of a build: the keys, their sort, and from them perm and
 * fkey.  The sort's two buffers are the largest arrays of the build; the
 * permutation is written into the one the sort left spare, which then keeps
 * only perm, fkey and room for the boxes (hd__reuse_shrink; 7.4 of its 8
 * bytes a point), and the other goes back to the pool.  The first request
 * takes the block the previous sort kept, if it fits, and gives back any
 * other (hd__reuse_take): nothing the build cannot use is held through
 * it.  The block that goes back is made at least back_min bytes (the pair's
 * quantised copies, which take it last). */
static int tree_sort(hd__tree_t *t, const hd__src_t *src, size_t n, const hd__box_t *grid_box,
                     size_t back_min, int threads, hd__reuse_t *pool, hd_error_t *err) {
    memset(t, 0, sizeof *t);
    t->pool = pool;
    if (n == 0) return hd__err(err, HD_EEMPTY, "empty point set");
    if (n > UINT32_MAX)
        return hd__err(err, HD_EOVERFLOW,
                       "the auto engine indexes at most 4294967295 points per set, not %zu", n);
    if (threads < 1) threads = 1;
    t->n = n;
    t->src = *src;
    t->nb = (n + HD__BUCKET - 1) / HD__BUCKET;
    t->count[0] = t->nb;
    t->off[0] = 0;
    t->levels = 1;
    while (t->count[t->levels - 1] > 1) {
        int l = t->levels++;
        t->count[l] = (t->count[l - 1] + 1) / 2;
        t->off[l] = l == 1 ? 0 : t->off[l - 1] + t->count[l - 1];
    }

    key_ctx kc;
    kc.src = src;
    kc.n = n;
    size_t slices = (n + SLICE - 1) / SLICE;
    /* n <= UINT32_MAX: none of these sizes overflows. */
    size_t words = perm_bytes(t) / sizeof(uint64_t) + 1;
    if (words < n) words = n;
    size_t tmp_words = words > back_min / sizeof(uint64_t) ? words : back_min / sizeof(uint64_t) + 1;
    /* The sort's three passes leave the sorted keys in tmp's buffer and
     * keys' buffer spare: keys' becomes perm's block, and tmp's goes back
     * to the pool, for the next sort's tmp or the quantised copies. */
    uint64_t *tmp = hd__reuse_take(pool, tmp_words, sizeof *tmp);
    uint64_t *keys = hd__reuse_get(pool, words, sizeof *keys);
    kc.part_box = hd__malloc_array(slices, sizeof *kc.part_box);
    int rc = HD_OK;
    if (!keys || !tmp || !kc.part_box) {
        rc = HD_ENOMEM;
        goto done;
    }
    kc.keys = keys;
    if (grid_box) {
        t->box = *grid_box;
    } else {
        hd__parallel_for(threads, slices, box_task, &kc);
        t->box = kc.part_box[0];
        for (size_t s = 1; s < slices; s++) hd__box_merge(&t->box, &kc.part_box[s]);
    }
    hd__keygrid_init(&kc.grid, &t->box);
    t->grid = kc.grid;
    hd__parallel_for(threads, slices, key_task, &kc);
    if ((rc = hd__radix_sort(&keys, &tmp, n, threads))) goto done;
    /* The runs of equal keys longer than a bucket: the keys are sorted, so
     * such a run starting at s has key(s) = key(s + HD__BUCKET), and the
     * first k where that holds is a run's start (an earlier k of the same
     * run would hold it too).  Comparing each key with the one a bucket on
     * needs no branch that depends on the run lengths. */
    for (size_t s = 0; s + HD__BUCKET < n; s++) {
        if ((keys[s] ^ keys[s + HD__BUCKET]) >> 32) continue;
        assert(s == 0 || keys[s - 1] >> 32 != keys[s] >> 32);
        size_t e = s + HD__BUCKET + 1;
        while (e < n && keys[e] >> 32 == keys[s] >> 32) e++;
        /* Refining re-keys the run on its own grid; the run's key on
         * the set's grid is put back afterwards, so that the keys kept
         * (t->fkey) are all on one grid and never decrease. */
        uint64_t top = keys[s] >> 32 << 32;
        if ((rc = refine(src, keys + s, tmp + s, e - s, 0))) goto done;
        for (size_t i = s; i < e; i++) keys[i] = top | (keys[i] & 0xffffffffu);
        s = e - 1; /* the loop goes on at e */
    }
    /* tmp is spare now: perm and fkey go there, read from the sorted keys. */
    t->perm = (uint32_t *)tmp;
    t->fkey = (uint32_t *)((unsigned char *)tmp + fkey_at(t));
    t->bucket = (hd__bucket_t *)((unsigned char *)tmp + bucket_at(t));
    t->nodes = (hd__box_t *)((unsigned char *)tmp + nodes_at(t));
    tmp = NULL;
    for (size_t k = 0; k < n; k++) {
        t->perm[k] = (uint32_t)keys[k];
        assert(t->perm[k] < n);
    }
    for (size_t b = 0; b < t->nb; b++) t->fkey[b] = (uint32_t)(keys[b * HD__BUCKET] >> 32);
    hd__reuse_shrink(pool, t->perm, perm_bytes(t));
done:
    hd__reuse_put(pool, keys);
    hd__reuse_put(pool, tmp);
    free(kc.part_box);
    if (rc != HD_OK) {
        hd__tree_free(t);
        return hd__err(err, rc, "cannot allocate the index of %zu points", n);
    }
    return HD_OK;
}

/* The boxes, from perm and q. */
static void tree_boxes(hd__tree_t *t, int threads) {
    if (threads < 1) threads = 1;
    boxes_ctx bc;
    bc.t = t;
    bc.level = 0;
    hd__parallel_for(threads, (t->nb + BOX_TASK - 1) / BOX_TASK, bucket_task, &bc);
    for (int l = 1; l < t->levels; l++) {
        bc.level = l;
        hd__parallel_for(threads, (t->count[l] + BOX_TASK - 1) / BOX_TASK, node_boxes, &bc);
    }
}

/* The second half: the quantised copy and the boxes, from perm.  q takes
 * the block kept from a sort when one fits (given back beyond q's size),
 * and any other kept block is given back (hd__reuse_take). */
static int tree_finish(hd__tree_t *t, int threads, hd_error_t *err) {
    hd__reuse_t *pool = t->pool;
    t->q = hd__reuse_take(pool, q_bytes(t), 1);
    if (!t->q) {
        hd__tree_free(t);
        return hd__err(err, HD_ENOMEM, "cannot allocate the index of %zu points", t->n);
    }
    hd__reuse_shrink(pool, t->q, q_bytes(t));
    tree_boxes(t, threads);
    return HD_OK;
}

int hd__tree_build(hd__tree_t *t, const hd__src_t *src, size_t n, const hd__box_t *grid_box,
                   int threads, hd__reuse_t *pool, hd_error_t *err) {
    int rc = tree_sort(t, src, n, grid_box, 0, threads, pool, err);
    return rc ? rc : tree_finish(t, threads, err);
}

int hd__tree_build_pair(hd__tree_t t[2], const hd__src_t src[2], const size_t n[2],
                        const hd__box_t grid_box[2], int threads, hd__reuse_t *pool, hd_error_t *err) {
    memset(t, 0, 2 * sizeof *t);
    hd__reuse_trim(pool);
    const int order[2] = {n[1] > n[0], n[1] <= n[0]}; /* the larger set first */
    hd__tree_t *t0 = &t[order[0]], *t1 = &t[order[1]];
    /* Both quantised copies share one block, t0's first: the buffer the
     * first sort gives back is made large enough for it (q_pair bytes),
     * the second sort takes it as its own tmp when it may (a kept
     * block serves a request of at least a third of its size: 8 n1 >=
     * max(8 n0, q_pair) / 3), and the copies take it after that sort; else
     * the copies get a fresh block.  Either way one block, so one last 2 MiB
     * page kept whole instead of two. */
    size_t q0 = ALIGN64(q_bytes_of(n[order[0]])), q_pair = q0 + q_bytes_of(n[order[1]]);
    int rc = tree_sort(t0, &src[order[0]], n[order[0]], &grid_box[order[0]], q_pair, threads, pool, err);
    if (rc == HD_OK)
        rc = tree_sort(t1, &src[order[1]], n[order[1]], &grid_box[order[1]], 0, threads, pool, err);
    if (rc == HD_OK) {
        unsigned char *q = hd__reuse_take(pool, q_pair, 1);
        if (q) {
            hd__reuse_shrink(pool, q, q_pair);
            t0->q = (uint16_t *)q;
            t1->q = (uint16_t *)(q + q0);
            t1->q_borrowed = 1;
            tree_boxes(t0, threads);
            tree_boxes(t1, threads);
        } else {
            rc = hd__err(err, HD_ENOMEM, "cannot allocate the index of %zu + %zu points", n[0], n[1]);
        }
    }
    if (rc)
        for (int k = 0; k < 2; k++) hd__tree_free(&t[k]);
    return rc;
}
