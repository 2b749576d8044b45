/*
 * test_analysis.c -- the analysis functions as a specification: per-point
 * distances agree with the brute force bit for bit (ties, both directions,
 * float32 views, thread counts), selection and percentiles agree with a full
 * sort for every rank and every percentile step, P = 100 is the Hausdorff
 * distance, sums are exact, histograms put every value in the bin
 * whose edges enclose it, and bad input is refused with the right code.
 * Bit-exact agreement with numpy itself is tested in cli_analysis_lib.py.
 */
#include "brute.h"
#include "check.h"
#include "gen.h"
#include "nearest/nearest.h"
#include "classic/classic.h"

#include <math.h>
#include <stdlib.h>

/* ---- references ----------------------------------------------------------- */

static int cmp_d(const void *x, const void *y) {
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* numpy.percentile(v, p) written from its documentation on a full sort. */
static double ref_percentile(const double *v, size_t n, double p) {
    double *s = malloc(n * sizeof *s);
    memcpy(s, v, n * sizeof *s);
    qsort(s, n, sizeof *s, cmp_d);
    double pos = (double)(n - 1) * (p / 100.0), r;
    if (pos >= (double)(n - 1)) {
        r = s[n - 1];
    } else {
        size_t lo = (size_t)floor(pos);
        double t = pos - floor(pos), a = s[lo], b = s[lo + 1];
        r = t >= 0.5 ? b - (b - a) * (1.0 - t) : a + (b - a) * t;
    }
    free(s);
    return r;
}

/* Distances with ties: lattice points, few distinct values. */
static double *lattice_values(gen_rng_t *g, size_t n, int side) {
    double *v = malloc(n * sizeof *v);
    for (size_t k = 0; k < n; k++) {
        double x = (double)(gen_u64(g) % (uint64_t)side), y = (double)(gen_u64(g) % (uint64_t)side);
        v[k] = sqrt(x * x + y * y);
    }
    return v;
}

/* Two clouds for per-point tests, by seed: Gaussians, lattices with many
 * equidistant neighbours, duplicates, very unequal sizes (kind = seed % 4).
 * case_open sets the failure context to the seed and the kind. */
typedef struct {
    double *a, *b;
    size_t na, nb;
    hd_points_t A, B;
} case_t;

static void case_open(case_t *c, uint64_t seed) {
    int kind = (int)(seed % 4);
    CONTEXT("seed=%llu kind=%d", (unsigned long long)seed, kind);
    gen_rng_t g;
    gen_seed(&g, seed);
    c->na = 1 + gen_u64(&g) % 400;
    c->nb = 1 + gen_u64(&g) % 400;
    if (kind == 3) c->nb = 1 + gen_u64(&g) % 4;
    c->a = malloc(24 * c->na);
    c->b = malloc(24 * c->nb);
    double m0[3] = {0, 0, 0}, m1[3] = {0.7, 0, 0};
    if (kind == 0 || kind == 3) {
        gen_gauss(&g, c->a, c->na, m0, 1.0);
        gen_gauss(&g, c->b, c->nb, m1, 1.0);
    } else if (kind == 1) {
        gen_lattice(&g, c->a, c->na, 6);
        gen_lattice(&g, c->b, c->nb, 6);
    } else {
        gen_lattice(&g, c->a, c->na, 3); /* duplicates in both */
        gen_lattice(&g, c->b, c->nb, 3);
        gen_affine(c->b, c->nb, 1.0, 0.5);
    }
    c->A = hd_points_f64(c->a, c->na);
    c->B = hd_points_f64(c->b, c->nb);
}

static void case_close(case_t *c) {
    free(c->a);
    free(c->b);
}

/* Brute-force distances of the points of p (n) to q (m). */
static double *brute_distances(const double *p, size_t n, const double *q, size_t m) {
    double *d = malloc(8 * n);
    for (size_t i = 0; i < n; i++) d[i] = sqrt(brute_nearest(p + 3 * i, q, m, NULL));
    return d;
}

/* ---- per-point distances ---------------------------------------------------- */

TEST(per_point_distances_match_brute_force_in_both_directions) {
    for (uint64_t seed = 1; seed <= 40; seed++) {
        case_t c;
        case_open(&c, seed);
        hd_options_t o;
        hd_options_init(&o);
        o.threads = (int)(seed % 3) + 1;
        double *dab = malloc(8 * c.na), *dba = malloc(8 * c.nb);
        size_t *jab = malloc(sizeof(size_t) * c.na), *jba = malloc(sizeof(size_t) * c.nb);
        CHECK_RC(hd_distances(&c.A, &c.B, &o, dab, jab, dba, jba, NULL), HD_OK);
        for (size_t i = 0; i < c.na && !hdt_failed(); i++) {
            size_t j;
            double d2 = brute_nearest(c.a + 3 * i, c.b, c.nb, &j);
            CHECK_BITS(dab[i], sqrt(d2));
            CHECK_EQ(jab[i], j);
        }
        for (size_t i = 0; i < c.nb && !hdt_failed(); i++) {
            size_t j;
            double d2 = brute_nearest(c.b + 3 * i, c.a, c.na, &j);
            CHECK_BITS(dba[i], sqrt(d2));
            CHECK_EQ(jba[i], j);
        }
        free(dab), free(dba), free(jab), free(jba);
        case_close(&c);
    }
}

TEST(per_point_distances_of_float32_views_are_exact_for_the_floats) {
    gen_rng_t g;
    gen_seed(&g, 77);
    CONTEXT("seed=77");
    size_t na = 300, nb = 250;
    float fa[900], fb[750];
    double a[900], b[750];
    for (size_t k = 0; k < 3 * na; k++) a[k] = fa[k] = (float)gen_normal(&g);
    for (size_t k = 0; k < 3 * nb; k++) b[k] = fb[k] = (float)(gen_normal(&g) + 0.25);
    hd_points_t A = hd_points_f32(fa, na), B = hd_points_f32(fb, nb);
    double d[300];
    size_t j[300];
    CHECK_RC(hd_distances(&A, &B, NULL, d, j, NULL, NULL, NULL), HD_OK);
    for (size_t i = 0; i < na; i++) {
        size_t bj;
        CHECK_BITS(d[i], sqrt(brute_nearest(a + 3 * i, b, nb, &bj)));
        CHECK_EQ(j[i], bj);
    }
}

TEST(distances_skip_a_direction_whose_outputs_are_null) {
    double a[] = {0, 0, 0, 3, 0, 0}, b[] = {1, 0, 0};
    hd_points_t A = hd_points_f64(a, 2), B = hd_points_f64(b, 1);
    size_t j[1] = {99};
    CHECK_RC(hd_distances(&A, &B, NULL, NULL, NULL, NULL, j, NULL), HD_OK);
    CHECK_EQ(j[0], 0); /* B[0] is at 1 from A[0] and 2 from A[1] */
    double d[2];
    CHECK_RC(hd_distances(&A, &B, NULL, d, NULL, NULL, NULL, NULL), HD_OK);
    CHECK_BITS(d[0], 1.0);
    CHECK_BITS(d[1], 2.0);
}

TEST(distances_refuse_empty_and_nonfinite_sets_naming_them) {
    double a[] = {0, 0, 0}, nan_[] = {0, NAN, 0};
    hd_points_t A = hd_points_f64(a, 1), E = hd_points_f64(a, 0), N = hd_points_f64(nan_, 1);
    double d[1];
    hd_error_t e;
    CHECK_RC(hd_distances(&A, &E, NULL, d, NULL, NULL, NULL, &e), HD_EEMPTY);
    CHECK(strstr(e.message, "B") != NULL);
    CHECK_RC(hd_distances(&E, &A, NULL, d, NULL, NULL, NULL, &e), HD_EEMPTY);
    CHECK(strstr(e.message, "A") != NULL);
    CHECK_RC(hd_distances(&N, &A, NULL, d, NULL, NULL, NULL, &e), HD_ENONFINITE);
}

/* ---- per-point distances: shapes that stress the search structure ---------------- */

/* hd_distances of the views A and B (whose points, widened to double, are
 * a and b) against the brute force in both directions, bit for bit and
 * index for index, with `threads` threads. */
static void check_against_brute(const hd_points_t *A, const double *a, size_t na,
                                const hd_points_t *B, const double *b, size_t nb, int threads) {
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    double *dab = malloc(8 * na), *dba = malloc(8 * nb);
    size_t *jab = malloc(sizeof(size_t) * na), *jba = malloc(sizeof(size_t) * nb);
    CHECK_RC(hd_distances(A, B, &o, dab, jab, dba, jba, NULL), HD_OK);
    for (size_t i = 0; i < na && !hdt_failed(); i++) {
        size_t j;
        double d2 = brute_nearest(a + 3 * i, b, nb, &j);
        CHECK_BITS(dab[i], sqrt(d2));
        CHECK_EQ(jab[i], j);
    }
    for (size_t i = 0; i < nb && !hdt_failed(); i++) {
        size_t j;
        double d2 = brute_nearest(b + 3 * i, a, na, &j);
        CHECK_BITS(dba[i], sqrt(d2));
        CHECK_EQ(jba[i], j);
    }
    free(dab), free(dba), free(jab), free(jba);
}

/* check_against_brute on packed doubles. */
static void check_packed(const double *a, size_t na, const double *b, size_t nb, int threads) {
    hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
    check_against_brute(&A, a, na, &B, b, nb, threads);
}

/* Shape `kind` of n points into xyz (seeded by g). */
enum { SH_GAUSS, SH_LATTICE, SH_DUPLICATES, SH_IDENTICAL, SH_PLANE, SH_LINE, SH_AXIS_PLANE, SH_KINDS };
static void shape(gen_rng_t *g, int kind, double *xyz, size_t n) {
    double m0[3] = {0, 0, 0};
    switch (kind) {
    case SH_GAUSS: gen_gauss(g, xyz, n, m0, 1.0); break;
    case SH_LATTICE: gen_lattice(g, xyz, n, 9); break;
    case SH_DUPLICATES: gen_lattice(g, xyz, n, 2); break;
    case SH_IDENTICAL:
        for (size_t k = 0; k < 3 * n; k++) xyz[k] = k % 3 == 0 ? 0.25 : -1.5;
        break;
    case SH_PLANE: gen_plane(g, xyz, n); break;
    case SH_LINE: gen_line(g, xyz, n); break;
    default: /* zero extent on two axes after rounding, lattice steps on z */
        gen_lattice(g, xyz, n, 7);
        for (size_t k = 0; k < n; k++) xyz[3 * k] = 3.0, xyz[3 * k + 1] = -2.0;
        break;
    }
}

TEST(per_point_distances_are_exact_on_shapes_sizes_scales_and_offsets) {
    /* Every pair of shapes, with sizes from 1 to a few thousand (ratios up
     * to 1:1000), B shifted from overlapping to far outside A's box, and
     * the whole scene scaled to 1e-150 or moved to 1e9 with small steps. */
    static const size_t sizes[][2] = {{1, 1}, {3, 3000}, {3000, 3}, {700, 900}, {2500, 2000}, {64, 65}};
    static const double shifts[] = {0.0, 0.3, 40.0, 1e4};
    uint64_t seed = 1000;
    for (int ka = 0; ka < SH_KINDS; ka++)
        for (int kb = 0; kb < SH_KINDS; kb++) {
            seed++;
            gen_rng_t g;
            gen_seed(&g, seed);
            const size_t *sz = sizes[seed % 6];
            double shift = shifts[seed / 6 % 4];
            int scale = (int)(seed / 24 % 3); /* 0: as is, 1: 1e-150, 2: 1e9 + 1e-3 steps */
            int threads = seed % 2 ? 1 : 3;
            CONTEXT("seed=%llu shapes=%d,%d sizes=%zu,%zu shift=%g scale=%d threads=%d",
                    (unsigned long long)seed, ka, kb, sz[0], sz[1], shift, scale, threads);
            double *a = malloc(24 * sz[0]), *b = malloc(24 * sz[1]);
            shape(&g, ka, a, sz[0]);
            shape(&g, kb, b, sz[1]);
            for (size_t k = 0; k < sz[1]; k++) b[3 * k] += shift;
            if (scale == 1) {
                gen_affine(a, sz[0], 1e-150, 0.0);
                gen_affine(b, sz[1], 1e-150, 0.0);
            } else if (scale == 2) {
                gen_affine(a, sz[0], 1e-3, 1e9);
                gen_affine(b, sz[1], 1e-3, 1e9);
            }
            check_packed(a, sz[0], b, sz[1], threads);
            free(a), free(b);
            if (hdt_failed()) return;
        }
}

TEST(per_point_distances_are_exact_with_crowds_of_equal_points) {
    /* Thousands of copies of a few points: buckets and groups of equal
     * Morton keys far larger than their nominal sizes, ties everywhere. */
    for (uint64_t seed = 1; seed <= 4; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t na = 3000, nb = 2000;
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        for (size_t k = 0; k < na; k++) {
            int c = (int)(gen_u64(&g) % 3);
            a[3 * k] = c, a[3 * k + 1] = 0.5 * c, a[3 * k + 2] = seed == 4 ? 1e-9 * (double)(k % 2) : 0;
        }
        for (size_t k = 0; k < nb; k++) {
            int c = (int)(gen_u64(&g) % 4);
            b[3 * k] = 0.5 * c, b[3 * k + 1] = 0.25 * c, b[3 * k + 2] = 0;
        }
        check_packed(a, na, b, nb, (int)seed % 3 + 1);
        free(a), free(b);
    }
}

TEST(per_point_distances_are_exact_for_clusters_next_to_far_outliers) {
    /* A tight cluster and one far point: the cluster falls into one cell of
     * the grid over the whole box and must be refined (nested clusters
     * too); the outliers' nearest points are in the clusters. */
    for (uint64_t seed = 21; seed <= 24; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t na = 4000, nb = 3000;
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        double m0[3] = {0, 0, 0}, m1[3] = {1e-6, 0, 0};
        gen_gauss(&g, a, na, m0, 1e-5);
        gen_gauss(&g, b, nb, m1, 1e-5);
        if (seed >= 23) { /* a cluster within the cluster */
            gen_affine(a, na / 2, 1e-7, 0.0);
            gen_affine(b, nb / 3, 1e-7, 0.0);
        }
        a[3 * (na - 1)] = 1e6;
        b[0] = -1e6, b[1] = 5e5;
        check_packed(a, na, b, nb, (int)seed % 3 + 1);
        free(a), free(b);
    }
}

/* The box of the n points of a and the n points of b: the grid both
 * structures are sorted on, as hd_distances takes it. */
static hd__box_t union_box(const double *a, const double *b, size_t n) {
    hd__box_t box;
    for (int d = 0; d < 3; d++) {
        box.lo[d] = box.hi[d] = a[d];
        for (size_t k = 0; k < n; k++) {
            double u = a[3 * k + (size_t)d], v = b[3 * k + (size_t)d];
            box.lo[d] = fmin(box.lo[d], fmin(u, v));
            box.hi[d] = fmax(box.hi[d], fmax(u, v));
        }
    }
    return box;
}

/* How many groups of A's queries the partner path of src/nearest/allnearest.c settled
 * when A (n points) asks B (n points), B's point i being A's point i's
 * partner; *groups gets the number of A's groups. */
static size_t partner_groups(const double *a, const double *b, size_t n, int threads, size_t *groups) {
    hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
    hd__box_t box = union_box(a, b, n);
    hd__an_t sa, sb;
    hd__an_counts_t counts = {0};
    CHECK_RC(hd__an_build(&sa, &A, NULL, &box, threads, NULL), HD_OK);
    CHECK_RC(hd__an_build(&sb, &B, NULL, &box, threads, NULL), HD_OK);
    CHECK_RC(hd__an_nearest(&sa, &sb, &B, threads, NULL, NULL, &counts, NULL), HD_OK);
    *groups = sa.ng;
    hd__an_free(&sa);
    hd__an_free(&sb);
    return counts.paired;
}

TEST(same_order_copies_are_exact_and_mostly_settled_by_their_partners) {
    /* B is A moved a little, point for point: each query's partner is
     * tried first.  Ties at the partner's distance (exact binary steps,
     * half lattice steps, repeated points) must still go to the smallest
     * index, and exchanged partners or outliers must not fool it. */
    int settled = 0, cases = 0;
    for (uint64_t seed = 20000; seed < 20000 + 4 * GEN_COPY_KINDS && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        int how = (int)(seed % GEN_COPY_KINDS), threads = seed % 2 ? 1 : 3;
        size_t n = 1 + gen_u64(&g) % (seed % 4 == 0 ? 6000 : 900);
        CONTEXT("seed=%llu copy=%s n=%zu threads=%d", (unsigned long long)seed, gen_copy_name[how], n,
                threads);
        double *a = malloc(24 * n), *b = malloc(24 * n);
        gen_copy(&g, how, a, b, n);
        check_packed(a, n, b, n, threads);
        size_t groups;
        settled += partner_groups(a, b, n, threads, &groups) > 0;
        cases++;
        free(a), free(b);
    }
    /* The partner path itself was under test in most cases. */
    CONTEXT("cases with groups settled by partners: %d of %d", settled, cases);
    CHECK(settled >= cases / 2);
}

/* A asks B (n points each) without partners, on the grid over both
 * boxes as hd_distances builds them: each answer against the brute force,
 * bit for bit and index for index; *counts gets what the searches took. */
static void check_window(const double *a, const double *b, size_t n, int threads, hd__an_counts_t *counts) {
    hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
    hd__box_t box = union_box(a, b, n);
    hd__an_t sa, sb;
    double *d = malloc(8 * n);
    size_t *j = malloc(sizeof(size_t) * n);
    CHECK_RC(hd__an_build(&sa, &A, NULL, &box, threads, NULL), HD_OK);
    CHECK_RC(hd__an_build(&sb, &B, NULL, &box, threads, NULL), HD_OK);
    CHECK_RC(hd__an_nearest(&sa, &sb, NULL, threads, d, j, counts, NULL), HD_OK);
    for (size_t i = 0; i < n && !hdt_failed(); i++) {
        size_t jb;
        double d2 = brute_nearest(a + 3 * i, b, n, &jb);
        CONTEXT("query %zu", i);
        CHECK_BITS(d[i], sqrt(d2));
        CHECK_EQ(j[i], jb);
    }
    hd__an_free(&sa);
    hd__an_free(&sb);
    free(d), free(j);
}

TEST(shuffled_copies_are_exact_and_mostly_settled_by_the_window) {
    /* B is a copy of A (every kind gen_copy makes: noise, exact, binary
     * and half-lattice steps with ties, repeated points, outliers, far
     * away at 1e9, scaled to 1e-150, and here also to 1e-9) in a random
     * order, so no partner helps: each query's first answer comes from
     * the points at its own key on B's curve.  Ties must still go to the
     * smallest index, the queries set apart (their answers across a jump
     * of the curve) must still find theirs. */
    int windowed = 0, apart = 0, cases = 0;
    for (uint64_t seed = 31000; seed < 31000 + 4 * GEN_COPY_KINDS && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        int how = (int)(seed % GEN_COPY_KINDS), threads = seed % 2 ? 1 : 3;
        size_t n = 1 + gen_u64(&g) % (seed % 4 == 0 ? 9000 : 1500);
        int tiny = seed % 3 == 0;
        CONTEXT("seed=%llu copy=%s n=%zu threads=%d scale=%s", (unsigned long long)seed, gen_copy_name[how], n,
                threads, tiny ? "1e-9" : "1");
        double *a = malloc(24 * n), *b = malloc(24 * n);
        gen_copy(&g, how, a, b, n);
        for (size_t k = n; k > 1; k--) gen_swap(b, k - 1, gen_u64(&g) % k);
        if (tiny) gen_affine(a, n, 1e-9, 0.0), gen_affine(b, n, 1e-9, 0.0);
        hd__an_counts_t c = {0};
        check_window(a, b, n, threads, &c);
        check_window(b, a, n, threads, &c);
        check_packed(a, n, b, n, threads);
        windowed += c.windowed > 0;
        apart += c.apart > 0;
        cases++;
        free(a), free(b);
    }
    /* Both routes of the window path were under test. */
    CONTEXT("cases with groups settled by the window: %d of %d, with queries set apart: %d", windowed, cases,
            apart);
    CHECK(windowed >= cases / 2);
    CHECK(apart >= 4);
}

TEST(queries_set_apart_by_the_window_find_their_answers_within_and_beyond_the_group_bound) {
    /* B is a copy of A (a Gaussian of sigma 1, noise 1e-3) in a random
     * order with one point in 40 moved 0.2 away (a few spacings between
     * neighbours).  A query whose
     * window lies across a jump of B's curve is set apart; when its answer
     * is within the group's bound U the group's list holds it, and when
     * its copy moved away its answer may be above U: then the best it
     * reaches on the list is above U too, and it lists its own
     * candidates.  And two samples of one cube, and small Gaussians one
     * sigma apart, where the answers of the queries set apart lie near U,
     * on either side.  Both directions,
     * every answer against the brute force, at 1 and 3 threads. */
    size_t apart = 0, windowed = 0;
    for (uint64_t seed = 39500; seed < 39530 && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t n = seed % 3 == 2 ? 50 + gen_u64(&g) % 350 : 4000 + gen_u64(&g) % 4000;
        int threads = seed % 2 ? 1 : 3;
        CONTEXT("seed=%llu n=%zu threads=%d", (unsigned long long)seed, n, threads);
        double *a = malloc(24 * n), *b = malloc(24 * n);
        if (seed % 3 == 2) {
            double m0[3] = {0, 0, 0}, m1[3] = {1, 0, 0};
            gen_gauss(&g, a, n, m0, 1.0);
            gen_gauss(&g, b, n, m1, 1.0);
        } else if (seed % 3 == 1) {
            gen_cube(&g, a, n, -1.0, 1.0);
            gen_cube(&g, b, n, -1.0, 1.0);
        } else {
            gen_copy(&g, GEN_COPY_NOISE, a, b, n);
            for (size_t k = n; k > 1; k--) gen_swap(b, k - 1, gen_u64(&g) % k);
            for (size_t k = 0; k < n; k += 40) b[3 * k + (k / 40) % 3] += 0.2;
        }
        hd__an_counts_t c = {0};
        check_window(a, b, n, threads, &c);
        check_window(b, a, n, threads, &c);
        apart += c.apart;
        windowed += c.windowed;
        free(a), free(b);
    }
    CONTEXT("groups windowed %zu, queries listing their own candidates %zu", windowed, apart);
    CHECK(windowed > 0);
    CHECK(apart > 0);
}

TEST(a_sparse_set_asking_a_dense_one_is_searched_point_by_point_and_stays_exact) {
    /* A few points asking many: each group of queries spreads over far
     * more searched buckets than it has queries, so its queries are
     * searched on their own (the solo path); the dense set asking the
     * sparse one answers a chunk of queries at a time from the few
     * points that can be any of their answers (point lists), its small
     * groups too, so that most of its queries are answered so.  Ties and
     * copies included: half-lattice coordinates, some queries repeated. */
    size_t solo = 0, pointed = 0, dense = 0;
    for (uint64_t seed = 32000; seed < 32006 && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        int threads = seed % 2 ? 1 : 3;
        size_t na = 300 + gen_u64(&g) % 700, nb = 40000 + gen_u64(&g) % 20000;
        CONTEXT("seed=%llu na=%zu nb=%zu threads=%d", (unsigned long long)seed, na, nb, threads);
        double *a = malloc(24 * nb), *b = malloc(24 * nb);
        double m0[3] = {0, 0, 0}, m1[3] = {seed % 3 ? 0.0 : 0.5, 0, 0};
        gen_gauss(&g, a, na, m0, 1.0);
        gen_gauss(&g, b, nb, m1, 1.0);
        if (seed % 2 == 0)
            for (size_t k = 0; k < 3 * nb; k++) b[k] = 0.125 * (double)(long)(b[k] * 8);
        for (size_t k = 0; k + 1 < na; k += 5) memcpy(a + 3 * (k + 1), a + 3 * k, 24);
        hd__an_counts_t c = {0};
        double *both = malloc(24 * (na + nb));
        memcpy(both, a, 24 * na), memcpy(both + 3 * na, b, 24 * nb);
        hd__box_t box;
        hd__box_of(both, na + nb, &box);
        hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
        hd__an_t sa, sb;
        double *d = malloc(8 * nb);
        size_t *j = malloc(sizeof(size_t) * nb);
        CHECK_RC(hd__an_build(&sa, &A, NULL, &box, threads, NULL), HD_OK);
        CHECK_RC(hd__an_build(&sb, &B, NULL, &box, threads, NULL), HD_OK);
        CHECK_RC(hd__an_nearest(&sa, &sb, NULL, threads, d, j, &c, NULL), HD_OK);
        for (size_t i = 0; i < na && !hdt_failed(); i++) {
            size_t jb;
            double d2 = brute_nearest(a + 3 * i, b, nb, &jb);
            CONTEXT("seed=%llu A->B query %zu", (unsigned long long)seed, i);
            CHECK_BITS(d[i], sqrt(d2));
            CHECK_EQ(j[i], jb);
        }
        solo += c.solo;
        hd__an_counts_t cb = {0};
        CHECK_RC(hd__an_nearest(&sb, &sa, NULL, threads, d, j, &cb, NULL), HD_OK);
        pointed += cb.pointed, dense += nb;
        for (size_t i = 0; i < nb && !hdt_failed(); i += 7) {
            size_t ja;
            double d2 = brute_nearest(b + 3 * i, a, na, &ja);
            CONTEXT("seed=%llu B->A query %zu", (unsigned long long)seed, i);
            CHECK_BITS(d[i], sqrt(d2));
            CHECK_EQ(j[i], ja);
        }
        hd__an_free(&sa);
        hd__an_free(&sb);
        free(a), free(b), free(both), free(d), free(j);
    }
    CONTEXT("queries searched on their own: %zu, answered from point lists: %zu of %zu", solo, pointed, dense);
    CHECK(solo > 0);
    CHECK(5 * pointed >= 4 * dense); /* small groups too (the dense set is 40 times the other) */
}

TEST(a_structure_over_selected_points_answers_with_their_names) {
    /* hd__an_build_sel, as the MPI layer's slabs use it: B's structure
     * holds a random subset of B named by B's numbers, A's a subset of A
     * named by their ranks in it.  Each answer is the brute force's over
     * the subset (smallest B number on ties: copies with ties, lattices,
     * repeated points), written at the asking point's name; the build's
     * account of its peak covers what it keeps. */
    for (uint64_t seed = 41000; seed < 41000 + 3 * GEN_COPY_KINDS && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        int how = (int)(seed % GEN_COPY_KINDS), threads = seed % 2 ? 1 : 3;
        size_t n = 2 + gen_u64(&g) % (seed % 4 == 0 ? 7000 : 1200);
        CONTEXT("seed=%llu copy=%s n=%zu threads=%d", (unsigned long long)seed, gen_copy_name[how], n, threads);
        double *a = malloc(24 * n), *b = malloc(24 * n), *bs = malloc(24 * n);
        uint32_t *sa = malloc(4 * n), *sb = malloc(4 * n), *names = malloc(4 * n);
        size_t *got = malloc(sizeof(size_t) * n);
        gen_copy(&g, how, a, b, n);
        size_t ma = 0, mb = 0, keep = 1 + gen_u64(&g) % 4; /* about keep in 5 */
        for (size_t k = 0; k < n; k++) {
            if (gen_u64(&g) % 5 < keep) sa[ma] = (uint32_t)k, names[ma] = (uint32_t)ma, ma++;
            if (gen_u64(&g) % 5 < keep) memcpy(bs + 3 * mb, b + 3 * k, 24), sb[mb++] = (uint32_t)k;
        }
        if (mb == 0) memcpy(bs, b, 24), sb[mb++] = 0;
        hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
        hd__box_t box = union_box(a, b, n);
        hd__an_t qa, qb;
        CHECK_RC(hd__an_build_sel(&qb, &B, sb, NULL, mb, &box, threads, NULL), HD_OK);
        CHECK_RC(hd__an_build_sel(&qa, &A, sa, names, ma, &box, threads, NULL), HD_OK);
        CHECK(qb.peak >= hd__an_bytes(&qb) && qa.peak >= hd__an_bytes(&qa));
        for (size_t t = 0; t < n; t++) got[t] = SIZE_MAX;
        if (ma) CHECK_RC(hd__an_nearest(&qa, &qb, NULL, threads, NULL, got, NULL, NULL), HD_OK);
        for (size_t t = 0; t < ma && !hdt_failed(); t++) {
            size_t jb;
            brute_nearest(a + 3 * sa[t], bs, mb, &jb);
            CONTEXT("query %zu (point %u of A)", t, sa[t]);
            CHECK_EQ(got[t], (size_t)sb[jb]);
        }
        for (size_t t = ma; t < n && !hdt_failed(); t++) CHECK_EQ(got[t], SIZE_MAX);
        hd__an_free(&qa);
        hd__an_free(&qb);
        free(a), free(b), free(bs), free(sa), free(sb), free(names), free(got);
    }
}

TEST(partners_given_by_position_leave_every_answer_exact) {
    /* hd__an_nearest_paired, as the MPI layer gives a rank's local parts
     * of a copy: B keeps a random subset of its points (named by B's
     * numbers), and each query of A is paired with the position in B's
     * structure of B's point of its own number when kept, none when not;
     * every third case gets wrong partners instead (random positions).
     * Each answer is the brute force's over the subset, bit for bit and
     * index for index (copies with ties, half-lattice steps, repeated
     * points, outliers, far away, tiny); the true partners settle groups
     * in most cases (the path was under test). */
    int settled = 0, cases = 0;
    for (uint64_t seed = 43000; seed < 43000 + 4 * GEN_COPY_KINDS && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        int how = (int)(seed % GEN_COPY_KINDS), threads = seed % 2 ? 1 : 3, wrong = seed % 3 == 0;
        size_t n = 2 + gen_u64(&g) % (seed % 4 == 0 ? 8000 : 1500);
        CONTEXT("seed=%llu copy=%s n=%zu threads=%d partners=%s", (unsigned long long)seed, gen_copy_name[how], n,
                threads, wrong ? "wrong" : "true");
        double *a = malloc(24 * n), *b = malloc(24 * n), *bs = malloc(24 * n), *d = malloc(8 * n);
        uint32_t *sb = malloc(4 * n), *at = malloc(4 * n), *pos = malloc(4 * n);
        size_t *j = malloc(sizeof(size_t) * n);
        gen_copy(&g, how, a, b, n);
        size_t mb = 0, drop = gen_u64(&g) % 4; /* about drop in 10 of B left out */
        for (size_t k = 0; k < n; k++)
            if (gen_u64(&g) % 10 >= drop || k == 0) memcpy(bs + 3 * mb, b + 3 * k, 24), sb[mb++] = (uint32_t)k;
        hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
        hd__box_t box = union_box(a, b, n);
        hd__an_t qa, qb;
        hd__an_counts_t counts = {0};
        CHECK_RC(hd__an_build(&qa, &A, NULL, &box, threads, NULL), HD_OK);
        CHECK_RC(hd__an_build_sel(&qb, &B, sb, NULL, mb, &box, threads, NULL), HD_OK);
        for (size_t k = 0; k < n; k++) pos[k] = HD__AN_NO_PARTNER; /* B's number -> position in qb */
        for (size_t t = 0; t < mb; t++) pos[qb.idx[t]] = (uint32_t)t;
        for (size_t t = 0; t < n; t++) at[t] = wrong ? (uint32_t)(gen_u64(&g) % mb) : pos[qa.idx[t]];
        CHECK_RC(hd__an_nearest_paired(&qa, &qb, at, threads, d, j, &counts, NULL), HD_OK);
        for (size_t i = 0; i < n && !hdt_failed(); i++) {
            size_t jb;
            double d2 = brute_nearest(a + 3 * i, bs, mb, &jb);
            CONTEXT("query %zu", i);
            CHECK_BITS(d[i], sqrt(d2));
            CHECK_EQ(j[i], (size_t)sb[jb]);
        }
        settled += !wrong && counts.paired > 0;
        cases += !wrong;
        hd__an_free(&qa);
        hd__an_free(&qb);
        free(a), free(b), free(bs), free(d), free(sb), free(at), free(pos), free(j);
    }
    CONTEXT("cases with groups settled by partners: %d of %d", settled, cases);
    CHECK(settled >= cases / 2);
}

TEST(a_structure_build_holds_at_most_39_bytes_a_point) {
    /* The build's account (hd__an_t.peak, which the MPI layer charges):
     * coordinates and indices (28 B), the sort's keys (8 B), the node and
     * bucket arrays grown as the octree is cut (about 2 B).  Sized for the
     * worst case (n + 1 buckets) the bucket arrays alone were 24 B more. */
    const size_t sizes[] = {1000, 200000, 1000000};
    for (size_t k = 0; k < 3 && !hdt_failed(); k++) {
        size_t n = sizes[k];
        uint64_t seed = 52000 + k;
        CONTEXT("seed=%llu n=%zu", (unsigned long long)seed, n);
        gen_rng_t g;
        gen_seed(&g, seed);
        double *a = malloc(24 * n);
        gen_cube(&g, a, n, -1.0, 1.0);
        hd_points_t A = hd_points_f64(a, n);
        hd__box_t box = union_box(a, a, n);
        hd__an_t s;
        CHECK_RC(hd__an_build(&s, &A, NULL, &box, 2, NULL), HD_OK);
        CONTEXT("seed=%llu n=%zu peak=%zu kept=%zu", (unsigned long long)seed, n, s.peak, hd__an_bytes(&s));
        CHECK(s.peak >= hd__an_bytes(&s));
        CHECK(s.peak <= 39 * n + 4096);
        hd__an_free(&s);
        free(a);
    }
}

TEST(the_keys_of_packed_doubles_are_the_keys_of_any_view) {
    /* The build computes packed doubles' keys by hd__keys_f64's loop; the
     * same points read through a strided view take hd__src_get: both
     * structures hold the same keys, point for point, hd__key30's when the
     * key box holds the set, and also where it is smaller (clamped cells
     * at both ends, the fullest corners refined alike). */
    for (uint64_t seed = 53000; seed < 53004 && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t n = 1000 + gen_u64(&g) % 3000;
        double *a = malloc(24 * n), *w = malloc(32 * n);
        gen_cube(&g, a, n, -1.0, 1.0);
        for (size_t k = 0; k < n; k++) memcpy(w + 4 * k, a + 3 * k, 24);
        CONTEXT("seed=%llu n=%zu (a key box smaller than the set: %d)", (unsigned long long)seed, n, (int)(seed % 2));
        hd_points_t A = hd_points_f64(a, n), W = A;
        W.data = w, W.stride = 32;
        hd__box_t box = union_box(a, a, n);
        for (int d = 0; d < 3 && seed % 2; d++) box.lo[d] *= 0.5, box.hi[d] *= 0.7;
        hd__keygrid_t grid;
        hd__keygrid_init(&grid, &box);
        hd__an_t s, t;
        CHECK_RC(hd__an_build(&s, &A, NULL, &box, 1 + (int)(seed % 3), NULL), HD_OK);
        CHECK_RC(hd__an_build(&t, &W, NULL, &box, 1, NULL), HD_OK);
        for (size_t k = 0; k < n && !hdt_failed(); k++) {
            double p[3] = {s.x[k], s.y[k], s.z[k]};
            CHECK(seed % 2 || s.key32[k] == hd__key30(&grid, p));
            CHECK(s.key32[k] == t.key32[k] && s.idx[k] == t.idx[k]);
        }
        hd__an_free(&s), hd__an_free(&t);
        free(a), free(w);
    }
}

TEST(the_window_gives_up_on_disjoint_sets_and_stays_exact) {
    /* Two Gaussians 20 sigma apart, and a lattice against a plane far
     * away: the points at a query's key on the other curve are far from
     * its answer, so the groups fall back to the seeds; every answer
     * exact, ties on the lattice to the smallest index. */
    for (uint64_t seed = 32000; seed < 32004 && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t n = 2000 + gen_u64(&g) % 3000;
        CONTEXT("seed=%llu n=%zu", (unsigned long long)seed, n);
        double *a = malloc(24 * n), *b = malloc(24 * n), m0[3] = {0, 0, 0}, m1[3] = {20, 0, 0};
        if (seed % 2) {
            gen_gauss(&g, a, n, m0, 1.0);
            gen_gauss(&g, b, n, m1, 1.0);
        } else {
            gen_lattice(&g, a, n, 9);
            gen_plane(&g, b, n);
            gen_affine(b, n, 1.0, 50.0);
        }
        hd__an_counts_t c = {0};
        check_window(a, b, n, (int)seed % 3 + 1, &c);
        check_window(b, a, n, (int)seed % 3 + 1, &c);
        free(a), free(b);
    }
}

/* A's points (na) and B's (nb) on one key box, each asking the other at
 * `threads` threads: every answer against the brute force; what the
 * searches took added to c[0] (A->B) and c[1] (B->A). */
static void check_both_ways(const double *a, size_t na, const double *b, size_t nb, int threads, uint64_t seed,
                            hd__an_counts_t c[2]) {
    double *both = malloc(24 * (na + nb));
    memcpy(both, a, 24 * na), memcpy(both + 3 * na, b, 24 * nb);
    hd__box_t box;
    hd__box_of(both, na + nb, &box);
    hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
    hd__an_t s[2];
    CHECK_RC(hd__an_build(&s[0], &A, NULL, &box, threads, NULL), HD_OK);
    CHECK_RC(hd__an_build(&s[1], &B, NULL, &box, threads, NULL), HD_OK);
    for (int dir = 0; dir < 2 && !hdt_failed(); dir++) {
        const double *p = dir ? b : a, *o = dir ? a : b;
        size_t np = dir ? nb : na, no = dir ? na : nb;
        double *d = malloc(8 * np);
        size_t *j = malloc(sizeof(size_t) * np);
        CHECK_RC(hd__an_nearest(&s[dir], &s[1 - dir], NULL, threads, d, j, &c[dir], NULL), HD_OK);
        for (size_t i = 0; i < np && !hdt_failed(); i++) {
            size_t jo;
            double d2 = brute_nearest(p + 3 * i, o, no, &jo);
            CONTEXT("seed=%llu %s query %zu (far groups %zu)", (unsigned long long)seed, dir ? "B->A" : "A->B", i,
                    c[dir].far);
            CHECK_BITS(d[i], sqrt(d2));
            CHECK_EQ(j[i], jo);
        }
        free(d), free(j);
    }
    hd__an_free(&s[0]);
    hd__an_free(&s[1]);
    free(both);
}

TEST(far_groups_are_answered_from_boxes_alone_and_stay_exact) {
    /* A group of queries far from the searched set (its box outside the
     * set's box by more than its own diagonal) lists the buckets within
     * the nearest leaf's bound and scans no seed: a lattice with copies
     * asking a small lattice cluster 40 away whose coordinates sit half
     * way between A's (so A's points at y or z = 1, 2 have two nearest
     * points: the smaller index must win), and Gaussians 20 sigma apart.
     * Both directions, every answer against the brute force, at 1 and 3
     * threads. */
    size_t far = 0;
    for (uint64_t seed = 39000; seed < 39008 && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        int threads = seed % 2 ? 1 : 3, lattice = seed % 4 < 2;
        size_t na = 3000 + gen_u64(&g) % 3000, nb = lattice ? 100 + gen_u64(&g) % 300 : na;
        CONTEXT("seed=%llu na=%zu nb=%zu threads=%d lattice=%d", (unsigned long long)seed, na, nb, threads, lattice);
        double *a = malloc(24 * na), *b = malloc(24 * nb), m0[3] = {0, 0, 0}, m1[3] = {20, 0, 0};
        if (lattice) {
            gen_lattice(&g, a, na, 16);
            gen_lattice(&g, b, nb, 3);
            for (size_t k = 0; k < nb; k++) b[3 * k] += 40, b[3 * k + 1] += 0.5, b[3 * k + 2] += 0.5;
        } else {
            gen_gauss(&g, a, na, m0, 1.0);
            gen_gauss(&g, b, nb, m1, 1.0);
        }
        hd__an_counts_t c[2] = {{0}, {0}};
        check_both_ways(a, na, b, nb, threads, seed, c);
        far += c[0].far + c[1].far;
        free(a), free(b);
    }
    CONTEXT("far groups: %zu", far);
    CHECK(far > 0);
}

TEST(runs_of_a_dense_sets_groups_share_one_point_list_and_stay_exact) {
    /* A set many times as large as the other (here 40 to 80 times) asks
     * it in runs of consecutive groups that share one list of candidate
     * points: A on a grid of 1/64 and B on a grid of 1/8 (so that many of
     * A's points have several nearest points: the smaller index must
     * win), with copies in both sets; every answer of both directions
     * against the brute force, at 1 and 3 threads, and most of A's groups
     * answered from their run's list. */
    size_t shared = 0, groups = 0;
    for (uint64_t seed = 39200; seed < 39206 && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        int threads = seed % 2 ? 1 : 3;
        size_t na = 20000 + gen_u64(&g) % 20000, nb = na / (40 + gen_u64(&g) % 40);
        CONTEXT("seed=%llu na=%zu nb=%zu threads=%d", (unsigned long long)seed, na, nb, threads);
        double *a = malloc(24 * na), *b = malloc(24 * nb), m0[3] = {0, 0, 0}, m1[3] = {seed % 3 ? 0.0 : 0.5, 0, 0};
        gen_gauss(&g, a, na, m0, 1.0);
        gen_gauss(&g, b, nb, m1, 1.0);
        for (size_t k = 0; k < 3 * na; k++) a[k] = (double)(long)(a[k] * 64) / 64;
        for (size_t k = 0; k < 3 * nb; k++) b[k] = (double)(long)(b[k] * 8) / 8;
        for (size_t k = 0; k + 1 < nb; k += 7) memcpy(b + 3 * (k + 1), b + 3 * k, 24);
        for (size_t k = 0; k + 1 < na; k += 5) memcpy(a + 3 * (k + 1), a + 3 * k, 24);
        hd__an_counts_t c[2] = {{0}, {0}};
        check_both_ways(a, na, b, nb, threads, seed, c);
        shared += c[0].shared;
        groups += c[0].shared + c[0].windowed + c[0].far + c[0].paired;
        free(a), free(b);
    }
    CONTEXT("groups answered from their run's list: %zu of %zu", shared, groups);
    CHECK(2 * shared >= groups);
}

TEST(small_far_groups_share_their_candidate_points) {
    /* A group far from the searched set with fewer queries than two
     * chunks is answered like a large one, from its candidate points (no
     * seed scanned): here a whole set of a few points, a small lattice
     * with copies, asking a lattice 40 away whose points at y or z = 0
     * have two nearest points (ties: the smaller index must win); every
     * answer against the brute force. */
    for (uint64_t seed = 39100; seed < 39106 && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t na = 8 + gen_u64(&g) % 24, nb = 20 + gen_u64(&g) % 20;
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        int threads = seed % 2 ? 1 : 2;
        CONTEXT("seed=%llu na=%zu nb=%zu threads=%d", (unsigned long long)seed, na, nb, threads);
        gen_lattice(&g, a, na, 3);
        gen_affine(a, na, 0.25, 0.0);
        gen_lattice(&g, b, nb, 3);
        for (size_t k = 0; k < nb; k++) b[3 * k] += 40, b[3 * k + 1] -= 0.5, b[3 * k + 2] -= 0.5;
        hd__an_counts_t c[2] = {{0}, {0}};
        check_both_ways(a, na, b, nb, threads, seed, c);
        CONTEXT("seed=%llu na=%zu far groups %zu, from point lists %zu", (unsigned long long)seed, na, c[0].far,
                c[0].pointed);
        CHECK(c[0].far == 1 && c[0].pointed == na);
        free(a), free(b);
    }
}

TEST(same_order_copies_in_strided_and_float32_views_read_the_right_partners) {
    /* The partners are read from the caller's views: here a float32 view
     * with a 20-byte stride and a double view with a coordinate stride.  A
     * read at the wrong place that lands on values nearer than every point
     * (or on a point tied with the answer, under a smaller index) would
     * survive every scan; the brute force checks each answer. */
    for (uint64_t seed = 40; seed < 46 && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        int how = seed % 2 ? GEN_COPY_NOISE : GEN_COPY_LATTICE_HALF;
        size_t n = 1 + gen_u64(&g) % 5000;
        CONTEXT("seed=%llu copy=%s n=%zu", (unsigned long long)seed, gen_copy_name[how], n);
        double *a = malloc(24 * n), *b = malloc(24 * n), *braw = malloc(48 * n);
        float *fa = malloc(20 * n);
        gen_copy(&g, how, a, b, n);
        for (size_t k = 0; k < 3 * n; k++) {
            fa[5 * (k / 3) + k % 3] = (float)a[k];
            a[k] = (float)a[k];
            braw[6 * (k / 3) + 2 * (k % 3)] = b[k];
        }
        hd_points_t A = {fa, n, HD_FLOAT32, 20, 4}, B = {braw, n, HD_FLOAT64, 48, 16};
        check_against_brute(&A, a, n, &B, b, n, (int)seed % 3 + 1);
        free(a), free(b), free(braw), free(fa);
    }
}

TEST(same_size_sets_that_are_not_copies_fall_back_and_stay_exact) {
    /* Two unrelated clouds of one size, and a copy in reversed order: the
     * partners are far, the path gives up, and the seeds take over. */
    for (uint64_t seed = 30; seed < 34 && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t n = 3000;
        CONTEXT("seed=%llu %s", (unsigned long long)seed, seed % 2 ? "reversed copy" : "unrelated");
        double *a = malloc(24 * n), *b = malloc(24 * n), m0[3] = {0, 0, 0};
        if (seed % 2) {
            gen_copy(&g, GEN_COPY_NOISE, a, b, n);
            for (size_t k = 0; k < n / 2; k++) gen_swap(b, k, n - 1 - k);
        } else {
            gen_gauss(&g, a, n, m0, 1.0);
            gen_gauss(&g, b, n, m0, 1.0);
            /* A sparse tail may hold few enough buckets; the rest fail. */
            size_t groups, paired = partner_groups(a, b, n, 1, &groups);
            CONTEXT("seed=%llu unrelated: %zu of %zu groups paired", (unsigned long long)seed, paired, groups);
            CHECK(paired * 10 < groups);
        }
        check_packed(a, n, b, n, (int)seed % 3 + 1);
        free(a), free(b);
    }
}

TEST(per_point_distances_of_strided_float32_views_match_the_widened_doubles) {
    /* Points interleaved with other fields (stride 20 bytes, floats), and a
     * double view with a coordinate stride: the brute force sees the same
     * values widened to double. */
    for (uint64_t seed = 11; seed <= 13; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t na = 1500, nb = 1200;
        float *fa = malloc(20 * na);
        double *a = malloc(24 * na), *braw = malloc(48 * nb), *b = malloc(24 * nb);
        for (size_t k = 0; k < na; k++)
            for (int c = 0; c < 3; c++) {
                float v = (float)(seed == 12 ? (double)(gen_u64(&g) % 5) : gen_normal(&g));
                fa[5 * k + (size_t)c] = v;
                a[3 * k + (size_t)c] = v;
            }
        for (size_t k = 0; k < nb; k++)
            for (int c = 0; c < 3; c++) {
                double v = seed == 12 ? (double)(gen_u64(&g) % 5) + 0.5 : gen_normal(&g) + 0.1;
                braw[6 * k + 2 * (size_t)c] = v;
                b[3 * k + (size_t)c] = v;
            }
        hd_points_t A = {fa, na, HD_FLOAT32, 20, 4};
        hd_points_t B = {braw, nb, HD_FLOAT64, 48, 16};
        check_against_brute(&A, a, na, &B, b, nb, (int)seed % 3 + 1);
        free(fa), free(a), free(braw), free(b);
    }
}

TEST(per_point_distances_do_not_depend_on_the_thread_count) {
    gen_rng_t g;
    gen_seed(&g, 99);
    CONTEXT("seed=99");
    /* Over 65536 points: the sort is split between threads too. */
    size_t na = 140000, nb = 70000;
    double *a = malloc(24 * na), *b = malloc(24 * nb);
    double m0[3] = {0, 0, 0}, m1[3] = {0.5, 0, 0};
    gen_gauss(&g, a, na, m0, 1.0);
    gen_gauss(&g, b, nb, m1, 2.0);
    for (size_t k = 0; k < nb; k += 7) b[3 * k + 2] = 0; /* some points share a plane */
    hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
    double *d1 = malloc(8 * na), *d3 = malloc(8 * na);
    size_t *j1 = malloc(sizeof(size_t) * na), *j3 = malloc(sizeof(size_t) * na);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = 1;
    CHECK_RC(hd_distances(&A, &B, &o, d1, j1, NULL, NULL, NULL), HD_OK);
    o.threads = 3;
    CHECK_RC(hd_distances(&A, &B, &o, d3, j3, NULL, NULL, NULL), HD_OK);
    for (size_t i = 0; i < na && !hdt_failed(); i++) {
        CHECK_BITS(d1[i], d3[i]);
        CHECK_EQ(j1[i], j3[i]);
    }
    for (size_t i = 0; i < na && !hdt_failed(); i += 101) {
        size_t j;
        CHECK_BITS(d1[i], sqrt(brute_nearest(a + 3 * i, b, nb, &j)));
        CHECK_EQ(j1[i], j);
    }
    free(a), free(b), free(d1), free(d3), free(j1), free(j3);
}

/* ---- selection and percentiles ----------------------------------------------- */

TEST(select_puts_every_rank_in_place_with_ties) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 30; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_seed(&g, seed);
        size_t n = 1 + gen_u64(&g) % 700;
        int side = 1 + (int)(seed % 7);
        double *v = lattice_values(&g, n, side), *s = malloc(n * sizeof *s), *w = malloc(n * sizeof *w);
        memcpy(s, v, n * sizeof *s);
        qsort(s, n, sizeof *s, cmp_d);
        for (size_t k = 0; k < n && !hdt_failed(); k++) {
            memcpy(w, v, n * sizeof *w);
            hd__select(w, n, k);
            CHECK_BITS(w[k], s[k]);
            for (size_t i = 0; i < k; i++) CHECK(w[i] <= w[k]);
            for (size_t i = k + 1; i < n; i++) CHECK(w[i] >= w[k]);
        }
        free(v), free(s), free(w);
    }
}

