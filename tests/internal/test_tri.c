/*
 * test_tri.c -- the point-to-triangle kernel (src/mesh/): its fast path
 * gives the exact path's correctly rounded distance on every case, the two
 * agree with hand-computed answers, degenerate triangles are their hulls,
 * and coordinates outside the domain are refused.
 *
 * The families of cases are the shapes that make a floating-point kernel
 * go wrong: points on and near the face, the edges and the corners,
 * slivers and needles, collinear and coincident corners, repeated corners,
 * integer lattices (exact zeros in every test), coordinates from 1e-300 to
 * 1e150 and mixed within one case, and distances placed on, just above and
 * just below the midpoint between two doubles.  Each family prints how
 * often the exact path decided.  tests/tri_reference.py checks both paths
 * against exact rational arithmetic written independently, in Python.
 */
#include "check.h"
#include "gen.h"
#include "mesh/mesh.h"
#include "mesh/mesh_int.h"

#include <math.h>
#include <stdint.h>

typedef struct {
    double p[3], a[3], b[3], c[3];
} tri_case_t;

/* |x - y| without underflow or overflow at any scale of the domain. */
static double dist3(const double *x, const double *y) {
    double d[3], m = 0, s = 0;
    for (int i = 0; i < 3; i++) {
        d[i] = x[i] - y[i];
        m = fabs(d[i]) > m ? fabs(d[i]) : m;
    }
    if (m == 0) return 0;
    for (int i = 0; i < 3; i++) s += (d[i] / m) * (d[i] / m);
    return sqrt(s) * m;
}

static void nearest_ok(const tri_case_t *t, hd__tri_near_t *o) {
    CHECK_RC(hd__tri_nearest(t->p, t->a, t->b, t->c, o), HD_OK);
}

static void set3(double *v, double x, double y, double z) { v[0] = x; v[1] = y; v[2] = z; }

TEST(a_point_above_the_face_is_its_height_away) {
    tri_case_t t;
    hd__tri_near_t o;
    set3(t.a, 0, 0, 0); set3(t.b, 4, 0, 0); set3(t.c, 0, 4, 0); set3(t.p, 1, 1, 3);
    nearest_ok(&t, &o);
    CHECK_BITS(o.d, 3.0);
    CHECK_EQ(o.feature, HD__TRI_FACE);
    CHECK(fabs(o.point[0] - 1) < 1e-15 && fabs(o.point[1] - 1) < 1e-15 && o.point[2] == 0);
    CHECK(fabs(o.bary[0] - 0.5) < 1e-15 && fabs(o.bary[1] - 0.25) < 1e-15);
}

TEST(a_point_beyond_an_edge_or_a_corner_measures_to_it) {
    tri_case_t t;
    hd__tri_near_t o;
    set3(t.a, 0, 0, 0); set3(t.b, 4, 0, 0); set3(t.c, 0, 4, 0);
    set3(t.p, 2, -3, 4);                       /* beyond AB: (3, 4) away */
    nearest_ok(&t, &o);
    CHECK_BITS(o.d, 5.0);
    CHECK_EQ(o.feature, HD__TRI_EDGE_AB);
    CHECK(fabs(o.point[0] - 2) < 1e-15 && o.point[1] == 0);
    set3(t.p, -3, -4, 0);                      /* beyond A */
    nearest_ok(&t, &o);
    CHECK_BITS(o.d, 5.0);
    CHECK_EQ(o.feature, HD__TRI_VERTEX_A);
    set3(t.p, 3, 3, 0);                        /* beyond BC, in the plane */
    nearest_ok(&t, &o);
    CHECK_BITS(o.d, sqrt(2.0));
    CHECK_EQ(o.feature, HD__TRI_EDGE_BC);
}

