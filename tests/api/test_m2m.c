/*
 * test_m2m.c -- the distance between surfaces as an enclosure
 * (hd_surface_hausdorff, hd_surface_points_hausdorff, hd_surface_within,
 * hd_surface_face_maxima) against a dense check: every triangle of A
 * sampled on a barycentric grid of N = 2^k steps whose points are exactly
 * on A (integer corners, so every sample is computed without rounding),
 * each sample's correctly rounded distance to B from hd_mesh_distances.
 * What must hold: every sample's distance <= upper; the largest sample <=
 * lower + tolerance; the witness's distance as documented; the same
 * enclosure, witness and counters at 1 and 3 threads; both directions.
 */
#include "check.h"
#include "gen.h"

#include <math.h>
#include <stdlib.h>

#ifdef __SANITIZE_ADDRESS__
#define SCALE 4
#else
#define SCALE 1
#endif

static gen_soup_t soup_new(size_t nv, size_t nt) {
    gen_soup_t s = {calloc(3 * nv + 1, sizeof(double)), nv, calloc(3 * nt + 1, sizeof(uint64_t)), nt};
    return s;
}

static gen_soup_t soup_of(const double *v, size_t nv, const uint64_t *t, size_t nt) {
    gen_soup_t s = soup_new(nv, nt);
    memcpy(s.v, v, 3 * nv * sizeof *v);
    memcpy(s.t, t, 3 * nt * sizeof *t);
    return s;
}

/* A soup of nt random triangles with integer corners in [-side, side]. */
static gen_soup_t random_soup(gen_rng_t *r, size_t nt, int side) {
    gen_soup_t s = soup_new(3 * nt, nt);
    for (size_t k = 0; k < 3 * nt * 3; k++) s.v[k] = (double)((int)(gen_u64(r) % (uint64_t)(2 * side + 1)) - side);
    for (size_t k = 0; k < 3 * nt; k++) s.t[k] = k;
    return s;
}

/* Samples of face k of A on the grid of n steps (exact: integer corners,
 * n a power of two, coordinates below 2^40). */
static size_t face_samples(const gen_soup_t *A, size_t k, int n, double *out) {
    const double *a = A->v + 3 * A->t[3 * k], *b = A->v + 3 * A->t[3 * k + 1], *c = A->v + 3 * A->t[3 * k + 2];
    size_t m = 0;
    for (int i = 0; i <= n; i++)
        for (int j = 0; i + j <= n; j++, m++)
            for (int d = 0; d < 3; d++)
                out[3 * m + d] = ((double)(n - i - j) * a[d] + (double)i * b[d] + (double)j * c[d]) / n;
    return m;
}

/* The correctly rounded distances of n points to B. */
static double *distances(const double *pts, size_t n, const gen_soup_t *B) {
    double *d = malloc(n * sizeof *d);
    hd_points_t P = hd_points_f64(pts, n);
    hd_mesh_t M = gen_soup_view(B);
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, d, NULL, NULL, NULL, NULL, NULL), HD_OK);
    return d;
}

static double dist1(const double *p, const gen_soup_t *B) {
    double *d = distances(p, 1, B), r = d[0];
    free(d);
    return r;
}

/* The largest sampled distance of each face of A to B (grid of n). */
static double *dense(const gen_soup_t *A, const gen_soup_t *B, int n) {
    size_t per = (size_t)(n + 1) * (size_t)(n + 2) / 2;
    double *pts = malloc(3 * per * A->nt * sizeof *pts), *best = malloc(A->nt * sizeof *best);
    for (size_t k = 0; k < A->nt; k++) face_samples(A, k, n, pts + 3 * per * k);
    double *d = distances(pts, per * A->nt, B);
    for (size_t k = 0; k < A->nt; k++) {
        best[k] = 0;
        for (size_t s = 0; s < per; s++) best[k] = fmax(best[k], d[per * k + s]);
    }
    free(pts);
    free(d);
    return best;
}

/* The witness is what the header says: its distance correctly rounded,
 * lower derived from it, the point where its weights put it. */
static void witness_holds(const hd_enclosure_t *e, const gen_soup_t *X, const gen_soup_t *Y) {
    if (e->face_a == SIZE_MAX) {
        CHECK(e->lower == 0 && e->upper == 0);
        return;
    }
    CHECK(e->face_a < X->nt);
    CHECK_BITS(e->witness_distance, dist1(e->point_a, Y));
    if (e->witness_error == 0) {
        CHECK_BITS(e->lower, e->witness_distance);
    } else {
        double want = fmax(0.0, nextafter(nextafter(e->witness_distance, 0) - e->witness_error, -INFINITY));
        CHECK_BITS(e->lower, want);
    }
    const uint64_t *f = X->t + 3 * e->face_a;
    double sum = e->bary_a[0] + e->bary_a[1] + e->bary_a[2];
    CHECK(fabs(sum - 1) <= 1e-15);
    for (int d = 0; d < 3; d++) {
        double want = e->bary_a[0] * X->v[3 * f[0] + d] + e->bary_a[1] * X->v[3 * f[1] + d] +
                      e->bary_a[2] * X->v[3 * f[2] + d];
        CHECK(fabs(want - e->point_a[d]) <= e->witness_error + 1e-12 * fabs(want));
    }
}

