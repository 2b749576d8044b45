/*
 * test_index.c -- the reusable index (hd_index_*) and the "kdtree"
 * algorithm: every distance, witness and nearest index agrees bit for bit
 * with the independent brute force, for transformed queries, lattice ties,
 * duplicates, float32 and strided views, far offsets and tiny scales, at one
 * and at three threads.
 */
#include "brute.h"
#include "check.h"
#include "gen.h"
#include "index.h" /* hd__index_nearest_by and its paths */

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

/* The expected answers for T(A) against B: the brute force on the
 * transformed copy (the transform applied by the test's own code). */
static void check_against_brute(const hd_points_t *A, const double *a, size_t na,
                                const hd_points_t *B, const double *b, size_t nb,
                                const hd_transform_t *T, int threads) {
    double *ta = malloc(24 * na);
    if (T) brute_transform(T->r, T->t, a, ta, na);
    else memcpy(ta, a, 24 * na);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    hd_index_t *idx = NULL;
    CHECK_RC(hd_index_build(B, &o, &idx, NULL), HD_OK);
    if (!idx) {
        free(ta);
        return;
    }
    CHECK_EQ(hd_index_count(idx), nb);

    brute_t want = brute_directed(ta, na, b, nb);
    hd_result_t r;
    CHECK_RC(hd_index_directed(idx, A, T, &o, &r, NULL), HD_OK);
    CHECK_BITS(r.distance2, want.d2);
    CHECK_BITS(r.distance, sqrt(want.d2));
    CHECK_EQ(r.i, want.i);
    CHECK_EQ(r.j, want.j);

    /* Both paths of hd_index_nearest: the groups of src/nearest/allnearest.c, which it
     * takes, and one search of the tree per query, which it keeps for sets
     * beyond that file's limit. */
    double *dist = malloc(8 * na);
    size_t *near = malloc(sizeof(size_t) * na);
    static const hd__nearest_path_t paths[] = {HD__NEAREST_AUTO, HD__NEAREST_TREE};
    for (int k = 0; k < 2 && !hdt_failed(); k++) {
        hd__nearest_path_t path = paths[k];
        CONTEXT("hd_index_nearest path %s", path == HD__NEAREST_TREE ? "tree" : "auto");
        memset(dist, 0, 8 * na);
        memset(near, 0, sizeof(size_t) * na);
        CHECK_RC(hd__index_nearest_by(idx, A, T, &o, dist, near, path, NULL), HD_OK);
        for (size_t k = 0; k < na && !hdt_failed(); k++) {
            size_t j;
            double d2 = brute_nearest(ta + 3 * k, b, nb, &j);
            CHECK_BITS(dist[k], sqrt(d2));
            CHECK_EQ(near[k], j);
        }
    }
    free(dist);
    free(near);
    hd_index_free(idx);
    free(ta);
}

static void check_packed(const double *a, size_t na, const double *b, size_t nb,
                         const hd_transform_t *T, int threads) {
    hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
    check_against_brute(&A, a, na, &B, b, nb, T, threads);
}

/* A random rotation (from a unit quaternion) and translation. */
static void random_transform(gen_rng_t *g, hd_transform_t *T, double shift) {
    double q[4], n = 0;
    for (int k = 0; k < 4; k++) {
        q[k] = gen_normal(g);
        n += q[k] * q[k];
    }
    n = sqrt(n);
    double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
                   2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                   2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)};
    memcpy(T->r, r, sizeof r);
    for (int k = 0; k < 3; k++) T->t[k] = shift * gen_normal(g);
}

TEST(index_matches_brute_force_on_gaussians) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 40; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_seed(&g, seed);
        size_t na = 1 + gen_u64(&g) % 700, nb = 1 + gen_u64(&g) % 2000;
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        double m0[3] = {0, 0, 0}, m1[3] = {0.3 * (double)(seed % 5), 0, 0};
        gen_gauss(&g, a, na, m0, 1.0);
        gen_gauss(&g, b, nb, m1, 1.0);
        check_packed(a, na, b, nb, NULL, seed % 2 ? 1 : 3);
        free(a);
        free(b);
    }
}

