/*
 * test_histogram.c -- histograms of the nearest distances without every
 * distance (hd_hausdorff_histogram through hd__an_hist) as a
 * specification: both directions' counts equal hd_histogram's on every
 * exact distance (hd_distances'; test_analysis.c checks those against a
 * brute force), to the count, at 1 and 3 threads: random sets, lattices
 * (ties, duplicates), edges placed on actual distances, one bin and many,
 * ranges that cut values off on either side, an empty range (numpy's
 * widening), a subnormal range; and placing the ends of an interval
 * decides every value between them (hd__hist_decided).
 */
#include "check.h"
#include "gen.h"
#include "nearest/nearest.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Both directions' counts against hd_histogram of every distance. */
static void check_counts(const hd_points_t *A, const hd_points_t *B, size_t bins, double lo, double hi) {
    size_t na = A->count, nb = B->count;
    double *d = malloc(8 * (na + nb));
    uint64_t *want = calloc(2 * bins, 8), *got = calloc(2 * bins, 8);
    CHECK_RC(hd_distances(A, B, NULL, d, NULL, d + na, NULL, NULL), HD_OK);
    CHECK_RC(hd_histogram(d, na, lo, hi, bins, want, NULL), HD_OK);
    CHECK_RC(hd_histogram(d + na, nb, lo, hi, bins, want + bins, NULL), HD_OK);
    for (int threads = 1; threads <= 3; threads += 2) {
        hd_options_t o;
        hd_options_init(&o);
        o.threads = threads;
        memset(got, 0xff, 2 * bins * 8); /* overwritten */
        CHECK_RC(hd_hausdorff_histogram(A, B, &o, bins, lo, hi, got, got + bins, NULL), HD_OK);
        for (size_t k = 0; k < 2 * bins; k++) {
            if (got[k] == want[k]) continue;
            CHECK_EQ(got[k], want[k]);
            printf("    bins=%zu range [%.17g, %.17g] threads=%d: %s bin %zu\n", bins, lo, hi, threads,
                   k < bins ? "A->B" : "B->A", k % bins);
            break;
        }
    }
    free(d);
    free(want);
    free(got);
}

/* The largest distance of either direction, and one distance by index. */
static double largest(const hd_points_t *A, const hd_points_t *B, size_t pick, double *picked) {
    size_t na = A->count, nb = B->count;
    double *d = malloc(8 * (na + nb)), m = 0;
    CHECK_RC(hd_distances(A, B, NULL, d, NULL, d + na, NULL, NULL), HD_OK);
    for (size_t k = 0; k < na + nb; k++) m = d[k] > m ? d[k] : m;
    *picked = d[pick % (na + nb)];
    free(d);
    return m;
}

/* Two sets by seed (gen_mixed_pair), named in the failure context. */
static void make_pair(uint64_t seed, size_t n, double **a, double **b, hd_points_t *A, hd_points_t *B) {
    int kind = gen_mixed_pair(seed, n, a, b, A, B);
    CONTEXT("seed=%llu kind=%d |A|=%zu |B|=%zu", (unsigned long long)seed, kind, A->count, B->count);
}

TEST(counts_equal_every_distance_for_any_bins_and_range) {
    static const size_t bins[] = {1, 2, 7, 64, 1000, 20000};
    for (uint64_t seed = 1; seed <= 15; seed++) {
        size_t n = seed % 3 == 0 ? 1 + seed % 7 : seed % 3 == 1 ? 3000 : 12000;
        double *a, *b, v;
        hd_points_t A, B;
        make_pair(seed, n, &a, &b, &A, &B);
        double H = largest(&A, &B, seed * 7919, &v);
        for (size_t k = 0; k < sizeof bins / sizeof bins[0]; k++) {
            check_counts(&A, &B, bins[k], 0.0, H);          /* the CLI's range */
            check_counts(&A, &B, bins[k], 0.0, H / 3);      /* cuts the largest off */
            check_counts(&A, &B, bins[k], H / 4, 0.75 * H); /* cuts off both sides */
        }
        check_counts(&A, &B, 5, v, v);        /* an empty range, widened */
        check_counts(&A, &B, 3, -2.0 * H, -H); /* every value above */
        free(a);
        free(b);
        if (hdt_failed()) return;
    }
}