/* The enclosure of h(X, Y) holds against the dense check of grid n. */
static void encloses(const hd_enclosure_t *e, const gen_soup_t *X, const gen_soup_t *Y, int n) {
    CHECK(e->lower <= e->upper);
    CHECK(e->converged);
    CHECK(e->upper - e->lower <= e->tolerance);
    double *best = dense(X, Y, n), far = 0;
    for (size_t k = 0; k < X->nt; k++) far = fmax(far, best[k]);
    CHECK(far <= e->upper);
    CHECK(far <= e->lower + e->tolerance);
    if (far > e->upper || far > e->lower + e->tolerance)
        CONTEXT("dense %.17g, enclosure [%.17g, %.17g], tolerance %.3g", far, e->lower, e->upper, e->tolerance);
    witness_holds(e, X, Y);
    free(best);
}

static void same_enclosure(const hd_enclosure_t *x, const hd_enclosure_t *y) {
    CHECK_BITS(x->lower, y->lower);
    CHECK_BITS(x->upper, y->upper);
    CHECK_EQ(x->face_a, y->face_a);
    CHECK_EQ(x->face_b, y->face_b);
    for (int d = 0; d < 3; d++) CHECK_BITS(x->point_a[d], y->point_a[d]);
    CHECK_EQ(x->faces_split, y->faces_split);
    CHECK_EQ(x->kernel_calls, y->kernel_calls);
}

static hd_surface_options_t options(double tol, int relative, int threads) {
    hd_surface_options_t o;
    hd_surface_options_init(&o);
    o.tolerance = tol;
    o.relative = relative;
    o.threads = threads;
    return o;
}

/* Both directions at 1 and 3 threads, each enclosing, the same at both. */
static void both_ways(const gen_soup_t *A, const gen_soup_t *B, double tol, int n) {
    hd_mesh_t a = gen_soup_view(A), b = gen_soup_view(B);
    hd_enclosure_t ab1, ba1, ab3, ba3;
    hd_surface_options_t o1 = options(tol, 1, 1), o3 = options(tol, 1, 3);
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o1, &ab1, &ba1, NULL), HD_OK);
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o3, &ab3, &ba3, NULL), HD_OK);
    encloses(&ab1, A, B, n);
    encloses(&ba1, B, A, n);
    same_enclosure(&ab1, &ab3);
    same_enclosure(&ba1, &ba3);
}

TEST(identical_meshes_are_zero) {
    const double v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 1};
    const uint64_t t[] = {0, 1, 2, 1, 3, 2};
    gen_soup_t A = soup_of(v, 4, t, 2);
    hd_mesh_t a = gen_soup_view(&A);
    hd_enclosure_t ab, ba;
    CHECK_RC(hd_surface_hausdorff(&a, &a, NULL, &ab, &ba, NULL), HD_OK);
    CHECK(ab.lower == 0 && ab.upper == 0 && ba.upper == 0);
    CHECK_EQ(ab.faces_dropped, 2);
    CHECK_EQ(ab.faces_split, 0);
    gen_soup_free(&A);
}

/* Shared faces are found for both directions at once: B holds one of A's
 * faces twice (corners in another order) and a face of its own; A's other
 * face is not in B.  h(A, B) drops one face, h(B, A) both copies. */
TEST(shared_faces_are_dropped_both_ways_with_copies) {
    const double va[] = {0, 0, 0, 8, 0, 0, 0, 8, 0, 8, 8, 4};
    const uint64_t ta[] = {0, 1, 2, 1, 3, 2};
    const double vb[] = {0, 0, 0, 8, 0, 0, 0, 8, 0, 0, 0, 8};
    const uint64_t tb[] = {0, 1, 2, 2, 0, 1, 0, 1, 3};
    gen_soup_t A = soup_of(va, 4, ta, 2), B = soup_of(vb, 4, tb, 3);
    hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
    hd_surface_options_t o = options(1e-9, 1, 1);
    hd_enclosure_t ab, ba;
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o, &ab, &ba, NULL), HD_OK);
    CHECK_EQ(ab.faces_dropped, 1);
    CHECK_EQ(ba.faces_dropped, 2);
    encloses(&ab, &A, &B, 16);
    encloses(&ba, &B, &A, 16);
    gen_soup_free(&A), gen_soup_free(&B);
}

TEST(parallel_shifted_triangle_is_its_shift) {
    const double v[] = {0, 0, 0, 8, 0, 0, 0, 8, 0, 0, 0, 3, 8, 0, 3, 0, 8, 3};
    const uint64_t ta[] = {0, 1, 2}, tb[] = {3, 4, 5};
    gen_soup_t A = soup_of(v, 6, ta, 1), B = soup_of(v, 6, tb, 1);
    hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
    hd_enclosure_t ab;
    hd_surface_options_t o = options(0, 0, 1);
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o, &ab, NULL, NULL), HD_OK);
    CHECK_BITS(ab.lower, 3.0);
    CHECK(ab.upper >= 3.0 && ab.upper - 3.0 <= 1e-12);
    CHECK_EQ(ab.witness_error, 0);
    encloses(&ab, &A, &B, 16);
    gen_soup_free(&A);
    gen_soup_free(&B);
}

/* A right triangle against its three corners as points: the farthest
 * point is the hypotenuse's midpoint, at the circumradius 2 sqrt 2. */
