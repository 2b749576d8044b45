/*
 * m2m_dense_test -- the dense check of surface-to-surface enclosures
 * (tests/m2m_dense_check.h): first the check itself on pairs whose
 * Hausdorff distance is known in closed form (it must find the distance,
 * accept a true enclosure and refuse one whose upper bound is one double
 * too low), then hd_surface_hausdorff's enclosures on seeded random small
 * cases, both directions, at one thread and at three.
 */
#include "check.h"
#include "gen.h"
#include "m2m_dense_check.h"

#include <math.h>
#include <stdlib.h>

static hd_mesh_t view(const double *v, size_t nv, const uint64_t *t, size_t nt) {
    return (hd_mesh_t){hd_points_f64(v, nv), t, nt, HD_INDEX_U64};
}

static m2m_dense_t dense(const hd_mesh_t *A, const hd_mesh_t *B, int level) {
    m2m_dense_t r;
    hd_error_t err;
    CHECK_RC(m2m_dense_run(A, B, level, 1, &r, &err), HD_OK);
    return r;
}

/* A triangle against itself moved by 1/4 along its normal: every point is
 * 1/4 from the copy, so h = 0.25 exactly, found at the vertices. */
TEST(shifted_triangle_is_found_at_its_shift) {
    const double a[] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, b[] = {0, 0, 0.25, 1, 0, 0.25, 0, 1, 0.25};
    const uint64_t t[] = {0, 1, 2};
    hd_mesh_t A = view(a, 3, t, 1), B = view(b, 3, t, 1);
    m2m_dense_t r = dense(&A, &B, 8);
    CHECK_BITS(r.largest, 0.25);
    CHECK(r.largest <= 0.25);                      /* [0.25, 0.25] holds */
    CHECK(r.largest > nextafter(0.25, 0));         /* one double lower is refused */
    CHECK_EQ(r.samples, 3 + (9 * 10 / 2 - 3));
}

/* The unit square against the origin (a triangle collapsed to a point):
 * h = sqrt(2), at the far corner. */
TEST(square_against_a_point_is_its_far_corner) {
    const double a[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, b[] = {0, 0, 0};
    const uint64_t ta[] = {0, 1, 2, 0, 2, 3}, tb[] = {0, 0, 0};
    hd_mesh_t A = view(a, 4, ta, 2), B = view(b, 1, tb, 1);
    m2m_dense_t r = dense(&A, &B, 4);
    CHECK_BITS(r.largest, sqrt(2.0));
    CHECK_BITS(r.at[0], 1.0);
    CHECK_BITS(r.at[1], 1.0);
    CHECK(r.face == SIZE_MAX);
    CHECK(r.largest > nextafter(sqrt(2.0), 0));
}

/* The unit square against its four corners: h = sqrt(1/2) at the centre,
 * inside the square, where no vertex is: the grid finds it (from below:
 * a grid point's bound is taken down by rounding) and the vertices alone
 * do not. */
TEST(square_against_its_corners_is_found_inside) {
    const double a[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const uint64_t ta[] = {0, 1, 2, 0, 2, 3}, tb[] = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3};
    hd_mesh_t A = view(a, 4, ta, 2), B = view(a, 4, tb, 4);
    double h = sqrt(0.5);
    CHECK_BITS(dense(&A, &B, 1).largest, 0.0);
    m2m_dense_t r = dense(&A, &B, 2);
    CHECK(r.largest <= h);
    CHECK(r.largest >= nextafter(nextafter(nextafter(h, 0), 0), 0));
    CHECK(r.face != SIZE_MAX);
    CHECK(r.largest > 0.7); /* an upper bound of 0.7 is refused */
}

/* A tilted triangle against itself: h = 0.  Its grid points are computed
 * in doubles and fall off the plane by rounding; their bound subtracts
 * that offset, so the true enclosure [0, 0] is never refused. */
TEST(rounding_off_the_surface_never_refuses_a_true_bound) {
    gen_rng_t rng;
    for (uint64_t seed = 1; seed <= 200; seed++) {
        CONTEXT("seed %llu", (unsigned long long)seed);
        gen_seed(&rng, seed);
        double a[9];
        for (int k = 0; k < 9; k++) a[k] = gen_unit(&rng) * 3 - 1;
        const uint64_t t[] = {0, 1, 2};
        hd_mesh_t A = view(a, 3, t, 1);
        m2m_dense_t r = dense(&A, &A, 7);
        CHECK_BITS(r.largest, 0.0);
    }
}

TEST(the_level_fits_the_sample_budget) {
    CHECK_EQ(m2m_dense_level(1, 1), 1);
    CHECK_EQ(m2m_dense_level(1000, 50000), 10);
    CHECK_EQ(m2m_dense_level(0, 10), 1);
    CHECK_EQ(m2m_dense_level(1, (size_t)1e12), 4096);
}

TEST(a_witness_is_measured_exactly) {
    const double b[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const uint64_t t[] = {0, 1, 2};
    hd_mesh_t B = view(b, 3, t, 1);
    hd_error_t err;
    const double w[3] = {1, 1, 0.5};
    CHECK_BITS(m2m_dense_point(w, &B, 1, &err), sqrt(0.5 + 0.25));
}
