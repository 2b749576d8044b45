/*
 * _ndim.c -- exact h(A, B) and nearest distances in any number of
 * coordinates (see _ndim.h for the contract).
 *
 * The squared distance of a point to a candidate is summed coordinate by
 * coordinate, first to last, and a candidate is abandoned once its partial
 * sum exceeds the bound that matters (the best squared distance so far):
 * every term is >= 0 and rounding is monotone, so the partial sums never
 * decrease and the full sum would exceed the bound too.  A candidate equal
 * to the bound is always summed to the end, so ties are seen and go to the
 * smallest index.  Eight candidates are summed side by side (eight
 * independent chains of the same operations), which changes no double.
 *
 * B's rows are sorted by the coordinate along which B spreads most, and a
 * point's scan goes outwards from its own value of that coordinate, leaving
 * a side once that coordinate's squared difference alone exceeds the best
 * so far (see gap2).
 *
 * The early-break algorithm (Taha and Hanbury, as scipy's
 * directed_hausdorff): points of A are visited in a seeded random order;
 * the scan of a point stops as soon as a candidate is strictly
 * nearer than the largest nearest squared distance c known so far (the
 * point's own nearest is then below c, so it is not the maximum), or equal
 * to c when the point's index is above the witness's (it can then at most
 * tie with a smaller index).  A point whose scan ends without stopping has
 * its exact nearest squared distance and the smallest index attaining it.
 * The point realising the maximum with the smallest index is therefore
 * never stopped, and the result is the brute force's whatever the order.
 *
 * Threads share A by interleaving; each keeps its own c and witness and
 * publishes c to the others, who use it for the strict test only.  Every
 * value published is some point's exact nearest squared distance, so it
 * never exceeds the maximum M, and a point whose nearest is M is never
 * stopped by it; the thread holding the smallest such index records it.
 * Merging keeps the largest value, on ties the smallest index.
 */
#include "_ndim.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

enum { LANES = 8, BLOCK = 8 /* coordinates summed between two tests of the bound */ };

/* B as scanned: its rows in blocks of LANES, each block's coordinates
 * interleaved (coordinate k of the block's row l at [k * LANES + l]), so
 * that the LANES sums advance side by side on contiguous memory; the last
 * block is padded with zeros, which are never offered.  order[r] is stored
 * row r's index in the caller's B (NULL: r).  When keys is not NULL the
 * rows are sorted by coordinate `axis` (keys[r] is row r's), ties by
 * index. */
typedef struct {
    double *blocks, *keys;
    size_t *order;
    size_t n, dims, axis;
} nd_set_t;

static size_t index_of(const nd_set_t *s, size_t r) {
    return s->order ? s->order[r] : r;
}

static void set_free(nd_set_t *s) {
    free(s->blocks);
    free(s->keys);
    free(s->order);
}

/* A double's bits as an unsigned integer of the same order (for finite
 * values; -0 and +0, equal as doubles, may come in either order). */
static uint64_t order_bits(double v) {
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    return u >> 63 ? ~u : u | (UINT64_C(1) << 63);
}

/* order[0..n) sorted by coordinate `axis` of the rows of B (an LSD radix
 * sort on order_bits,
 * a byte a pass, passes where every key has the same byte skipped);
 * tmp holds n more indices and bits 2n integers.  Only the order of keys
 * matters to the scan, not the order among equal ones. */
static void radix_sort(const double *B, size_t dims, size_t axis, size_t n, size_t *order,
                       size_t *tmp, uint64_t *bits) {
    uint64_t *u = bits, *v = bits + n;
    if (n == 0) return;
    for (size_t r = 0; r < n; r++) {
        order[r] = r;
        u[r] = order_bits(B[r * dims + axis]);
    }
    for (int shift = 0; shift < 64; shift += 8) {
        size_t count[257] = {0};
        for (size_t r = 0; r < n; r++) count[((u[r] >> shift) & 255) + 1]++;
        if (count[((u[0] >> shift) & 255) + 1] == n) continue;
        for (int d = 0; d < 256; d++) count[d + 1] += count[d];
        for (size_t r = 0; r < n; r++) {
            size_t at = count[(u[r] >> shift) & 255]++;
            v[at] = u[r];
            tmp[at] = order[r];
        }
        uint64_t *sw = u;
        u = v;
        v = sw;
        memcpy(order, tmp, n * sizeof *order);
    }
}