TEST(index_applies_the_documented_transform) {
    gen_rng_t g;
    for (uint64_t seed = 100; seed < 120; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_seed(&g, seed);
        size_t na = 1 + gen_u64(&g) % 500, nb = 1 + gen_u64(&g) % 1500;
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        gen_torus(&g, a, na, 2.0, 0.5);
        gen_torus(&g, b, nb, 2.0, 0.5);
        hd_transform_t T;
        random_transform(&g, &T, 0.5);
        check_packed(a, na, b, nb, &T, seed % 2 ? 1 : 3);
        hd_transform_identity(&T);
        check_packed(a, na, b, nb, &T, 3);
        free(a);
        free(b);
    }
}

TEST(lattice_ties_give_the_smallest_indices) {
    gen_rng_t g;
    for (uint64_t seed = 200; seed < 230; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_seed(&g, seed);
        size_t na = 1 + gen_u64(&g) % 400, nb = 1 + gen_u64(&g) % 400;
        int side = 2 + (int)(gen_u64(&g) % 6);
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        gen_lattice(&g, a, na, side + 2);
        gen_lattice(&g, b, nb, side);
        check_packed(a, na, b, nb, NULL, seed % 2 ? 1 : 3);
        free(a);
        free(b);
    }
}

TEST(duplicates_and_identical_sets) {
    gen_rng_t g;
    gen_seed(&g, 300);
    CONTEXT("seed=300");
    size_t n = 600;
    double *a = malloc(24 * n), *b = malloc(24 * n);
    double m[3] = {0, 0, 0};
    gen_gauss(&g, a, n / 3, m, 1.0);
    /* Every point three times, in three blocks. */
    memcpy(a + 3 * (n / 3), a, 24 * (n / 3));
    memcpy(a + 6 * (n / 3), a, 24 * (n / 3));
    memcpy(b, a, 24 * n);
    check_packed(a, n, b, n, NULL, 1);
    check_packed(a, n, b, n, NULL, 3);
    /* All points equal. */
    for (size_t k = 0; k < 3 * n; k++) b[k] = 0.25;
    check_packed(a, n, b, n, NULL, 3);
    check_packed(b, n, a, n, NULL, 3);
    free(a);
    free(b);
}

TEST(float32_views_are_widened_exactly) {
    gen_rng_t g;
    for (uint64_t seed = 400; seed < 410; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_seed(&g, seed);
        size_t na = 1 + gen_u64(&g) % 500, nb = 1 + gen_u64(&g) % 900;
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        float *fa = malloc(12 * na), *fb = malloc(12 * nb);
        double m0[3] = {0, 0, 0}, m1[3] = {0.5, 0, 0};
        gen_gauss(&g, a, na, m0, 1.0);
        gen_gauss(&g, b, nb, m1, 1.0);
        for (size_t k = 0; k < 3 * na; k++) a[k] = (double)(fa[k] = (float)a[k]);
        for (size_t k = 0; k < 3 * nb; k++) b[k] = (double)(fb[k] = (float)b[k]);
        hd_points_t A = hd_points_f32(fa, na), B = hd_points_f32(fb, nb);
        check_against_brute(&A, a, na, &B, b, nb, NULL, seed % 2 ? 1 : 3);
        free(a);
        free(b);
        free(fa);
        free(fb);
    }
}

TEST(strided_views_read_the_right_points) {
    gen_rng_t g;
    gen_seed(&g, 500);
    CONTEXT("seed=500");
    size_t na = 333, nb = 777;
    double *a = malloc(24 * na), *b = malloc(24 * nb);
    double m[3] = {0, 0, 0};
    gen_gauss(&g, a, na, m, 1.0);
    gen_gauss(&g, b, nb, m, 1.0);
    /* B column-major (Fortran order); A reversed with a negative stride
     * inside records of four doubles. */
    double *col = malloc(24 * nb), *rec = malloc(32 * na), *arev = malloc(24 * na);
    for (size_t k = 0; k < nb; k++)
        for (int c = 0; c < 3; c++) col[c * nb + k] = b[3 * k + c];
    for (size_t k = 0; k < na; k++) {
        for (int c = 0; c < 3; c++) rec[4 * k + c] = a[3 * k + c];
        rec[4 * k + 3] = NAN; /* a field the view must skip */
    }
    for (size_t k = 0; k < na; k++) memcpy(arev + 3 * k, a + 3 * (na - 1 - k), 24);
    hd_points_t B = hd_points_f64(col, nb);
    B.stride = sizeof(double);
    B.cstride = (ptrdiff_t)(nb * sizeof(double));
    hd_points_t A = hd_points_f64(rec + 4 * (na - 1), na);
    A.stride = -4 * (ptrdiff_t)sizeof(double);
    check_against_brute(&A, arev, na, &B, b, nb, NULL, 1);
    check_against_brute(&A, arev, na, &B, b, nb, NULL, 3);
    free(a);
    free(b);
    free(col);
    free(rec);
    free(arev);
}