TEST(a_point_on_the_triangle_is_at_zero) {
    tri_case_t t;
    hd__tri_near_t o;
    set3(t.a, 0, 0, 0); set3(t.b, 4, 0, 0); set3(t.c, 0, 4, 0);
    double on[4][3] = {{4, 0, 0}, {2, 0, 0}, {1, 1, 0}, {2, 2, 0}};
    for (int i = 0; i < 4; i++) {
        CONTEXT("point %d", i);
        set3(t.p, on[i][0], on[i][1], on[i][2]);
        nearest_ok(&t, &o);
        CHECK_BITS(o.d, 0.0);
    }
}

TEST(a_degenerate_triangle_is_its_segment_or_its_point) {
    tri_case_t t;
    hd__tri_near_t o;
    set3(t.a, 0, 0, 0); set3(t.b, 2, 0, 0); set3(t.c, 6, 0, 0);   /* collinear: the segment [0, 6] */
    set3(t.p, 5, 3, 4);
    nearest_ok(&t, &o);
    CHECK_BITS(o.d, 5.0);
    CHECK(o.feature != HD__TRI_FACE);
    set3(t.p, 9, 4, 0);                                          /* beyond its end c */
    nearest_ok(&t, &o);
    CHECK_BITS(o.d, 5.0);
    CHECK_EQ(o.feature, HD__TRI_VERTEX_C);
    set3(t.c, 2, 0, 0);                                          /* a repeated corner */
    set3(t.p, 1, 0, 7);
    nearest_ok(&t, &o);
    CHECK_BITS(o.d, 7.0);
    set3(t.a, 1, 1, 1); set3(t.b, 1, 1, 1); set3(t.c, 1, 1, 1);   /* one point */
    set3(t.p, 4, 5, 1);
    nearest_ok(&t, &o);
    CHECK_BITS(o.d, 5.0);
    CHECK(o.feature >= HD__TRI_VERTEX_A);
}

TEST(coordinates_outside_the_domain_are_refused) {
    tri_case_t t;
    hd__tri_near_t o;
    set3(t.a, 0, 0, 0); set3(t.b, 1, 0, 0); set3(t.c, 0, 1, 0); set3(t.p, 0, 0, 1);
    double bad[3] = {NAN, INFINITY, 0x1p512};
    for (int i = 0; i < 3; i++) {
        CONTEXT("bad value %g", bad[i]);
        t.b[1] = bad[i];
        CHECK_RC(hd__tri_nearest(t.p, t.a, t.b, t.c, &o), HD_ERANGE);
        CHECK_RC(hd__tri_nearest_exact(t.p, t.a, t.b, t.c, &o), HD_ERANGE);
    }
}

/* ---- families ------------------------------------------------------------ */

enum {
    F_RANDOM, F_NEAR_FACE, F_NEAR_EDGE, F_NEAR_VERTEX, F_SLIVER, F_NEEDLE, F_COLLINEAR,
    F_COINCIDENT, F_REPEATED, F_LATTICE, F_SCALES, F_MIXED, F_MIDPOINT, F_COUNT
};
static const char *const family_name[F_COUNT] = {
    "random", "near face", "near edge", "near vertex", "sliver", "needle", "collinear",
    "coincident", "repeated corner", "lattice", "scales 1e-300..1e150", "mixed scales",
    "midpoints",
};

static void rand3(gen_rng_t *g, double *v) {
    for (int i = 0; i < 3; i++) v[i] = gen_unit(g) * 2 - 1;
}

/* x + s y */
static void axpy(double *r, const double *x, double s, const double *y) {
    for (int i = 0; i < 3; i++) r[i] = x[i] + s * y[i];
}

/* A distance on (or next to) the midpoint between two doubles: a
 * Pythagorean triple (u^2 - v^2, 2uv, u^2 + v^2) whose hypotenuse has 54
 * significant bits with the last one set, so sqrt(dx^2 + dy^2) is exactly
 * a midpoint; nudging dy by an ulp puts it just beside. */
