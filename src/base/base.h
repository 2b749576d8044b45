/*
 * base.h -- the foundation every layer stands on (src/base/): result codes
 * and messages, checked allocation and arenas, seeded randomness, the
 * thread pool, clocks, selection and percentiles, and the binary heap.
 * Nothing here knows about points; everything above may use it.
 */
#ifndef HD_BASE_H
#define HD_BASE_H

#include "hausdorff.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define HD__NONE ((size_t)-1)

#if defined(__GNUC__)
#define HD__INLINE static inline __attribute__((always_inline))
#define HD__PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define HD__INLINE static inline
#define HD__PRINTF(f, a)
#endif

/* The few hottest loops (distances to a whole bucket) are compiled twice on
 * x86-64, for AVX2 and for the baseline, and the loader picks the version
 * the machine runs (GCC's function multi-versioning).  Neither version uses
 * fused multiply-add: -ffp-contract=off holds for both. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define HD__HOT __attribute__((target_clones("avx2", "default")))
#else
#define HD__HOT
#endif

/* ---- errors ----------------------------------------------------------- */
/* Set err (if not NULL) and return code. */
int hd__err(hd_error_t *err, int code, const char *fmt, ...) HD__PRINTF(3, 4);
int hd__verr(hd_error_t *err, int code, const char *fmt, va_list ap);
void hd__err_clear(hd_error_t *err);

/* ---- memory ------------------------------------------------------------ */
/* malloc(n * size) with the product checked; NULL on overflow or failure. */
void *hd__malloc_array(size_t n, size_t size);
void *hd__calloc_array(size_t n, size_t size);
void *hd__realloc_array(void *p, size_t n, size_t size);
/* 1 when a*b overflows size_t. */
HD__INLINE int hd__mul_overflows(size_t a, size_t b) {
    return b != 0 && a > SIZE_MAX / b;
}

/* A bump allocator: nodes come from large blocks, freed all at once. */
typedef struct hd__arena {
    struct hd__arena_block *head;
    size_t block_size;
    size_t total;
} hd__arena_t;
void hd__arena_init(hd__arena_t *a, size_t block_size);
void *hd__arena_alloc(hd__arena_t *a, size_t size); /* 16-byte aligned */
void hd__arena_free(hd__arena_t *a);

/* Large blocks kept for reuse within one call.  A block
 * given back (hd__reuse_put) is kept, and a later request that fits it
 * (at most three times smaller) gets it again instead of fresh memory:
 * the first write to a fresh page costs a page fault, far more than the
 * write itself, and one call of the engine allocates and frees several
 * arrays of a few bytes per point in turn (docs/engine.md, "Threads and
 * memory").  Blocks come with a small header, so every block from
 * hd__reuse_get goes back through hd__reuse_put; with a NULL set they are
 * plain allocations (hd__reuse_put(NULL, p) frees p).  Fresh blocks of a
 * set are mapped in 2 MiB huge pages where the kernel gives them (blocks
 * from 64 KiB up to about 2 MiB are cut from 2 MiB chunks that the set
 * unmaps in hd__reuse_free).  Not thread safe: one thread allocates. */
#define HD__REUSE_KEEP 16
#define HD__REUSE_CHUNKS 4
typedef struct hd__reuse {
    void *block[HD__REUSE_KEEP];
    int n;
    void *chunk[HD__REUSE_CHUNKS]; /* 2 MiB blocks that middle-sized arrays are cut from */
    int n_chunks;
    size_t chunk_used; /* bytes cut from the last chunk */
    int cut_out;       /* blocks cut from the chunks and in use (not kept) */
    size_t held;       /* bytes the set holds from the system: its blocks in use or kept, its chunks */
    size_t peak;       /* the most it held at once since hd__reuse_init (kept by hd__reuse_free) */
} hd__reuse_t;
void hd__reuse_init(hd__reuse_t *pool);
/* n * size bytes (checked for overflow), aligned as malloc's; NULL when out of memory. */
void *hd__reuse_get(hd__reuse_t *pool, size_t n, size_t size);
void hd__reuse_put(hd__reuse_t *pool, void *p); /* p may be NULL */
void hd__reuse_free(hd__reuse_t *pool);          /* frees every kept block */
/* Give the kept blocks back to the system (and the chunks, when no block
 * cut from them is in use): for a caller whose next requests cannot reuse
 * them, or could only by holding them through a larger peak.  NULL: no-op. */