TEST(select_survives_inputs_that_defeat_median_of_three) {
    /* Sorted, reversed, organ-pipe and all-equal inputs of 5000 values. */
    size_t n = 5000;
    double *v = malloc(n * sizeof *v), *w = malloc(n * sizeof *w), *s = malloc(n * sizeof *s);
    for (int shape = 0; shape < 4; shape++) {
        CONTEXT("shape=%d", shape);
        for (size_t k = 0; k < n; k++) {
            double x = (double)k;
            v[k] = shape == 0 ? x : shape == 1 ? -x : shape == 2 ? (k < n / 2 ? x : (double)(n - k)) : 1.0;
        }
        memcpy(s, v, n * sizeof *s);
        qsort(s, n, sizeof *s, cmp_d);
        for (size_t k = 0; k < n; k += 499) {
            memcpy(w, v, n * sizeof *w);
            hd__select(w, n, k);
            CHECK_BITS(w[k], s[k]);
        }
    }
    free(v), free(w), free(s);
}

TEST(percentiles_match_a_full_sort_at_every_half_percent_with_ties) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 25; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_seed(&g, seed);
        size_t n = 1 + gen_u64(&g) % 500;
        double *v = lattice_values(&g, n, 2 + (int)(seed % 9));
        double ps[201], got[201];
        for (int k = 0; k <= 200; k++) ps[k] = 0.5 * k;
        CHECK_RC(hd_percentiles(v, n, ps, 201, got, NULL), HD_OK);
        for (int k = 0; k <= 200; k++) CHECK_BITS(got[k], ref_percentile(v, n, ps[k]));
        for (int k = 0; k < 20; k++) { /* arbitrary p, one at a time */
            double p = 100.0 * gen_unit(&g), one;
            CHECK_RC(hd_percentile(v, n, p, &one, NULL), HD_OK);
            CHECK_BITS(one, ref_percentile(v, n, p));
        }
        free(v);
    }
}

