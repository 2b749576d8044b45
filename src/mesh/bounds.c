/*
 * bounds.c -- rigorous bounds lo2 <= d^2 <= hi2 on the squared distance from
 * a point to a triangle, from plain doubles (mesh.h), for a search to
 * discard triangles without the kernel.  Nothing here decides a sign: every
 * bound holds for every triangle, degenerate ones too.
 *
 * Geometry.  d^2 = h^2 + delta^2 for h the distance from p to the plane of a
 * non-degenerate triangle (h^2 = g^2 / M, n = AB x AC, g = n . AP, M = |n|^2)
 * and delta the distance, in the plane, from p's projection p' to the
 * triangle.  The triangle lies inside each edge's line, on the side of the
 * opposite corner: with L_C = n . (AB x AP) = (n x AB) . AP,
 * L_B = n . (AP x AC) = (AC x n) . AP and L_A = M - L_B - L_C (the three sum
 * to |n|^2), p' is L_X / (|n| |e|) inside the line of the edge e opposite X.
 * So delta >= max(0, -L_X) / (|n| |e|) for every edge, delta = 0 when no L_X
 * is negative, and d = |XP| when XY . XP <= 0 and XZ . XP <= 0 (then
 * (x - X) . XP <= 0 for every point x of the triangle, so
 * |p - x|^2 >= |XP|^2); that gives lo2.  hi2 is h^2 when every L_X is
 * certainly >= 0, else the least squared distance from p to the feet of p
 * on the edges it may lie beyond, their parameters clamped to [0, 1]:
 * points of the triangle whatever the rounding, and in an edge's or a
 * corner's region the closest point.
 *
 * Errors.  A polynomial evaluated through k roundings on every path (the
 * difference of two coordinates counted) is within gamma_k P of the exact
 * (Higham, Accuracy and Stability of Numerical Algorithms, 3.1), P its
 * permanent from the exact differences' magnitudes; computing P from the
 * rounded ones loses at most a factor (1 - u)^-(2k), so (k + 2) u P in
 * doubles bounds the error: k = 3 for n, 4 for the corner tests.  A product
 * of computed factors x (within e_x) and y (within e_y, a rounded
 * difference: 1.01 u |y|) through k roundings is within
 * gamma_k |x| |y| + e_x |y| + |x| e_y + e_x e_y of the exact: so the edge
 * normals n x AB and AC x n are within (1.01 e_n + 3.1 u |n|) |AB| per
 * product, and a dot product w . AP of a computed w with a point's AP within
 * sum |AP_i| (1.01 e_w,i + 4.1 u |w_i|): the weights (1.01 e + 4.1 u |w|)
 * are the triangle's, so a point pays three products and two sums for each
 * bound.  M = sum n_i^2 is within sum (2 |n_i| + e_i) e_i + 4u M of the
 * computed sum, an edge's |e|^2 below (1 - u)^-5 times its computed value
 * (8u is used), and a foot's component r = XP - tau XY within
 * 2u (|r| + |XP| + 2 |tau XY|).  A reciprocal rounded down is
 * fl(fl(1 / fl(x (1 + 2u))) (1 - 2u)) <= 1 / x, and up symmetrically.
 * Every bound is multiplied by 1 + 2^-40, which covers the roundings of its
 * own formula.  The results are moved outward by 2^-48 relatively and
 * 2^-1060 absolutely, which covers the roundings of the final formulas,
 * including a subnormal result: reciprocals are rounded outward, a squared
 * ratio x^2 / y is formed as x (x r) with r such a reciprocal of y, a
 * lower bound drops a term whose factors are not normal (their rounding
 * would not be relative), and an upper bound adds 2^-1000 to x r.
 * Coordinates below 2^100 in magnitude keep every factor a rounding error
 * is multiplied by under 2^306, so the 2^-700 every error bound carries
 * covers what underflow could lose.  Other coordinates are first scaled by
 * a power of two (the kernel's step 1); where that would not be exact, or
 * beyond the domain, the bounds are [0, infinity].
 */
#include <math.h>
#include <string.h>

#include "mesh/mesh_int.h"

