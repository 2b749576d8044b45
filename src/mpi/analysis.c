/*
 * analysis.c -- the per-point figures of distances spread over the ranks
 * (hausdorff_mpi.h: hd_mpi_summarize, hd_mpi_percentile_of,
 * hd_mpi_histogram): each the single-process function's result on the
 * concatenation of every rank's values, in rank order, to the bit, on every
 * rank.  No value moves between ranks.
 *
 * Summaries.  hd_summarize's sums are exact and rounded once
 * (base/xsum.c), so they do not depend on the order: each rank adds its own
 * values into exact accumulators (hd__xsum_values, the very loop
 * hd_summarize runs), normalises them (every limb in [0, 2^32)), and one
 * MPI_Allreduce of int64 sums adds the limbs of every rank (at most
 * K 2^32 each, K < 2^30 ranks, far below int64's range: the sum is their
 * exact merge), then every rank rounds the same merged number.  The maxima
 * are gathered and folded in rank order with hd_summarize's strict >, so
 * even a -0.0 among zeros comes out as the single process finds it.  The
 * derived figures (means, Chamfer distances) come from hd__summary_derive,
 * hd_summarize's own.
 *
 * Percentiles.  The single process selects the values of ranks lo and
 * lo + 1 (hd__percentile_ranks); here each is found by an exact
 * distributed radix selection over the values' keys: a double's bits
 * turned into a uint64 that orders as the doubles do (negative values'
 * bits inverted, the sign bit of the others set; -0.0 is taken as +0.0,
 * which compares equal to it).  Eight rounds, 8 bits of the key each: every
 * rank counts its values whose key starts with the prefix found so far in
 * 256 bins of the next 8 bits, one MPI_Allreduce adds the counts, and
 * every rank walks the same sums to the bin holding rank k (the prefix
 * grows by 8 bits, k drops by the counts below the bin).  Small digits
 * keep the reductions small (2 KB a figure, where 16-bit digits would
 * reduce 512 KB a round), and a local pass costs less than a large
 * reduction across many ranks (tests/api/mpi_figures.c on oversubscribed
 * ranks shows it; the times are in docs/scale-out.md).  After two rounds (the sign, the exponent and 4 bits
 * of the significand) few values still match the prefix as a rule: when at
 * most an eighth of a rank's do, their keys are copied once and the later
 * rounds count only those (compact(); the smallest key above the prefix's
 * range is kept for rank k + 1).  After eight rounds the prefix is the whole key of rank k, and the last bin's count
 * says whether rank k + 1 holds the same key; if not, it is the smallest
 * key above it (one MPI_Allreduce of minima).  The three selections (A->B,
 * B->A, both pooled) share their rounds.  hd__lerp, the single process's
 * interpolation, then gives the same double.  NaN has no rank and is
 * refused before (hd__nan_check, with the global index).
 *
 * Histograms: hd_histogram on each rank's values, counts summed.
 *
 * Failures: argument checks and the NaN check are local; the ranks agree
 * (hd__mpi_agree: the first failing rank's code and message) before every
 * collective, so a failure on one rank returns the same code everywhere,
 * never a hang.  The checks run in the single process's order (the result
 * pointer, the percentile, A's distances, then B's), so the code is the
 * one hd_summarize or hd_percentile_of returns on the concatenation.
 */
#include "mpi/course.h"
#include "mpi/search.h"

#include <assert.h>
#include <limits.h>
#include <stdlib.h>

/* ---- the common checks ----------------------------------------------------- */

typedef struct {
    const double *d[2];
    size_t n[2];
    uint64_t N[2];     /* over all ranks */
    int has_ba;        /* some rank passed B's distances */
} dists_t;

/* The checks hd_summarize and hd_percentile_of make, over the ranks:
 * this rank's NULL pointers, then (agreed) the totals, then NaN in A's
 * distances, then in B's, each with its global index. */
static int check_dists(hd__mpi_ctx_t *c, dists_t *v, int rc) {
    static const char *what[2] = {"A to B", "B to A"};
    if (rc == HD_OK && !v->d[0] && v->n[0]) rc = hd__err(&c->e, HD_EINVAL, "distances A to B are NULL");
    if (!v->d[1]) v->n[1] = 0;
    if ((rc = hd__mpi_agree(c, rc))) return rc;
    uint64_t mine[3] = {v->n[0], v->n[1], v->d[1] != NULL}, all[3], before[2] = {0, 0};
    HD__MPI_TRY(c, MPI_Allreduce(mine, all, 3, MPI_UINT64_T, MPI_SUM, c->comm));
    HD__MPI_TRY(c, MPI_Exscan(mine, before, 2, MPI_UINT64_T, MPI_SUM, c->comm));
    if (c->rank == 0) before[0] = before[1] = 0; /* MPI_Exscan leaves rank 0's undefined */
    v->N[0] = all[0];
    v->N[1] = all[1];
    v->has_ba = all[2] != 0;
    for (int s = 0; s < 1 + v->has_ba; s++) {
        if (v->N[s] == 0) return hd__err(&c->e, HD_EEMPTY, "distances %s are empty", what[s]); /* everywhere */
        rc = hd__nan_check(v->d[s], v->n[s], (size_t)before[s], what[s], &c->e);
        if ((rc = hd__mpi_agree(c, rc))) return rc;
    }
    return HD_OK;
}

