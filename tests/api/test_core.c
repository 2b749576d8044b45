/*
 * test_core.c -- the library's contract outside any one algorithm: result
 * codes, options, validation of inputs, views with strides, NAIVEHDD
 * against the independent brute force, and thread-count independence.
 */
#include "brute.h"
#include "check.h"
#include "gen.h"

#include <math.h>
#include <stdlib.h>

TEST(every_result_code_has_a_text_and_a_name) {
    int codes[] = {HD_OK, HD_EINVAL, HD_ENOMEM, HD_EEMPTY, HD_ENONFINITE, HD_ERANGE, HD_EIO,
                   HD_EFORMAT, HD_EUNSUPPORTED, HD_ETHREAD, HD_EOVERFLOW, HD_EALGORITHM};
    for (size_t k = 0; k < sizeof codes / sizeof codes[0]; k++) {
        CHECK(strcmp(hd_strerror(codes[k]), "unknown error") != 0);
        CHECK(strncmp(hd_err_name(codes[k]), "HD_", 3) == 0);
    }
    CHECK(strcmp(hd_strerror(12345), "unknown error") == 0);
}

TEST(result_codes_run_without_gaps_from_ok_down_to_the_tables_end) {
    for (int c = HD_OK; c >= HD__ERRNO_MIN; c--) CHECK(strcmp(hd_strerror(c), "unknown error") != 0);
    CHECK(strcmp(hd_strerror(HD__ERRNO_MIN - 1), "unknown error") == 0);
    CHECK_EQ(HD__ERRNO_MIN, HD_EALGORITHM);
}

TEST(algorithm_names_round_trip) {
    for (int k = 0; k < HD__ALG_COUNT; k++) {
        hd_algorithm_t a;
        CHECK_RC(hd_algorithm_from_name(hd_algorithm_name((hd_algorithm_t)k), &a), HD_OK);
        CHECK_EQ(a, k);
    }
    hd_algorithm_t a;
    CHECK_RC(hd_algorithm_from_name("fastest", &a), HD_EALGORITHM);
}

TEST(empty_policy_names_round_trip_and_end_with_null) {
    int k = 0;
    for (; hd_empty_policy_name((hd_empty_policy_t)k); k++) {
        hd_empty_policy_t p;
        CHECK_RC(hd_empty_policy_from_name(hd_empty_policy_name((hd_empty_policy_t)k), &p), HD_OK);
        CHECK_EQ(p, k);
    }
    CHECK_EQ(k, HD_EMPTY_SKIMAGE + 1);
    hd_empty_policy_t p = HD_EMPTY_INF;
    CHECK_RC(hd_empty_policy_from_name("Inf", &p), HD_EINVAL);
    CHECK_EQ(p, HD_EMPTY_INF);
    CHECK_RC(hd_empty_policy_from_name(NULL, &p), HD_EINVAL);
}

TEST(empty_policy_values_for_one_and_both_sets_empty) {
    /* one side empty (either), then both */
    for (int side = 0; side < 2; side++) {
        size_t na = side ? 0 : 5, nb = side ? 5 : 0;
        CHECK(isinf(hd_empty_value(HD_EMPTY_INF, na, nb)) && hd_empty_value(HD_EMPTY_INF, na, nb) > 0);
        CHECK(isnan(hd_empty_value(HD_EMPTY_NAN, na, nb)));
        CHECK(hd_empty_value(HD_EMPTY_ZERO, na, nb) == 0.0);
        CHECK(isinf(hd_empty_value(HD_EMPTY_MONAI, na, nb)));
        CHECK(isinf(hd_empty_value(HD_EMPTY_SKIMAGE, na, nb)));
        CHECK(isnan(hd_empty_value(HD_EMPTY_ERROR, na, nb)));
    }
    CHECK(isinf(hd_empty_value(HD_EMPTY_INF, 0, 0)));
    CHECK(isnan(hd_empty_value(HD_EMPTY_MONAI, 0, 0)));
    CHECK(hd_empty_value(HD_EMPTY_SKIMAGE, 0, 0) == 0.0);
    CHECK(isnan(hd_empty_value((hd_empty_policy_t)99, 0, 0)));
}