TEST(far_offsets_and_tiny_scales_stay_exact) {
    gen_rng_t g;
    double scales[] = {1.0, 1e-9, 1.0, 1e-9};
    double offsets[] = {1e9, 0.0, -1e9, 1e9};
    for (int c = 0; c < 4; c++) {
        uint64_t seed = 600 + (uint64_t)c;
        CONTEXT("seed=%llu scale=%g offset=%g", (unsigned long long)seed, scales[c], offsets[c]);
        gen_seed(&g, seed);
        size_t na = 700, nb = 900;
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        double m0[3] = {0, 0, 0}, m1[3] = {0.2, 0.1, 0};
        gen_gauss(&g, a, na, m0, 1.0);
        gen_gauss(&g, b, nb, m1, 1.0);
        gen_affine(a, na, scales[c], offsets[c]);
        gen_affine(b, nb, scales[c], offsets[c]);
        check_packed(a, na, b, nb, NULL, 1);
        check_packed(a, na, b, nb, NULL, 3);
        free(a);
        free(b);
    }
}

TEST(kdtree_algorithm_matches_brute_force) {
    gen_rng_t g;
    for (uint64_t seed = 700; seed < 760; seed++) {
        CONTEXT("seed=%llu", (unsigned long long)seed);
        gen_seed(&g, seed);
        size_t na = 1 + gen_u64(&g) % 900, nb = 1 + gen_u64(&g) % 900;
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        switch (seed % 4) {
        case 0: {
            double m0[3] = {0, 0, 0}, m1[3] = {20, 0, 0};
            gen_gauss(&g, a, na, m0, 1.0);
            gen_gauss(&g, b, nb, m1, 1.0);
            break;
        }
        case 1:
            gen_lattice(&g, a, na, 5);
            gen_lattice(&g, b, nb, 4);
            break;
        case 2:
            gen_plane(&g, a, na);
            gen_line(&g, b, nb);
            break;
        default:
            gen_cube(&g, a, na, -1, 1);
            gen_cube(&g, b, nb, 0, 2);
            gen_affine(a, na, 1e-9, 1e9);
            gen_affine(b, nb, 1e-9, 1e9);
        }
        brute_t want = brute_directed(a, na, b, nb);
        hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
        hd_options_t o;
        hd_options_init(&o);
        o.algorithm = HD_ALG_KDTREE;
        o.threads = seed % 2 ? 1 : 3;
        hd_result_t r;
        CHECK_RC(hd_directed(&A, &B, &o, &r, NULL), HD_OK);
        CHECK_BITS(r.distance2, want.d2);
        CHECK_EQ(r.i, want.i);
        CHECK_EQ(r.j, want.j);
        CHECK_EQ(r.algorithm, HD_ALG_KDTREE);
        CHECK(r.stats.distance_evals >= na);
        free(a);
        free(b);
    }
}

TEST(nearest_of_a_same_order_copy_is_exact_with_and_without_a_transform) {
    /* Queries of B's size meet their partners at the same indices
     * (src/nearest/allnearest.c); after a rotation the partners are far and the path
     * must give up without changing an answer. */
    for (uint64_t seed = 50; seed < 50 + 2 * GEN_COPY_KINDS && !hdt_failed(); seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        int how = (int)(seed % GEN_COPY_KINDS);
        size_t n = 1 + gen_u64(&g) % 2500;
        hd_transform_t T;
        random_transform(&g, &T, 0.01);
        int moved = seed / GEN_COPY_KINDS % 2 == 1;
        CONTEXT("seed=%llu copy=%s n=%zu transform=%d", (unsigned long long)seed, gen_copy_name[how], n, moved);
        double *a = malloc(24 * n), *b = malloc(24 * n);
        gen_copy(&g, how, a, b, n);
        check_packed(a, n, b, n, moved ? &T : NULL, (int)seed % 3 + 1);
        free(a), free(b);
    }
}