static void midpoint_case(gen_rng_t *g, tri_case_t *t) {
    uint64_t u, v, c;
    do {
        u = (UINT64_C(1) << 26) + (gen_u64(g) >> 40);
        v = u - 1 - (gen_u64(g) >> 44);
        c = u * u + v * v;
    } while (!(c >> 53) || (c >> 54) || !(c & 1) || (2 * u * v) >> 53 || (u * u - v * v) >> 53);
    double dx = (double)(u * u - v * v), dy = (double)(2 * u * v);
    int nudge = (int)(gen_u64(g) % 3) - 1;
    if (nudge) dy = nextafter(dy, nudge > 0 ? INFINITY : 0);
    double scale = ldexp(1, (int)(gen_u64(g) % 200) - 100);
    /* a at the origin, b and c behind it: p = (dx, dy, 0) is in a's region. */
    set3(t->a, 0, 0, 0);
    set3(t->b, -1 * scale, -2 * scale, -3 * scale);
    set3(t->c, -2 * scale, -1 * scale, -5 * scale);
    set3(t->p, dx * scale * 0x1p-40, dy * scale * 0x1p-40, 0);
}

static void make_case(gen_rng_t *g, int family, tri_case_t *t) {
    double e1[3], e2[3], n[3];
    rand3(g, t->a); rand3(g, t->b); rand3(g, t->c); rand3(g, t->p);
    for (int i = 0; i < 3; i++) { e1[i] = t->b[i] - t->a[i]; e2[i] = t->c[i] - t->a[i]; }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double h = ldexp(1, -(int)(gen_u64(g) % 50));
    double s = gen_unit(g), r = gen_unit(g) * (1 - s);
    switch (family) {
    case F_NEAR_FACE:
        axpy(t->p, t->a, s, e1); axpy(t->p, t->p, r, e2); axpy(t->p, t->p, h * (gen_unit(g) - 0.5), n);
        break;
    case F_NEAR_EDGE:
        axpy(t->p, t->a, s, e1); axpy(t->p, t->p, h * (gen_unit(g) - 0.5), n);
        axpy(t->p, t->p, h * (gen_unit(g) - 0.5), e2);
        break;
    case F_NEAR_VERTEX:
        for (int i = 0; i < 3; i++) t->p[i] = t->b[i] + h * (gen_unit(g) - 0.5);
        break;
    case F_SLIVER:
        axpy(t->c, t->a, 0.5, e1); axpy(t->c, t->c, h * 0x1p-10, n);
        break;
    case F_NEEDLE:
        for (int i = 0; i < 3; i++) t->b[i] = t->a[i] + h * 0x1p-10 * (gen_unit(g) - 0.5);
        break;
    case F_COLLINEAR:
        for (int i = 0; i < 3; i++) {
            t->a[i] = floor(t->a[i] * 64); t->b[i] = floor(t->b[i] * 64);
            t->c[i] = 2 * t->b[i] - t->a[i];      /* exactly on the line */
        }
        break;
    case F_COINCIDENT:
        for (int i = 0; i < 3; i++) t->c[i] = t->b[i] = t->a[i];
        break;
    case F_REPEATED:
        for (int i = 0; i < 3; i++) t->c[i] = t->a[i];
        break;
    case F_LATTICE:
        for (int i = 0; i < 3; i++) {
            t->a[i] = floor(t->a[i] * 3); t->b[i] = floor(t->b[i] * 3);
            t->c[i] = floor(t->c[i] * 3); t->p[i] = floor(t->p[i] * 3);
        }
        break;
    case F_SCALES: {
        double k = pow(10, -300 + (double)(gen_u64(g) % 451));
        for (int i = 0; i < 3; i++) { t->a[i] *= k; t->b[i] *= k; t->c[i] *= k; t->p[i] *= k; }
        break;
    }
    case F_MIXED:
        for (int i = 0; i < 3; i++) {
            t->a[i] = ldexp(t->a[i], (int)(gen_u64(g) % 120) - 60);
            t->p[i] = ldexp(t->p[i], (int)(gen_u64(g) % 120) - 60);
        }
        break;
    case F_MIDPOINT:
        midpoint_case(g, t);
        break;
    }
}