TEST(percentiles_leave_the_callers_values_untouched) {
    double v[] = {5, 1, 4, 2, 3}, p95;
    CHECK_RC(hd_percentile(v, 5, 95, &p95, NULL), HD_OK);
    CHECK(v[0] == 5 && v[1] == 1 && v[2] == 4 && v[3] == 2 && v[4] == 3);
    CHECK_BITS(p95, ref_percentile(v, 5, 95));
}

TEST(percentile_100_is_the_hausdorff_distance_and_0_the_smallest_distance) {
    for (uint64_t seed = 1; seed <= 12; seed++) {
        case_t c;
        case_open(&c, seed);
        hd_percentile_t p100, p0;
        hd_symmetric_t s;
        CHECK_RC(hd_hausdorff_percentile(&c.A, &c.B, NULL, 100, &p100, NULL), HD_OK);
        CHECK_RC(hd_hausdorff_percentile(&c.A, &c.B, NULL, 0, &p0, NULL), HD_OK);
        CHECK_RC(hd_hausdorff(&c.A, &c.B, NULL, &s, NULL), HD_OK);
        CHECK_BITS(p100.ab, s.ab.distance);
        CHECK_BITS(p100.ba, s.ba.distance);
        CHECK_BITS(p100.symmetric, s.distance);
        CHECK_BITS(p100.pooled, s.distance);
        double *d = brute_distances(c.a, c.na, c.b, c.nb), mn = INFINITY;
        for (size_t i = 0; i < c.na; i++)
            if (d[i] < mn) mn = d[i];
        CHECK_BITS(p0.ab, mn);
        free(d);
        case_close(&c);
    }
}