void hd__reuse_trim(hd__reuse_t *pool);
/* hd__reuse_get, but the set first gives back every kept block that this
 * request does not get: no block it cannot reuse is held while a fresh
 * one is mapped. */
void *hd__reuse_take(hd__reuse_t *pool, size_t n, size_t size);
/* Block p of the set (or of none: NULL) keeps only its first `bytes`
 * (at most what it was asked for): the pages after them go back to the
 * system, but a 2 MiB page only whole.  A no-op for blocks that are not
 * mapped on their own (cut from a chunk, or malloc'ed). */
void hd__reuse_shrink(hd__reuse_t *pool, void *p, size_t bytes);

/* Map the pages of the fresh block p[0..bytes) now, in one call, rather
 * than one page fault per page as it is first written (a fault costs far
 * more than the write on virtual machines: bench/page_cost.c measures
 * both ways; docs/engine.md, "Threads and memory", and docs/scale-out.md,
 * "Memory pages on this machine", have the figures).  For arrays about to
 * be written whole; a no-op below HD__PREFAULT_MIN bytes (16 pages, small
 * enough that the MPI layer's slab structures are mapped so too) and
 * where the system has no such call.  hd__reuse_get does it
 * for the fresh blocks it allocates. */
#define HD__PREFAULT_MIN (1u << 16)
void hd__prefault(void *p, size_t bytes);

/* ---- randomness (explicit seeds only) ------------------------------------ */
typedef struct hd__rng {
    uint64_t s[4];
} hd__rng_t;
void hd__rng_seed(hd__rng_t *r, uint64_t seed);
uint64_t hd__rng_next(hd__rng_t *r);
/* Uniform integer in [0, n), n > 0, without modulo bias. */
uint64_t hd__rng_below(hd__rng_t *r, uint64_t n);
/* Uniform double in [0, 1). */
double hd__rng_unit(hd__rng_t *r);
/* A random permutation of 0..n-1 (Fisher-Yates). */
void hd__rng_permute(hd__rng_t *r, size_t *perm, size_t n);

/* ---- threads ------------------------------------------------------------ */
/* Number of threads to use for `requested` (0 = every core) and n items. */
int hd__thread_count(int requested, size_t work_items);
/* The fewest points a part of a parallel pass over a point set gets: each
 * part has its own table or histogram to fill and merge, which a smaller
 * part would not repay. */
#define HD__PART_MIN_POINTS 65536
/* At most `parts` parts for a pass over n points, and no more than one a
 * HD__PART_MIN_POINTS points (at least one). */
HD__INLINE int hd__parts_for(size_t n, int parts) {
    size_t most = n / HD__PART_MIN_POINTS + 1;
    return (size_t)parts > most ? (int)most : parts;
}

/* Run fn(ctx, task, worker) for task in [0, n_tasks) on `threads` threads
 * (the caller's thread is worker 0).  Tasks are handed out in increasing
 * order through an atomic counter.  It cannot fail: every task has run when
 * it returns, even when threads or their handles cannot be had (then on
 * fewer threads). */
typedef void (*hd__task_fn)(void *ctx, size_t task, int worker);
void hd__parallel_for(int threads, size_t n_tasks, hd__task_fn fn, void *ctx);

/* ---- a double's bits ---------------------------------------------------- */
/* The IEEE 754 binary64 bits of x, and the double with bits u: for an
 * x >= 0 (or +0), the order of the bits is the order of the values. */
HD__INLINE uint64_t hd__bits_of(double x) {
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}
HD__INLINE double hd__double_of(uint64_t u) {
    double x;
    memcpy(&x, &u, sizeof x);
    return x;
}