TEST(index_refuses_bad_input) {
    double good[6] = {0, 0, 0, 1, 1, 1}, nan_[3] = {0, NAN, 0};
    hd_points_t G = hd_points_f64(good, 2), E = hd_points_f64(good, 0), N = hd_points_f64(nan_, 1);
    hd_index_t *idx = (hd_index_t *)&idx;
    hd_error_t e;
    CHECK_RC(hd_index_build(&E, NULL, &idx, &e), HD_EEMPTY);
    CHECK(idx == NULL);
    CHECK_RC(hd_index_build(&N, NULL, &idx, &e), HD_ENONFINITE);
    CHECK_RC(hd_index_build(NULL, NULL, &idx, &e), HD_EINVAL);
    CHECK_RC(hd_index_build(&G, NULL, NULL, &e), HD_EINVAL);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = -1;
    CHECK_RC(hd_index_build(&G, &o, &idx, &e), HD_EINVAL);
    CHECK_RC(hd_index_build(&G, NULL, &idx, &e), HD_OK);
    CHECK(hd_index_memory(idx) > 0);
    hd_result_t r;
    CHECK_RC(hd_index_directed(idx, &E, NULL, NULL, &r, &e), HD_EEMPTY);
    CHECK_RC(hd_index_directed(idx, &N, NULL, NULL, &r, &e), HD_ENONFINITE);
    CHECK_RC(hd_index_directed(idx, &G, NULL, NULL, NULL, &e), HD_EINVAL);
    CHECK_RC(hd_index_directed(NULL, &G, NULL, NULL, &r, &e), HD_EINVAL);
    /* A transform can carry valid points out of range: refused, not wrong. */
    hd_transform_t T;
    hd_transform_identity(&T);
    T.r[0] = 1e145; /* 1e155: finite, beyond HD_MAX_COORD */
    double far_[3] = {1e10, 0, 0};
    hd_points_t F = hd_points_f64(far_, 1);
    CHECK_RC(hd_index_directed(idx, &F, &T, NULL, &r, &e), HD_ERANGE);
    double dist[1];
    CHECK_RC(hd_index_nearest(idx, &F, &T, NULL, dist, NULL, &e), HD_ERANGE);
    CHECK(strstr(e.message, "point 0") != NULL);
    hd_index_free(idx);
    hd_index_free(NULL);
    CHECK_EQ(hd_index_count(NULL), 0);
}

TEST(a_transform_that_makes_a_nan_or_an_infinity_is_refused_as_nonfinite) {
    /* hausdorff.h promises HD_ENONFINITE for NaN and infinities and
     * HD_ERANGE beyond HD_MAX_COORD; a transform can produce either from
     * valid points, so the codes must be the same after it.  The bad point
     * is the last of 10000 (the third slice of 4096 checked in parallel):
     * the message names it. */
    size_t n = 10000;
    double *q = malloc(24 * n), b[6] = {0, 0, 0, 1, 1, 1};
    for (size_t k = 0; k < 3 * n; k++) q[k] = k % 3 ? (double)(k % 7) : 0.0;
    q[3 * (n - 1)] = 1e10; /* x = 0 but here */
    hd_points_t Q = hd_points_f64(q, n), B = hd_points_f64(b, 2);
    hd_index_t *idx = NULL;
    CHECK_RC(hd_index_build(&B, NULL, &idx, NULL), HD_OK);
    struct {
        const char *what;
        double r0, t0;
        int code;
    } cases[] = {
        {"r[0] = NaN", NAN, 0.0, HD_ENONFINITE},       /* every point NaN */
        {"t[0] = +inf", 1.0, INFINITY, HD_ENONFINITE}, /* every point infinite */
        {"r[0] = 1e300", 1e300, 0.0, HD_ENONFINITE},   /* 1e310 overflows, 0 stays 0 */
        {"r[0] = 1e150", 1e150, 0.0, HD_ERANGE},       /* 1e160: finite, beyond */
        {"r[0] = 1e140", 1e140, 0.0, HD_OK},           /* 1e150: within */
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0] && idx; c++) {
        hd_transform_t T;
        hd_transform_identity(&T);
        T.r[0] = cases[c].r0;
        T.t[0] = cases[c].t0;
        int last_only = c >= 2; /* only the last point goes wrong */
        for (int threads = 1; threads <= 2; threads++) {
            CONTEXT("%s, threads %d", cases[c].what, threads);
            hd_options_t o;
            hd_options_init(&o);
            o.threads = threads;
            hd_error_t e;
            hd_result_t r;
            CHECK_RC(hd_index_directed(idx, &Q, &T, &o, &r, &e), cases[c].code);
            if (cases[c].code != HD_OK)
                CHECK(strstr(e.message, last_only ? "point 9999 of A" : "point 0 of A") != NULL);
            double *dist = malloc(8 * n);
            for (int k = 0; k < 2; k++) {
                hd__nearest_path_t path = k ? HD__NEAREST_TREE : HD__NEAREST_AUTO;
                CHECK_RC(hd__index_nearest_by(idx, &Q, &T, &o, dist, NULL, path, &e), cases[c].code);
                if (cases[c].code != HD_OK)
                    CHECK(strstr(e.message, last_only ? "point 9999 of Q" : "point 0 of Q") != NULL);
            }
            free(dist);
        }
    }
    hd_index_free(idx);
    free(q);
}