#define U 0x1p-53
#define SLACK (1 + 0x1p-40)
#define TB 0x1p-700
#define OUT_LO (1 - 0x1p-48)
#define OUT_HI (1 + 0x1p-48)
#define SAFE 0x1p100

typedef struct {
    double v[3];
} v3_t;

HD__INLINE v3_t v3_diff(const double *p, const double *q) {
    return (v3_t){{p[0] - q[0], p[1] - q[1], p[2] - q[2]}};
}

HD__INLINE v3_t v3_neg(const double *x) { return (v3_t){{-x[0], -x[1], -x[2]}}; }

HD__INLINE double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* sum w_i |x_i| */
HD__INLINE double pdot3(const double *w, const double *x) {
    return w[0] * fabs(x[0]) + w[1] * fabs(x[1]) + w[2] * fabs(x[2]);
}

HD__INLINE double dmax(double x, double y) { return x > y ? x : y; }

/* x y for a lower bound: 0 unless both factors are normal, so that each
 * carries only its relative rounding (and the product an absolute one). */
HD__INLINE double lower_product(double x, double y) {
    return x > 0x1p-900 && y > 0x1p-900 ? x * y : 0;
}

/* ---- the triangle's part --------------------------------------------- */

/* x y for x within ex (per component) and y a rounded difference: the
 * cross product, its error bound, and the weights of a later dot product
 * with a point's rounded difference. */
HD__INLINE void cross_weights(const double *x, const double *ex, const double *y, double *r,
                          double *w) {
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        r[i] = x[j] * y[k] - x[k] * y[j];
        double e = ((1.01 * ex[j] + 3.1 * U * fabs(x[j])) * fabs(y[k]) +
                    (1.01 * ex[k] + 3.1 * U * fabs(x[k])) * fabs(y[j])) * SLACK + TB;
        w[i] = (1.01 * e + 4.1 * U * fabs(r[i])) * SLACK;
    }
}

/* 1 / x rounded down (x > 0), or up. */
HD__INLINE double recip_down(double x) { return 1 / (x * (1 + 2 * U)) * (1 - 2 * U); }
HD__INLINE double recip_up(double x) { return 1 / (x * (1 - 2 * U)) * (1 + 2 * U); }

/* The file's comment: everything that depends on the triangle alone. */
static void prep_core(const double *a, const double *b, const double *c, hd__tri_prep_t *t) {
    double en[3], M, eM = 0, len2[3];
    for (int i = 0; i < 3; i++) {
        t->ab[i] = b[i] - a[i];
        t->ac[i] = c[i] - a[i];
        t->bc[i] = c[i] - b[i];
    }
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        t->n[i] = t->ab[j] * t->ac[k] - t->ab[k] * t->ac[j];
        en[i] = 5 * U * (fabs(t->ab[j] * t->ac[k]) + fabs(t->ab[k] * t->ac[j])) + TB;
        t->wn[i] = (1.01 * en[i] + 4.1 * U * fabs(t->n[i])) * SLACK;
    }
    cross_weights(t->n, en, t->ab, t->mc, t->wc);          /* n x AB: L_C */
    cross_weights(t->n, en, t->ac, t->mb, t->wb);          /* n x AC = -(AC x n) */
    for (int i = 0; i < 3; i++) t->mb[i] = -t->mb[i];      /* L_B */
    M = dot3(t->n, t->n);
    for (int i = 0; i < 3; i++) eM += (2 * fabs(t->n[i]) + en[i]) * en[i];
    eM = (eM + 4 * U * M) * SLACK + TB;
    t->M = M;
    t->eM = eM;
    len2[0] = dot3(t->bc, t->bc);     /* the edge opposite a */
    len2[1] = dot3(t->ac, t->ac);
    len2[2] = dot3(t->ab, t->ab);
    t->flat = !(M - eM > 0x1p-900);
    t->rMu = recip_down(M + eM);
    t->rMl = t->flat ? 0 : recip_up(M - eM);
    for (int i = 0; i < 3; i++) {
        t->rl[i] = recip_down(len2[i] * (1 + 8 * U) + TB);
        t->rd[i] = len2[i] > 0 ? 1 / len2[i] : 0;
    }
}

