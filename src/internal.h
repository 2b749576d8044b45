/*
 * internal.h -- what the library's modules share and users never see.
 *
 * The one rule every module obeys is here: squared distances are evaluated
 * by hd__d2() and nothing else, as dx*dx + dy*dy + dz*dz left to right.  The
 * build passes -ffp-contract=off so no compiler fuses a multiply into an add;
 * with that, every algorithm computes exactly the doubles the brute force
 * computes, and since the only other operations on them are comparisons and
 * one final sqrt, results agree to the bit.
 *
 * Bounds on boxes are evaluated with the same operation order (hd__box_lb2,
 * hd__box_ub2).  IEEE rounding is monotone: if |u| <= |v| exactly then
 * fl(u*u) <= fl(v*v), and fl(fl(a+b)+c) is monotone in each argument.  A
 * box whose faces are coordinates of points it contains (or any doubles that
 * enclose those points exactly) therefore gives a computed lower bound no
 * larger, and a computed upper bound no smaller, than the computed squared
 * distance to any point inside.  That is why no epsilon appears in the
 * pruning tests: they compare values that rounding cannot reorder.
 */
#ifndef HD_INTERNAL_H
#define HD_INTERNAL_H

#include "hausdorff.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#define HD__NONE ((size_t)-1)

#if defined(__GNUC__)
#define HD__INLINE static inline __attribute__((always_inline))
#define HD__PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define HD__INLINE static inline
#define HD__PRINTF(f, a)
#endif

/* ---- the squared distance ------------------------------------------- */
HD__INLINE double hd__d2(const double *p, const double *q) {
    double dx = p[0] - q[0];
    double dy = p[1] - q[1];
    double dz = p[2] - q[2];
    return dx * dx + dy * dy + dz * dz;
}

/* Same function on separate coordinates (structure-of-arrays callers). */
HD__INLINE double hd__d2s(double px, double py, double pz, double qx, double qy,
                          double qz) {
    double dx = px - qx;
    double dy = py - qy;
    double dz = pz - qz;
    return dx * dx + dy * dy + dz * dz;
}

/* ---- boxes -------------------------------------------------------------- */
typedef struct hd__box {
    double lo[3], hi[3];
} hd__box_t;

/* Grow `into` to hold the box b too. */
HD__INLINE void hd__box_merge(hd__box_t *into, const hd__box_t *b) {
    for (int k = 0; k < 3; k++) {
        into->lo[k] = b->lo[k] < into->lo[k] ? b->lo[k] : into->lo[k];
        into->hi[k] = b->hi[k] > into->hi[k] ? b->hi[k] : into->hi[k];
    }
}