/* The coordinate along which B spreads most: its sorted order prunes best. */
static size_t widest_axis(const double *B, size_t nb, size_t dims) {
    size_t axis = 0;
    double widest = -1.0;
    for (size_t k = 0; k < dims; k++) {
        double lo = B[k], hi = B[k];
        for (size_t r = 1; r < nb; r++) {
            double v = B[r * dims + k];
            if (v < lo) lo = v;
            if (v > hi) hi = v;
        }
        if (hi - lo > widest) {
            widest = hi - lo;
            axis = k;
        }
    }
    return axis;
}

/* Sort B's rows by their widest coordinate: s->order and s->keys. */
static int set_sort(nd_set_t *s, const double *B, size_t nb, size_t dims) {
    size_t *tmp = malloc(nb * sizeof *tmp);
    uint64_t *bits = nb <= SIZE_MAX / 2 / sizeof *bits ? malloc(2 * nb * sizeof *bits) : NULL;
    s->order = malloc(nb * sizeof *s->order);
    s->keys = malloc(nb * sizeof *s->keys);
    int ok = tmp && bits && s->order && s->keys;
    if (ok) {
        s->axis = widest_axis(B, nb, dims);
        radix_sort(B, dims, s->axis, nb, s->order, tmp, bits);
        for (size_t r = 0; r < nb; r++) s->keys[r] = B[s->order[r] * dims + s->axis];
    }
    free(tmp);
    free(bits);
    return ok ? 0 : -1;
}

/* The blocked copy of B, sorted (see nd_set_t) or in index order; -1 when
 * there is no memory for it (set_free frees what was had). */
static int set_build(nd_set_t *s, const double *B, size_t nb, size_t dims, int sorted) {
    *s = (nd_set_t){NULL, NULL, NULL, nb, dims, 0};
    size_t nblocks = (nb + LANES - 1) / LANES;
    if (sorted && set_sort(s, B, nb, dims)) return -1;
    s->blocks = dims && nblocks <= SIZE_MAX / sizeof(double) / LANES / dims
                    ? calloc(nblocks * LANES * dims, sizeof(double))
                    : NULL;
    if (!s->blocks) return -1;
    for (size_t r = 0; r < nb; r++) {
        const double *row = B + index_of(s, r) * dims;
        double *dst = s->blocks + (r / LANES) * LANES * dims + r % LANES;
        for (size_t k = 0; k < dims; k++) dst[k * LANES] = row[k];
    }
    return 0;
}

/* Stored row r at squared distance d improves (*best, *best_r)? */
static void offer(const nd_set_t *s, double d, size_t r, double *best, size_t *best_r) {
    if (d < *best || (d == *best && index_of(s, r) < index_of(s, *best_r))) {
        *best = d;
        *best_r = r;
    }
}

/* The squared distances of a to the LANES rows of block blk: each s[l] is
 * exact unless all of them passed the bound at the same test (they are then
 * partial sums, all > bound). */
static void sq_dist_block(const double *a, const double *blk, size_t dims, double bound,
                          double s[LANES]) {
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0, s4 = 0.0, s5 = 0.0, s6 = 0.0, s7 = 0.0;
    size_t k = 0;
    while (k < dims) {
        size_t end = dims - k > BLOCK ? k + BLOCK : dims;
        for (; k < end; k++) {
            const double x = a[k], *p = blk + k * LANES;
            double d0 = x - p[0], d1 = x - p[1], d2 = x - p[2], d3 = x - p[3];
            double d4 = x - p[4], d5 = x - p[5], d6 = x - p[6], d7 = x - p[7];
            s0 += d0 * d0;
            s1 += d1 * d1;
            s2 += d2 * d2;
            s3 += d3 * d3;
            s4 += d4 * d4;
            s5 += d5 * d5;
            s6 += d6 * d6;
            s7 += d7 * d7;
        }
        if (s0 > bound && s1 > bound && s2 > bound && s3 > bound && s4 > bound && s5 > bound &&
            s6 > bound && s7 > bound)
            break;
    }
    const double v[LANES] = {s0, s1, s2, s3, s4, s5, s6, s7};
    memcpy(s, v, sizeof v);
}

/* The rows of block q offered to (*best, *best_r); the rows counted. */
static size_t visit_block(const nd_set_t *s, const double *a, size_t q, double *best,
                          size_t *best_r) {
    double d[LANES];
    size_t r = q * LANES;
    sq_dist_block(a, s->blocks + r * s->dims, s->dims, *best, d);
    size_t rows = s->n - r < LANES ? s->n - r : LANES;
    double least = d[0];
    for (size_t l = 1; l < rows; l++) least = d[l] < least ? d[l] : least;
    if (least <= *best)
        for (size_t l = 0; l < rows; l++) offer(s, d[l], r + l, best, best_r);
    return rows;
}