TEST(triangle_to_its_corners_is_the_circumradius) {
    const double v[] = {0, 0, 0, 4, 0, 0, 0, 4, 0};
    const uint64_t t[] = {0, 1, 2};
    gen_soup_t A = soup_of(v, 3, t, 1);
    hd_mesh_t a = gen_soup_view(&A);
    hd_points_t B = hd_points_f64(v, 3);
    hd_enclosure_t ab, ba;
    hd_surface_options_t o = options(1e-12, 1, 1);
    CHECK_RC(hd_surface_points_hausdorff(&a, &B, &o, &ab, &ba, NULL), HD_OK);
    double r = sqrt(8.0);
    CHECK(ab.lower <= r && r <= ab.upper);
    CHECK(ab.upper - ab.lower <= ab.tolerance);
    CHECK(ab.index_b < 3 && ab.face_b == SIZE_MAX);
    CHECK(ba.lower == 0 && ba.upper == 0); /* the points are A's corners */
    /* the same with tolerance 0: a few rounding errors wide */
    o = options(0, 0, 1);
    CHECK_RC(hd_surface_points_hausdorff(&a, &B, &o, &ab, NULL, NULL), HD_OK);
    CHECK(ab.lower <= r && r <= ab.upper);
    CHECK(ab.upper - ab.lower <= 1e-13);
    gen_soup_free(&A);
}

/* The same scaled by 2^-500: the squared edges lie where a square may
 * have underflowed, so the bound from the corners takes the reach of the
 * face from its edges' 1-norms (mesh/m2m.c, reach). */
TEST(tiny_triangle_to_its_corners_is_the_circumradius) {
    const double s = 0x1p-500, v[] = {0, 0, 0, 4 * s, 0, 0, 0, 4 * s, 0};
    const uint64_t t[] = {0, 1, 2};
    gen_soup_t A = soup_of(v, 3, t, 1);
    hd_mesh_t a = gen_soup_view(&A);
    hd_points_t B = hd_points_f64(v, 3);
    hd_enclosure_t ab;
    hd_surface_options_t o = options(1e-12, 1, 1);
    CHECK_RC(hd_surface_points_hausdorff(&a, &B, &o, &ab, NULL, NULL), HD_OK);
    double r = sqrt(8.0) * s;
    CONTEXT("enclosure [%.17g, %.17g], r %.17g", ab.lower, ab.upper, r);
    CHECK(ab.lower <= r && r <= ab.upper);
    CHECK(ab.upper - ab.lower <= ab.tolerance);
    gen_soup_free(&A);
}

/* The two triangulations of a non-planar quad share every vertex, so a
 * vertex-only distance is 0; the surfaces are apart along the diagonals. */
TEST(quad_split_two_ways_is_not_zero) {
    const double v[] = {0, 0, 0, 4, 0, 0, 4, 4, 4, 0, 4, 0};
    const uint64_t ta[] = {0, 1, 2, 0, 2, 3}, tb[] = {0, 1, 3, 1, 2, 3};
    gen_soup_t A = soup_of(v, 4, ta, 2), B = soup_of(v, 4, tb, 2);
    double *corners = dense(&A, &B, 1); /* grid 1: the vertices */
    CHECK(corners[0] == 0 && corners[1] == 0);
    free(corners);
    both_ways(&A, &B, 1e-9, 64 / SCALE);
    hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
    hd_enclosure_t ab;
    CHECK_RC(hd_surface_hausdorff(&a, &b, NULL, &ab, NULL, NULL), HD_OK);
    CHECK(ab.lower >= 2 / sqrt(3.0) - 1e-6); /* the diagonal's midpoint */
    /* planar: the same two triangulations of a flat square are one surface */
    const double w[] = {0, 0, 0, 4, 0, 0, 4, 4, 0, 0, 4, 0};
    gen_soup_t F = soup_of(w, 4, ta, 2), G = soup_of(w, 4, tb, 2);
    hd_mesh_t f = gen_soup_view(&F), g = gen_soup_view(&G);
    CHECK_RC(hd_surface_hausdorff(&f, &g, NULL, &ab, NULL, NULL), HD_OK);
    CHECK(ab.lower == 0 && ab.upper <= ab.tolerance);
    gen_soup_free(&A), gen_soup_free(&B), gen_soup_free(&F), gen_soup_free(&G);
}

/* A's vertices one ulp apart in height over a flat B: their bounds
 * without the kernel are tens of ulps wide and overlap, and the farthest
 * vertex, right above a vertex of B, has an upper bound below the others'.
 * Only exact distances tell it is the farthest: with a tolerance that
 * stops at the corners the lower bound is its distance. */
