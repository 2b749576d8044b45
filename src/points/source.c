/*
 * source.c -- where a set's coordinates come from, and the radix sort that
 * orders points by Morton key.
 *
 * A source (hd__src_t) reads point k of a caller's view as three doubles,
 * widening floats exactly and applying the optional transform in the
 * documented order; the kind (packed doubles, packed floats, any strides)
 * lets the hot loops skip the general path.  The view is borrowed: nothing
 * is copied.
 *
 * The radix sort is least-significant-digit first on bits 32..61 of 64-bit
 * words (a 30-bit Morton key above a 32-bit point index): three stable
 * counting passes of 10 bits, each counted and scattered in parallel parts
 * whose offsets come from a prefix sum in part order, so the result is the
 * same at any thread count.  With one part, the three digits are counted
 * in one read of the words before the first pass (a pass permutes the
 * words, which leaves every digit's counts as they were).  Stability makes
 * equal keys keep increasing index order, which is what makes every order
 * built on it a function of the input alone.  The engine's builds, the index's queries and the
 * all-nearest structures all sort with it.
 */
#include "points/points.h"

#include <stdlib.h>
#include <string.h>

/* Entry v: bit i of v moved to bit 3i. */
#define S1(v) ((((v)&1u) | ((v)&2u) << 2 | ((v)&4u) << 4 | ((v)&8u) << 6))
#define S3(v) (S1(v) | S1((v) >> 4) << 12 | S1((v) >> 8) << 24)
#define R8(b) S3(b), S3(b + 1), S3(b + 2), S3(b + 3), S3(b + 4), S3(b + 5), S3(b + 6), S3(b + 7)
#define R64(b) R8(b), R8(b + 8), R8(b + 16), R8(b + 24), R8(b + 32), R8(b + 40), R8(b + 48), R8(b + 56)
#define R256(b) R64(b), R64(b + 64), R64(b + 128), R64(b + 192)
const uint32_t hd__spread_table[1024] = {R256(0u), R256(256u), R256(512u), R256(768u)};
#undef R256
#undef R64
#undef R8
#undef S3
#undef S1

/* hd__key_cell's value: u lies in [0, 1023] after the clamps, where the
 * signed conversion (one instruction, which vectorises) equals the
 * unsigned one (a sequence of a dozen). */
HD__INLINE uint32_t key_cell(double v, double lo, double scale) {
    double u = (v - lo) * scale;
    u = u < 1023.0 ? u : 1023.0;
    u = u > 0 ? u : 0;
    return (uint32_t)(int32_t)u;
}

/* hd__spread10's value by shifts and masks (which vectorise; the table's
 * reads do not). */
HD__INLINE uint32_t spread10(uint32_t v) {
    v = (v | v << 16) & 0x030000ffu;
    v = (v | v << 8) & 0x0300f00fu;
    v = (v | v << 4) & 0x030c30c3u;
    return (v | v << 2) & 0x09249249u;
}

/* The grid in locals, so that the stores cannot be taken to change it. */
HD__HOT void hd__keys_f64(const double *xyz, const hd__keygrid_t *grid, size_t lo, size_t hi,
                          uint64_t *restrict keys) {
    double l0 = grid->lo[0], l1 = grid->lo[1], l2 = grid->lo[2], sc = grid->scale;
    for (size_t i = lo; i < hi; i++) {
        const double *q = xyz + 3 * i;
        uint32_t k = spread10(key_cell(q[0], l0, sc)) | spread10(key_cell(q[1], l1, sc)) << 1 |
                     spread10(key_cell(q[2], l2, sc)) << 2;
        keys[i] = (uint64_t)k << 32 | (uint64_t)i;
    }
}

void hd__src_init(hd__src_t *s, const hd_points_t *p, const hd_transform_t *T) {
    ptrdiff_t el = p->dtype == HD_FLOAT32 ? (ptrdiff_t)sizeof(float) : (ptrdiff_t)sizeof(double);
    s->base = p->data;
    s->dtype = p->dtype;
    s->cs = p->cstride ? p->cstride : el;
    s->ps = p->stride ? p->stride : 3 * el;
    s->T = T;
    s->kind = HD__SRC_ANY;
    if (s->cs == el && s->ps == 3 * el) s->kind = p->dtype == HD_FLOAT32 ? HD__SRC_F32 : HD__SRC_F64;
}

/* ---- parallel LSD radix sort on bits 32..61 ------------------------------- */

#define RADIX_BITS 10
#define RADIX (1u << RADIX_BITS)
#define MAX_SORT_THREADS 64

typedef struct {
    uint64_t *src, *dst;
    size_t n;
    int parts, shift;
    size_t (*hist)[RADIX];
} radix_ctx;

static void radix_count(void *vctx, size_t part, int worker) {
    (void)worker;
    radix_ctx *c = vctx;
    size_t lo = c->n * part / (size_t)c->parts, hi = c->n * (part + 1) / (size_t)c->parts;
    size_t *h = c->hist[part];
    memset(h, 0, RADIX * sizeof *h);
    for (size_t k = lo; k < hi; k++) h[(c->src[k] >> c->shift) & (RADIX - 1)]++;
}

static void radix_scatter(void *vctx, size_t part, int worker) {
    (void)worker;
    radix_ctx *c = vctx;
    size_t lo = c->n * part / (size_t)c->parts, hi = c->n * (part + 1) / (size_t)c->parts;
    size_t *h = c->hist[part]; /* now the write positions */
    for (size_t k = lo; k < hi; k++) {
        uint64_t v = c->src[k];
        c->dst[h[(v >> c->shift) & (RADIX - 1)]++] = v;
    }
}

int hd__radix_sort(uint64_t **a, uint64_t **tmp, size_t n, int threads) {
    int parts = threads;
    if (parts > MAX_SORT_THREADS) parts = MAX_SORT_THREADS;
    parts = hd__parts_for(n, parts);
    size_t(*hist)[RADIX] = hd__malloc_array((size_t)parts, sizeof *hist);
    if (!hist) return HD_ENOMEM;
    radix_ctx c;
    c.n = n;
    c.parts = parts;
    c.hist = hist;
    /* One part: the three digits' counts in one read of the words (a
     * permutation does not change them), not one read a pass. */
    size_t (*all)[RADIX] = NULL;
    if (parts == 1 && (all = hd__calloc_array(3, sizeof *all)) != NULL) {
        const uint64_t *w = *a;
        for (size_t k = 0; k < n; k++) {
            uint64_t v = w[k];
            all[0][(v >> 32) & (RADIX - 1)]++;
            all[1][(v >> (32 + RADIX_BITS)) & (RADIX - 1)]++;
            all[2][(v >> (32 + 2 * RADIX_BITS)) & (RADIX - 1)]++;
        }
    }
    for (int pass = 0; pass < 3; pass++) {
        c.src = *a;
        c.dst = *tmp;
        c.shift = 32 + RADIX_BITS * pass;
        if (all) memcpy(hist[0], all[pass], sizeof all[pass]);
        else hd__parallel_for(parts, (size_t)parts, radix_count, &c);
        size_t sum = 0;
        for (unsigned d = 0; d < RADIX; d++)
            for (int p = 0; p < parts; p++) {
                size_t v = hist[p][d];
                hist[p][d] = sum;
                sum += v;
            }
        hd__parallel_for(parts, (size_t)parts, radix_scatter, &c);
        uint64_t *s = *a;
        *a = *tmp;
        *tmp = s;
    }
    free(all);
    free(hist);
    return HD_OK;
}

