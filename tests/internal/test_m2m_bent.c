/*
 * test_m2m_bent.c -- the bound for a sub-triangle over a bent pair of
 * triangles (hd__m2m_bent_bound, src/mesh/m2m.c): never below the largest
 * value over the sub-triangle of the smaller of the two interpolated
 * corner bounds (computed in long double from the corners and the
 * crossings on the edges), nor below any sampled distance to the nearer of
 * two triangles folded at many angles, at tiny and huge scales; and close
 * to that largest value, so that it is the bound and not a weaker one.
 */
#include "check.h"
#include "gen.h"
#include "mesh/mesh.h"

#include <math.h>

#ifdef __SANITIZE_ADDRESS__
#define SCALE 4
#else
#define SCALE 1
#endif

/* The largest over the triangle of min(A(w), B(w)) for A, B the affine
 * functions with corner values a, b: at a corner or where A = B crosses an
 * edge (min is concave). */
static long double true_max(const double *a, const double *b) {
    long double m = 0;
    for (int k = 0; k < 3; k++) {
        int l = (k + 1) % 3;
        m = fmaxl(m, fminl(a[k], b[k]));
        long double f0 = (long double)a[k] - b[k], f1 = (long double)a[l] - b[l];
        if ((f0 < 0 && f1 > 0) || (f0 > 0 && f1 < 0)) {
            long double t = f0 / (f0 - f1);
            m = fmaxl(m, a[k] + t * ((long double)a[l] - a[k]));
        }
    }
    return m;
}

TEST(bent_bound_is_never_below_the_largest_smaller_interpolant) {
    gen_rng_t r;
    gen_seed(&r, 38);
    int below_tang = 0;
    for (int it = 0; it < 200000 / SCALE; it++) {
        double a[3], b[3], s = ldexp(1, (int)(gen_u64(&r) % 1200) - 600);
        for (int k = 0; k < 3; k++) a[k] = s * gen_unit(&r), b[k] = s * gen_unit(&r);
        double U = hd__m2m_bent_bound(a, b, INFINITY);
        long double t = true_max(a, b);
        if (!((long double)U >= t && U <= t * (1 + 0x1p-45L) + 0x1p-1070L)) {
            CONTEXT("seed 38 case %d: a %.17g %.17g %.17g b %.17g %.17g %.17g bound %.17g true %.21Lg", it, a[0],
                    a[1], a[2], b[0], b[1], b[2], U, t);
            CHECK((long double)U >= t);
            CHECK(U <= t * (1 + 0x1p-45L) + 0x1p-1070L);
            return;
        }
        double tang = fmin(fmax(a[0], fmax(a[1], a[2])), fmax(b[0], fmax(b[1], b[2])));
        below_tang += U < tang * 0.99;
    }
    CHECK(below_tang > 1000); /* the pair bound is tighter than one triangle's */
}

/* d(p, t) rounded up: the kernel's correctly rounded distance, one up. */
static double dist_up(const double *p, double t[3][3]) {
    hd__tri_near_t n;
    hd__tri_nearest(p, t[0], t[1], t[2], &n);
    return nextafter(n.d, INFINITY);
}

TEST(bent_bound_holds_over_sampled_folded_pairs) {
    gen_rng_t r;
    gen_seed(&r, 380);
    for (int it = 0; it < 400 / SCALE; it++) {
        double s = ldexp(1, (int)(gen_u64(&r) % 400) - 200), ang = 0.02 + 3.1 * gen_unit(&r);
        /* t1 in z = 0, t2 folded about the x axis by ang; they share the
         * edge from (-1, 0, 0) to (1, 0, 0). */
        double t1[3][3] = {{-s, 0, 0}, {s, 0, 0}, {0, -s, 0}};
        double t2[3][3] = {{-s, 0, 0}, {s, 0, 0}, {0, s * cos(ang), s * sin(ang)}};
        double v[3][3];
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++) v[k][d] = s * (gen_unit(&r) - 0.5) * (d == 2 ? 1 : 1.6);
        double a[3], b[3];
        for (int k = 0; k < 3; k++) a[k] = dist_up(v[k], t1), b[k] = dist_up(v[k], t2);
        double U = hd__m2m_bent_bound(a, b, INFINITY);
        const int n = 48;
        for (int i = 0; i <= n; i++)
            for (int j = 0; i + j <= n; j++) {
                double w1 = (double)i / n, w2 = (double)j / n, w0 = 1 - w1 - w2, p[3];
                for (int d = 0; d < 3; d++) p[d] = w0 * v[0][d] + w1 * v[1][d] + w2 * v[2][d];
                hd__tri_near_t n1, n2;
                hd__tri_nearest(p, t1[0], t1[1], t1[2], &n1);
                hd__tri_nearest(p, t2[0], t2[1], t2[2], &n2);
                /* the sample is within a few ulps of the hull of v: allow
                 * for that, relative to the scale */
                double m = fmin(n1.d, n2.d) - 0x1p-48 * s;
                if (!(m <= U)) {
                    CONTEXT("seed 380 case %d: scale %g angle %g sample (%d, %d) min %.17g bound %.17g", it, s, ang,
                            i, j, m, U);
                    CHECK(m <= U);
                    return;
                }
            }
    }
}