TEST(percentile_hausdorff_has_monai_symmetric_and_medpy_pooled_figures) {
    gen_rng_t g;
    gen_seed(&g, 99);
    for (uint64_t seed = 1; seed <= 20; seed++) {
        case_t c;
        case_open(&c, seed);
        double *dab = brute_distances(c.a, c.na, c.b, c.nb), *dba = brute_distances(c.b, c.nb, c.a, c.na);
        double *both = malloc(8 * (c.na + c.nb));
        memcpy(both, dab, 8 * c.na);
        memcpy(both + c.na, dba, 8 * c.nb);
        double p = seed % 2 ? 95.0 : 100.0 * gen_unit(&g);
        hd_percentile_t r;
        CHECK_RC(hd_hausdorff_percentile(&c.A, &c.B, NULL, p, &r, NULL), HD_OK);
        double ab = ref_percentile(dab, c.na, p), ba = ref_percentile(dba, c.nb, p);
        CHECK_BITS(r.p, p);
        CHECK_BITS(r.ab, ab);
        CHECK_BITS(r.ba, ba);
        CHECK_BITS(r.symmetric, ab > ba ? ab : ba);
        CHECK_BITS(r.pooled, ref_percentile(both, c.na + c.nb, p));
        hd_percentile_t dir;
        CHECK_RC(hd_percentile_of(dab, c.na, NULL, 0, p, &dir, NULL), HD_OK);
        CHECK_BITS(dir.ab, ab);
        CHECK(isnan(dir.ba) && isnan(dir.symmetric) && isnan(dir.pooled));
        free(dab), free(dba), free(both);
        case_close(&c);
    }
}