TEST(defaults_are_the_papers_parameters) {
    hd_options_t o;
    hd_options_init(&o);
    CHECK_EQ(o.algorithm, HD_ALG_AUTO);
    CHECK_EQ(o.depth, 6);
    CHECK(o.lambda == 0.01);
    CHECK(o.theta == 0.33);
    CHECK(o.early_break && o.culling);
}

TEST(empty_sets_are_refused) {
    double a[3] = {0, 0, 0};
    hd_points_t A = hd_points_f64(a, 1), E = hd_points_f64(a, 0);
    hd_result_t r;
    hd_error_t e;
    CHECK_RC(hd_directed(&A, &E, NULL, &r, &e), HD_EEMPTY);
    CHECK(strstr(e.message, "B") != NULL);
    CHECK_RC(hd_directed(&E, &A, NULL, &r, &e), HD_EEMPTY);
}

TEST(nan_inf_and_huge_coordinates_are_refused) {
    double good[3] = {0, 0, 0};
    double nan_[3] = {0, NAN, 0}, inf_[3] = {INFINITY, 0, 0}, huge[3] = {0, 0, 2e153};
    hd_points_t G = hd_points_f64(good, 1);
    hd_result_t r;
    hd_points_t N = hd_points_f64(nan_, 1), I = hd_points_f64(inf_, 1), H = hd_points_f64(huge, 1);
    CHECK_RC(hd_directed(&G, &N, NULL, &r, NULL), HD_ENONFINITE);
    CHECK_RC(hd_directed(&I, &G, NULL, &r, NULL), HD_ENONFINITE);
    CHECK_RC(hd_directed(&G, &H, NULL, &r, NULL), HD_ERANGE);
    double edge[3] = {-1e153, 1e153, 0};
    hd_points_t Ed = hd_points_f64(edge, 1);
    CHECK_RC(hd_directed(&G, &Ed, NULL, &r, NULL), HD_OK);
}

TEST(bad_options_are_refused) {
    double a[3] = {0, 0, 0};
    hd_points_t A = hd_points_f64(a, 1);
    hd_options_t o;
    hd_result_t r;
    hd_options_init(&o);
    o.lambda = 0;
    CHECK_RC(hd_directed(&A, &A, &o, &r, NULL), HD_EINVAL);
    hd_options_init(&o);
    o.threads = -2;
    CHECK_RC(hd_directed(&A, &A, &o, &r, NULL), HD_EINVAL);
    CHECK_RC(hd_directed(&A, &A, NULL, NULL, NULL), HD_EINVAL);
    CHECK_RC(hd_directed(NULL, &A, NULL, &r, NULL), HD_EINVAL);
}

TEST(naive_matches_brute_force_on_gaussians) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 20; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_seed(&g, seed);
        size_t na = 1 + gen_u64(&g) % 300, nb = 1 + gen_u64(&g) % 300;
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        double m0[3] = {0, 0, 0}, m1[3] = {0.5, 0, 0};
        gen_gauss(&g, a, na, m0, 1.0);
        gen_gauss(&g, b, nb, m1, 1.0);
        brute_t want = brute_directed(a, na, b, nb);
        hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
        hd_options_t o;
        hd_options_init(&o);
        o.algorithm = HD_ALG_NAIVE;
        o.threads = (int)(seed % 3) + 1;
        hd_result_t r;
        CHECK_RC(hd_directed(&A, &B, &o, &r, NULL), HD_OK);
        CHECK_BITS(r.distance2, want.d2);
        CHECK_BITS(r.distance, sqrt(want.d2));
        CHECK_EQ(r.i, want.i);
        CHECK_EQ(r.j, want.j);
        CHECK_EQ(r.stats.distance_evals, na * nb);
        free(a);
        free(b);
    }
}

