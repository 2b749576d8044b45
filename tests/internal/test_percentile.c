/*
 * test_percentile.c -- percentiles without every distance
 * (hd_hausdorff_percentile through nearest/percentile.c and hd__an_band) as
 * a specification: every figure (A->B, B->A, MONAI's symmetric, medpy's
 * pooled) has the bits of numpy's linear percentile on a full sort of every
 * exact distance, at 1 and 3 threads, on sets small enough to be sampled
 * whole and large enough to be sampled, with ties (lattices, where many
 * distances equal the percentile), duplicates, very unequal sizes and
 * P = 0, 95, 99.9, 100 and others; a sample that misleads the bands on
 * either side still gives the same bits; the band pass, and the one that
 * settles whole nodes from bounds (hd__an_band_settled), count and keep
 * exactly what a brute classification does.  The exact distances of the
 * reference are hd_distances' (test_analysis.c checks them against a brute
 * force).
 */
#include "brute.h"
#include "check.h"
#include "gen.h"
#include "nearest/nearest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int cmp_d(const void *x, const void *y) {
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* numpy.percentile(v, p) written from its documentation on a full sort
 * (v is sorted in place). */
static double sorted_percentile(double *v, size_t n, double p) {
    qsort(v, n, sizeof *v, cmp_d);
    double pos = (double)(n - 1) * (p / 100.0);
    if (pos >= (double)(n - 1)) return v[n - 1];
    size_t lo = (size_t)floor(pos);
    double t = pos - floor(pos), a = v[lo], b = v[lo + 1];
    return t >= 0.5 ? b - (b - a) * (1.0 - t) : a + (b - a) * t;
}

/* The four figures from every exact distance, sorted. */
static hd_percentile_t reference(const hd_points_t *A, const hd_points_t *B, double p) {
    size_t na = A->count, nb = B->count;
    double *d = malloc(8 * (na + nb)), *e = malloc(8 * (na + nb));
    CHECK_RC(hd_distances(A, B, NULL, d, NULL, d + na, NULL, NULL), HD_OK);
    memcpy(e, d, 8 * (na + nb));
    hd_percentile_t r = {p, sorted_percentile(e, na, p), sorted_percentile(e + na, nb, p), 0,
                         sorted_percentile(d, na + nb, p)};
    r.symmetric = r.ab >= r.ba ? r.ab : r.ba;
    free(d);
    free(e);
    return r;
}

static void check_figures(const hd_points_t *A, const hd_points_t *B, double p) {
    hd_percentile_t want = reference(A, B, p);
    for (int threads = 1; threads <= 3; threads += 2) {
        hd_options_t o;
        hd_options_init(&o);
        o.threads = threads;
        hd_percentile_t got;
        CHECK_RC(hd_hausdorff_percentile(A, B, &o, p, &got, NULL), HD_OK);
        CHECK_BITS(got.p, p);
        CHECK_BITS(got.ab, want.ab);
        CHECK_BITS(got.ba, want.ba);
        CHECK_BITS(got.symmetric, want.symmetric);
        CHECK_BITS(got.pooled, want.pooled);
    }
}

/* Two sets by seed (gen_mixed_pair), named in the failure context. */
static void make_pair(uint64_t seed, size_t n, double **a, double **b, hd_points_t *A, hd_points_t *B) {
    int kind = gen_mixed_pair(seed, n, a, b, A, B);
    CONTEXT("seed=%llu kind=%d |A|=%zu |B|=%zu", (unsigned long long)seed, kind, A->count, B->count);
}

TEST(percentiles_equal_a_full_sort_on_tiny_and_sampled_sets) {
    static const double ps[] = {0, 95, 99.9, 100, 50, 5, 0.01};
    for (uint64_t seed = 1; seed <= 30; seed++) {
        size_t n = seed % 3 == 0 ? 1 + seed % 7 : seed % 3 == 1 ? 3000 : 12000;
        double *a, *b;
        hd_points_t A, B;
        make_pair(seed, n, &a, &b, &A, &B);
        for (size_t k = 0; k < sizeof ps / sizeof ps[0]; k++) check_figures(&A, &B, ps[k]);
        free(a);
        free(b);
        if (hdt_failed()) return;
    }
}