TEST(percentiles_refuse_bad_p_empty_input_and_nan) {
    double v[] = {1, 2, NAN}, out;
    hd_error_t e;
    CHECK_RC(hd_percentile(v, 2, -0.5, &out, &e), HD_EINVAL);
    CHECK(strstr(e.message, "[0, 100]") != NULL);
    CHECK_RC(hd_percentile(v, 2, 100.5, &out, NULL), HD_EINVAL);
    CHECK_RC(hd_percentile(v, 2, NAN, &out, NULL), HD_EINVAL);
    CHECK_RC(hd_percentile(v, 0, 50, &out, NULL), HD_EEMPTY);
    CHECK_RC(hd_percentile(v, 3, 50, &out, NULL), HD_ENONFINITE);
    hd_percentile_t r;
    CHECK_RC(hd_percentile_of(v, 0, NULL, 0, 50, &r, NULL), HD_EEMPTY);
    CHECK_RC(hd_percentile_of(v, 2, v, 3, 50, &r, NULL), HD_ENONFINITE);
}

/* ---- sums, means, Chamfer ---------------------------------------------------- */

TEST(summary_means_and_chamfer_follow_their_definitions) {
    double ab[] = {0, 1, 2, 3}, ba[] = {4, 0};
    hd_summary_t s;
    CHECK_RC(hd_summarize(ab, 4, ba, 2, &s, NULL), HD_OK);
    CHECK_EQ(s.n_ab, 4);
    CHECK_EQ(s.n_ba, 2);
    CHECK_BITS(s.max_ab, 3.0);
    CHECK_BITS(s.max_ba, 4.0);
    CHECK_BITS(s.mean_ab, 1.5);
    CHECK_BITS(s.mean_ba, 2.0);
    CHECK_BITS(s.mean_symmetric, 2.0);
    CHECK_BITS(s.mean_average, 1.75);
    CHECK_BITS(s.mean_pooled, 10.0 / 6.0);
    CHECK_BITS(s.mean2_ab, 14.0 / 4.0);
    CHECK_BITS(s.mean2_ba, 8.0);
    CHECK_BITS(s.chamfer, 3.5 + 8.0);
    CHECK_BITS(s.chamfer_sum2, 14.0 + 16.0);
    CHECK_BITS(s.chamfer_mean, 3.5);
    CHECK_BITS(s.chamfer_sum, 10.0);
    hd_summary_t d;
    CHECK_RC(hd_summarize(ab, 4, NULL, 0, &d, NULL), HD_OK);
    CHECK_BITS(d.mean_ab, 1.5);
    CHECK(isnan(d.mean_ba) && isnan(d.chamfer) && isnan(d.mean_pooled));
}