TEST(the_fast_path_gives_the_exact_paths_distance) {
    const long per_family = 20000;
    for (int f = 0; f < F_COUNT; f++) {
        gen_rng_t g;
        uint64_t seed = 1000 + (uint64_t)f;
        gen_seed(&g, seed);
        long exact = 0;
        for (long i = 0; i < per_family && !hdt_failed(); i++) {
            tri_case_t t;
            hd__tri_near_t fast, ref;
            make_case(&g, f, &t);
            CONTEXT("family %s, seed %llu, case %ld", family_name[f], (unsigned long long)seed, i);
            CHECK_RC(hd__tri_nearest(t.p, t.a, t.b, t.c, &fast), HD_OK);
            CHECK_RC(hd__tri_nearest_exact(t.p, t.a, t.b, t.c, &ref), HD_OK);
            CHECK_BITS(fast.d, ref.d);
            /* The closest point is the feature's, within rounding of the distance. */
            double slack = 1e-9 * (ref.d + dist3(t.a, t.b) + dist3(t.a, t.c) + dist3(t.a, t.p));
            CHECK(fabs(dist3(t.p, fast.point) - ref.d) <= slack);
            if (hdt_failed())
                printf("p %a %a %a\na %a %a %a\nb %a %a %a\nc %a %a %a\n", t.p[0], t.p[1], t.p[2],
                       t.a[0], t.a[1], t.a[2], t.b[0], t.b[1], t.b[2], t.c[0], t.c[1], t.c[2]);
            exact += fast.exact;
        }
        printf("  %-22s exact path decided %5.2f %% of %ld\n", family_name[f],
               100.0 * (double)exact / (double)per_family, per_family);
    }
}

TEST(dekkers_product_and_the_fused_multiply_add_give_the_same_bits) {
    /* On a CPU without fused multiply-add both calls take Dekker's path. */
    for (int f = 0; f < F_COUNT; f++) {
        gen_rng_t g;
        uint64_t seed = 5000 + (uint64_t)f;
        gen_seed(&g, seed);
        for (long i = 0; i < 5000 && !hdt_failed(); i++) {
            tri_case_t t;
            hd__tri_near_t x, y;
            make_case(&g, f, &t);
            CONTEXT("family %s, seed %llu, case %ld", family_name[f], (unsigned long long)seed, i);
            CHECK_RC(hd__tri_nearest_variant(t.p, t.a, t.b, t.c, &x, 0), HD_OK);
            CHECK_RC(hd__tri_nearest_variant(t.p, t.a, t.b, t.c, &y, 1), HD_OK);
            CHECK_BITS(x.d, y.d);
            CHECK_EQ(x.exact, y.exact);
            CHECK_EQ(x.feature, y.feature);
        }
    }
}

TEST(every_feature_is_reached_and_sums_its_weights_to_one) {
    gen_rng_t g;
    gen_seed(&g, 7);
    long seen[7] = {0};
    for (long i = 0; i < 20000; i++) {
        tri_case_t t;
        hd__tri_near_t o;
        make_case(&g, F_RANDOM, &t);
        nearest_ok(&t, &o);
        seen[o.feature]++;
        CHECK(fabs(o.bary[0] + o.bary[1] + o.bary[2] - 1) < 1e-12);
    }
    for (int f = 0; f < 7; f++) {
        CONTEXT("feature %d", f);
        CHECK(seen[f] > 100);
    }
}

/* The face is decided first only when the projection is certainly inside
 * (tri.c, face_first): a point whose projection lies within rounding of an
 * edge, on either side, and whose height above the plane is as small as
 * its offset, has a distance that differs from the height alone when it
 * is beyond the edge; every such point gets the exact path's distance. */