TEST(percentiles_equal_a_full_sort_where_many_distances_tie_at_the_percentile) {
    /* Integer lattices against the same lattice shifted by half a step:
     * every distance is one of a few values, so the ranks around the
     * percentile all hold the same value and the bands' edges fall on it. */
    for (uint64_t seed = 100; seed < 106; seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t n = 20000;
        double *a = malloc(24 * n), *b = malloc(24 * n);
        gen_lattice(&g, a, n, 30);
        gen_lattice(&g, b, n, 30);
        gen_affine(b, n, 1.0, 0.5 * (double)(seed % 2));
        hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
        CONTEXT("seed=%llu lattice 30, shift %g", (unsigned long long)seed, 0.5 * (double)(seed % 2));
        check_figures(&A, &B, 95);
        check_figures(&A, &B, 50 + (double)(seed % 7) * 7.125);
        free(a);
        free(b);
        if (hdt_failed()) return;
    }
}

/* A of n points whose sampled points (index k * n / SAMPLE: every point
 * of the sample stride) lie on B's points and the others `far` away, or
 * the reverse (near = 0): the sample sees the opposite of the set. */
static void misleading(size_t n, int sampled_near, double **a, double **b, hd_points_t *A, hd_points_t *B) {
    gen_rng_t g;
    gen_seed(&g, 7);
    *b = malloc(24 * n);
    *a = malloc(24 * n);
    gen_cube(&g, *b, n, 0, 1);
    char *sampled = calloc(n, 1);
    for (size_t k = 0; k < 4096; k++) sampled[(uint64_t)k * n / 4096] = 1;
    for (size_t i = 0; i < n; i++) {
        int near = sampled[i] == sampled_near;
        for (int d = 0; d < 3; d++) (*a)[3 * i + d] = (*b)[3 * i + d] + (near ? 0.0 : 5.0 + 1e-3 * (double)(i % 97));
    }
    free(sampled);
    *A = hd_points_f64(*a, n);
    *B = hd_points_f64(*b, n);
}

TEST(a_misleading_sample_changes_no_bit) {
    for (int sampled_near = 0; sampled_near < 2; sampled_near++) {
        CONTEXT("sampled points %s", sampled_near ? "on B, the others far" : "far, the others on B");
        double *a, *b;
        hd_points_t A, B;
        misleading(4096 * 3 + 17, sampled_near, &a, &b, &A, &B);
        static const double ps[] = {5, 50, 95, 100, 0};
        for (size_t k = 0; k < sizeof ps / sizeof ps[0]; k++) check_figures(&A, &B, ps[k]);
        free(a);
        free(b);
    }
}

/* A band test's sets: A (a) against B (b), every brute-force nearest
 * squared distance of A's points (d2) and both structures on one key box. */
typedef struct {
    double *a, *b, *d2;
    hd_points_t A, B;
    hd__box_t keybox;
    hd__an_t s[2];
} band_sets_t;

static void band_sets_build(band_sets_t *t) {
    size_t na = t->A.count;
    t->d2 = malloc(8 * na);
    for (size_t i = 0; i < na; i++) t->d2[i] = brute_nearest(t->a + 3 * i, t->b, t->B.count, NULL);
    hd__box_t ba, bb;
    CHECK_RC(hd__points_scan(&t->A, "A", 1, &ba, NULL), HD_OK);
    CHECK_RC(hd__points_scan(&t->B, "B", 1, &bb, NULL), HD_OK);
    hd__box_merge(&ba, &bb);
    t->keybox = ba;
    CHECK_RC(hd__an_build_pair(&t->A, &t->B, &ba, 2, t->s, NULL), HD_OK);
}

/* A band pass's answer `got` (freed here) against the brute classification
 * of the n squared distances d2 by [lo2, hi2]. */
static void check_band(const double *d2, size_t n, double lo2, double hi2, hd__an_band_t *got) {
    double *want = malloc(8 * (n ? n : 1));
    size_t below = 0, above = 0, in = 0;
    for (size_t i = 0; i < n; i++) {
        below += d2[i] < lo2;
        above += d2[i] > hi2;
        if (d2[i] >= lo2 && d2[i] <= hi2) want[in++] = d2[i];
    }
    qsort(want, in, 8, cmp_d);
    CHECK_EQ(got->below, below);
    CHECK_EQ(got->above, above);
    CHECK_EQ(got->n, in);
    qsort(got->v, got->n, 8, cmp_d);
    for (size_t k = 0; k < in && k < got->n; k++) CHECK_BITS(got->v[k], want[k]);
    free(got->v);
    free(want);
}

static void band_sets_free(band_sets_t *t) {
    hd__an_free(&t->s[0]);
    hd__an_free(&t->s[1]);
    free(t->d2);
    free(t->a);
    free(t->b);
}

/* A band whose edges are actual values (ties sit on them), ordered;
 * trial 0 opens it below, trial 1 above. */
