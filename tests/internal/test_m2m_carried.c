/*
 * test_m2m_carried.c -- the bound carried from an anchor to a point
 * (hd__m2m_carried_bound, src/mesh/m2m.c): never below hi + |p - a|
 * (computed in long double, whose error is far below a double's rounding),
 * at every scale down to distances whose squares are subnormal; never
 * below a point's distance to a triangle when hi bounds the anchor's; and
 * within a few ulps of hi + |p - a|, so that it is that bound and not a
 * weaker one.
 */
#include "check.h"
#include "gen.h"
#include "mesh/mesh.h"

#include <math.h>

/* hi + |p - a| in long double (64-bit significands: a relative error of a
 * few 2^-64, against 2^-53 for a double's rounding). */
static long double exact_sum(double hi, const double *a, const double *p) {
    long double d2 = 0;
    for (int d = 0; d < 3; d++) {
        long double x = (long double)p[d] - a[d];
        d2 += x * x;
    }
    return hi + sqrtl(d2);
}

TEST(carried_bound_is_never_below_the_anchor_bound_plus_the_distance) {
    gen_rng_t r;
    gen_seed(&r, 3838);
    int tight = 0;
    for (int it = 0; it < 2000000; it++) {
        /* scales from 2^-560 (squares subnormal) to 2^400 */
        double s = ldexp(1, (int)(gen_u64(&r) % 960) - 560), a[3], p[3];
        for (int d = 0; d < 3; d++) {
            a[d] = s * (gen_unit(&r) - 0.5) * 16;
            /* near a (the differences exact), or anywhere (rounded) */
            p[d] = it % 2 ? a[d] + s * (gen_unit(&r) - 0.5) : s * (gen_unit(&r) - 0.5) * 16;
        }
        double hi = it % 4 ? s * gen_unit(&r) : 0;
        double g = hd__m2m_carried_bound(hi, a, p);
        long double t = exact_sum(hi, a, p);
        if (!((long double)g >= t * (1 - 0x1p-61L))) {
            CONTEXT("seed 3838 case %d: hi %.17g a %.17g %.17g %.17g p %.17g %.17g %.17g bound %.17g true %.21Lg", it,
                    hi, a[0], a[1], a[2], p[0], p[1], p[2], g, t);
            CHECK((long double)g >= t * (1 - 0x1p-61L));
            return;
        }
        if (s >= 0x1p-400) tight += g <= t * (1 + 0x1p-48L);
    }
    CHECK(tight > 1500000); /* not a looser bound than hi + |p - a| */
}

/* d(p, t): the kernel's correctly rounded distance. */
static double dist(const double *p, double t[3][3]) {
    hd__tri_near_t n;
    hd__tri_nearest(p, t[0], t[1], t[2], &n);
    return n.d;
}

TEST(carried_bound_holds_for_points_near_a_triangle) {
    gen_rng_t r;
    gen_seed(&r, 3839);
    for (int it = 0; it < 20000; it++) {
        double s = ldexp(1, (int)(gen_u64(&r) % 200) - 100), t[3][3], a[3], p[3];
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++) t[k][d] = s * gen_unit(&r);
        for (int d = 0; d < 3; d++) {
            a[d] = s * (gen_unit(&r) * 2 - 0.5);
            p[d] = a[d] + s * (gen_unit(&r) - 0.5) * 0.1;
        }
        double hi = nextafter(dist(a, t), INFINITY), g = hd__m2m_carried_bound(hi, a, p), dp = dist(p, t);
        if (!(dp <= g)) {
            CONTEXT("seed 3839 case %d: scale %g d(a, t) <= %.17g d(p, t) %.17g bound %.17g", it, s, hi, dp, g);
            CHECK(dp <= g);
            return;
        }
    }
}

TEST(carried_bound_is_infinite_for_values_that_are_not_finite) {
    double a[3] = {0, 0, 0}, p[3] = {1, 0, 0}, q[3] = {NAN, 0, 0};
    CHECK(isinf(hd__m2m_carried_bound(INFINITY, a, p)));
    CHECK(isinf(hd__m2m_carried_bound(NAN, a, p)));
    CHECK(isinf(hd__m2m_carried_bound(1, a, q)));
    CHECK(hd__m2m_carried_bound(1, a, p) >= 2);
}