TEST(a_point_within_rounding_of_an_edge_is_not_taken_for_the_face) {
    gen_rng_t g;
    uint64_t seed = 9100;
    gen_seed(&g, seed);
    long face = 0;
    for (long i = 0; i < 20000 && !hdt_failed(); i++) {
        tri_case_t t;
        hd__tri_near_t fast, ref;
        double ab[3], out[3], w = gen_unit(&g), off = ldexp(gen_unit(&g) - 0.5, -52);
        set3(t.a, gen_unit(&g), gen_unit(&g), 0);
        set3(t.b, gen_unit(&g), gen_unit(&g), 0);
        set3(t.c, gen_unit(&g), gen_unit(&g), 0);
        for (int k = 0; k < 3; k++) ab[k] = t.b[k] - t.a[k];
        set3(out, ab[1], -ab[0], 0);   /* in the plane, across AB */
        axpy(t.p, t.a, w, ab);
        axpy(t.p, t.p, off, out);
        t.p[2] = ldexp(gen_unit(&g), -54);
        CONTEXT("seed %llu, case %ld", (unsigned long long)seed, i);
        CHECK_RC(hd__tri_nearest(t.p, t.a, t.b, t.c, &fast), HD_OK);
        CHECK_RC(hd__tri_nearest_exact(t.p, t.a, t.b, t.c, &ref), HD_OK);
        CHECK_BITS(fast.d, ref.d);
        face += fast.feature == HD__TRI_FACE;
    }
    printf("  the face decided for %ld of 20000 points at an edge\n", face);
}

/* ---- bounds from plain doubles -------------------------------------------- */

/* lo2 <= t^2 <= hi2 for the true distance t, seen through the correctly
 * rounded d: t lies within half a gap of d, so sqrt(lo2) (correctly rounded,
 * monotone) is at most the double above d, and sqrt(hi2) at least the one
 * below.  (tests/tri_reference.py checks lo2 <= t^2 <= hi2 exactly.) */
static int bounds_hold(double lo2, double hi2, double d) {
    return lo2 >= 0 && lo2 <= hi2 && sqrt(lo2) <= nextafter(d, INFINITY) &&
           sqrt(hi2) >= nextafter(d, 0);
}

TEST(the_bounds_contain_the_distance_on_every_family) {
    const long per_family = 20000;
    for (int f = 0; f < F_COUNT; f++) {
        gen_rng_t g;
        uint64_t seed = 2000 + (uint64_t)f;
        gen_seed(&g, seed);
        long tight = 0;
        for (long i = 0; i < per_family && !hdt_failed(); i++) {
            tri_case_t t;
            hd__tri_near_t o;
            double lo2, hi2;
            make_case(&g, f, &t);
            CONTEXT("family %s, seed %llu, case %ld", family_name[f], (unsigned long long)seed, i);
            CHECK_RC(hd__tri_nearest(t.p, t.a, t.b, t.c, &o), HD_OK);
            hd__tri_bounds(t.p, t.a, t.b, t.c, &lo2, &hi2);
            CHECK(bounds_hold(lo2, hi2, o.d));
            tight += hi2 <= lo2 * (1 + 0x1p-40);
        }
        printf("  %-22s bounds within 2^-40 relatively: %5.2f %% of %ld\n", family_name[f],
               100.0 * (double)tight / (double)per_family, per_family);
    }
}