/* ---- clocks ------------------------------------------------------------ */
double hd__now(void); /* seconds, monotonic */

/* ---- selection and percentiles (select.c) ------------------------------ */
/* Rearrange v[0..n) (no NaN) so that v[k] holds the value of rank k, with
 * v[i] <= v[k] before it and v[i] >= v[k] after it; expected O(n), worst
 * O(n log n) (introselect). */
void hd__select(double *v, size_t n, size_t k);
/* HD_OK when 0 <= p <= 100, else HD_EINVAL with a message. */
int hd__percentile_check(double p, hd_error_t *err);
/* numpy-linear percentiles p[0..np) of v[0..n) (n > 0, no NaN, p checked),
 * reordering v; out[r] answers p[r]. */
int hd__percentiles_inplace(double *v, size_t n, const double *p, size_t np,
                            double *out, hd_error_t *err);

/* The ranks and weight of numpy's linear percentile p (checked) of n > 0
 * sorted values v: the result is hd__lerp(v[*lo], v[*hi], *t), where
 * *hi = *lo + 1, or *hi = *lo = n - 1 when pos = (n - 1) * (p / 100)
 * reaches the last value.  One definition for every caller (the selection
 * here, the MPI library's distributed one). */
double hd__percentile_pos(size_t n, double p);
void hd__percentile_ranks(size_t n, double p, size_t *lo, size_t *hi, double *t);
/* numpy's _lerp: a + (b - a) * t, or b - (b - a) * (1 - t) when t >= 0.5. */
double hd__lerp(double a, double b, double t);

/* HD_ENONFINITE naming the first NaN of d[0..n) as "distance first + k of
 * <what>", else HD_OK: the per-point figures' check (hd_summarize,
 * hd_percentile_of and the MPI library's, which pass their offset). */
int hd__nan_check(const double *d, size_t n, size_t first, const char *what, hd_error_t *err);

/* Keep the k items with the largest scores, in decreasing order of score,
 * in score[0..*n) and item[0..*n) (*n grows to k). */
HD__INLINE void hd__top_insert(double *score, size_t *item, int *n, int k, double sc, size_t it) {
    if (*n == k && !(sc > score[k - 1])) return;
    int at = *n < k ? (*n)++ : k - 1;
    while (at > 0 && score[at - 1] < sc) {
        score[at] = score[at - 1];
        item[at] = item[at - 1];
        at--;
    }
    score[at] = sc;
    item[at] = it;
}

/* ---- exact sums (xsum.c) -------------------------------------------------- */
/* An exact accumulator of doubles: the sum of any number of finite doubles
 * held without rounding, as a fixed-point number in int64 limbs of 32-bit
 * digits; hd__xsum_round rounds it once, to nearest even.  The result does
 * not depend on the order of the additions, nor on how they were split
 * between accumulators that were merged.  Limb k weighs 2^(32 k - 1074):
 * limb 0's lowest bit is the smallest subnormal, and the HD__XSUM_LIMBS
 * limbs reach 2^(32 * 70 - 1074) = 2^1166, far above any sum of 2^64
 * doubles (< 2^1088).  Between normalisations a limb holds more than its
 * 32-bit digit (each addition adds less than 2^52 to a limb's magnitude):
 * `pending` counts the additions since the last normalisation (which
 * leaves every limb but the top one in [0, 2^32), the top one signed, and
 * pending = 1), so |limb| < pending 2^52, and the limbs are normalised
 * before pending exceeds HD__XSUM_PENDING_MAX = 2^10.  Infinities and NaN
 * are counted apart.  The struct is HD__XSUM_WORDS int64 values and nothing
 * else, so it can be sent as bytes or as int64s; the limb-wise sum of up to
 * 2^30 normalised accumulators (their pending and special counts added
 * too) is their merge, normalised when it is used. */
