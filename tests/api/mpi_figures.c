/*
 * mpi_figures.c -- hd_mpi_summarize, hd_mpi_percentile_of and
 * hd_mpi_histogram (hausdorff_mpi.h) equal hd_summarize, hd_percentile_of
 * and hd_histogram on all the values, bit for bit, however the values are
 * spread over the ranks; and a failure on one rank is the same failure on
 * every rank, after which a good call works.  Run under mpirun with 1, 2,
 * 3, 4 and 7 ranks (tests/mpi.cmake).
 *
 * Every rank generates the same arrays from the same seed (printed on
 * failure); each layout gives each rank some runs of them, copied into one
 * buffer (in any order: the figures do not depend on it); the reference is
 * the single-process function on the whole arrays, on every rank.  The
 * arrays: distinct magnitudes, massive ties (lattice distances), all values
 * equal, one value, extremes (subnormals to 1e300, infinities), signed
 * values, and the exact sum's hard cases (values whose Neumaier sum was off
 * by an ulp).  Percentiles 0, 50, 95, 100 and two between ranks.
 *
 * The harness is tests/support/mpicheck.h (tests/support/check.c knows
 * nothing of ranks): a failure prints the rank, the case and the seed; rank
 * 0 prints "N checks, M failed", and the exit status is agreed.
 */
#include <hausdorff_mpi.h>

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gen.h"
#include "mpicheck.h"

/* ---- arrays ------------------------------------------------------------------ */

enum { AR_SPREAD, AR_TIES, AR_EQUAL, AR_ONE, AR_EXTREME, AR_SIGNED, AR_CANCEL, AR_HUGE, AR_COUNT };
static const char *const ar_name[AR_COUNT] = {"distinct magnitudes", "lattice ties", "all equal", "one value",
                                              "extremes", "signed", "cancelling pairs",
                                              "squares summing beyond DBL_MAX"};

/* n values of kind `which`, seeded. */
static double *make_values(int which, uint64_t seed, size_t *n) {
    gen_rng_t g;
    gen_seed(&g, seed);
    size_t m = which == AR_ONE ? 1 : which == AR_EQUAL ? 500 : 3001;
    double *v = malloc(m * sizeof *v);
    static const double lat[6] = {0.0, 1.0, 1.4142135623730951, 1.7320508075688772, 2.0, 2.23606797749979};
    for (size_t k = 0; k < m; k++) {
        switch (which) {
        case AR_SPREAD: v[k] = fabs(gen_normal(&g)) * pow(10.0, floor(gen_unit(&g) * 7) - 3); break;
        case AR_TIES: v[k] = lat[gen_u64(&g) % 6]; break;
        case AR_EQUAL: v[k] = 0.1; break;
        case AR_ONE: v[k] = 2.5; break;
        case AR_EXTREME: {
            uint64_t r = gen_u64(&g) % 8;
            v[k] = r == 0 ? INFINITY : r == 1 ? 0x1p-1074 * (double)(gen_u64(&g) % 100) : r == 2 ? 0.0
                 : gen_unit(&g) * pow(10.0, floor(gen_unit(&g) * 600) - 300);
            break;
        }
        case AR_SIGNED: v[k] = gen_normal(&g) * 1e3 + (k % 5 == 0 ? 1.0 : 0.0); break;
        case AR_CANCEL: v[k] = k % 2 ? -v[k - 1] * (1 + 0x1p-40) : gen_normal(&g) * 1e15; break;
        case AR_HUGE: v[k] = 3.4641016151377544e153 * (0.5 + gen_unit(&g) / 2); break; /* within 1e153 coordinates */
        }
        if (v[k] == 0.0) v[k] = 0.0; /* never -0.0: the percentile's one documented difference */
    }
    *n = m;
    return v;
}

/* ---- layouts ---------------------------------------------------------------- */

enum { LAY_BLOCKS, LAY_CHUNKS, LAY_ALL_ON_0, LAY_ALL_ON_LAST, LAY_HOLES, LAY_COUNT };
static const char *const lay_name[LAY_COUNT] = {"blocks", "chunks of 7 round robin", "all on rank 0",
                                                "all on the last rank", "rank 1 empty, random runs"};

/* This rank's values of v[0..n) under layout `how`, copied into a new
 * buffer (*m of them; the buffer is never NULL). */