void hd__tri_prep(const double a[3], const double b[3], const double c[3], hd__tri_prep_t *t) {
    memcpy(t->a, a, sizeof t->a);
    memcpy(t->b, b, sizeof t->b);
    memcpy(t->c, c, sizeof t->c);
    t->direct = 1;
    for (int i = 0; i < 3; i++)
        t->direct &= fabs(a[i]) < SAFE && fabs(b[i]) < SAFE && fabs(c[i]) < SAFE;
    if (t->direct) prep_core(a, b, c, t);
}

/* ---- the point's part ------------------------------------------------ */

/* An upper bound on |XP - tau XY|^2 for tau = (XP . XY) rd clamped to
 * [0, 1]: X + tau XY is a point of the edge for any tau there. */
HD__INLINE double foot_hi2(const double *xp, const double *xy, double rd) {
    double tau = dot3(xp, xy) * rd, s = 0;
    tau = tau > 0 ? (tau < 1 ? tau : 1) : 0;
    for (int i = 0; i < 3; i++) {
        double t = tau * xy[i], r = xp[i] - t;
        double m = fabs(r) + 2 * U * (fabs(r) + fabs(xp[i]) + 2 * fabs(t)) + TB;
        s += m * m;
    }
    return s * OUT_HI + 0x1p-1060;
}

/* |XP|^2 (less its rounding) when p is certainly in the corner X's region,
 * else 0: a lower bound either way. */
HD__INLINE double corner_lo2(const double *xp, const double *xy, const double *xz) {
    double m[3] = {fabs(xp[0]), fabs(xp[1]), fabs(xp[2])};
    double e1 = dot3(xy, xp) + (6 * U * pdot3(m, xy) + TB);
    double e2 = dot3(xz, xp) + (6 * U * pdot3(m, xz) + TB);
    return e1 <= 0 && e2 <= 0 ? dot3(xp, xp) * (1 - 6 * U) : 0;
}

/* The lower bound as returned, from the lo accumulated. */
HD__INLINE double lo_final(double lo) {
    lo = lo * OUT_LO - 0x1p-1060;
    return lo > 0 ? lo : 0;
}

/* Beyond the edges it may lie beyond: the corners, and unless their lower
 * bound already exceeds `skip`, the least foot (else hi stays infinite). */
static void outside(const double *p, const hd__tri_prep_t *t, const v3_t *ap, const int *sure,
                    double skip, double *lo, double *hi) {
    int all = t->flat;
    v3_t bp = v3_diff(p, t->b);
    double q;
    if (lo_final(*lo) > skip) { /* the plane's and the edges' terms suffice */
        *hi = INFINITY;
        return;
    }
    /* A corner's region lies beyond one of its edges' lines at least. */
    if (all || !(sure[1] && sure[2])) {
        q = corner_lo2(ap->v, t->ab, t->ac);
        *lo = dmax(*lo, q);
    }
    if (all || !(sure[0] && sure[2])) {
        v3_t ba = v3_neg(t->ab);
        q = corner_lo2(bp.v, ba.v, t->bc);
        *lo = dmax(*lo, q);
    }
    if (all || !(sure[0] && sure[1])) {
        v3_t cp = v3_diff(p, t->c), ca = v3_neg(t->ac), cb = v3_neg(t->bc);
        q = corner_lo2(cp.v, ca.v, cb.v);
        *lo = dmax(*lo, q);
    }
    double h = INFINITY;
    if (lo_final(*lo) > skip) {
        *hi = h;
        return;
    }
    if (all || !sure[2]) h = fmin(h, foot_hi2(ap->v, t->ab, t->rd[2]));
    if (all || !sure[1]) h = fmin(h, foot_hi2(ap->v, t->ac, t->rd[1]));
    if (all || !sure[0]) h = fmin(h, foot_hi2(bp.v, t->bc, t->rd[0]));
    *hi = h;
}

/* The bounds for a prepared triangle and a point below 2^100; hi2 left
 * infinite when lo2 > skip. */