TEST(corners_whose_bounds_overlap_give_the_exact_farthest) {
    enum { N = 12, M = 8, NB = (M + 1) * (M + 1) };
    gen_soup_t A = soup_new(N * N, 2 * (N - 1) * (N - 1)), B = soup_new(NB + 4, 2 * M * M + 2);
    for (int i = 0; i < N * N; i++) {
        double *p = A.v + 3 * i;
        p[0] = (i % N + 0.37) / N, p[1] = (i / N + 0.61) / N;
        p[2] = 1 + (double)((i * 37 + 11) % (N * N)) * 0x1p-52; /* the farthest: i = 132, column 0 */
    }
    for (int i = 0; i < NB; i++) {
        double *p = B.v + 3 * i;
        p[0] = 0.1 + 1.0 * (i % (M + 1)) / M, p[1] = -0.1 + 1.2 * (i / (M + 1)) / M, p[2] = 0;
    }
    A.v[3 * 132] = B.v[3 * 72], A.v[3 * 132 + 1] = B.v[3 * 72 + 1]; /* above a vertex of B */
    const double big[4][3] = {{-0.2, -1e3, 0}, {0.1, -1e3, 0}, {0.1, 1e3, 0}, {-0.2, 1e3, 0}};
    memcpy(B.v + 3 * NB, big, sizeof big);
    for (int k = 0, q = 0; q < (N - 1) * (N - 1); q++) {
        uint64_t a = (uint64_t)(q % (N - 1) + q / (N - 1) * N);
        uint64_t t[6] = {a, a + 1, a + N + 1, a, a + N + 1, a + N};
        for (int j = 0; j < 6; j++) A.t[k++] = t[j];
    }
    int k = 0;
    for (int q = 0; q < M * M; q++) {
        uint64_t a = (uint64_t)(q % M + q / M * (M + 1));
        uint64_t t[6] = {a, a + 1, a + M + 2, a, a + M + 2, a + M + 1};
        for (int j = 0; j < 6; j++) B.t[k++] = t[j];
    }
    const uint64_t sq[6] = {NB, NB + 1, NB + 2, NB, NB + 2, NB + 3};
    for (int j = 0; j < 6; j++) B.t[k++] = sq[j];
    double *d = distances(A.v, A.nv, &B), far = 0;
    for (size_t i = 0; i < A.nv; i++) far = fmax(far, d[i]);
    free(d);
    hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
    hd_enclosure_t ab1, ab3;
    hd_surface_options_t o1 = options(1, 1, 1), o3 = options(1, 1, 3);
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o1, &ab1, NULL, NULL), HD_OK);
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o3, &ab3, NULL, NULL), HD_OK);
    CHECK_BITS(far, 1 + 143 * 0x1p-52);
    CHECK_BITS(ab1.lower, far);
    CHECK_EQ(ab1.witness_error, 0);
    witness_holds(&ab1, &A, &B);
    same_enclosure(&ab1, &ab3);
    gen_soup_free(&A);
    gen_soup_free(&B);
}

TEST(tetrahedron_against_its_scaled_copy) {
    const double v[] = {0, 0, 0, 8, 0, 0, 0, 8, 0, 0, 0, 8, -4, -4, -4, 12, -4, -4, -4, 12, -4, -4, -4, 12};
    const uint64_t ta[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3}, tb[] = {4, 6, 5, 4, 5, 7, 4, 7, 6, 5, 6, 7};
    gen_soup_t A = soup_of(v, 8, ta, 4), B = soup_of(v, 8, tb, 4);
    both_ways(&A, &B, 1e-9, 64 / SCALE);
    both_ways(&A, &B, 1e-4, 32 / SCALE);
    gen_soup_free(&A);
    gen_soup_free(&B);
}

TEST(degenerate_faces_are_their_hulls) {
    /* A: a proper triangle, a segment (collinear), a point (repeated
     * index); B: a sliver and a segment */
    const double v[] = {0, 0, 0, 8, 0, 0, 0, 8, 0, 16, 0, 0, 24, 0, 0, 4, 4, 4,
                        0, 0, 4, 8, 0, 4, 16, 8, 4, -8, 0, 2, 0, 8, 6};
    const uint64_t ta[] = {0, 1, 2, 1, 3, 4, 5, 5, 5}, tb[] = {6, 7, 8, 9, 10, 10};
    gen_soup_t A = soup_of(v, 11, ta, 3), B = soup_of(v, 11, tb, 2);
    both_ways(&A, &B, 1e-9, 64 / SCALE);
    gen_soup_free(&A);
    gen_soup_free(&B);
}

TEST(random_soups_both_ways) {
    for (uint64_t seed = 1; seed <= 12 / SCALE; seed++) {
        CONTEXT("seed %llu", (unsigned long long)seed);
        gen_rng_t r;
        gen_seed(&r, seed);
        gen_soup_t A = random_soup(&r, 2 + seed % 5, 16), B = random_soup(&r, 1 + seed % 7, 16);
        both_ways(&A, &B, seed % 2 ? 1e-9 : 1e-5, 32);
        gen_soup_free(&A);
        gen_soup_free(&B);
        if (hdt_failed()) break;
    }
}

/* Far from the origin (2^20 + k 2^-26): every point the search computes
 * inside a face is rounded, so the bounds must carry the rounding error
 * of the computed corners; the samples stay exact (52 bits). */
TEST(meshes_far_from_the_origin) {
    for (uint64_t seed = 1; seed <= 6 / SCALE + 1; seed++) {
        CONTEXT("seed %llu", (unsigned long long)seed);
        gen_rng_t r;
        gen_seed(&r, seed);
        gen_soup_t A = random_soup(&r, 3, 1024), B = random_soup(&r, 3, 1024);
        for (size_t k = 0; k < 3 * A.nv; k++) A.v[k] = 0x1p20 + A.v[k] * 0x1p-26;
        for (size_t k = 0; k < 3 * B.nv; k++) B.v[k] = 0x1p20 + B.v[k] * 0x1p-26;
        hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
        hd_enclosure_t ab, ba, ab3, ba3;
        hd_surface_options_t o1 = options(0, 0, 1), o3 = options(0, 0, 3);
        CHECK_RC(hd_surface_hausdorff(&a, &b, &o1, &ab, &ba, NULL), HD_OK);
        CHECK_RC(hd_surface_hausdorff(&a, &b, &o3, &ab3, &ba3, NULL), HD_OK);
        encloses(&ab, &A, &B, 16);
        encloses(&ba, &B, &A, 16);
        same_enclosure(&ab, &ab3);
        same_enclosure(&ba, &ba3);
        gen_soup_free(&A), gen_soup_free(&B);
        if (hdt_failed()) break;
    }
}