static void band_edges(gen_rng_t *g, const double *d2, size_t n, int trial, double *lo2, double *hi2) {
    *lo2 = trial == 0 ? 0 : d2[gen_u64(g) % n];
    *hi2 = trial == 1 ? INFINITY : d2[gen_u64(g) % n];
    if (*lo2 > *hi2) {
        double t = *lo2;
        *lo2 = *hi2, *hi2 = t;
    }
}

TEST(the_band_pass_counts_and_keeps_what_a_full_classification_does) {
    for (uint64_t seed = 200; seed < 206; seed++) {
        band_sets_t t;
        make_pair(seed, 2500, &t.a, &t.b, &t.A, &t.B);
        band_sets_build(&t);
        size_t na = t.A.count;
        gen_rng_t g;
        gen_seed(&g, seed);
        for (int trial = 0; trial < 6; trial++) {
            double lo2, hi2;
            band_edges(&g, t.d2, na, trial, &lo2, &hi2);
            for (int threads = 1; threads <= 3; threads += 2) {
                CONTEXT("seed=%llu band [%.17g, %.17g] threads=%d", (unsigned long long)seed, lo2, hi2, threads);
                hd__an_band_t got;
                CHECK_RC(hd__an_band(&t.s[0], &t.s[1], lo2, hi2, threads, &got, NULL), HD_OK);
                check_band(t.d2, na, lo2, hi2, &got);
            }
        }
        band_sets_free(&t);
        if (hdt_failed()) return;
    }
}

TEST(the_band_pass_classifies_each_point_as_a_full_classification_does) {
    /* hd__an_band_each: every point's class by its index (-1 below, +inf
     * above, else its exact d2), with a run of copies of one point (a
     * bucket settled once for all of them), lattice ties on the edges, and
     * a band at the largest value (whole buckets below at once). */
    for (uint64_t seed = 300; seed < 304; seed++) {
        band_sets_t t;
        make_pair(seed, 3000, &t.a, &t.b, &t.A, &t.B);
        size_t na = t.A.count;
        for (size_t i = na / 2; i < na / 2 + 200 && i < na; i++) memcpy(t.a + 3 * i, t.a, 3 * sizeof(double));
        for (size_t i = 0; i < na / 4; i++) /* lattice points: ties */
            for (int d = 0; d < 3; d++) t.a[3 * i + d] = floor(t.a[3 * i + d] * 8) / 8;
        band_sets_build(&t);
        const double *d2 = t.d2;
        double *each = malloc(8 * na), top = 0;
        for (size_t i = 0; i < na; i++) top = d2[i] > top ? d2[i] : top;
        gen_rng_t g;
        gen_seed(&g, seed);
        for (int trial = 0; trial < 6; trial++) {
            double lo2 = top, hi2 = INFINITY;
            if (trial < 5) band_edges(&g, d2, na, trial, &lo2, &hi2);
            for (int threads = 1; threads <= 3; threads += 2) {
                CONTEXT("seed=%llu band [%.17g, %.17g] threads=%d", (unsigned long long)seed, lo2, hi2, threads);
                hd__an_band_t got;
                for (size_t i = 0; i < na; i++) each[i] = NAN;
                CHECK_RC(hd__an_band_each(&t.s[0], &t.s[1], lo2, hi2, threads, &got, each, NULL), HD_OK);
                size_t wrong = 0;
                for (size_t i = 0; i < na; i++) {
                    double want = d2[i] < lo2 ? -1.0 : d2[i] > hi2 ? INFINITY : d2[i];
                    wrong += memcmp(&each[i], &want, sizeof want) != 0;
                }
                CHECK_EQ(wrong, (size_t)0);
                free(got.v);
            }
        }
        band_sets_free(&t);
        free(each);
        if (hdt_failed()) return;
    }
}