TEST(counts_equal_every_distance_with_edges_on_actual_distances) {
    /* Lattices against the same lattice shifted by half a step or not:
     * every distance is one of a few values; edges at v (range [0, 2v],
     * 2 bins: edge 1 is exactly v) and ranges ending on a value. */
    for (uint64_t seed = 100; seed < 108; seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t n = 8000;
        double *a = malloc(24 * n), *b = malloc(24 * n), v;
        gen_lattice(&g, a, n, 20);
        gen_lattice(&g, b, n, 20);
        gen_affine(b, n, 1.0, 0.5 * (double)(seed % 2));
        hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
        double H = largest(&A, &B, seed * 104729, &v);
        CONTEXT("seed=%llu lattice 20, shift %g, v=%.17g", (unsigned long long)seed, 0.5 * (double)(seed % 2), v);
        check_counts(&A, &B, 2, 0.0, 2 * v);
        check_counts(&A, &B, 4, 0.0, 4 * v);
        check_counts(&A, &B, 3, 0.0, v);
        check_counts(&A, &B, 3, v, H);
        check_counts(&A, &B, 1, v, H);
        check_counts(&A, &B, 10, 0.0, H);
        free(a);
        free(b);
        if (hdt_failed()) return;
    }
}

TEST(counts_equal_every_distance_on_a_subnormal_range) {
    /* Copies at distance 0 and tiny offsets: numpy's norm is infinite. */
    size_t n = 5000;
    gen_rng_t g;
    gen_seed(&g, 9);
    double *a = malloc(24 * n), *b = malloc(24 * n);
    gen_cube(&g, a, n, 0, 1);
    memcpy(b, a, 24 * n);
    for (size_t k = 0; k < n; k += 3) b[3 * k] = nextafter(b[3 * k], 2.0);
    hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
    check_counts(&A, &B, 4, 0.0, 1e-310);
    check_counts(&A, &B, 7, 0.0, 3e-16);
    free(a);
    free(b);
}

TEST(an_interval_decided_by_its_ends_is_decided_throughout) {
    /* hd__hist_decided against placing many values of the interval. */
    gen_rng_t g;
    gen_seed(&g, 31);
    for (int trial = 0; trial < 20000; trial++) {
        double lo = gen_unit(&g) * (trial % 2 ? 1.0 : 1e3), hi = lo + gen_unit(&g) * 10;
        size_t bins = 1 + gen_u64(&g) % 50;
        hd__hist_t h;
        CHECK_RC(hd__hist_init(&h, lo, hi, bins, NULL), HD_OK);
        /* ends near an edge, so that the corrections matter */
        double e = hd__hist_edge(&h, gen_u64(&g) % (bins + 1)), l = e, u = e;
        for (int s = (int)(gen_u64(&g) % 4); s > 0; s--) l = nextafter(l, -INFINITY);
        for (int s = (int)(gen_u64(&g) % 4); s > 0; s--) u = nextafter(u, INFINITY);
        size_t bin, guess;
        if (!hd__hist_decided(&h, l, u, &bin)) continue;
        for (double x = l; x <= u; x = nextafter(x, INFINITY)) {
            CONTEXT("trial %d range [%.17g, %.17g] bins %zu x %.17g", trial, lo, hi, bins, x);
            CHECK_EQ(hd__hist_place(&h, x, &guess), bin);
        }
        if (hdt_failed()) return;
    }
}

TEST(bad_arguments_are_refused) {
    double p[3] = {0, 0, 0};
    hd_points_t A = hd_points_f64(p, 1);
    uint64_t c[2];
    hd_error_t e;
    CHECK_RC(hd_hausdorff_histogram(&A, &A, NULL, 2, 0, 1, NULL, c, &e), HD_EINVAL);
    CHECK_RC(hd_hausdorff_histogram(&A, &A, NULL, 0, 0, 1, c, c, &e), HD_EINVAL);
    CHECK_RC(hd_hausdorff_histogram(&A, &A, NULL, 2, 1, 0, c, c, &e), HD_EINVAL);
    CHECK_RC(hd_hausdorff_histogram(&A, &A, NULL, 2, 0, INFINITY, c, c, &e), HD_EINVAL);
    CHECK_RC(hd_hausdorff_histogram(&A, &A, NULL, 2, -DBL_MAX, DBL_MAX, c, c, &e), HD_ERANGE);
    hd_points_t E = hd_points_f64(p, 0);
    CHECK_RC(hd_hausdorff_histogram(&A, &E, NULL, 2, 0, 1, c, c, &e), HD_EEMPTY);
    CHECK_RC(hd_hausdorff_histogram(&A, &A, NULL, 2, 0, 1, c, NULL, &e), HD_OK); /* B->A skipped */
    CHECK_EQ(c[0], 1);
    CHECK_EQ(c[1], 0);
}