TEST(surface_to_points_encloses_and_points_to_surface_is_exact) {
    for (uint64_t seed = 1; seed <= 6 / SCALE + 1; seed++) {
        CONTEXT("seed %llu", (unsigned long long)seed);
        gen_rng_t r;
        gen_seed(&r, seed);
        gen_soup_t A = random_soup(&r, 4, 16), Bt = random_soup(&r, 5, 16);
        /* B: the points, and the same points as point-triangles for the check */
        gen_soup_t Bp = soup_new(Bt.nv, Bt.nv);
        memcpy(Bp.v, Bt.v, 3 * Bt.nv * sizeof(double));
        for (size_t k = 0; k < Bt.nv; k++) Bp.t[3 * k] = Bp.t[3 * k + 1] = Bp.t[3 * k + 2] = k;
        hd_mesh_t a = gen_soup_view(&A);
        hd_points_t B = hd_points_f64(Bt.v, Bt.nv);
        hd_enclosure_t ab, ba, ab3;
        hd_surface_options_t o1 = options(1e-9, 1, 1), o3 = options(1e-9, 1, 3);
        CHECK_RC(hd_surface_points_hausdorff(&a, &B, &o1, &ab, &ba, NULL), HD_OK);
        CHECK_RC(hd_surface_points_hausdorff(&a, &B, &o3, &ab3, NULL, NULL), HD_OK);
        encloses(&ab, &A, &Bp, 32);
        same_enclosure(&ab, &ab3);
        hd_surface_result_t want;
        CHECK_RC(hd_mesh_distances(&B, &a, NULL, NULL, NULL, NULL, NULL, &want, NULL), HD_OK);
        CHECK_BITS(ba.lower, want.distance);
        CHECK_BITS(ba.upper, want.distance);
        CHECK_EQ(ba.index_a, want.i);
        CHECK_EQ(ba.face_b, want.triangle);
        gen_soup_free(&A), gen_soup_free(&Bt), gen_soup_free(&Bp);
        if (hdt_failed()) break;
    }
}

/* The largest dense sample of h(X, Y) over grid n. */
static double dense_max(const gen_soup_t *X, const gen_soup_t *Y, int n) {
    double *best = dense(X, Y, n), far = 0;
    for (size_t k = 0; k < X->nt; k++) far = fmax(far, best[k]);
    free(best);
    return far;
}

/* hd_surface_within(A, B, d) at 1 and 2 threads: the same answer and
 * enclosures, and the answer what they prove: 1 with every upper bound <= d
 * (and the dense samples, `far`, too), 0 with a witness's lower bound > d,
 * -1 with d inside an enclosure no wider than the tolerance.  Returns the
 * answer. */
static int predicate(const gen_soup_t *A, const gen_soup_t *B, double d, int directed, double far) {
    hd_mesh_t a = gen_soup_view(A), b = gen_soup_view(B);
    hd_surface_options_t o1 = options(1e-9, 1, 1), o2 = options(1e-9, 1, 2);
    hd_enclosure_t ab, ba, ab2, ba2;
    int answer, answer2;
    CONTEXT("d %.17g, directed %d", d, directed);
    CHECK_RC(hd_surface_within(&a, &b, d, directed, &o1, &answer, &ab, &ba, NULL), HD_OK);
    CHECK_RC(hd_surface_within(&a, &b, d, directed, &o2, &answer2, &ab2, &ba2, NULL), HD_OK);
    CHECK_EQ(answer, answer2);
    same_enclosure(&ab, &ab2);
    double lower = ab.lower, upper = ab.upper;
    if (!directed) {
        same_enclosure(&ba, &ba2);
        lower = fmax(lower, ba.lower), upper = fmax(upper, ba.upper);
    }
    if (answer == 1) {
        CHECK(upper <= d);
        CHECK(far <= d);
    } else if (answer == 0) {
        CHECK(lower > d);
        witness_holds(ab.lower > d ? &ab : &ba, ab.lower > d ? A : B, ab.lower > d ? B : A);
    } else {
        CHECK_EQ(answer, -1);
        CHECK(lower <= d && d < upper);
        CHECK(upper - lower <= ab.tolerance);
    }
    return answer;
}

TEST(predicate_agrees_with_the_enclosure) {
    for (uint64_t seed = 1; seed <= 16 / SCALE; seed++) {
        CONTEXT("seed %llu", (unsigned long long)seed);
        gen_rng_t r;
        gen_seed(&r, seed);
        gen_soup_t A = random_soup(&r, 4, 16), B = random_soup(&r, 4, 16);
        hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
        hd_enclosure_t ab, ba;
        hd_surface_options_t o = options(1e-9, 1, 2);
        CHECK_RC(hd_surface_hausdorff(&a, &b, &o, &ab, &ba, NULL), HD_OK);
        double far_ab = dense_max(&A, &B, 16), far = fmax(far_ab, dense_max(&B, &A, 16));
        for (int directed = 0; directed <= 1; directed++) {
            double lo = directed ? ab.lower : fmax(ab.lower, ba.lower);
            double hi = directed ? ab.upper : fmax(ab.upper, ba.upper), x = directed ? far_ab : far;
            CHECK_EQ(predicate(&A, &B, lo * (1 - 1e-6), directed, x), 0);
            CHECK(predicate(&A, &B, nextafter(lo, 0), directed, x) != 1);
            predicate(&A, &B, lo / 2 + hi / 2, directed, x);
            CHECK(predicate(&A, &B, nextafter(hi, INFINITY), directed, x) != 0);
            CHECK_EQ(predicate(&A, &B, hi * (1 + 1e-6), directed, x), 1);
            CHECK_EQ(predicate(&A, &B, 2 * hi, directed, x), 1);
            CHECK_EQ(predicate(&A, &B, lo / 2, directed, x), 0);
        }
        gen_soup_free(&A), gen_soup_free(&B);
        if (hdt_failed()) break;
    }
}