#define HD__XSUM_LIMBS 70
#define HD__XSUM_WORDS (HD__XSUM_LIMBS + 4)
#define HD__XSUM_PENDING_MAX 1024
typedef struct hd__xsum {
    int64_t limb[HD__XSUM_LIMBS];
    int64_t pending; /* |limb[k]| < pending * 2^52 (k below the top) */
    int64_t pinf, ninf, nan; /* how many +inf, -inf and NaN were added */
} hd__xsum_t;
void hd__xsum_init(hd__xsum_t *s);
/* Carry every limb into [0, 2^32) (the top one keeps the sign); pending = 1. */
void hd__xsum_normalize(hd__xsum_t *s);
void hd__xsum_add_special(hd__xsum_t *s, double x);
/* dst += src (src unchanged). */
void hd__xsum_merge(hd__xsum_t *dst, const hd__xsum_t *src);
/* The exact sum rounded once to nearest even: subnormal results are exact
 * or rounded as any other, |sum| >= 2^1024 - 2^970 gives +-inf; +inf and
 * -inf together, or a NaN, give NaN.  An exact zero is +0.0 (as a loop
 * starting from 0.0 gives).  s is unchanged. */
double hd__xsum_round(const hd__xsum_t *s);
/* The exact sum times 2^-k (0 <= k < 2187) rounded once, as
 * hd__xsum_round rounds (subnormal results at 2^-1074 of the scaled value). */
double hd__xsum_round_scaled(const hd__xsum_t *s, int k);
/* s += x without counting it in pending: the caller counts its additions
 * with hd__xsum_count, at most HD__XSUM_PENDING_MAX / 2 between two calls
 * (a loop keeps its counter in a register so).  x = m 2^(e - 1075) with the
 * 53-bit significand m of a finite double (e its biased exponent, 1 for
 * subnormals): m << ((e - 1) mod 32) is split into its low 32 bits, added
 * to limb (e - 1) / 32, and the rest (< 2^52), added to the next limb. */
HD__INLINE void hd__xsum_add_uncounted(hd__xsum_t *s, double x) {
    union { double d; uint64_t u; } v;
    v.d = x;
    uint64_t m = v.u & (((uint64_t)1 << 52) - 1);
    unsigned e = (unsigned)(v.u >> 52) & 0x7ff;
    if (e == 0x7ff) {
        hd__xsum_add_special(s, x);
        return;
    }
    if (e) m |= (uint64_t)1 << 52;
    else e = 1;
    unsigned p = e - 1, w = p >> 5, sh = p & 31;
    int64_t c0 = (int64_t)((m << sh) & 0xffffffffu);
    int64_t c1 = (int64_t)(m >> (32 - sh));
    int64_t neg = -(int64_t)(v.u >> 63); /* 0 or -1: negate by (c ^ neg) - neg */
    s->limb[w] += (c0 ^ neg) - neg;
    s->limb[w + 1] += (c1 ^ neg) - neg;
}
/* Count `added` uncounted additions (<= HD__XSUM_PENDING_MAX / 2),
 * normalising first when the bound would be passed. */
HD__INLINE void hd__xsum_count(hd__xsum_t *s, int64_t added) {
    s->pending += added;
    if (s->pending > HD__XSUM_PENDING_MAX / 2) hd__xsum_normalize(s);
}
/* s += x. */
HD__INLINE void hd__xsum_add(hd__xsum_t *s, double x) {
    hd__xsum_add_uncounted(s, x);
    hd__xsum_count(s, 1);
}

/* sum += d[k] and sum2 += d[k] * d[k] (rounded) for k in [0, n), one
 * pass, counted a block at a time (the loop keeps its counter in a
 * register); returns the largest of m and the d[k], the first of equal
 * ones (a strict > from m on: the same fold, split anywhere, gives the
 * same bits). */
double hd__xsum_values(hd__xsum_t *sum, hd__xsum_t *sum2, const double *d, size_t n, double m);