static double *spread(int how, const double *v, size_t n, uint64_t seed, size_t *m) {
    double *out = malloc((n + 1) * sizeof *out);
    size_t c = 0;
    gen_rng_t g;
    gen_seed(&g, seed * 17 + 5);
    for (size_t lo = 0, chunk = 0; lo < n; chunk++) {
        size_t w = n - lo;
        int to = 0;
        switch (how) {
        case LAY_BLOCKS:
            to = (int)(lo * (size_t)K_ / n);
            w = 1;
            break;
        case LAY_CHUNKS:
            to = (int)(chunk % (size_t)K_);
            w = w < 7 ? w : 7;
            break;
        case LAY_ALL_ON_0: to = 0; break;
        case LAY_ALL_ON_LAST: to = K_ - 1; break;
        case LAY_HOLES:
            w = 1 + (size_t)(gen_u64(&g) % 300);
            w = w < n - lo ? w : n - lo;
            to = (int)(gen_u64(&g) % (uint64_t)K_);
            if (K_ > 1 && to == 1) to = 0;
            break;
        }
        if (to == rank_) memcpy(out + c, v + lo, w * sizeof *v), c += w;
        lo += w;
    }
    *m = c;
    return out;
}

/* ---- the figures, against the single process ---------------------------------- */

static int same_summary(const hd_summary_t *x, const hd_summary_t *y) {
    const double *a = &x->max_ab, *b = &y->max_ab; /* every double field, after the counts */
    size_t nd = (sizeof *x - offsetof(hd_summary_t, max_ab)) / sizeof(double);
    return x->n_ab == y->n_ab && x->n_ba == y->n_ba && memcmp(a, b, nd * sizeof(double)) == 0;
}

static int same_percentile(const hd_percentile_t *x, const hd_percentile_t *y) {
    return memcmp(x, y, sizeof *x) == 0;
}

/* A->B values `ab`, B->A values `ba` (NULL: directed) under layout how. */
static void check_figures(int wa, int wb, int how, int directed, uint64_t seed) {
    size_t na, nb = 0, ma, mb = 0;
    double *ab = make_values(wa, seed, &na), *ba = directed ? NULL : make_values(wb, seed + 1, &nb);
    double *la = spread(how, ab, na, seed, &ma), *lb = ba ? spread((how + 2) % LAY_COUNT, ba, nb, seed + 1, &mb) : NULL;
    snprintf(context_, sizeof context_, "A->B %s, B->A %s, layout %s (B: %s), seed %llu", ar_name[wa],
             directed ? "absent" : ar_name[wb], lay_name[how], lay_name[(how + 2) % LAY_COUNT],
             (unsigned long long)seed);
    hd_error_t err;
    /* B's distances present: a rank with none of them passes NULL (allowed) */
    const double *pb = lb && mb ? lb : NULL;
    if (!directed && K_ == 1) pb = lb;
    hd_summary_t want, got;
    CHECK(hd_summarize(ab, na, ba, nb, &want, &err) == HD_OK);
    int rc = hd_mpi_summarize(MPI_COMM_WORLD, la, ma, pb, mb, &got, &err);
    CHECK(rc == HD_OK);
    if (rc) fprintf(stderr, "rank %d: %s\n", rank_, err.message);
    CHECK(same_summary(&want, &got));
    static const double ps[6] = {0, 50, 95, 100, 37.3, 99.9};
    for (int k = 0; k < 6; k++) {
        hd_percentile_t pw, pg;
        CHECK(hd_percentile_of(ab, na, ba, nb, ps[k], &pw, &err) == HD_OK);
        CHECK(hd_mpi_percentile_of(MPI_COMM_WORLD, la, ma, pb, mb, ps[k], &pg, &err) == HD_OK);
        CHECK(same_percentile(&pw, &pg));
        if (!same_percentile(&pw, &pg))
            fprintf(stderr, "  p %g: ab %.17g %.17g ba %.17g %.17g pooled %.17g %.17g\n", ps[k], pw.ab, pg.ab, pw.ba,
                    pg.ba, pw.pooled, pg.pooled);
    }
    double hi = isfinite(want.max_ab) && want.max_ab > 0 ? want.max_ab : 1.0;
    size_t bins[2] = {20, 7};
    double top[2] = {hi, hi / 2};
    for (int k = 0; k < 2; k++) {
        uint64_t hw[20], hg[20];
        CHECK(hd_histogram(ab, na, 0.0, top[k], bins[k], hw, &err) == HD_OK);
        CHECK(hd_mpi_histogram(MPI_COMM_WORLD, la, ma, 0.0, top[k], bins[k], hg, &err) == HD_OK);
        CHECK(memcmp(hw, hg, bins[k] * sizeof hw[0]) == 0);
    }
    free(ab);
    free(ba);
    free(la);
    free(lb);
}

/* ---- failures ----------------------------------------------------------------------- */

static void check_good_call_after(void) {
    double v[3] = {1, 2, 3 + rank_};
    hd_summary_t s;
    hd_percentile_t p;
    hd_error_t err;
    CHECK(hd_mpi_summarize(MPI_COMM_WORLD, v, 3, v, 3, &s, &err) == HD_OK);
    CHECK(s.n_ab == 3 * (size_t)K_ && s.max_ab == 3 + (K_ - 1));
    CHECK(hd_mpi_percentile_of(MPI_COMM_WORLD, v, 3, v, 3, 100, &p, &err) == HD_OK);
    CHECK(p.symmetric == 3 + (K_ - 1));
}