/* Two parallel grids of n x n squares (2 n^2 triangles), z = 0 and z = 1:
 * h = 1 both ways. */
static gen_soup_t grid(int n, double z) {
    gen_soup_t s = soup_new((size_t)(n + 1) * (size_t)(n + 1), 2 * (size_t)n * (size_t)n);
    for (int i = 0; i <= n; i++)
        for (int j = 0; j <= n; j++) {
            double *v = s.v + 3 * ((size_t)i * (size_t)(n + 1) + (size_t)j);
            v[0] = i, v[1] = j, v[2] = z;
        }
    for (int i = 0, k = 0; i < n; i++)
        for (int j = 0; j < n; j++, k += 6) {
            uint64_t c = (uint64_t)i * (uint64_t)(n + 1) + (uint64_t)j, up_ = c + (uint64_t)(n + 1);
            uint64_t t[6] = {c, c + 1, up_, c + 1, up_ + 1, up_};
            memcpy(s.t + k, t, sizeof t);
        }
    return s;
}

TEST(predicate_far_from_the_distance_measures_few_corners) {
    gen_soup_t A = grid(64, 0), B = grid(64, 1);
    hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
    hd_surface_options_t o = options(1e-9, 1, 1), o2 = options(1e-9, 1, 2);
    hd_enclosure_t ab, ba, ab2, ba2;
    int answer;
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o, &ab, &ba, NULL), HD_OK);
    CHECK(ab.lower == 1 && ba.lower == 1);
    uint64_t full = ab.kernel_calls;
    CHECK(full >= 65 * 65);
    /* d = 2: every face is within by bounds on its corners alone */
    CHECK_RC(hd_surface_within(&a, &b, 2, 0, &o, &answer, &ab, &ba, NULL), HD_OK);
    CHECK_EQ(answer, 1);
    CHECK_EQ(ab.kernel_calls, 0);
    CHECK_EQ(ba.kernel_calls, 0);
    CHECK(ab.upper <= 2 && ba.upper <= 2);
    /* d = 1/2: the first corners measured are beyond it, and the search
     * stops there (the faces never reached leave upper infinite) */
    CHECK_RC(hd_surface_within(&a, &b, 0.5, 0, &o, &answer, &ab, &ba, NULL), HD_OK);
    CHECK_RC(hd_surface_within(&a, &b, 0.5, 0, &o2, &answer, &ab2, &ba2, NULL), HD_OK);
    CHECK_EQ(answer, 0);
    CHECK(ab.lower == 1 && isinf(ab.upper));
    CHECK(ab.kernel_calls * 8 <= full);
    same_enclosure(&ab, &ab2);
    CHECK(isinf(ba.upper));
    gen_soup_free(&A), gen_soup_free(&B);
}

/* B: two strips in z = 0, y in [-3, -1] and [1, 3], x in [-10, 100].
 * A: eight wide faces across the gap, whose distance has a ridge at
 * exactly 1 along y = 0, which no edge of their subdivisions follows (y = 0
 * is 9/17 of the way from their base to their apex); a face at z = 1/2 over
 * the gap whose largest distance, sqrt(5) / 2 at y = 0, is inside it (its
 * corners are at sqrt(2) / 2); and a small face at z = 1 + 1e-9 over a
 * strip, whose corners put the first lower bound just above the ridges.
 * The wide faces have the largest first bounds, so they come first: a
 * face refined to the end against that lower bound would need every
 * sub-triangle along its ridge within 1e-9 of it. */