TEST(witness_is_the_smallest_index_among_ties) {
    /* A = three copies of (0,0,0) then (5,0,0) twice; B = (1,0,0) twice:
     * the farthest A points are indices 3 and 4, both at 4 from B[0]/B[1]. */
    double a[] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 5, 0, 0, 5, 0, 0};
    double b[] = {1, 0, 0, 1, 0, 0};
    hd_points_t A = hd_points_f64(a, 5), B = hd_points_f64(b, 2);
    hd_options_t o;
    hd_options_init(&o);
    for (int t = 1; t <= 4; t++) {
        o.threads = t;
        hd_result_t r;
        CHECK_RC(hd_directed(&A, &B, &o, &r, NULL), HD_OK);
        CHECK_BITS(r.distance, 4.0);
        CHECK_EQ(r.i, 3);
        CHECK_EQ(r.j, 0);
    }
}

TEST(strided_float_and_fortran_views_read_the_same_points) {
    /* Four points stored three ways: packed double, float, and column-major. */
    double p[] = {0, 0, 0, 1, 2, 3, -1, 0.5, 2, 4, 4, 4};
    float f[12];
    double col[12];
    for (int k = 0; k < 12; k++) f[k] = (float)p[k];
    for (int k = 0; k < 4; k++)
        for (int c = 0; c < 3; c++) col[c * 4 + k] = p[3 * k + c];
    hd_points_t P = hd_points_f64(p, 4), F = hd_points_f32(f, 4), C = hd_points_f64(col, 4);
    C.stride = sizeof(double);
    C.cstride = 4 * sizeof(double);
    for (size_t k = 0; k < 4; k++) {
        double x[3], y[3], z[3];
        hd_points_get(&P, k, x);
        hd_points_get(&F, k, y);
        hd_points_get(&C, k, z);
        for (int c = 0; c < 3; c++) {
            CHECK_BITS(x[c], y[c]);
            CHECK_BITS(x[c], z[c]);
        }
    }
    hd_symmetric_t s1, s2;
    CHECK_RC(hd_hausdorff(&P, &C, NULL, &s1, NULL), HD_OK);
    CHECK_BITS(s1.distance, 0.0);
    CHECK_RC(hd_hausdorff(&F, &P, NULL, &s2, NULL), HD_OK);
    CHECK_BITS(s2.distance, 0.0);
}

TEST(symmetric_is_the_max_of_both_directions) {
    double a[] = {0, 0, 0, 1, 0, 0};
    double b[] = {0, 0, 0, 1, 0, 0, 10, 0, 0};
    hd_points_t A = hd_points_f64(a, 2), B = hd_points_f64(b, 3);
    hd_symmetric_t s;
    CHECK_RC(hd_hausdorff(&A, &B, NULL, &s, NULL), HD_OK);
    CHECK_BITS(s.ab.distance, 0.0);
    CHECK_BITS(s.ba.distance, 9.0);
    CHECK_BITS(s.distance, 9.0);
    CHECK_EQ(s.ba.i, 2);
    CHECK_EQ(s.ba.j, 1);
}

TEST(alpha_is_zero_when_touching_and_one_when_coinciding) {
    double a[] = {0, 0, 0, 1, 1, 1};
    double b[] = {1, 0, 0, 2, 1, 1};     /* touches a at x = 1 */
    double c[] = {0, 0, 0, 1, 1, 1};     /* same box */
    double d[] = {0.5, 0, 0, 1.5, 1, 1}; /* half overlap in x */
    double e[] = {3, 0, 0, 4, 1, 1};     /* apart */
    double flat[] = {0.2, 0.2, 0.5, 0.8, 0.8, 0.5}; /* z-flat, inside a */
    hd_points_t A = hd_points_f64(a, 2), B = hd_points_f64(b, 2), C = hd_points_f64(c, 2),
                D = hd_points_f64(d, 2), E = hd_points_f64(e, 2), F = hd_points_f64(flat, 2);
    double alpha;
    int disjoint;
    CHECK_RC(hd_overlap(&A, &B, &alpha, &disjoint, NULL), HD_OK);
    CHECK(alpha == 0.0 && !disjoint);
    CHECK_RC(hd_overlap(&A, &C, &alpha, &disjoint, NULL), HD_OK);
    CHECK(alpha == 1.0 && !disjoint);
    CHECK_RC(hd_overlap(&A, &D, &alpha, &disjoint, NULL), HD_OK);
    CHECK(alpha == 0.5);
    CHECK_RC(hd_overlap(&A, &E, &alpha, &disjoint, NULL), HD_OK);
    CHECK(alpha == 0.0 && disjoint);
    CHECK_RC(hd_overlap(&A, &F, &alpha, &disjoint, NULL), HD_OK);
    CHECK(alpha == 1.0 && !disjoint);
}