TEST(packed_views_must_be_aligned_and_strided_views_need_not_be) {
    /* Packed doubles one byte off their alignment: the library would read
     * them through double pointers (undefined behaviour, caught by the
     * sanitizers), so every hd_index_* call refuses them with HD_EINVAL.
     * The same bytes described with a stride that is not packed are read
     * with memcpy and answered exactly. */
    enum { N = 300 };
    static double store[3 * N + 8];
    double a[3 * N], b[3 * N];
    gen_rng_t g;
    gen_seed(&g, 4242);
    double m0[3] = {0, 0, 0};
    gen_gauss(&g, a, N, m0, 1.0);
    gen_gauss(&g, b, N, m0, 1.0);
    char *odd = (char *)store + 1;
    memcpy(odd, a, sizeof a);
    hd_points_t A = hd_points_f64(a, N), B = hd_points_f64(b, N);
    hd_points_t M = hd_points_f64((const double *)(const void *)odd, N);
    hd_error_t e;
    hd_index_t *idx = (hd_index_t *)&idx;
    CHECK_RC(hd_index_build(&M, NULL, &idx, &e), HD_EINVAL);
    CHECK(idx == NULL);
    CHECK(strstr(e.message, "aligned to 8 bytes") != NULL);
    float af[3 * N];
    for (size_t k = 0; k < 3 * N; k++) af[k] = (float)a[k];
    memcpy((char *)store + 2, af, sizeof af);
    hd_points_t Mf = hd_points_f32((const float *)(const void *)((char *)store + 2), N);
    CHECK_RC(hd_index_build(&Mf, NULL, &idx, &e), HD_EINVAL);
    CHECK(strstr(e.message, "aligned to 4 bytes") != NULL);
    memcpy(odd, a, sizeof a);
    M.stride = 24; /* explicit packed strides are packed too */
    CHECK_RC(hd_index_build(&M, NULL, &idx, &e), HD_EINVAL);
    M.stride = 0;
    CHECK_RC(hd_index_build(&B, NULL, &idx, &e), HD_OK);
    if (!idx) return;
    hd_result_t r;
    double dist[N];
    CHECK_RC(hd_index_directed(idx, &M, NULL, NULL, &r, &e), HD_EINVAL);
    CHECK_RC(hd_index_nearest(idx, &M, NULL, NULL, dist, NULL, &e), HD_EINVAL);
    CHECK(strstr(e.message, "point set Q") != NULL);
    /* Strided (here: Fortran-like, x of every point first) at an odd
     * address: accepted, exact. */
    double *soa = malloc(sizeof a + 1);
    char *s1 = (char *)soa + 1;
    for (size_t k = 0; k < N; k++)
        for (int c = 0; c < 3; c++) memcpy(s1 + 8 * (c * N + k), &a[3 * k + c], 8);
    hd_points_t S = {s1, N, HD_FLOAT64, 8, 8 * N};
    hd_result_t want;
    CHECK_RC(hd_index_directed(idx, &A, NULL, NULL, &want, NULL), HD_OK);
    CHECK_RC(hd_index_directed(idx, &S, NULL, NULL, &r, &e), HD_OK);
    CHECK_BITS(r.distance2, want.distance2);
    CHECK_EQ(r.i, want.i);
    CHECK_EQ(r.j, want.j);
    hd_index_free(idx);
    idx = NULL;
    CHECK_RC(hd_index_build(&S, NULL, &idx, &e), HD_OK);
    hd_index_free(idx);
    free(soa);
}