TEST(a_sparse_set_classified_against_a_dense_one_counts_and_keeps_what_a_full_classification_does) {
    /* A few hundred points against tens of thousands: each bucket of the
     * few spreads over many buckets of the many, and its points list
     * their candidates on their own.  Lattice coordinates put ties on the
     * band's edges. */
    size_t solo = 0;
    for (uint64_t seed = 230; seed < 234 && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t na = 200 + gen_u64(&g) % 300, nb = 30000 + gen_u64(&g) % 10000;
        double *a = malloc(24 * na), *b = malloc(24 * nb), m0[3] = {0, 0, 0};
        gen_gauss(&g, a, na, m0, 1.0);
        gen_gauss(&g, b, nb, m0, 1.0);
        for (size_t k = 0; seed % 2 && k < 3 * nb; k++) b[k] = 0.0625 * floor(b[k] * 16);
        for (size_t k = 0; seed % 2 && k < 3 * na; k++) a[k] = 0.0625 * floor(a[k] * 16) + 0.03125;
        hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
        double *d2 = malloc(8 * na);
        for (size_t i = 0; i < na; i++) d2[i] = brute_nearest(a + 3 * i, b, nb, NULL);
        hd__box_t ba, bb;
        CHECK_RC(hd__points_scan(&A, "A", 1, &ba, NULL), HD_OK);
        CHECK_RC(hd__points_scan(&B, "B", 1, &bb, NULL), HD_OK);
        hd__box_merge(&ba, &bb);
        hd__an_t s[2];
        CHECK_RC(hd__an_build_pair(&A, &B, &ba, 2, s, NULL), HD_OK);
        for (int trial = 0; trial < 4; trial++) {
            double lo2 = trial == 0 ? 0 : d2[gen_u64(&g) % na], hi2 = trial == 1 ? INFINITY : d2[gen_u64(&g) % na];
            if (lo2 > hi2) {
                double t = lo2;
                lo2 = hi2, hi2 = t;
            }
            for (int threads = 1; threads <= 3; threads += 2) {
                CONTEXT("seed=%llu |A|=%zu |B|=%zu band [%.17g, %.17g] threads=%d", (unsigned long long)seed, na, nb,
                        lo2, hi2, threads);
                hd__an_band_t got;
                CHECK_RC(hd__an_band(&s[0], &s[1], lo2, hi2, threads, &got, NULL), HD_OK);
                solo += got.solo;
                check_band(d2, na, lo2, hi2, &got);
            }
        }
        hd__an_free(&s[0]);
        hd__an_free(&s[1]);
        free(a), free(b), free(d2);
    }
    CONTEXT("points that listed their own candidates: %zu", solo);
    CHECK(solo > 0);
}

/* Sets where node bounds settle most points (shape 0: disjoint Gaussians,
 * B 20 sigma away; 1: B a hundredth the size; 2: a lattice against the
 * same lattice 40 steps away, every distance one of a few values, so ties
 * sit on the band's edges; 3: as 2 with A's points each copied 70 times,
 * so that a bucket is one point and its upper bound is a distance). */
static void settled_sets(uint64_t seed, int shape, band_sets_t *t) {
    gen_rng_t g;
    gen_seed(&g, seed);
    size_t na = shape >= 2 ? 8400 : 6000 + gen_u64(&g) % 3000, nb = shape == 1 ? na / 100 : na;
    double m0[3] = {0, 0, 0}, m1[3] = {20, 0, 0};
    t->a = malloc(24 * na), t->b = malloc(24 * nb);
    if (shape >= 2) {
        gen_lattice(&g, t->a, na, 20);
        gen_lattice(&g, t->b, nb, 20);
        for (size_t i = 0; i < nb; i++) t->b[3 * i] += 40;
        for (size_t i = 0; shape == 3 && i < na; i++) memcpy(t->a + 3 * i, t->a + 3 * (i / 70), 24);
    } else {
        gen_gauss(&g, t->a, na, m0, 1.0);
        gen_gauss(&g, t->b, nb, shape == 0 ? m1 : m0, 1.0);
    }
    t->A = hd_points_f64(t->a, na), t->B = hd_points_f64(t->b, nb);
    band_sets_build(t);
}

TEST(the_settled_band_pass_counts_and_keeps_what_a_full_classification_does) {
    /* hd__an_band_settled against a brute classification: nodes counted
     * from their bounds, the open buckets' points classified exactly.  A
     * bound made too tight (an upper bound below a point's distance, a
     * lower bound above it) miscounts the points on the band's edges. */
    size_t settled = 0;
    for (int shape = 0; shape < 4; shape++)
        for (uint64_t seed = 400; seed < 403 && !hdt_failed(); seed++) {
            band_sets_t t;
            settled_sets(seed, shape, &t);
            size_t na = t.A.count;
            gen_rng_t g;
            gen_seed(&g, seed);
            for (int trial = 0; trial < 7; trial++) {
                double lo2, hi2;
                band_edges(&g, t.d2, na, trial, &lo2, &hi2);
                if (trial == 6) lo2 = hi2; /* a band of one value */
                for (int threads = 1; threads <= 3; threads += 2) {
                    CONTEXT("seed=%llu shape=%d |A|=%zu band [%.17g, %.17g] threads=%d", (unsigned long long)seed,
                            shape, na, lo2, hi2, threads);
                    hd__an_band_t got;
                    size_t s = 0;
                    CHECK_RC(hd__an_band_settled(&t.s[0], &t.s[1], &t.A, &t.keybox, lo2, hi2, threads, &got, &s,
                                                 NULL),
                             HD_OK);
                    settled += s;
                    check_band(t.d2, na, lo2, hi2, &got);
                }
            }
            band_sets_free(&t);
        }
    CONTEXT("points settled from bounds: %zu", settled);
    CHECK(settled > 0);
}