/* ---- summaries ----------------------------------------------------------------- */

typedef struct {
    dists_t v;
    hd_summary_t *out;
} summary_arg_t;

static int summarize_body(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, void *arg, hd_mpi_stats_t *st) {
    (void)opt, (void)in, (void)st;
    summary_arg_t *a = arg;
    int rc = a->out ? HD_OK : hd__err(&c->e, HD_EINVAL, "result pointer is NULL");
    if ((rc = check_dists(c, &a->v, rc))) return rc;
    hd__xsum_t s[4];
    double max[2] = {-INFINITY, -INFINITY};
    for (int k = 0; k < 4; k++) hd__xsum_init(&s[k]);
    for (int d = 0; d < 2; d++) {
        max[d] = hd__xsum_values(&s[2 * d], &s[2 * d + 1], a->v.d[d], a->v.n[d], -INFINITY);
        hd__xsum_normalize(&s[2 * d]);
        hd__xsum_normalize(&s[2 * d + 1]);
    }
    /* the limbs (and the pending and special counts) of every rank added */
    HD__MPI_TRY(c, MPI_Allreduce(MPI_IN_PLACE, s, 4 * HD__XSUM_WORDS, MPI_INT64_T, MPI_SUM, c->comm));
    double *maxes = hd__mpi_alloc(c, 2 * (size_t)c->K, sizeof *maxes);
    rc = maxes ? HD_OK : hd__mpi_nomem(c, "the ranks' maxima", 2 * (size_t)c->K);
    if ((rc = hd__mpi_agree(c, rc))) {
        hd__mpi_free(c, maxes, 2 * (size_t)c->K, sizeof *maxes);
        return rc;
    }
    int e = MPI_Allgather(max, 2, MPI_DOUBLE, maxes, 2, MPI_DOUBLE, c->comm);
    double m[2] = {-INFINITY, -INFINITY};
    for (int r = 0; r < c->K; r++)
        for (int d = 0; d < 2; d++) m[d] = maxes[2 * r + d] > m[d] ? maxes[2 * r + d] : m[d];
    hd__mpi_free(c, maxes, 2 * (size_t)c->K, sizeof *maxes);
    if (e != MPI_SUCCESS) return hd__mpi_failed(c, "MPI_Allgather", e);
    size_t nb = a->v.has_ba ? (size_t)a->v.N[1] : 0;
    hd__summary_derive(a->out, (size_t)a->v.N[0], m[0], nb, m[1], s);
    return HD_OK;
}

int hd_mpi_summarize(MPI_Comm comm, const double *d_ab, size_t n_a, const double *d_ba, size_t n_b,
                     hd_summary_t *out, hd_error_t *err) {
    summary_arg_t a = {{{d_ab, d_ba}, {n_a, n_b}, {0, 0}, 0}, out};
    return hd__mpi_call(comm, NULL, 0, NULL, 0, NULL, summarize_body, &a, NULL, err);
}

/* ---- percentiles ---------------------------------------------------------------- */

#define DIGIT 8
#define BINS (1u << DIGIT)
#define ROUNDS (64 / DIGIT)

/* A key that orders as the doubles do (no NaN); -0.0 is +0.0's. */
static uint64_t key_of(double x) {
    union { double d; uint64_t u; } v;
    v.d = x == 0.0 ? 0.0 : x;
    return v.u >> 63 ? ~v.u : v.u | (uint64_t)1 << 63;
}

static double value_of(uint64_t k) {
    union { double d; uint64_t u; } v;
    v.u = k >> 63 ? k & ~((uint64_t)1 << 63) : ~k;
    return v.d;
}

/* One selection: rank k of the values of the directions in `dirs` (bit d
 * for direction d). */
typedef struct {
    int dirs;
    uint64_t k;       /* the rank still sought below the prefix */
    uint64_t prefix;  /* the key's bits found so far */
    uint64_t same;    /* values with the whole key of rank k, after the last round */
} sel_t;

/* A selection's local values: the directions' arrays, or (after
 * COMPACT_AFTER rounds, when few of them still match the prefix) the keys
 * that do, copied once, with the smallest key above the prefix's range
 * (`beyond`), which the last step needs. */