/* The first row whose key is >= x (n when none is), without branches on
 * the keys: base[0..len) always holds that row or ends before it. */
static size_t lower_bound(const double *keys, size_t n, double x) {
    const double *base = keys;
    size_t len = n;
    while (len > 1) {
        size_t half = len / 2;
        base = base[half] < x ? base + half : base;
        len -= half;
    }
    return (size_t)(base - keys) + (*base < x);
}

/* fl((x - key)^2): a lower bound of the squared distance of a (x = a[axis])
 * to a row whose coordinate `axis` is key, and to every row whose key lies
 * further from x: each partial sum is at least any one of its terms, and
 * the term of that coordinate grows with |x - key| (rounding is monotone). */
static double gap2(double x, double key) {
    double d = x - key;
    return d * d;
}

/* Scan B for a's nearest row: *best, *best_r (a stored row).  Stops, and
 * returns 1, as soon as *best < stop; otherwise *best is a's exact nearest
 * squared distance and *best_r the row of the smallest index attaining it.
 * Sorted rows are visited from a's own key outwards, the nearer side first,
 * and a side is left once its next block's gap2 exceeds *best (none of its
 * rows can then reach *best, not even tie). */
static int scan(const nd_set_t *s, const double *a, double stop, double *best, size_t *best_r,
                uint64_t *evals) {
    double b = INFINITY;
    size_t br = 0, nblocks = (s->n + LANES - 1) / LANES, seen = 0;
    int stopped = 0;
    if (!s->keys) {
        for (size_t q = 0; !stopped && q < nblocks; q++) {
            seen += visit_block(s, a, q, &b, &br);
            stopped = b < stop;
        }
    } else {
        double x = a[s->axis];
        size_t q = lower_bound(s->keys, s->n, x) / LANES;
        if (q >= nblocks) q = nblocks - 1;
        seen += visit_block(s, a, q, &b, &br);
        stopped = b < stop;
        size_t lo = q, hi = q + 1; /* next blocks: lo - 1 below, hi above */
        while (!stopped) {
            double glo = lo > 0 ? gap2(x, s->keys[lo * LANES - 1]) : INFINITY;
            double ghi = hi < nblocks ? gap2(x, s->keys[hi * LANES]) : INFINITY;
            if (!(glo <= b) && !(ghi <= b)) break;
            seen += visit_block(s, a, glo <= ghi ? --lo : hi++, &b, &br);
            stopped = b < stop;
        }
    }
    *evals += seen;
    *best = b;
    *best_r = br;
    return stopped;
}

/* ------------------------------------------------------------------------
 * Threads: job 0 runs on the caller's thread; a job whose thread cannot
 * start runs there too, after it.
 * ---------------------------------------------------------------------- */

static void run_jobs(void *(*fn)(void *), void *jobs, size_t size, int n) {
    pthread_t tid[64];
    int started[64] = {0};
    for (int t = 1; t < n; t++)
        started[t] = pthread_create(&tid[t], NULL, fn, (char *)jobs + (size_t)t * size) == 0;
    fn(jobs);
    for (int t = 1; t < n; t++) {
        if (started[t]) pthread_join(tid[t], NULL);
        else fn((char *)jobs + (size_t)t * size);
    }
}

static int clamp_threads(int threads, size_t work) {
    if (threads < 1) threads = 1;
    if (threads > 64) threads = 64;
    if ((size_t)threads > work) threads = work ? (int)work : 1;
    return threads;
}

/* ------------------------------------------------------------------------
 * h(A, B).
 * ---------------------------------------------------------------------- */

typedef struct {
    const double *A;
    size_t na;
    const size_t *visit; /* A's indices in visiting order (NULL: 0, 1, ...) */
    nd_set_t B;
    int early, t, T;
    _Atomic uint64_t *shared; /* bits of the largest c published (>= 0) */
    nd_directed_t res;
    int found;
} directed_job_t;