TEST(sums_are_exact_where_a_plain_loop_loses_everything) {
    /* 1e16 followed by 10000 ones: a plain left-to-right sum stays at 1e16
     * (each 1 is below half an ulp), the exact sum is 1e16 + 10000. */
    size_t n = 10001;
    double *v = malloc(n * sizeof *v);
    v[0] = 1e16;
    for (size_t k = 1; k < n; k++) v[k] = 1.0;
    hd_summary_t s;
    CHECK_RC(hd_summarize(v, n, NULL, 0, &s, NULL), HD_OK);
    CHECK_BITS(s.sum_ab, 1e16 + 10000.0);
    free(v);
}

TEST(summary_refuses_empty_and_nan) {
    double v[] = {1, NAN};
    hd_summary_t s;
    CHECK_RC(hd_summarize(v, 0, NULL, 0, &s, NULL), HD_EEMPTY);
    CHECK_RC(hd_summarize(v, 1, v, 0, &s, NULL), HD_EEMPTY);
    CHECK_RC(hd_summarize(v, 2, NULL, 0, &s, NULL), HD_ENONFINITE);
    CHECK_RC(hd_summarize(v, 1, NULL, 0, NULL, NULL), HD_EINVAL);
}

/* ---- histograms ---------------------------------------------------------- */