/* ---- the summary's derived figures (xsum.c) ------------------------------- */
/* Fill every field of out from the counts, maxima and exact sums (sums[0],
 * sums[1]: of d and of d * d over A's n_a distances; sums[2], sums[3]: B's,
 * n_b = 0 when B's are absent: its fields are then NaN).  The one place
 * where hd_summarize's means and Chamfer figures are defined, for
 * hd_summarize and the MPI library's distributed version: computed from
 * the sums rounded once, and again from the sums scaled by a power of two
 * where a figure overflowed (a mean is finite whenever it is at most
 * DBL_MAX, though its sum may be beyond). */
void hd__summary_derive(hd_summary_t *out, size_t n_a, double max_ab, size_t n_b, double max_ba,
                        const hd__xsum_t sums[4]);

/* ---- a bound that only grows, shared by threads ------------------------- */
/* A lower bound on h(A,B)^2 that threads raise together (the engine's
 * cmax, and MaxLB / Maxlb of the paper's algorithms).  It holds a non-negative double whose bits, read as an unsigned
 * integer, order like the values; it only grows, so a stale read is a
 * smaller, still valid bound.  Pruning against it is strict (<), so it may
 * start at 0 with no witness: nothing is ever strictly below 0. */
typedef struct hd__bound {
    _Atomic uint64_t bits;
} hd__bound_t;
HD__INLINE uint64_t hd__bound_bits(double d2) {
    union { double d; uint64_t u; } v;
    v.d = d2 > 0 ? d2 : 0.0; /* never -0.0, whose bits would sort last */
    return v.u;
}
HD__INLINE void hd__bound_init(hd__bound_t *b, double d2) {
    atomic_init(&b->bits, hd__bound_bits(d2));
}
HD__INLINE double hd__bound_get(hd__bound_t *b) {
    union { double d; uint64_t u; } v;
    v.u = atomic_load_explicit(&b->bits, memory_order_relaxed);
    return v.d;
}
HD__INLINE void hd__bound_raise(hd__bound_t *b, double d2) {
    uint64_t want = hd__bound_bits(d2);
    uint64_t cur = atomic_load_explicit(&b->bits, memory_order_relaxed);
    while (want > cur && !atomic_compare_exchange_weak_explicit(
                             &b->bits, &cur, want, memory_order_relaxed,
                             memory_order_relaxed)) {
    }
}

/* ---- the binary heap (heap.c) ------------------------------------------- */
/* a binary heap of (key, payload) pairs, usable as a max-queue
 * (NOHD's decreasing priority queue, INC's queue of A entries) or as a
 * min-queue (OHD's ascending queue in NNDist).
 *
 * The order is total and deterministic: a larger key comes first in a
 * max-heap, a smaller key first in a min-heap, and equal keys come out by
 * increasing payload in both.  Payloads are small integers chosen by the
 * caller (node ids, entry slots), so two runs on the same input pop entries
 * in the same order and report the same counters.
 */
typedef struct hd__heap_item {
    double key;
    uint64_t val;
} hd__heap_item_t;

typedef struct hd__heap {
    hd__heap_item_t *a;
    size_t n, cap;
    int max_first; /* 1: largest key first; 0: smallest key first */
} hd__heap_t;

/* An empty heap; nothing is allocated until the first push or reserve. */
void hd__heap_init(hd__heap_t *h, int max_first);
/* Make room for `cap` items, so that the next pushes up to that size cannot
 * fail.  Returns HD_OK or HD_ENOMEM. */
int hd__heap_reserve(hd__heap_t *h, size_t cap);
/* Insert an item, growing the storage when needed: HD_OK or HD_ENOMEM. */
int hd__heap_push(hd__heap_t *h, double key, uint64_t val);
/* Remove and return the first item; the heap must not be empty. */
hd__heap_item_t hd__heap_pop(hd__heap_t *h);
/* The first item without removing it (NULL when empty). */
const hd__heap_item_t *hd__heap_top(const hd__heap_t *h);
/* Forget every item, keeping the storage. */
void hd__heap_clear(hd__heap_t *h);
void hd__heap_free(hd__heap_t *h);

static inline size_t hd__heap_size(const hd__heap_t *h) { return h->n; }

#endif /* HD_BASE_H */