TEST(the_bounds_are_tight_off_the_boundaries) {
    /* Random points and triangles, and points at 1e-3 of the triangle's
     * size from its face: both bounds within 2^-30 of each other on 97 % or
     * more (the plain-double errors are u times the size over the distance,
     * more on the random slivers). */
    for (int near = 0; near <= 1; near++) {
        gen_rng_t g;
        gen_seed(&g, 3000 + (uint64_t)near);
        long tight = 0, n = 20000;
        for (long i = 0; i < n; i++) {
            tri_case_t t;
            double lo2, hi2;
            make_case(&g, F_RANDOM, &t);
            if (near) {
                double e1[3], e2[3], nv[3], s = gen_unit(&g), r = gen_unit(&g) * (1 - s);
                for (int k = 0; k < 3; k++) { e1[k] = t.b[k] - t.a[k]; e2[k] = t.c[k] - t.a[k]; }
                nv[0] = e1[1] * e2[2] - e1[2] * e2[1];
                nv[1] = e1[2] * e2[0] - e1[0] * e2[2];
                nv[2] = e1[0] * e2[1] - e1[1] * e2[0];
                axpy(t.p, t.a, s, e1); axpy(t.p, t.p, r, e2);
                axpy(t.p, t.p, 1e-3 * (gen_unit(&g) - 0.5), nv);
            }
            hd__tri_bounds(t.p, t.a, t.b, t.c, &lo2, &hi2);
            tight += hi2 <= lo2 * (1 + 0x1p-30);
        }
        CONTEXT("%s: %ld of %ld tight", near ? "near the face" : "random", tight, n);
        CHECK(tight >= n * 97 / 100);
    }
}

TEST(a_prepared_triangle_gives_the_same_bounds) {
    for (int f = 0; f < F_COUNT; f++) {
        gen_rng_t g;
        uint64_t seed = 4000 + (uint64_t)f;
        gen_seed(&g, seed);
        for (long i = 0; i < 2000 && !hdt_failed(); i++) {
            tri_case_t t;
            hd__tri_prep_t tp;
            double lo2, hi2, plo2, phi2;
            make_case(&g, f, &t);
            CONTEXT("family %s, seed %llu, case %ld", family_name[f], (unsigned long long)seed, i);
            hd__tri_bounds(t.p, t.a, t.b, t.c, &lo2, &hi2);
            hd__tri_prep(t.a, t.b, t.c, &tp);
            hd__tri_bounds_prep(t.p, &tp, &plo2, &phi2);
            CHECK_BITS(plo2, lo2);
            CHECK_BITS(phi2, hi2);
        }
    }
}

/* hd__tri_bounds_below: hd__tri_bounds_prep's lo2 and hi2 whenever its
 * lo2 <= skip; above skip a lower bound still above skip and at most
 * hd__tri_bounds_prep's, the upper bound possibly left infinite, as it is
 * for a point in a corner's region (the corners' lower bound alone
 * exceeds skip, the feet on the edges are not formed) and for a point
 * whose distance to the plane alone exceeds skip (nothing else formed). */
TEST(bounds_below_a_threshold_keep_the_lower_bound) {
    for (int f = 0; f < F_COUNT; f++) {
        gen_rng_t g;
        uint64_t seed = 4500 + (uint64_t)f;
        gen_seed(&g, seed);
        for (long i = 0; i < 2000 && !hdt_failed(); i++) {
            tri_case_t t;
            hd__tri_prep_t tp;
            double lo2, hi2, blo2, bhi2;
            make_case(&g, f, &t);
            hd__tri_prep(t.a, t.b, t.c, &tp);
            hd__tri_bounds_prep(t.p, &tp, &lo2, &hi2);
            const double skips[] = {0, lo2 / 2, lo2, nextafter(lo2, INFINITY), hi2, INFINITY};
            for (int k = 0; k < 6; k++) {
                CONTEXT("family %s, seed %llu, case %ld, skip %d", family_name[f], (unsigned long long)seed, i, k);
                hd__tri_bounds_below(t.p, &tp, skips[k], &blo2, &bhi2);
                if (lo2 <= skips[k]) {
                    CHECK_BITS(blo2, lo2);
                    CHECK_BITS(bhi2, hi2);
                } else {
                    CHECK(blo2 > skips[k] && blo2 <= lo2);
                    CHECK(bhi2 >= hi2);
                }
            }
        }
    }
    tri_case_t t;
    hd__tri_prep_t tp;
    double lo2, hi2;
    set3(t.a, 0, 0, 0); set3(t.b, 4, 0, 0); set3(t.c, 0, 4, 0);
    set3(t.p, -3, -4, 0);                          /* beyond A: 25 */
    hd__tri_prep(t.a, t.b, t.c, &tp);
    hd__tri_bounds_below(t.p, &tp, 20, &lo2, &hi2);
    CHECK(lo2 > 20 && lo2 <= 25);
    CHECK(hi2 == INFINITY);
    hd__tri_bounds_below(t.p, &tp, 30, &lo2, &hi2);
    CHECK(lo2 <= 25 && hi2 >= 25 && hi2 < 26);
    set3(t.p, 1, 1, 5);                            /* above the face: 25 */
    hd__tri_bounds_below(t.p, &tp, 20, &lo2, &hi2);
    CHECK(lo2 > 20 && lo2 <= 25);
    CHECK(hi2 == INFINITY);                        /* the plane's term decided */
    set3(t.p, 3, 3, 3);                            /* beyond BC: 9 from the plane, 11 in all */
    hd__tri_bounds_below(t.p, &tp, 10, &lo2, &hi2);
    CHECK(lo2 > 10 && lo2 <= 11);
    CHECK(hi2 == INFINITY);                        /* the edges' term decided */
}