/* Smallest computed squared distance from p to any point in the box. */
HD__INLINE double hd__box_lb2(const hd__box_t *b, const double *p) {
    double d[3];
    for (int k = 0; k < 3; k++) {
        double v = 0.0;
        if (p[k] < b->lo[k]) v = b->lo[k] - p[k];
        else if (p[k] > b->hi[k]) v = p[k] - b->hi[k];
        d[k] = v;
    }
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* Largest computed squared distance from p to any point in the box (the
 * farthest corner). */
HD__INLINE double hd__box_ub2(const hd__box_t *b, const double *p) {
    double d[3];
    for (int k = 0; k < 3; k++) {
        double u = p[k] - b->lo[k], v = b->hi[k] - p[k];
        if (u < 0) u = -u;
        if (v < 0) v = -v;
        d[k] = u > v ? u : v;
    }
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* Box of n packed xyz doubles (n > 0). */
void hd__box_of(const double *xyz, size_t n, hd__box_t *out);

/* ---- the running maximum with its witness ------------------------------- */
/* best.d2 = -1 means "nothing yet".  Merge keeps the larger d2 and, on a
 * tie, the smaller i: so the witness is independent of evaluation order. */
typedef struct hd__best {
    double d2;
    size_t i, j;
} hd__best_t;

HD__INLINE void hd__best_init(hd__best_t *b) {
    b->d2 = -1.0;
    b->i = HD__NONE;
    b->j = HD__NONE;
}

HD__INLINE void hd__best_offer(hd__best_t *b, double d2, size_t i, size_t j) {
    if (d2 > b->d2 || (d2 == b->d2 && i < b->i)) {
        b->d2 = d2;
        b->i = i;
        b->j = j;
    }
}

/* Merge the partial results of n tasks into b (in task order; by the tie
 * rule the result would be the same in any order). */
HD__INLINE void hd__best_merge(hd__best_t *b, const hd__best_t *part, size_t n) {
    for (size_t t = 0; t < n; t++) hd__best_offer(b, part[t].d2, part[t].i, part[t].j);
}

/* Store b's squared distance and witness in a directed result. */
HD__INLINE void hd__best_store(const hd__best_t *b, hd_result_t *out) {
    out->distance2 = b->d2;
    out->i = b->i;
    out->j = b->j;
}

/* Exact nearest distance of p to n packed points with the smallest index at
 * that distance (a full scan). */
double hd__nn_scan(const double *p, const double *xyz, size_t n, size_t *j,
                   uint64_t *evals);

/* Smallest j in B with d2(p, B[j]) == d2; used to canonicalise a witness
 * after an algorithm found *some* nearest point at the winning distance. */
size_t hd__first_at(const double *p, const double *xyz, size_t n, double d2,
                    uint64_t *evals);

/* ---- Morton keys -------------------------------------------------------- */
/* Cubic cells over a box, 1024 per axis along its longest side (cell =
 * (c - lo) * scale, clamped to the grid), and the 30-bit Morton key of a
 * point's cell.  Keys only order points along the curve, for locality: any
 * value would be correct, so no rounding argument is needed here. */
typedef struct hd__keygrid {
    double lo[3], scale;
} hd__keygrid_t;

HD__INLINE void hd__keygrid_init(hd__keygrid_t *g, const hd__box_t *b) {
    double ext = 0;
    for (int k = 0; k < 3; k++) {
        g->lo[k] = b->lo[k];
        ext = b->hi[k] - b->lo[k] > ext ? b->hi[k] - b->lo[k] : ext;
    }
    g->scale = ext > 0 ? 1024.0 / ext : 0.0;
}

/* The low 10 bits of v spread to every third bit. */
HD__INLINE uint32_t hd__spread10(uint32_t v) {
    v &= 0x3ffu;
    v = (v | v << 16) & 0x30000ffu;
    v = (v | v << 8) & 0x300f00fu;
    v = (v | v << 4) & 0x30c30c3u;
    v = (v | v << 2) & 0x9249249u;
    return v;
}

HD__INLINE uint32_t hd__key30(const hd__keygrid_t *g, const double p[3]) {
    uint32_t key = 0;
    for (int k = 0; k < 3; k++) {
        double v = (p[k] - g->lo[k]) * g->scale;
        uint32_t c = v >= 1023.0 ? 1023u : v > 0 ? (uint32_t)v : 0u;
        key |= hd__spread10(c) << k;
    }
    return key;
}

/* ---- errors ----------------------------------------------------------- */
/* Set err (if not NULL) and return code. */
int hd__err(hd_error_t *err, int code, const char *fmt, ...) HD__PRINTF(3, 4);
int hd__verr(hd_error_t *err, int code, const char *fmt, va_list ap);
/* As hd__err, recording a text line (1-based) or a byte offset. */
int hd__err_line(hd_error_t *err, int code, long long line, const char *fmt,
                 ...) HD__PRINTF(4, 5);
int hd__err_offset(hd_error_t *err, int code, long long offset,
                   const char *fmt, ...) HD__PRINTF(4, 5);
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

/* ---- point sets --------------------------------------------------------- */
/* Validate a view (non-empty, finite, |c| <= HD_MAX_COORD) and compute its
 * box in the same pass.  `what` names the set in messages ("A", "B"). */
int hd__points_check(const hd_points_t *p, const char *what, hd__box_t *box,
                     hd_error_t *err);

/* Packed doubles for a view: borrowed when the view already is packed
 * doubles, else a new copy in *owned (free it).  T, if not NULL, is applied
 * (which always copies). */
int hd__points_f64(const hd_points_t *p, const hd_transform_t *T,
                   double **owned, const double **xyz, hd_error_t *err);

/* Apply T to one point, in the documented order. */
HD__INLINE void hd__transform_apply(const hd_transform_t *T, const double *p,
                                    double *o) {
    const double *r = T->r;
    o[0] = ((r[0] * p[0] + r[1] * p[1]) + r[2] * p[2]) + T->t[0];
    o[1] = ((r[3] * p[0] + r[4] * p[1]) + r[5] * p[2]) + T->t[1];
    o[2] = ((r[6] * p[0] + r[7] * p[1]) + r[8] * p[2]) + T->t[2];
}

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

/* Run fn(ctx, task, worker) for task in [0, n_tasks) on `threads` threads
 * (the caller's thread is worker 0).  Tasks are handed out in increasing
 * order through an atomic counter.  It cannot fail: every task has run when
 * it returns, even when threads or their handles cannot be had (then on
 * fewer threads). */
typedef void (*hd__task_fn)(void *ctx, size_t task, int worker);
void hd__parallel_for(int threads, size_t n_tasks, hd__task_fn fn, void *ctx);

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

/* ---- algorithms --------------------------------------------------------- */
/* What every directed algorithm receives: A and B as packed doubles (after
 * any transform), their boxes, the options and the thread count. */
typedef struct hd__job {
    const double *a;
    size_t na;
    const double *b;
    size_t nb;
    hd__box_t box_a, box_b;
    const hd_options_t *opt;
    int threads;
} hd__job_t;

/* Each algorithm computes h(A,B) into out (distance2, i, j, stats; the
 * caller fills distance, algorithm and seconds).  The witness must already
 * be canonical (smallest i, smallest j). */
typedef int (*hd__directed_fn)(const hd__job_t *job, hd_result_t *out,
                               hd_error_t *err);

int hd__naive(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__earlybreak(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__inc(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__nohd(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__ohd(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__kdtree(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
int hd__engine(const hd__job_t *job, hd_result_t *out, hd_error_t *err);
/* The auto engine on validated views, without packed copies (engine.c):
 * h(A,B), and H(A,B) with each set indexed once for both directions. */
int hd__engine_directed(const hd_points_t *A, const hd_points_t *B,
                        const hd__box_t *box_a, const hd__box_t *box_b,
                        const hd_options_t *opt, hd_result_t *out,
                        hd_error_t *err);
int hd__engine_hausdorff(const hd_points_t *A, const hd_points_t *B,
                         const hd__box_t *box_a, const hd__box_t *box_b,
                         const hd_options_t *opt, hd_symmetric_t *out,
                         hd_error_t *err);
/* The engine's plan for H(A,B) as a sentence in buf (for benchmarks). */
int hd__engine_explain(const hd_points_t *A, const hd_points_t *B,
                       const hd_options_t *opt, char *buf, size_t len,
                       hd_error_t *err);
/* hd__points_check's result, computed with `threads` threads by a fast pass
 * for packed views (engine_scan.c); any problem is reported by
 * hd__points_check itself. */
int hd__points_scan(const hd_points_t *p, const char *what, int threads,
                    hd__box_t *box, hd_error_t *err);

/* Run h(A,B) on a prepared job (fills seconds, distance, algorithm). */
int hd__run_directed(hd__job_t *job, hd_algorithm_t alg, hd_result_t *out,
                     hd_error_t *err);

/* The overlap degree (see hd_overlap in the public header). */
double hd__alpha(const hd__box_t *a, const hd__box_t *b, int *disjoint);
/* The framework's choice for h(A,B). */
hd_algorithm_t hd__framework_choice(const hd__box_t *a, const hd__box_t *b,
                                    double theta);

/* ---- shared by the paper's algorithms (earlybreak.c, nohd.c, ohd.c) ---- */
/* A lower bound on h(A,B)^2 that threads raise together (cmax, MaxLB,
 * Maxlb).  It holds a non-negative double whose bits, read as an unsigned
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

/* The inner loop of Algorithms 2 and 5: scan the n packed points for x's
 * nearest neighbour, giving up ("cut short") when some squared distance d is
 * below `bound` or equal to `tie`.  Returns 1 with the minimum in *d2 and
 * the smallest original index at it in *j (idx[k] is point k's original
 * index; NULL means k), or 0 when cut short.  Whether a scan is cut short
 * does not depend on the order of the points, so it is decided per block,
 * and *evals counts every distance evaluated. */
int hd__scan_break(const double *x, const double *pts, const size_t *idx, size_t n,
                   double bound, double tie, double *d2, size_t *j, uint64_t *evals);

/* EARLYBREAK's loop (Algorithm 2, lines 4-15) over the points of A listed
 * in `order` (visited in that order), against B scanned in a random order
 * drawn from rng; with exclude_common, points of A equal to a point of B
 * are skipped (counted in stats->points_culled).  On return *best is the
 * largest exact nearest-neighbour distance among the points that were not
 * cut short, with the smallest i among those and the smallest j at that
 * distance.  A point is cut short only when a distance below the shared
 * bound proves its nn distance smaller than the final value, or equal to a
 * value already found at a smaller index; so the witness is canonical among
 * the points not excluded.  OHD uses it for its AHD. */
int hd__eb_loop(const hd__job_t *job, const size_t *order, size_t n_order,
                int exclude_common, hd__rng_t *rng, hd__best_t *best,
                hd_stats_t *stats, hd_error_t *err);

#endif /* HD_INTERNAL_H */