static double from_bits(uint64_t u) {
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

static uint64_t to_bits(double d) {
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    return u;
}

/* Non-negative doubles order as their bit patterns. */
static void publish(_Atomic uint64_t *shared, double c) {
    uint64_t want = to_bits(c), cur = atomic_load_explicit(shared, memory_order_relaxed);
    while (want > cur &&
           !atomic_compare_exchange_weak_explicit(shared, &cur, want, memory_order_relaxed,
                                                  memory_order_relaxed)) {
    }
}

/* The bound below which point i's scan stops (see the file's comment). */
static double stop_of(const directed_job_t *J, double c, size_t ci, size_t i) {
    if (!J->early) return -INFINITY;
    double g = from_bits(atomic_load_explicit(J->shared, memory_order_relaxed));
    double own = c >= 0 && i > ci ? nextafter(c, INFINITY) : c;
    return g > own ? g : own;
}

static void *directed_job(void *arg) {
    directed_job_t *J = arg;
    size_t dims = J->B.dims, ci = 0, cj = 0;
    double c = -1.0; /* no point yet */
    uint64_t evals = 0;
    for (size_t v = (size_t)J->t; v < J->na; v += (size_t)J->T) {
        size_t i = J->visit ? J->visit[v] : v, k;
        double best;
        if (scan(&J->B, J->A + i * dims, stop_of(J, c, ci, i), &best, &k, &evals)) continue;
        if (best > c || (best == c && i < ci)) {
            c = best;
            ci = i;
            cj = index_of(&J->B, k);
            if (J->early) publish(J->shared, c);
        }
    }
    J->found = c >= 0;
    J->res = (nd_directed_t){c, ci, cj, evals};
    return NULL;
}

/* splitmix64: the visiting orders' random numbers. */
static uint64_t next_random(uint64_t *state) {
    uint64_t z = (*state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

static void shuffle(size_t *v, size_t n, uint64_t *state) {
    for (size_t k = 0; k < n; k++) v[k] = k;
    for (size_t k = n; k > 1; k--) {
        size_t r = (size_t)(next_random(state) % k), t = v[k - 1];
        v[k - 1] = v[r];
        v[r] = t;
    }
}

int nd_directed(const double *A, size_t na, const double *B, size_t nb, size_t dims,
                int early, uint64_t seed, int threads, nd_directed_t *out) {
    size_t *visit = NULL;
    nd_set_t set = {NULL, NULL, NULL, nb, dims, 0};
    if (early) { /* A in a random order; B sorted (see scan) */
        visit = malloc(na * sizeof *visit);
        if (visit) {
            uint64_t state = seed;
            shuffle(visit, na, &state);
        }
    }
    if ((early && !visit) || set_build(&set, B, nb, dims, early)) {
        free(visit);
        set_free(&set);
        return -1;
    }
    int T = clamp_threads(threads, na);
    directed_job_t jobs[64];
    _Atomic uint64_t shared = 0;
    for (int t = 0; t < T; t++)
        jobs[t] = (directed_job_t){A, na, visit, set, early, t, T, &shared, {0, 0, 0, 0}, 0};
    run_jobs(directed_job, jobs, sizeof jobs[0], T);
    nd_directed_t r = {-1.0, 0, 0, 0};
    uint64_t evals = 0;
    for (int t = 0; t < T; t++) {
        const nd_directed_t *x = &jobs[t].res;
        evals += x->distance_evals;
        if (jobs[t].found && (x->d2 > r.d2 || (x->d2 == r.d2 && x->i < r.i))) r = *x;
    }
    r.distance_evals = evals;
    *out = r;
    free(visit);
    set_free(&set);
    return 0;
}

/* ------------------------------------------------------------------------
 * Nearest distances.
 * ---------------------------------------------------------------------- */

typedef struct {
    const double *A;
    size_t lo, hi;
    nd_set_t B;
    double *dist;
    size_t *nearest;
} nearest_job_t;

static void *nearest_job(void *arg) {
    nearest_job_t *J = arg;
    uint64_t evals = 0;
    for (size_t i = J->lo; i < J->hi; i++) {
        double best;
        size_t k;
        scan(&J->B, J->A + i * J->B.dims, -INFINITY, &best, &k, &evals);
        if (J->dist) J->dist[i] = sqrt(best);
        if (J->nearest) J->nearest[i] = index_of(&J->B, k);
    }
    return NULL;
}

int nd_nearest(const double *A, size_t na, const double *B, size_t nb, size_t dims,
               int threads, double *dist, size_t *nearest) {
    nd_set_t set;
    if (set_build(&set, B, nb, dims, 1)) {
        set_free(&set);
        return -1;
    }
    int T = clamp_threads(threads, na);
    nearest_job_t jobs[64];
    for (int t = 0; t < T; t++)
        jobs[t] = (nearest_job_t){A, na * (size_t)t / (size_t)T, na * (size_t)(t + 1) / (size_t)T,
                                  set, dist, nearest};
    run_jobs(nearest_job, jobs, sizeof jobs[0], T);
    set_free(&set);
    return 0;
}