static void bounds_core(const double *p, const hd__tri_prep_t *t, double skip, double *lo2, double *hi2) {
    v3_t ap = v3_diff(p, t->a);
    double g = dot3(t->n, ap.v), eg = pdot3(t->wn, ap.v) + TB;
    double L[3], eL[3], lo = 0, hi;
    int sure[3] = {0, 0, 0}, inside = !t->flat;
    if (inside) { /* the plane's term alone, a part of lo below: done when it exceeds skip */
        double gl = fabs(g) - eg;
        lo = lower_product(gl, gl * t->rMu);
        if (lo_final(lo) > skip) {
            *lo2 = lo_final(lo);
            *hi2 = INFINITY;
            return;
        }
    }
    L[2] = dot3(t->mc, ap.v);
    L[1] = dot3(t->mb, ap.v);
    eL[2] = pdot3(t->wc, ap.v) + TB;
    eL[1] = pdot3(t->wb, ap.v) + TB;
    L[0] = (t->M - L[1]) - L[2];
    eL[0] = (t->eM + eL[1] + eL[2] + 2 * U * (t->M + fabs(L[1]) + fabs(L[2]))) * SLACK;
    if (inside) {
        double out = 0;
        for (int i = 0; i < 3; i++) {
            double o = -L[i] - eL[i];
            sure[i] = L[i] - eL[i] >= 0;
            inside &= sure[i];
            if (o > 0x1p-900) out = dmax(out, lower_product(o * t->rMu, o * t->rl[i]));
        }
        lo += out;
    }
    if (inside) {
        double gh = fabs(g) + eg;
        hi = (gh * t->rMl + 0x1p-1000) * gh * OUT_HI + 0x1p-1060;
    } else {
        outside(p, t, &ap, sure, skip, &lo, &hi);
    }
    *lo2 = lo_final(lo);
    *hi2 = hi;
}

/* Coordinates beyond 2^100: scaled by a power of two, or no information. */
static void bounds_scaled(const double *p, const double *a, const double *b, const double *c,
                          double *lo2, double *hi2) {
    const double *in[4] = {p, a, b, c}, *sc[4];
    double scaled[4][3], lo, hi;
    int s = 0;
    hd__tri_prep_t t;
    *lo2 = 0;
    *hi2 = INFINITY;
    if (hd__tri_scale(in, scaled, sc, &s) <= 0) return;
    prep_core(sc[1], sc[2], sc[3], &t);
    memcpy(t.a, sc[1], sizeof t.a);
    memcpy(t.b, sc[2], sizeof t.b);
    memcpy(t.c, sc[3], sizeof t.c);
    bounds_core(sc[0], &t, INFINITY, &lo, &hi);
    /* Unscaling multiplies by a power of four: exact unless it overflows
     * (the lower bound then exceeds every double) or underflows (s > 0:
     * a result below 2^-900 becomes 0 and 2^-900). */
    double f = ldexp(1, -s);
    lo = lo * f * f;
    hi = hi * f * f;
    *lo2 = lo < 0x1p-900 ? 0 : lo < INFINITY ? lo : 1.7976931348623157e308;
    *hi2 = hi < 0x1p-900 ? 0x1p-900 : hi;
}

void hd__tri_bounds_below(const double p[3], const hd__tri_prep_t *t, double skip, double *lo2, double *hi2) {
    if (t->direct && fabs(p[0]) < SAFE && fabs(p[1]) < SAFE && fabs(p[2]) < SAFE)
        bounds_core(p, t, skip, lo2, hi2);
    else
        bounds_scaled(p, t->a, t->b, t->c, lo2, hi2);
}

void hd__tri_bounds_prep(const double p[3], const hd__tri_prep_t *t, double *lo2, double *hi2) {
    hd__tri_bounds_below(p, t, INFINITY, lo2, hi2);
}

void hd__tri_bounds(const double p[3], const double a[3], const double b[3], const double c[3],
                    double *lo2, double *hi2) {
    hd__tri_prep_t t;
    hd__tri_prep(a, b, c, &t);
    hd__tri_bounds_prep(p, &t, lo2, hi2);
}