TEST(every_call_refuses_a_misaligned_packed_view_and_reads_a_strided_one_anywhere) {
    size_t n = 50;
    unsigned char *raw = malloc(24 * n + 8);
    double *a = malloc(24 * n);
    gen_rng_t r;
    gen_seed(&r, 5);
    gen_cube(&r, a, n, 0, 1);
    memcpy(raw + 1, a, 24 * n);
    hd_points_t bad = hd_points_f64(NULL, n), good = hd_points_f64(a, n);
    bad.data = raw + 1; /* packed doubles one byte off */
    hd_result_t res;
    hd_symmetric_t sym;
    hd_error_t e;
    hd_options_t o;
    hd_options_init(&o);
    for (int alg = 0; alg < HD__ALG_COUNT; alg++) {
        o.algorithm = (hd_algorithm_t)alg;
        CONTEXT("algorithm %s", hd_algorithm_name(o.algorithm));
        CHECK_RC(hd_directed(&bad, &good, &o, &res, &e), HD_EINVAL);
        CHECK(strstr(e.message, "must be aligned to 8 bytes") != NULL);
        CHECK_RC(hd_hausdorff(&good, &bad, &o, &sym, &e), HD_EINVAL);
    }
    double *d = malloc(n * sizeof *d);
    CHECK_RC(hd_distances(&bad, &good, NULL, d, NULL, NULL, NULL, &e), HD_EINVAL);
    /* the same points 32 bytes apart at an odd address: read anywhere */
    unsigned char *raw2 = malloc(32 * n + 8);
    for (size_t k = 0; k < n; k++) memcpy(raw2 + 1 + 32 * k, a + 3 * k, 24);
    hd_points_t strided = hd_points_f64(NULL, n);
    strided.data = raw2 + 1;
    strided.stride = 32;
    hd_options_init(&o);
    CHECK_RC(hd_directed(&strided, &good, &o, &res, &e), HD_OK);
    CHECK_BITS(res.distance, 0.0);
    free(raw2);
    free(d);
    free(a);
    free(raw);
}

/* The default engine reports in its results how much memory it held at
 * once (stats.peak_bytes: measured, the same in both directions of one
 * call); the paper's algorithms do not measure it and report 0.  On
 * 200K + 200K uniform points the engine holds its trees: more than their
 * permutations (4 bytes a point) and within its 16 bytes a point plus two
 * 2 MiB chunks (docs/engine.md, "Threads and memory"). */
TEST(the_engine_reports_its_peak_memory_and_the_other_algorithms_zero) {
    uint64_t seed = 9100;
    CONTEXT("seed=%llu", (unsigned long long)seed);
    gen_rng_t g;
    gen_seed(&g, seed);
    size_t n = 200000;
    double *a, *b;
    hd_points_t A, B;
    gen_cube_pair(&g, n, n, &a, &b, &A, &B);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = 2;
    hd_symmetric_t s;
    CHECK_RC(hd_hausdorff(&A, &B, &o, &s, NULL), HD_OK);
    CHECK_EQ(s.ab.stats.peak_bytes, s.ba.stats.peak_bytes);
    CHECK(s.ab.stats.peak_bytes > 4 * 2 * n);
    CHECK(s.ab.stats.peak_bytes <= 16 * 2 * n + 2 * (((uint64_t)2 << 20) + 4096));
    hd_result_t r;
    CHECK_RC(hd_directed(&A, &B, &o, &r, NULL), HD_OK);
    CHECK(r.stats.peak_bytes > 4 * n && r.stats.peak_bytes <= 16 * 2 * n + 2 * (((uint64_t)2 << 20) + 4096));
    o.algorithm = HD_ALG_NOHD;
    CHECK_RC(hd_directed(&A, &B, &o, &r, NULL), HD_OK);
    CHECK_EQ(r.stats.peak_bytes, 0);
    free(a);
    free(b);
}