static void check_errors(void) {
    snprintf(context_, sizeof context_, "errors");
    size_t n = 100;
    double *v = malloc(n * sizeof *v);
    for (size_t k = 0; k < n; k++) v[k] = (double)k;
    hd_summary_t s;
    hd_percentile_t p;
    hd_error_t err;
    /* a NaN on the last rank only: its global index, as the single process names it */
    if (rank_ == K_ - 1) v[40] = NAN;
    char want[64];
    snprintf(want, sizeof want, "distance %zu of A to B is NaN", (size_t)(K_ - 1) * n + 40);
    check_agreed(hd_mpi_summarize(MPI_COMM_WORLD, v, n, NULL, 0, &s, &err), HD_ENONFINITE, &err, want);
    check_agreed(hd_mpi_percentile_of(MPI_COMM_WORLD, v, n, v, n, 95, &p, &err), HD_ENONFINITE, &err, want);
    /* A's NaN on the last rank wins over B's on rank 0, as in the single
     * process, which checks A's distances first */
    double *u = malloc(n * sizeof *u);
    for (size_t k = 0; k < n; k++) u[k] = (double)k;
    if (rank_ == 0) u[3] = NAN;
    check_agreed(hd_mpi_summarize(MPI_COMM_WORLD, v, n, u, n, &s, &err), HD_ENONFINITE, &err, want);
    check_agreed(hd_mpi_percentile_of(MPI_COMM_WORLD, v, n, u, n, 5, &p, &err), HD_ENONFINITE, &err, want);
    free(u);
    /* B's NaN is found after A's checks pass */
    if (rank_ == K_ - 1) v[40] = 40;
    double *w = malloc(n * sizeof *w);
    memcpy(w, v, n * sizeof *w);
    if (rank_ == K_ - 1) w[99] = NAN;
    snprintf(want, sizeof want, "distance %zu of B to A is NaN", (size_t)(K_ - 1) * n + 99);
    check_agreed(hd_mpi_summarize(MPI_COMM_WORLD, v, n, w, n, &s, &err), HD_ENONFINITE, &err, want);
    check_good_call_after();
    /* a NULL result on the last rank only */
    check_agreed(hd_mpi_summarize(MPI_COMM_WORLD, v, n, NULL, 0, rank_ == K_ - 1 ? NULL : &s, &err), HD_EINVAL, &err,
                 "result pointer is NULL");
    check_agreed(hd_mpi_percentile_of(MPI_COMM_WORLD, v, n, NULL, 0, 50, rank_ == K_ - 1 ? NULL : &p, &err),
                 HD_EINVAL, &err, "result pointer is NULL");
    /* a NULL array with values on the last rank only */
    check_agreed(hd_mpi_summarize(MPI_COMM_WORLD, rank_ == K_ - 1 ? NULL : v, n, NULL, 0, &s, &err), HD_EINVAL, &err,
                 "distances A to B are NULL");
    /* no values anywhere; B present somewhere but empty everywhere */
    check_agreed(hd_mpi_summarize(MPI_COMM_WORLD, NULL, 0, NULL, 0, &s, &err), HD_EEMPTY, &err,
                 "distances A to B are empty");
    check_agreed(hd_mpi_percentile_of(MPI_COMM_WORLD, v, n, rank_ == 0 ? w : NULL, 0, 50, &p, &err), HD_EEMPTY, &err,
                 "distances B to A are empty");
    /* p outside [0, 100] */
    check_agreed(hd_mpi_percentile_of(MPI_COMM_WORLD, v, n, NULL, 0, 100.5, &p, &err), HD_EINVAL, &err,
                 "percentile must be in [0, 100]");
    /* a bad histogram range, and a histogram without a counts array on the last rank */
    uint64_t c[4];
    check_agreed(hd_mpi_histogram(MPI_COMM_WORLD, v, n, 2.0, 1.0, 4, c, &err), HD_EINVAL, &err, "not a finite interval");
    check_agreed(hd_mpi_histogram(MPI_COMM_WORLD, v, n, 0.0, 1.0, 4, rank_ == K_ - 1 ? NULL : c, &err), HD_EINVAL,
                 &err, "NULL");
    check_good_call_after();
    free(v);
    free(w);
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &K_);
    check_errors();
    for (int wa = 0; wa < AR_COUNT; wa++)
        for (int how = 0; how < LAY_COUNT; how++) {
            uint64_t seed = 500 + 10 * (uint64_t)wa + (uint64_t)how;
            check_figures(wa, (wa + how) % AR_COUNT, how, 0, seed);
            if (how == LAY_HOLES) check_figures(wa, 0, how, 1, seed);
        }
    return mpicheck_finish("mpi_figures");
}