TEST(a_ridge_just_below_the_first_lower_bound_waits_for_the_faces_above_it) {
    double v[3 * 8], va[3 * 30];
    uint64_t tb[3 * 4], ta[30];
    const double strip[8][3] = {{-10, -3, 0}, {100, -3, 0}, {100, -1, 0}, {-10, -1, 0},
                                {-10, 1, 0},  {100, 1, 0},  {100, 3, 0},  {-10, 3, 0}};
    memcpy(v, strip, sizeof strip);
    const uint64_t quads[4][3] = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
    memcpy(tb, quads, sizeof quads);
    gen_soup_t B = soup_of(v, 8, tb, 4);
    size_t n = 0;
    for (int k = 0; k < 8; k++, n += 3) {
        double x = 10.0 * k, c[3][3] = {{x, -0.9, 0}, {x + 8, -0.9, 0}, {x + 4, 0.8, 0}};
        memcpy(va + 3 * n, c, sizeof c);
    }
    const double mid[3][3] = {{80, -0.5, 0.5}, {84, -0.5, 0.5}, {82, 0.5, 0.5}};
    const double z = 1 + 1e-9, top[3][3] = {{90, -2, z}, {90.5, -2, z}, {90, -1.5, z}};
    memcpy(va + 3 * n, mid, sizeof mid), n += 3;
    memcpy(va + 3 * n, top, sizeof top), n += 3;
    for (size_t k = 0; k < n; k++) ta[k] = k;
    gen_soup_t A = soup_of(va, n, ta, n / 3);
    hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
    hd_surface_options_t o = options(1e-12, 0, 1), o2 = options(1e-12, 0, 2);
    o.max_splits = o2.max_splits = 20000;
    hd_enclosure_t ab, ab2;
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o, &ab, NULL, NULL), HD_OK);
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o2, &ab2, NULL, NULL), HD_OK);
    CONTEXT("[%.17g, %.17g], %llu splits", ab.lower, ab.upper, (unsigned long long)ab.faces_split);
    CHECK(ab.converged);
    CHECK(ab.lower <= sqrt(1.25) && sqrt(1.25) <= ab.upper);
    CHECK_EQ(ab.face_a, 8);
    CHECK(ab.faces_split < 20000);
    same_enclosure(&ab, &ab2);
    encloses(&ab, &A, &B, 16);
    gen_soup_free(&A), gen_soup_free(&B);
}

TEST(face_maxima_enclose_each_face) {
    gen_rng_t r;
    gen_seed(&r, 7);
    gen_soup_t A = random_soup(&r, 6, 16), B = random_soup(&r, 5, 16);
    hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
    double lo[6], hi[6], lo3[6], hi3[6];
    hd_enclosure_t ab, all;
    hd_surface_options_t o = options(1e-9, 1, 1), o3 = options(1e-9, 1, 3);
    CHECK_RC(hd_surface_face_maxima(&a, &b, &o, lo, hi, &ab, NULL), HD_OK);
    CHECK_RC(hd_surface_face_maxima(&a, &b, &o3, lo3, hi3, NULL, NULL), HD_OK);
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o, &all, NULL, NULL), HD_OK);
    double *best = dense(&A, &B, 32), top = 0;
    for (int k = 0; k < 6; k++) {
        CONTEXT("face %d: dense %.17g in [%.17g, %.17g]", k, best[k], lo[k], hi[k]);
        CHECK(best[k] <= hi[k]);
        CHECK(lo[k] <= hi[k] && hi[k] - lo[k] <= ab.tolerance);
        CHECK(best[k] <= lo[k] + ab.tolerance);
        CHECK_BITS(lo[k], lo3[k]);
        CHECK_BITS(hi[k], hi3[k]);
        top = fmax(top, hi[k]);
    }
    CHECK(top >= all.lower);
    free(best);
    gen_soup_free(&A), gen_soup_free(&B);
}

/* A UV sphere of radius r about c: m rings of 2 m segments (poles single
 * vertices), 4 m (m - 1) triangles. */
static gen_soup_t sphere(int m, double r, const double c[3]) {
    size_t nv = 2 + (size_t)(m - 1) * (size_t)(2 * m), nt = 4 * (size_t)m * (size_t)(m - 1);
    gen_soup_t s = soup_new(nv, nt);
    const double pi = 3.14159265358979323846;
    for (int d = 0; d < 3; d++) s.v[d] = c[d], s.v[3 + d] = c[d];
    s.v[2] += r, s.v[5] -= r;
    for (int i = 1; i < m; i++)
        for (int j = 0; j < 2 * m; j++) {
            double th = pi * i / m, ph = pi * j / m, *v = s.v + 3 * (2 + (size_t)(i - 1) * (size_t)(2 * m) + (size_t)j);
            v[0] = c[0] + r * sin(th) * cos(ph), v[1] = c[1] + r * sin(th) * sin(ph), v[2] = c[2] + r * cos(th);
        }
    size_t k = 0;
#define RING(i, j) (2 + (uint64_t)((i) - 1) * (uint64_t)(2 * m) + (uint64_t)((j) % (2 * m)))
    for (int j = 0; j < 2 * m; j++) {
        uint64_t t0[3] = {0, RING(1, j), RING(1, j + 1)}, t1[3] = {1, RING(m - 1, j + 1), RING(m - 1, j)};
        memcpy(s.t + 3 * k++, t0, sizeof t0);
        memcpy(s.t + 3 * k++, t1, sizeof t1);
    }
    for (int i = 1; i < m - 1; i++)
        for (int j = 0; j < 2 * m; j++) {
            uint64_t t0[3] = {RING(i, j), RING(i + 1, j), RING(i + 1, j + 1)};
            uint64_t t1[3] = {RING(i, j), RING(i + 1, j + 1), RING(i, j + 1)};
            memcpy(s.t + 3 * k++, t0, sizeof t0);
            memcpy(s.t + 3 * k++, t1, sizeof t1);
        }
#undef RING
    s.nt = k;
    return s;
}

/* A grid near the centre of a sphere: every point of it is nearly as far
 * from every triangle of the sphere, so a search for a corner's nearest
 * triangle visits most of them.  Only the corners near the centre can be
 * the farthest; the others need an upper bound below the sample's lower
 * bound, not their nearest triangle, so the corners cost far fewer than
 * (corners x triangles) bounds - and the enclosure still holds. */