TEST(histogram_puts_each_value_in_the_bin_whose_edges_enclose_it) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 20; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_seed(&g, seed);
        size_t n = 1 + gen_u64(&g) % 2000, bins = 1 + gen_u64(&g) % 37;
        double *v = lattice_values(&g, n, 5); /* many values on edges */
        double lo = seed % 3 ? 0.0 : 0.3, hi = seed % 2 ? 5.0 : 0.1 * (double)(gen_u64(&g) % 60);
        if (hi < lo) hi = lo;
        uint64_t *c = malloc(bins * sizeof *c), *want = calloc(bins, sizeof *want);
        CHECK_RC(hd_histogram(v, n, lo, hi, bins, c, NULL), HD_OK);
        double wlo = hd_histogram_edge(lo, hi, bins, 0), whi = hd_histogram_edge(lo, hi, bins, bins);
        for (size_t k = 0; k < n; k++) {
            if (v[k] < wlo || v[k] > whi) continue;
            size_t b = 0;
            while (b + 1 < bins && v[k] >= hd_histogram_edge(lo, hi, bins, b + 1)) b++;
            want[b]++;
        }
        for (size_t b = 0; b < bins; b++) CHECK_EQ(c[b], want[b]);
        free(v), free(c), free(want);
    }
}

TEST(histogram_edges_are_linspace_and_the_last_bin_is_closed) {
    CHECK_BITS(hd_histogram_edge(0, 1, 10, 3), 3 * 0.1 + 0.0);
    CHECK_BITS(hd_histogram_edge(0, 1, 10, 10), 1.0);
    CHECK_BITS(hd_histogram_edge(2, 2, 4, 0), 1.5); /* widened like numpy */
    CHECK_BITS(hd_histogram_edge(2, 2, 4, 4), 2.5);
    double v[] = {0.0, 0.5, 1.0, 1.5, 2.0};
    uint64_t c[2];
    CHECK_RC(hd_histogram(v, 5, 0, 1, 2, c, NULL), HD_OK);
    CHECK_EQ(c[0], 1); /* 0.0 */
    CHECK_EQ(c[1], 2); /* 0.5 on the edge goes up; 1.0 closes the last bin */
}