TEST(the_bounds_of_hand_cases) {
    tri_case_t t;
    double lo2, hi2;
    set3(t.a, 0, 0, 0); set3(t.b, 4, 0, 0); set3(t.c, 0, 4, 0);
    set3(t.p, 1, 1, 3);                            /* above the face: 9 */
    hd__tri_bounds(t.p, t.a, t.b, t.c, &lo2, &hi2);
    CHECK(lo2 <= 9 && hi2 >= 9 && hi2 - lo2 < 1e-12);
    set3(t.p, 2, -3, 4);                           /* beyond AB: 25 */
    hd__tri_bounds(t.p, t.a, t.b, t.c, &lo2, &hi2);
    CHECK(lo2 <= 25 && hi2 >= 25 && hi2 - lo2 < 1e-12);
    set3(t.p, -3, -4, 0);                          /* beyond A: 25, lo2 from the edge lines */
    hd__tri_bounds(t.p, t.a, t.b, t.c, &lo2, &hi2);
    CHECK(lo2 <= 25 && hi2 >= 25 && lo2 >= 16 && hi2 - 25 < 1e-12);
    set3(t.c, 8, 0, 0);                            /* collinear: the segment [0, 8] */
    set3(t.p, 5, 3, 4);
    hd__tri_bounds(t.p, t.a, t.b, t.c, &lo2, &hi2);
    CHECK(lo2 == 0 && hi2 >= 25 && hi2 - 25 < 1e-12);
    t.c[0] = NAN;                                  /* outside the domain: no information */
    hd__tri_bounds(t.p, t.a, t.b, t.c, &lo2, &hi2);
    CHECK(lo2 == 0 && hi2 == INFINITY);
    set3(t.c, 0x1p400, 0x1p-1070, 0);              /* scaling would not be exact */
    hd__tri_bounds(t.p, t.a, t.b, t.c, &lo2, &hi2);
    CHECK(lo2 == 0 && hi2 == INFINITY);
    set3(t.a, 0, 0, 0x1p300); set3(t.b, 0x1p300, 0, 0x1p300); set3(t.c, 0, 0x1p300, 0x1p300);
    set3(t.p, 0x1p298, 0x1p298, 0);                /* 2^300 below the face: scaled */
    hd__tri_bounds(t.p, t.a, t.b, t.c, &lo2, &hi2);
    CHECK(lo2 <= 0x1p600 && hi2 >= 0x1p600 && hi2 <= 0x1p600 * (1 + 0x1p-40) &&
          lo2 >= 0x1p600 * (1 - 0x1p-40));
}