TEST(corners_far_below_the_maximum_stop_at_a_sufficient_bound) {
    const double c[3] = {8, 8, 0};
    gen_soup_t A = grid(16, 0), B = sphere(24, 100, c);
    hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
    hd_surface_options_t o = options(1e-9, 1, 1), o3 = options(1e-9, 1, 3);
    hd_enclosure_t ab, ab3;
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o, &ab, NULL, NULL), HD_OK);
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o3, &ab3, NULL, NULL), HD_OK);
    encloses(&ab, &A, &B, 4);
    same_enclosure(&ab, &ab3);
    uint64_t all = (uint64_t)(17 * 17) * (uint64_t)B.nt;
    CONTEXT("%llu bounds for %llu corners x triangles", (unsigned long long)ab.kernel_calls, (unsigned long long)all);
    CHECK(ab.kernel_calls * 8 < all);
    gen_soup_free(&A), gen_soup_free(&B);
}

TEST(bad_input_is_refused) {
    const double v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, NAN, 0, 0};
    const uint64_t t[] = {0, 1, 2}, bad[] = {0, 1, 3}, far[] = {0, 1, 9};
    gen_soup_t A = soup_of(v, 4, t, 1), N = soup_of(v, 4, bad, 1), F = soup_of(v, 4, far, 1);
    hd_mesh_t a = gen_soup_view(&A), n = gen_soup_view(&N), f = gen_soup_view(&F), e = gen_soup_view(&A);
    e.n_triangles = 0;
    hd_enclosure_t ab;
    hd_error_t err;
    CHECK_RC(hd_surface_hausdorff(&a, &n, NULL, &ab, NULL, &err), HD_ENONFINITE);
    CHECK(strstr(err.message, "B") != NULL);
    CHECK_RC(hd_surface_hausdorff(&f, &a, NULL, &ab, NULL, &err), HD_EINVAL);
    CHECK_RC(hd_surface_hausdorff(&a, &e, NULL, &ab, NULL, &err), HD_EEMPTY);
    CHECK_RC(hd_surface_hausdorff(&a, &a, NULL, NULL, NULL, &err), HD_EINVAL);
    hd_surface_options_t o = options(-1, 1, 1);
    CHECK_RC(hd_surface_hausdorff(&a, &a, &o, &ab, NULL, &err), HD_EINVAL);
    o = options(NAN, 1, 1);
    CHECK_RC(hd_surface_hausdorff(&a, &a, &o, &ab, NULL, &err), HD_EINVAL);
    int answer;
    CHECK_RC(hd_surface_within(&a, &a, -1, 0, NULL, &answer, NULL, NULL, &err), HD_EINVAL);
    hd_points_t none = hd_points_f64(v, 0);
    CHECK_RC(hd_surface_points_hausdorff(&a, &none, NULL, &ab, NULL, &err), HD_EEMPTY);
    gen_soup_free(&A), gen_soup_free(&N), gen_soup_free(&F);
}

/* grid(n) against grid(n) split in four (grid(2 n) halved), each vertex
 * raised by a seeded multiple (0 to 63) of 2^ex: the splits of each
 * direction at the relative tolerance tol, after checking that the
 * enclosures hold both ways at 1 and 3 threads. */
static void raised_copy_splits(int n, uint64_t seed, int ex, double tol, uint64_t *ab_splits, uint64_t *ba_splits) {
    gen_rng_t r;
    gen_seed(&r, seed);
    gen_soup_t A = grid(n, 0), B = grid(2 * n, 0);
    for (size_t k = 0; k < B.nv; k++) {
        B.v[3 * k] *= 0.5, B.v[3 * k + 1] *= 0.5;
        B.v[3 * k + 2] = ldexp((double)(gen_u64(&r) % 64), ex);
    }
    hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B);
    hd_surface_options_t o = options(tol, 1, 1);
    hd_enclosure_t ab, ba;
    CHECK_RC(hd_surface_hausdorff(&a, &b, &o, &ab, &ba, NULL), HD_OK);
    *ab_splits = ab.faces_split, *ba_splits = ba.faces_split;
    both_ways(&A, &B, tol, 8);
    gen_soup_free(&A), gen_soup_free(&B);
}

/* A flat grid over a copy split finer whose vertices are raised by seeded
 * amounts (bent at every edge): a sub-triangle over two of B's triangles
 * is bounded by both at once (the bent-pair bound), so the refinement
 * splits fewer times than with one triangle at a time along B's edges
 * - and the enclosure holds both ways. */
TEST(sub_triangles_over_bent_pairs_split_fewer_times) {
    uint64_t ab, ba;
    raised_copy_splits(4, 3838, -8, 1e-9, &ab, &ba);
    CONTEXT("seed 3838: %llu and %llu splits", (unsigned long long)ab, (unsigned long long)ba);
    CHECK(ab + ba < 270);
}

/* A flat grid against a copy split in four whose vertices are raised by
 * seeded amounts far below the tolerance (nearzero's case): each child of
 * a face's first split lies over one triangle of B, but its corners sit at
 * B's vertices, each nearest to any triangle around it; Tang's bound with
 * the triangle under the child's centroid settles it, so a face splits
 * about once - and the enclosure holds both ways. */
TEST(sub_triangles_over_one_triangle_of_a_finer_copy_settle_at_once) {
    uint64_t ab, ba;
    raised_copy_splits(8, 3839, -30, 1e-4, &ab, &ba);
    CONTEXT("seed 3839: %llu and %llu splits of 128 and 512 faces", (unsigned long long)ab, (unsigned long long)ba);
    CHECK(ab <= 2 * 128);
}