TEST(histogram_of_a_subnormal_range_counts_each_value_in_its_bin) {
    /* [0, 1e-320] in 20 bins: bins / (hi - lo) is inf, so the usual
     * product is NaN at 0 (it was cast to an index far out of the array) */
    double v[] = {0.0, 1e-320, 3e-321, 0x1p-1074, 1.0};
    uint64_t c[20];
    CHECK_RC(hd_histogram(v, 5, 0, 1e-320, 20, c, NULL), HD_OK);
    uint64_t total = 0;
    for (int k = 0; k < 20; k++) {
        total += c[k];
        CONTEXT("bin %d", k);
        CHECK(c[k] == 0 || k == 0 || k == 19 || k == 6); /* 3e-321 is in [edge 6, edge 7) */
    }
    CHECK_EQ(total, 4); /* 1.0 is beyond the range */
    CHECK_EQ(c[0], 2);  /* 0 and the least subnormal */
    CHECK_EQ(c[19], 1); /* the top closes the last bin */
    CHECK(hd_histogram_edge(0, 1e-320, 20, 6) <= 3e-321 && 3e-321 < hd_histogram_edge(0, 1e-320, 20, 7));
}

TEST(histogram_refuses_bad_ranges_and_zero_bins) {
    double v[] = {1};
    uint64_t c[1];
    CHECK_RC(hd_histogram(v, 1, 0, 1, 0, c, NULL), HD_EINVAL);
    CHECK_RC(hd_histogram(v, 1, 1, 0, 1, c, NULL), HD_EINVAL);
    CHECK_RC(hd_histogram(v, 1, 0, INFINITY, 1, c, NULL), HD_EINVAL);
    CHECK_RC(hd_histogram(v, 1, -1e308, 1e308, 1, c, NULL), HD_ERANGE);
}