#define COMPACT_AFTER 2
typedef struct {
    uint64_t *keys;   /* NULL: scan the arrays */
    size_t n;
    uint64_t beyond;
} cand_t;

/* Count the local values of selection sel whose key starts with its
 * prefix into h, by their digit at `shift`. */
static void count_digits(const dists_t *v, const sel_t *sel, const cand_t *cd, int round, int shift, uint64_t *h) {
    if (cd->keys) {
        for (size_t i = 0; i < cd->n; i++)
            if (cd->keys[i] >> (shift + DIGIT) == sel->prefix) h[(cd->keys[i] >> shift) & (BINS - 1)]++;
        return;
    }
    for (int d = 0; d < 2; d++) {
        if (!(sel->dirs >> d & 1)) continue;
        const double *x = v->d[d];
        size_t n = v->n[d];
        if (round == 0) {
            for (size_t i = 0; i < n; i++) h[key_of(x[i]) >> shift]++;
        } else {
            for (size_t i = 0; i < n; i++) {
                uint64_t kk = key_of(x[i]);
                if (kk >> (shift + DIGIT) == sel->prefix) h[(kk >> shift) & (BINS - 1)]++;
            }
        }
    }
}

/* After COMPACT_AFTER rounds: the keys still matching the prefix, when
 * they are at most an eighth of the local values (a local choice: without
 * memory the arrays are scanned, with the same counts). */
static void compact(hd__mpi_ctx_t *c, const dists_t *v, const sel_t *sel, cand_t *cd) {
    int shift = 64 - DIGIT * COMPACT_AFTER;
    size_t all = 0, m = 0;
    uint64_t beyond = UINT64_MAX;
    for (int d = 0; d < 2; d++) {
        if (!(sel->dirs >> d & 1)) continue;
        all += v->n[d];
        for (size_t i = 0; i < v->n[d]; i++) {
            uint64_t kk = key_of(v->d[d][i]), top = kk >> shift;
            m += top == sel->prefix;
            if (top > sel->prefix && kk < beyond) beyond = kk;
        }
    }
    if (m > all / 8 || !(cd->keys = hd__mpi_alloc(c, m ? m : 1, sizeof *cd->keys))) return;
    cd->n = 0;
    cd->beyond = beyond;
    for (int d = 0; d < 2; d++) {
        if (!(sel->dirs >> d & 1)) continue;
        for (size_t i = 0; i < v->n[d]; i++) {
            uint64_t kk = key_of(v->d[d][i]);
            if (kk >> shift == sel->prefix) cd->keys[cd->n++] = kk;
        }
    }
    assert(cd->n == m);
}

/* The smallest local key above k. */
static uint64_t key_above(const dists_t *v, const sel_t *sel, const cand_t *cd, uint64_t k) {
    uint64_t above = UINT64_MAX;
    if (cd->keys) {
        above = cd->beyond;
        for (size_t i = 0; i < cd->n; i++)
            if (cd->keys[i] > k && cd->keys[i] < above) above = cd->keys[i];
        return above;
    }
    for (int d = 0; d < 2; d++) {
        if (!(sel->dirs >> d & 1)) continue;
        for (size_t i = 0; i < v->n[d]; i++) {
            uint64_t kk = key_of(v->d[d][i]);
            if (kk > k && kk < above) above = kk;
        }
    }
    return above;
}

/* Ranks k of every selection in sel[0..ns), and of k + 1 in *next
 * (next[s] = the key of rank k + 1). */
static int select_ranks(hd__mpi_ctx_t *c, const dists_t *v, sel_t *sel, int ns, uint64_t *key, uint64_t *next) {
    size_t words = (size_t)ns * BINS;
    cand_t cd[3] = {{NULL, 0, 0}, {NULL, 0, 0}, {NULL, 0, 0}};
    uint64_t *hist = hd__mpi_alloc(c, words, sizeof *hist);
    int rc = hist ? HD_OK : hd__mpi_nomem(c, "the selection's histograms", words);
    if ((rc = hd__mpi_agree(c, rc))) return rc;
    for (int round = 0; round < ROUNDS && rc == HD_OK; round++) {
        int shift = 64 - DIGIT * (round + 1);
        memset(hist, 0, words * sizeof *hist);
        for (int s = 0; s < ns; s++) {
            if (round == COMPACT_AFTER) compact(c, v, &sel[s], &cd[s]);
            count_digits(v, &sel[s], &cd[s], round, shift, hist + (size_t)s * BINS);
        }
        int e = MPI_Allreduce(MPI_IN_PLACE, hist, (int)words, MPI_UINT64_T, MPI_SUM, c->comm);
        if (e != MPI_SUCCESS) {
            rc = hd__mpi_failed(c, "MPI_Allreduce", e);
            break;
        }
        for (int s = 0; s < ns; s++) { /* the same walk on every rank */
            const uint64_t *h = hist + (size_t)s * BINS;
            uint32_t b = 0;
            while (sel[s].k >= h[b]) sel[s].k -= h[b++];
            assert(b < BINS);
            sel[s].prefix = sel[s].prefix << DIGIT | b;
            sel[s].same = h[b];
        }
    }
    hd__mpi_free(c, hist, words, sizeof *hist);
    /* rank k + 1: the same key, or the smallest key above it */
    uint64_t above[3] = {UINT64_MAX, UINT64_MAX, UINT64_MAX};
    for (int s = 0; s < ns; s++) {
        key[s] = sel[s].prefix;
        if (rc == HD_OK) above[s] = key_above(v, &sel[s], &cd[s], key[s]);
        hd__mpi_free(c, cd[s].keys, cd[s].n ? cd[s].n : 1, sizeof *cd[s].keys);
    }
    if (rc) return rc;
    HD__MPI_TRY(c, MPI_Allreduce(MPI_IN_PLACE, above, ns, MPI_UINT64_T, MPI_MIN, c->comm));
    for (int s = 0; s < ns; s++) next[s] = sel[s].k + 1 < sel[s].same ? key[s] : above[s];
    return HD_OK;
}