TEST(nearest_accepts_either_output_alone) {
    double b[] = {0, 0, 0, 2, 0, 0, 2, 0, 0};
    double q[] = {1.5, 0, 0, -1, 0, 0};
    hd_points_t B = hd_points_f64(b, 3), Q = hd_points_f64(q, 2);
    hd_index_t *idx;
    CHECK_RC(hd_index_build(&B, NULL, &idx, NULL), HD_OK);
    double dist[2];
    size_t near[2];
    CHECK_RC(hd_index_nearest(idx, &Q, NULL, NULL, dist, NULL, NULL), HD_OK);
    CHECK_BITS(dist[0], 0.5);
    CHECK_BITS(dist[1], 1.0);
    CHECK_RC(hd_index_nearest(idx, &Q, NULL, NULL, NULL, near, NULL), HD_OK);
    CHECK_EQ(near[0], 1); /* B[1] and B[2] tie: the smaller index */
    CHECK_EQ(near[1], 0);
    hd_index_free(idx);
}

/* One user thread's queries against the shared index: its own set, moved
 * by its own transform, answered with 2 threads of the library's own. */
typedef struct {
    const hd_index_t *idx;
    double *a;
    size_t na;
    hd_transform_t T;
    int rc[2];
    hd_result_t r;
    double *dist;
    size_t *near;
} user_t;

static void *user_queries(void *arg) {
    user_t *u = arg;
    hd_options_t o;
    hd_options_init(&o);
    o.threads = 2;
    hd_points_t A = hd_points_f64(u->a, u->na);
    for (int round = 0; round < 3; round++) {
        u->rc[0] = hd_index_directed(u->idx, &A, &u->T, &o, &u->r, NULL);
        u->rc[1] = hd_index_nearest(u->idx, &A, &u->T, &o, u->dist, u->near, NULL);
        if (u->rc[0] || u->rc[1]) break;
    }
    return NULL;
}

TEST(one_index_answers_many_user_threads_at_once) {
    /* The header's promise: a built index is immutable, and any number of
     * threads may query it at once. */
    enum { USERS = 4 };
    gen_rng_t g;
    gen_seed(&g, 900);
    CONTEXT("seed=900 users=%d", USERS);
    size_t nb = 20000;
    double *b = malloc(24 * nb);
    double m[3] = {0, 0, 0};
    gen_gauss(&g, b, nb, m, 1.0);
    hd_points_t B = hd_points_f64(b, nb);
    hd_index_t *idx = NULL;
    CHECK_RC(hd_index_build(&B, NULL, &idx, NULL), HD_OK);
    user_t u[USERS];
    pthread_t t[USERS];
    int started[USERS] = {0};
    for (int k = 0; k < USERS; k++) {
        u[k] = (user_t){.idx = idx, .na = 3000 + 500 * (size_t)k};
        u[k].a = malloc(24 * u[k].na);
        u[k].dist = malloc(8 * u[k].na);
        u[k].near = malloc(sizeof(size_t) * u[k].na);
        m[0] = 0.2 * k;
        gen_gauss(&g, u[k].a, u[k].na, m, 1.0);
        random_transform(&g, &u[k].T, 0.3);
    }
    for (int k = 0; k < USERS && idx; k++) started[k] = pthread_create(&t[k], NULL, user_queries, &u[k]) == 0;
    for (int k = 0; k < USERS; k++)
        if (started[k]) pthread_join(t[k], NULL);
    for (int k = 0; k < USERS && idx && !hdt_failed(); k++) {
        CONTEXT("seed=900 user %d", k);
        CHECK(started[k]);
        CHECK_RC(u[k].rc[0], HD_OK);
        CHECK_RC(u[k].rc[1], HD_OK);
        double *ta = malloc(24 * u[k].na);
        brute_transform(u[k].T.r, u[k].T.t, u[k].a, ta, u[k].na);
        brute_t want = brute_directed(ta, u[k].na, b, nb);
        CHECK_BITS(u[k].r.distance2, want.d2);
        CHECK_EQ(u[k].r.i, want.i);
        CHECK_EQ(u[k].r.j, want.j);
        for (size_t q = 0; q < u[k].na && !hdt_failed(); q++) {
            size_t j;
            double d2 = brute_nearest(ta + 3 * q, b, nb, &j);
            CHECK_BITS(u[k].dist[q], sqrt(d2));
            CHECK_EQ(u[k].near[q], j);
        }
        free(ta);
    }
    for (int k = 0; k < USERS; k++) free(u[k].a), free(u[k].dist), free(u[k].near);
    hd_index_free(idx);
    free(b);
}
