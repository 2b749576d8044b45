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

/* ---- hd_surface_hausdorff's enclosures against the dense check ---- */

enum { MAX_V = 64, MAX_T = 64 };

typedef struct {
    double v[3 * MAX_V];
    uint64_t t[3 * MAX_T];
    size_t nv, nt;
} small_t;

static hd_mesh_t small_view(const small_t *m) {
    return view(m->v, m->nv, m->t, m->nt);
}

/* n triangles over nv random vertices of the unit cube; a corner repeats
 * now and then (a triangle collapsed to a segment or a point). */
static void soup(gen_rng_t *r, small_t *m, size_t nv, size_t nt) {
    m->nv = nv, m->nt = nt;
    for (size_t i = 0; i < 3 * nv; i++) m->v[i] = gen_unit(r);
    for (size_t k = 0; k < 3 * nt; k++) m->t[k] = gen_u64(r) % nv;
}

/* A closed surface: the octahedron with each face split in four, pushed
 * onto the sphere of radius `radius`, turned by `turn` radians about z. */
static void ball(small_t *m, double radius, double turn) {
    static const double o[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    static const int f[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    m->nv = 0, m->nt = 0;
    for (int k = 0; k < 8; k++) {
        double p[6][3];
        for (int c = 0; c < 3; c++) {
            for (int j = 0; j < 3; j++) p[j][c] = o[f[k][j]][c];
            p[3][c] = (p[0][c] + p[1][c]) / 2, p[4][c] = (p[1][c] + p[2][c]) / 2, p[5][c] = (p[2][c] + p[0][c]) / 2;
        }
        size_t base = m->nv;
        for (int j = 0; j < 6; j++) {
            double n = sqrt(p[j][0] * p[j][0] + p[j][1] * p[j][1] + p[j][2] * p[j][2]);
            double x = p[j][0] / n, y = p[j][1] / n, z = p[j][2] / n;
            m->v[3 * m->nv] = radius * (cos(turn) * x - sin(turn) * y);
            m->v[3 * m->nv + 1] = radius * (sin(turn) * x + cos(turn) * y);
            m->v[3 * m->nv + 2] = radius * z;
            m->nv++;
        }
        const int q[4][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
        for (int s = 0; s < 4; s++, m->nt++)
            for (int c = 0; c < 3; c++) m->t[3 * m->nt + c] = base + q[s][c];
    }
}

/* The pair of case `seed`: independent soups, a soup against its perturbed
 * copy, shared faces, exactly collinear and repeated corners, two balls. */
static void pair_of(uint64_t seed, small_t *a, small_t *b) {
    gen_rng_t r;
    gen_seed(&r, seed);
    size_t nt = 1 + gen_u64(&r) % 8, nv = 3 + gen_u64(&r) % 8;
    switch (seed % 5) {
    case 0:
        soup(&r, a, nv, nt), soup(&r, b, 3 + gen_u64(&r) % 8, 1 + gen_u64(&r) % 8);
        break;
    case 1:
        soup(&r, a, nv, nt), *b = *a;
        for (size_t i = 0; i < 3 * b->nv; i++) b->v[i] += 1e-3 * gen_normal(&r);
        break;
    case 2: /* B: half of A's faces, the same corners, and two of its own */
        soup(&r, a, nv, nt + 2), *b = *a;
        b->nt = (nt + 3) / 2;
        for (int k = 0; k < 2; k++, b->nt++)
            for (int c = 0; c < 3; c++) b->t[3 * b->nt + c] = gen_u64(&r) % nv;
        break;
    case 3: /* A gains a collinear triangle of exact points and a point */
        soup(&r, a, nv, nt), soup(&r, b, nv, nt);
        for (int j = 0; j < 3; j++) {
            a->v[3 * (a->nv + j)] = 0.25 * j, a->v[3 * (a->nv + j) + 1] = 0.5, a->v[3 * (a->nv + j) + 2] = 0.75;
            a->t[3 * a->nt + j] = a->nv + j, a->t[3 * (a->nt + 1) + j] = a->nv;
        }
        a->nv += 3, a->nt += 2;
        break;
    default:
        ball(a, 1, 0), ball(b, 1 + 0.1 * gen_unit(&r), gen_unit(&r));
        break;
    }
}

/* One direction's enclosure against the dense check of (X, Y). */
static void check_enclosure(const hd_enclosure_t *e, const hd_mesh_t *X, const hd_mesh_t *Y,
                            const m2m_dense_t *d) {
    hd_error_t err;
    CHECK(e->lower <= e->upper);
    CHECK(!e->converged || e->upper - e->lower <= e->tolerance);
    CHECK(d->largest <= e->upper);
    if (e->face_a == SIZE_MAX) { /* no witness: every face of X is one of Y's */
        CHECK_BITS(e->lower, 0.0);
        return;
    }
    CHECK_BITS(m2m_dense_point(e->point_a, Y, 1, &err), e->witness_distance);
    CHECK(m2m_dense_point(e->point_a, X, 1, &err) <= e->witness_error);
    CHECK(e->lower <= e->witness_distance);
    if (e->witness_error == 0) CHECK_BITS(e->lower, e->witness_distance);
}

static void same_enclosure(const hd_enclosure_t *x, const hd_enclosure_t *y) {
    CHECK_BITS(x->lower, y->lower);
    CHECK_BITS(x->upper, y->upper);
    CHECK_EQ(x->face_a, y->face_a);
}

/* The tolerances tried: 1e-3 of the diagonal must converge; the default
 * (1e-9) and 0 run with a cap on the splits per face (a maximiser on B's
 * medial axis needs about tolerance^-1/2 sub-triangles), and whether they
 * converged or not, the enclosure must hold. */
static const struct {
    double tolerance;
    int relative;
    uint64_t max_splits;
    const char *name;
} tolerances[] = {{1e-3, 1, 0, "1e-3 relative"}, {1e-9, 1, 2000, "1e-9 relative, 2000 splits a face"},
                  {0, 0, 200, "0, 200 splits a face"}};

TEST(enclosures_hold_against_the_dense_check) {
    for (uint64_t seed = 1; seed <= 40; seed++) {
        small_t a, b;
        pair_of(seed, &a, &b);
        hd_mesh_t A = small_view(&a), B = small_view(&b);
        m2m_dense_t dab, dba;
        hd_error_t err;
        CONTEXT("seed %llu: dense check", (unsigned long long)seed);
        CHECK_RC(m2m_dense_run(&A, &B, m2m_dense_level(A.n_triangles, 10000), 1, &dab, &err), HD_OK);
        CHECK_RC(m2m_dense_run(&B, &A, m2m_dense_level(B.n_triangles, 10000), 1, &dba, &err), HD_OK);
        for (size_t k = 0; k < sizeof tolerances / sizeof *tolerances; k++) {
            hd_enclosure_t first_ab, first_ba;
            for (int threads = 1; threads <= 3; threads += 2) {
                CONTEXT("seed %llu, tolerance %s, %d threads", (unsigned long long)seed, tolerances[k].name, threads);
                hd_surface_options_t opt;
                hd_surface_options_init(&opt);
                opt.tolerance = tolerances[k].tolerance, opt.relative = tolerances[k].relative;
                opt.max_splits = tolerances[k].max_splits, opt.threads = threads;
                hd_enclosure_t ab, ba;
                CHECK_RC(hd_surface_hausdorff(&A, &B, &opt, &ab, &ba, &err), HD_OK);
                check_enclosure(&ab, &A, &B, &dab);
                check_enclosure(&ba, &B, &A, &dba);
                if (!opt.max_splits) CHECK(ab.converged && ba.converged);
                if (threads == 1) first_ab = ab, first_ba = ba;
                else same_enclosure(&ab, &first_ab), same_enclosure(&ba, &first_ba);
            }
        }
    }
}

/* A surface against a point set: the points as triangles collapsed to
 * them give the dense check its mesh. */
TEST(surface_to_points_holds_against_the_dense_check) {
    for (uint64_t seed = 1; seed <= 40; seed++) {
        gen_rng_t r;
        gen_seed(&r, seed);
        small_t a, p;
        soup(&r, &a, 3 + gen_u64(&r) % 8, 1 + gen_u64(&r) % 8);
        soup(&r, &p, 1 + gen_u64(&r) % 20, 0);
        p.nt = p.nv;
        for (size_t i = 0; i < p.nv; i++) p.t[3 * i] = p.t[3 * i + 1] = p.t[3 * i + 2] = i;
        hd_mesh_t A = small_view(&a), P = small_view(&p);
        hd_points_t B = hd_points_f64(p.v, p.nv);
        m2m_dense_t d;
        hd_error_t err;
        CONTEXT("seed %llu", (unsigned long long)seed);
        CHECK_RC(m2m_dense_run(&A, &P, m2m_dense_level(A.n_triangles, 20000), 1, &d, &err), HD_OK);
        hd_surface_result_t exact;
        CHECK_RC(hd_mesh_distances(&B, &A, NULL, NULL, NULL, NULL, NULL, &exact, &err), HD_OK);
        for (int threads = 1; threads <= 3; threads += 2) {
            hd_surface_options_t opt;
            hd_surface_options_init(&opt);
            opt.tolerance = 1e-3, opt.threads = threads;
            hd_enclosure_t ab, ba;
            CHECK_RC(hd_surface_points_hausdorff(&A, &B, &opt, &ab, &ba, &err), HD_OK);
            check_enclosure(&ab, &A, &P, &d);
            CHECK(ab.converged);
            CHECK_BITS(ba.lower, exact.distance);
            CHECK_BITS(ba.upper, exact.distance);
        }
    }
}