typedef struct {
    dists_t v;
    double p;
    hd_percentile_t *out;
} percentile_arg_t;

static int percentile_body(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, void *arg, hd_mpi_stats_t *st) {
    (void)opt, (void)in, (void)st;
    percentile_arg_t *a = arg;
    int rc = a->out ? HD_OK : hd__err(&c->e, HD_EINVAL, "result pointer is NULL");
    if (rc == HD_OK) rc = hd__percentile_check(a->p, &c->e);
    if ((rc = check_dists(c, &a->v, rc))) return rc;
    /* A->B, B->A, and both pooled: hd_percentile_of's three */
    uint64_t N[3] = {a->v.N[0], a->v.N[1], a->v.N[0] + a->v.N[1]};
    int dirs[3] = {1, 2, 3}, ns = a->v.has_ba ? 3 : 1;
    sel_t sel[3];
    size_t lo[3], hi[3];
    double t[3], res[3];
    for (int s = 0; s < ns; s++) {
        hd__percentile_ranks((size_t)N[s], a->p, &lo[s], &hi[s], &t[s]);
        sel[s] = (sel_t){dirs[s], lo[s], 0, 0};
    }
    uint64_t key[3], next[3];
    if ((rc = select_ranks(c, &a->v, sel, ns, key, next))) return rc;
    for (int s = 0; s < ns; s++) {
        double x = value_of(key[s]);
        res[s] = hd__lerp(x, hi[s] > lo[s] ? value_of(next[s]) : x, t[s]);
    }
    hd_percentile_t *o = a->out;
    o->p = a->p;
    o->ab = res[0];
    o->ba = o->symmetric = o->pooled = NAN;
    if (a->v.has_ba) {
        o->ba = res[1];
        o->pooled = res[2];
        o->symmetric = o->ab >= o->ba ? o->ab : o->ba;
    }
    return HD_OK;
}

int hd_mpi_percentile_of(MPI_Comm comm, const double *d_ab, size_t n_a, const double *d_ba, size_t n_b, double p,
                         hd_percentile_t *out, hd_error_t *err) {
    percentile_arg_t a = {{{d_ab, d_ba}, {n_a, n_b}, {0, 0}, 0}, p, out};
    return hd__mpi_call(comm, NULL, 0, NULL, 0, NULL, percentile_body, &a, NULL, err);
}

/* ---- histograms ------------------------------------------------------------------- */

typedef struct {
    const double *values;
    size_t n, bins;
    double lo, hi;
    uint64_t *counts;
} histogram_arg_t;

static int histogram_body(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, void *arg, hd_mpi_stats_t *st) {
    (void)opt, (void)in, (void)st;
    histogram_arg_t *a = arg;
    int rc = a->bins > INT_MAX ? hd__err(&c->e, HD_EOVERFLOW, "%zu bins are more than MPI can add", a->bins)
                               : hd_histogram(a->values, a->n, a->lo, a->hi, a->bins, a->counts, &c->e);
    if ((rc = hd__mpi_agree(c, rc))) return rc;
    HD__MPI_TRY(c, MPI_Allreduce(MPI_IN_PLACE, a->counts, (int)a->bins, MPI_UINT64_T, MPI_SUM, c->comm));
    return HD_OK;
}

int hd_mpi_histogram(MPI_Comm comm, const double *values, size_t n, double lo, double hi, size_t bins,
                     uint64_t *counts, hd_error_t *err) {
    histogram_arg_t a = {values, n, bins, lo, hi, counts};
    return hd__mpi_call(comm, NULL, 0, NULL, 0, NULL, histogram_body, &a, NULL, err);
}