TEST(percentiles_equal_a_full_sort_where_bounds_settle_most_points) {
    /* The same four shapes through hd_hausdorff_percentile: disjoint
     * sets, very unequal sizes, ties at the percentile, copies. */
    static const double ps[] = {95, 50, 99.9, 0, 100};
    for (int shape = 0; shape < 4 && !hdt_failed(); shape++) {
        band_sets_t t;
        settled_sets(500 + (uint64_t)shape, shape, &t);
        CONTEXT("shape=%d |A|=%zu |B|=%zu", shape, t.A.count, t.B.count);
        for (size_t k = 0; k < sizeof ps / sizeof ps[0]; k++) check_figures(&t.A, &t.B, ps[k]);
        band_sets_free(&t);
    }
}

TEST(percentiles_from_cell_bounds_equal_a_full_sort_on_sets_far_apart) {
    /* hd__percentile_cells on disjoint shapes (Gaussians 20 sigma apart,
     * lattices 40 steps apart with ties at the percentile and copies): it
     * must take its path (cells counted from bounds, the open points
     * classified against the part of the other set within their cells'
     * upper bounds), and give the bits of a full sort.  A bound too tight,
     * or a part of the other set missing a nearest point, moves a rank. */
    static const double ps[] = {95, 50, 99.9, 0, 100, 5};
    static const int shapes[] = {0, 2, 3};
    for (size_t k = 0; k < 3 && !hdt_failed(); k++) {
        band_sets_t t;
        settled_sets(600 + (uint64_t)k, shapes[k], &t);
        hd__box_t box_a, box_b;
        hd__box_of(t.a, t.A.count, &box_a);
        hd__box_of(t.b, t.B.count, &box_b);
        for (size_t j = 0; j < sizeof ps / sizeof ps[0]; j++) {
            hd_percentile_t want = reference(&t.A, &t.B, ps[j]);
            for (int threads = 1; threads <= 3; threads += 2) {
                CONTEXT("shape=%d |A|=%zu |B|=%zu p=%g threads=%d", shapes[k], t.A.count, t.B.count, ps[j],
                        threads);
                hd_percentile_t got;
                int done = 0;
                CHECK_RC(hd__percentile_cells(&t.A, &t.B, &box_a, &box_b, &t.keybox, threads, ps[j], &got, &done,
                                              NULL),
                         HD_OK);
                CHECK(done == 1);
                if (!done) continue;
                CHECK_BITS(got.ab, want.ab);
                CHECK_BITS(got.ba, want.ba);
                CHECK_BITS(got.symmetric, want.symmetric);
                CHECK_BITS(got.pooled, want.pooled);
            }
        }
        band_sets_free(&t);
    }
}

TEST(percentiles_from_cell_bounds_decline_sets_whose_boxes_overlap) {
    /* B a hundredth of A around the same centre: the cells path declines
     * (done = 0) and leaves the figures to the structures. */
    band_sets_t t;
    settled_sets(610, 1, &t);
    hd__box_t box_a, box_b;
    hd__box_of(t.a, t.A.count, &box_a);
    hd__box_of(t.b, t.B.count, &box_b);
    hd_percentile_t got;
    int done = 1;
    CHECK_RC(hd__percentile_cells(&t.A, &t.B, &box_a, &box_b, &t.keybox, 1, 95, &got, &done, NULL), HD_OK);
    CHECK(done == 0);
    band_sets_free(&t);
}

TEST(an_empty_side_is_refused_as_before) {
    double p[3] = {0, 0, 0};
    hd_points_t A = hd_points_f64(p, 1), E = hd_points_f64(p, 0);
    hd_percentile_t r;
    CHECK_RC(hd_hausdorff_percentile(&A, &E, NULL, 95, &r, NULL), HD_EEMPTY);
    CHECK_RC(hd_hausdorff_percentile(&E, &A, NULL, 95, &r, NULL), HD_EEMPTY);
    CHECK_RC(hd_hausdorff_percentile(&A, &A, NULL, 100.5, &r, NULL), HD_EINVAL);
}
