/*
 * tri.c -- the distance from a point to a triangle, correctly rounded
 * (mesh.h states the promise): the fast path, and when it cannot decide,
 * exact.c.
 *
 * 1. Scale.  All twelve coordinates are multiplied by the power of two that
 *    puts the largest magnitude in [1, 2), unless it already lies in
 *    [2^-8, 2) (every argument below needs only magnitudes below 2).  This
 *    is exact when no nonzero coordinate is or becomes subnormal (else:
 *    exact path), and it scales every squared distance by a power of four,
 *    so the rounding of the distance is the same in both scales as long as
 *    the result is a normal double.
 *
 * 2. The feature.  First the face alone (face_first): the three weights
 *    of p's projection, as signs of plain-double products each with an
 *    error bound; when all three are certainly positive the feature is the
 *    face and step 3 goes straight to its N / M (a near point's common
 *    case: the classification's twelve dot products are not formed).
 *    Otherwise Ericson's tests (Real-Time Collision Detection, 5.1.5)
 *    name the Voronoi region of p exactly when they are evaluated exactly on
 *    a non-degenerate triangle.  Each is evaluated in doubles from rounded
 *    differences, and its sign is accepted only when |value| exceeds
 *    c u P, where P is the test's permanent (the same polynomial with every
 *    monomial's absolute value, computed from the absolute values of the
 *    differences) and u = 2^-53.  Every monomial of the computed value
 *    carries at most k factors (1 + delta_i), |delta_i| <= u, one for each
 *    subtraction, product and sum that formed it, so the computed value is
 *    within gamma_k P of the exact one (Higham, Accuracy and Stability of
 *    Numerical Algorithms, 3.1); computing P itself rounds it down by at most
 *    (1 - u)^k.  k is 4 for n = AB x AC, 5 for the dot products d1..d6, 6
 *    for their differences and 12 for va, vb, vc: c = 8, 8, 8 and 16 cover
 *    gamma_k (1 - u)^-k with room.  Every bound also carries 2^-1000, what
 *    underflow could lose, so that no computed zero is ever taken for an
 *    exact one.  Non-degenerate is accepted when some component of n is
 *    certainly nonzero.  Any sign not certain sends the call to exact.c.
 *
 * 3. The squared distance N / M of that feature (exact.c lists the
 *    formulas) from the exact differences (two_sum), every polynomial a
 *    compensated sum of products (cdot): each product x y of double-doubles
 *    is TwoProd(xh, yh) = p + pi exactly plus xh yl + xl yh rounded, the p
 *    are summed with TwoSum, and every error term (the TwoSum errors sigma,
 *    the pi, the cross products) is summed in plain doubles into c; the
 *    value is TwoSum(s, c).  One a-priori bound per quantity replaces a
 *    running bound per operation (Higham 3.1, the leaves being these
 *    terms): with P = sum |xh_i yh_i| and n products, the terms sum in
 *    magnitude to at most (n + 2) u P (1 + n u) (|sigma_i| <= u |s_i|,
 *    |pi_i| <= u |p_i|, each cross product <= u |xh yh|), each passes
 *    through at most 3n + 1 roundings, and the dropped xl yl are at most
 *    u^2 P: the error is within gamma_{3n+1} (n + 2) u P + u^2 P, below
 *    C_n u^2 P with C_1 = 16, C_2 = 32, C_3 = 64.  An operand that carries
 *    its own error e (a component of n = AB x AC or of XP x XY) adds
 *    sum e_i |y_i| to a dot product and (2 |x_i| + e_i) e_i to a square.
 *    Each bound is computed in doubles from the leading parts (|x| <=
 *    |xh| (1 + u)) and multiplied by 1 + 2^-40, which covers the roundings
 *    of its own formula; every bound also carries 2^-1000, what underflow
 *    could lose (coordinates scaled below 2 keep every factor a result is
 *    multiplied by under 2^20).  TwoProd is Dekker's product, or on a CPU
 *    with fused multiply-add (chosen at run time) p = xh yh and
 *    pi = fma(xh, yh, -p): both exact, so both give the same N and M bits.
 *
 * 4. The rounding.  q0 = sqrt(N / M) in doubles, N and M known to 2^-60
 *    relatively.  With t the true distance and z = t - q0,
 *    z (2 q0 + z) M = R = N - q0^2 M, computed as r (q0^2 exactly by
 *    TwoProd, the rest as in cdot) within wr.  Then with mu >= |M / Mh - 1|
 *    and zeta >= |z| / (2 q0) (from t + q0 >= q0), both below 2^-40, the
 *    Newton step corr = r / (2 q0 Mh) in doubles is within
 *    ez = (wr + |r| (mu + zeta)) / (2 q0 Mh) (1 + 2^-37) + 2.02 u |corr|
 *    of z.  q = fl(q0 + corr); d = corr - (q - q0) is exact (the rounding
 *    error of that sum) and t - q lies in [d - ez, d + ez]: when that
 *    interval is strictly inside the half gaps around q, q is the nearest
 *    double.  Otherwise (t within about 2^-45 ulp of a midpoint) the sign
 *    of the residual says on which side of q0 t lies, and the sign of
 *    N - m^2 M at the midpoint m on that side (m^2 is the exact sum of
 *    q0^2, 2 q0 g and g^2 for the half gap g, in double-doubles with a
 *    running bound: Joldes, Muller, Popescu, ACM TOMS 44(2), 2017, 7 u^2
 *    for a product and 3 u^2 / (1 - 4u) for a sum, used with room as
 *    16 u^2 and 4 u^2) says whether t rounds to q0 or beyond it.  A sign
 *    that is not certain (t within about 2^-90 of a midpoint, or equal to
 *    it) goes to exact.c, which also rounds ties to even.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "mesh/mesh_int.h"

#define U 0x1p-53
#define C_ADD (4 * U * U)
#define C_MUL (16 * U * U)
#define SLACK (1 + 0x1p-40)
#define TINY 0x1p-1000

/* ---- error-free transformations (exact barring overflow and underflow) -- */

HD__INLINE void two_sum(double a, double b, double *s, double *e) {
    double x = a + b, bb = x - a;
    *s = x;
    *e = (a - (x - bb)) + (b - bb);
}

/* |a| >= |b| or a == 0. */
HD__INLINE void fast_two_sum(double a, double b, double *s, double *e) {
    double x = a + b;
    *s = x;
    *e = b - (x - a);
}

HD__INLINE void two_prod(double a, double b, double *p, double *e) {
    double x = a * b;
    double ta = 134217729.0 * a, ah = ta - (ta - a), al = a - ah;
    double tb = 134217729.0 * b, bh = tb - (tb - b), bl = b - bh;
    *p = x;
    *e = ((ah * bh - x) + ah * bl + al * bh) + al * bl;
}

/* TwoProd by the CPU's fused multiply-add when fma is 1 (a constant after
 * inlining: the kernel is compiled once for each), else Dekker's. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define TRI_FMA_CLONE 1
#else
#define TRI_FMA_CLONE 0
#endif

HD__INLINE void two_prod_x(double a, double b, double *p, double *e, int fma) {
#if TRI_FMA_CLONE
    if (fma) {
        double x = a * b;
        *p = x;
        *e = __builtin_fma(a, b, -x);
        return;
    }
#endif
    (void)fma;
    two_prod(a, b, p, e);
}

/* ---- powers of two and binades, by their bits -------------------------- */

/* 2^e for a normal result (-1022 <= e <= 1023). */
HD__INLINE double pow2(int e) { return hd__double_of((uint64_t)(e + 1023) << 52); }

/* floor(log2(x)) for a normal x > 0. */
HD__INLINE int binade(double x) { return (int)((hd__bits_of(x) >> 52) & 0x7ff) - 1023; }

/* ---- double-doubles with an error bound ------------------------------- */

/* h + l with |l| <= u |h|, within e of the exact value it stands for. */
typedef struct {
    double h, l, e;
} dd_t;

HD__INLINE double dd_mag(dd_t x) { return fabs(x.h) * (1 + 2 * U); }

HD__INLINE dd_t dd_exact(double x) { return (dd_t){x, 0, 0}; }

HD__INLINE dd_t dd_diff(double a, double b) {
    dd_t r;
    two_sum(a, -b, &r.h, &r.l);
    r.e = 0;
    return r;
}

HD__INLINE dd_t dd_add(dd_t x, dd_t y) {
    double sh, sl, th, tl, vh, vl, c, w;
    dd_t z;
    two_sum(x.h, y.h, &sh, &sl);
    two_sum(x.l, y.l, &th, &tl);
    c = sl + th;
    fast_two_sum(sh, c, &vh, &vl);
    w = tl + vl;
    fast_two_sum(vh, w, &z.h, &z.l);
    z.e = (C_ADD * fabs(z.h) + x.e + y.e) * SLACK + TINY;
    return z;
}

HD__INLINE dd_t dd_neg(dd_t x) { return (dd_t){-x.h, -x.l, x.e}; }

HD__INLINE dd_t dd_sub(dd_t x, dd_t y) { return dd_add(x, dd_neg(y)); }

HD__INLINE dd_t dd_mul(dd_t x, dd_t y) {
    double ch, cl1, cl2, cl3;
    dd_t z;
    two_prod(x.h, y.h, &ch, &cl1);
    cl2 = x.l * y.h + x.h * y.l;
    cl3 = cl1 + cl2;
    fast_two_sum(ch, cl3, &z.h, &z.l);
    z.e = (C_MUL * fabs(z.h) + dd_mag(x) * y.e + (dd_mag(y) + y.e) * x.e) * SLACK + TINY;
    return z;
}

/* ---- step 2: the feature, from filtered signs ------------------------- */

/* A value computed in doubles and a bound on its distance from the exact. */
typedef struct {
    double v, b;
} est_t;

enum { NO = 0, YES = 1, UNSURE = 2 };

HD__INLINE int le0(est_t x) { return x.v < -x.b ? YES : x.v > x.b ? NO : UNSURE; }
HD__INLINE int ge0(est_t x) { return x.v > x.b ? YES : x.v < -x.b ? NO : UNSURE; }
HD__INLINE int all2(int a, int b) { return (a == NO || b == NO) ? NO : (a == YES && b == YES) ? YES : UNSURE; }
HD__INLINE int all3(int a, int b, int c) { return all2(all2(a, b), c); }

typedef struct {
    double v[3], m[3];      /* rounded difference and its magnitude */
} dv_t;

static dv_t dv_diff(const double *p, const double *q) {
    dv_t r;
    for (int i = 0; i < 3; i++) {
        r.v[i] = p[i] - q[i];
        r.m[i] = fabs(r.v[i]);
    }
    return r;
}

static est_t dot_est(const dv_t *a, const dv_t *b) {
    est_t r;
    r.v = a->v[0] * b->v[0] + a->v[1] * b->v[1] + a->v[2] * b->v[2];
    r.b = a->m[0] * b->m[0] + a->m[1] * b->m[1] + a->m[2] * b->m[2];   /* permanent */
    return r;
}

/* x - y, both dot products (k = 6). */
static est_t diff_est(est_t x, est_t y) { return (est_t){x.v - y.v, x.b + y.b}; }

/* x y - z w of dot products (k = 12); the permanents are still bare. */
static est_t det_est(est_t x, est_t y, est_t z, est_t w) {
    return (est_t){x.v * y.v - z.v * w.v, (x.b * y.b + z.b * w.b) * (16 * U) + TINY};
}

static est_t bounded(est_t x, double c) { return (est_t){x.v, x.b * c + TINY}; }

/* Some component of AB x AC certainly nonzero (k = 4). */
static int spans_plane(const dv_t *ab, const dv_t *ac) {
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        double v = ab->v[j] * ac->v[k] - ab->v[k] * ac->v[j];
        double b = (ab->m[j] * ac->m[k] + ab->m[k] * ac->m[j]) * (8 * U) + TINY;
        if (fabs(v) > b) return 1;
    }
    return 0;
}

typedef struct {
    hd__tri_feature_t feature;
    double s, t;            /* the face's closest point: a + s AB + t AC */
} region_t;

/* Ericson's classification; 0 when a sign it needs is not certain. */
static int classify(const double *p, const double *a, const double *b, const double *c,
                    region_t *r) {
    dv_t ab = dv_diff(b, a), ac = dv_diff(c, a);
    if (!spans_plane(&ab, &ac)) return 0;
    dv_t ap = dv_diff(p, a), bp = dv_diff(p, b), cp = dv_diff(p, c);
    est_t d1 = dot_est(&ab, &ap), d2 = dot_est(&ac, &ap), d3 = dot_est(&ab, &bp);
    est_t d4 = dot_est(&ac, &bp), d5 = dot_est(&ab, &cp), d6 = dot_est(&ac, &cp);
    est_t e1 = bounded(d1, 8 * U), e2 = bounded(d2, 8 * U), e3 = bounded(d3, 8 * U);
    est_t e6 = bounded(d6, 8 * U);
    int k;
    if ((k = all2(le0(e1), le0(e2))) != NO) { r->feature = HD__TRI_VERTEX_A; return k == YES; }
    est_t d43 = bounded(diff_est(d4, d3), 8 * U);
    if ((k = all2(ge0(e3), le0(d43))) != NO) { r->feature = HD__TRI_VERTEX_B; return k == YES; }
    est_t vc = det_est(d1, d4, d3, d2);
    if ((k = all3(le0(vc), ge0(e1), le0(e3))) != NO) {
        r->feature = HD__TRI_EDGE_AB;
        return k == YES;
    }
    est_t d56 = bounded(diff_est(d5, d6), 8 * U);
    if ((k = all2(ge0(e6), le0(d56))) != NO) { r->feature = HD__TRI_VERTEX_C; return k == YES; }
    est_t vb = det_est(d5, d2, d1, d6);
    if ((k = all3(le0(vb), ge0(e2), le0(e6))) != NO) {
        r->feature = HD__TRI_EDGE_CA;
        return k == YES;
    }
    est_t va = det_est(d3, d6, d5, d4);
    if ((k = all3(le0(va), ge0(d43), ge0(d56))) != NO) {
        r->feature = HD__TRI_EDGE_BC;
        return k == YES;
    }
    double den = va.v + vb.v + vc.v;
    r->feature = HD__TRI_FACE;
    r->s = vb.v / den;
    r->t = vc.v / den;
    return 1;
}

/* ---- step 3: N and M of the feature ------------------------------------ */

typedef struct {
    double h, l;
} dw_t;

typedef struct {
    dw_t x[3];
} dwv_t;

#define C1 (16 * U * U)
#define C2 (32 * U * U)
#define C3 (64 * U * U)

/* sum of x_i y_i for i < n as h + l with |l| <= u |h|, within
 * C_n u^2 sum |xh_i yh_i| of the exact (the file's comment, step 3). */
HD__INLINE dw_t cdot(const dw_t *x, const dw_t *y, int n, int fma) {
    double s, c, p, e, sg;
    dw_t r;
    two_prod_x(x[0].h, y[0].h, &s, &c, fma);
    c += x[0].h * y[0].l + x[0].l * y[0].h;
    for (int i = 1; i < n; i++) {
        two_prod_x(x[i].h, y[i].h, &p, &e, fma);
        two_sum(s, p, &s, &sg);
        c += (sg + e) + (x[i].h * y[i].l + x[i].l * y[i].h);
    }
    two_sum(s, c, &r.h, &r.l);
    return r;
}

HD__INLINE dwv_t dwv_diff(const double *p, const double *q) {
    dwv_t r;
    for (int i = 0; i < 3; i++) two_sum(p[i], -q[i], &r.x[i].h, &r.x[i].l);
    return r;
}

/* a x b of exact vectors, and each component's error bound. */
HD__INLINE dwv_t dwv_cross(const dwv_t *a, const dwv_t *b, double e[3], int fma) {
    dwv_t r;
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        dw_t x[2] = {a->x[j], {-a->x[k].h, -a->x[k].l}}, y[2] = {b->x[k], b->x[j]};
        r.x[i] = cdot(x, y, 2, fma);
        e[i] = C2 * (fabs(a->x[j].h * b->x[k].h) + fabs(a->x[k].h * b->x[j].h)) * SLACK + TINY;
    }
    return r;
}

/* x . y for x within ex of exact and y exact. */
HD__INLINE dd_t dwv_dot(const dwv_t *x, const double ex[3], const dwv_t *y, int fma) {
    dw_t v = cdot(x->x, y->x, 3, fma);
    double b = 0;
    for (int i = 0; i < 3; i++) b += fabs(y->x[i].h) * (C3 * fabs(x->x[i].h) + ex[i] * (1 + 2 * U));
    return (dd_t){v.h, v.l, b * SLACK + TINY};
}

/* |x|^2 for x within ex of exact: |X^2 - x^2| <= (2 |x| + e) e. */
HD__INLINE dd_t dwv_norm2(const dwv_t *x, const double ex[3], int fma) {
    dw_t v = cdot(x->x, x->x, 3, fma);
    double b = 0;
    for (int i = 0; i < 3; i++) {
        double m = fabs(x->x[i].h);
        b += C3 * m * m + (2 * m * (1 + 2 * U) + ex[i]) * ex[i];
    }
    return (dd_t){v.h, v.l, b * SLACK + TINY};
}

/* g^2 for g within g.e of exact. */
HD__INLINE dd_t dd_square(dd_t g, int fma) {
    dw_t x = {g.h, g.l}, v = cdot(&x, &x, 1, fma);
    double m = fabs(g.h);
    return (dd_t){v.h, v.l, (C1 * m * m + (2 * m * (1 + 2 * U) + g.e) * g.e) * SLACK + TINY};
}

/* The feature's squared distance N / M and its closest point, in the scale
 * of the coordinates given: p less its offset from the plane (the face),
 * x + t xy with t in doubles (an edge), or the corner. */
typedef struct {
    dd_t N, M;
    double point[3], t;
} sqd_t;

static const double no_err[3] = {0, 0, 0};

HD__INLINE void face_sqd(const double *p, const double *a, const double *b, const double *c,
                         sqd_t *r, int fma) {
    double en[3];
    dwv_t ab = dwv_diff(b, a), ac = dwv_diff(c, a), ap = dwv_diff(p, a);
    dwv_t n = dwv_cross(&ab, &ac, en, fma);
    dd_t g = dwv_dot(&n, en, &ap, fma);
    r->N = dd_square(g, fma);
    r->M = dwv_norm2(&n, en, fma);
    double k = g.h / r->M.h;
    for (int i = 0; i < 3; i++) r->point[i] = p[i] - n.x[i].h * k;
}

HD__INLINE void edge_sqd(const double *p, const double *x, const double *y, sqd_t *r, int fma) {
    double ec[3];
    dwv_t xy = dwv_diff(y, x), xp = dwv_diff(p, x);
    dwv_t cr = dwv_cross(&xp, &xy, ec, fma);
    r->N = dwv_norm2(&cr, ec, fma);
    r->M = dwv_norm2(&xy, no_err, fma);
    double along = xp.x[0].h * xy.x[0].h + xp.x[1].h * xy.x[1].h + xp.x[2].h * xy.x[2].h;
    r->t = along / r->M.h;
    for (int i = 0; i < 3; i++) r->point[i] = x[i] + r->t * xy.x[i].h;
}

HD__INLINE void feature_sqd(const double *p, const double *a, const double *b, const double *c,
                            hd__tri_feature_t f, sqd_t *r, int fma) {
    switch (f) {
    case HD__TRI_FACE: face_sqd(p, a, b, c, r, fma); return;
    case HD__TRI_VERTEX_A: case HD__TRI_VERTEX_B: case HD__TRI_VERTEX_C: {
        const double *v = f == HD__TRI_VERTEX_A ? a : f == HD__TRI_VERTEX_B ? b : c;
        dwv_t vp = dwv_diff(p, v);
        r->N = dwv_norm2(&vp, no_err, fma);
        r->M = dd_exact(1);
        memcpy(r->point, v, sizeof r->point);
        return;
    }
    case HD__TRI_EDGE_AB: edge_sqd(p, a, b, r, fma); return;
    case HD__TRI_EDGE_BC: edge_sqd(p, b, c, r, fma); return;
    case HD__TRI_EDGE_CA: edge_sqd(p, c, a, r, fma); return;
    }
}

/* ---- step 4: the rounding ----------------------------------------------- */

/* N - x M for x = q^2 + 2 sigma q g + g^2 (sigma 0: x = q^2). */
static dd_t residual(dd_t N, dd_t M, double q, int sigma, double g) {
    dd_t x;
    two_prod(q, q, &x.h, &x.l);
    x.e = 0;
    if (sigma) {
        x = dd_add(x, dd_exact(2 * sigma * q * g));
        x = dd_add(x, dd_exact(g * g));
    }
    return dd_sub(N, dd_mul(x, M));
}

HD__INLINE int certain_sign(dd_t v) {
    double m = fabs(v.h) * (1 - 2 * U);
    return m > v.e ? (v.h > 0 ? 1 : -1) : 0;
}

/* The double nearest sqrt(N / M) from one Newton step; 0 when t may be
 * too near a midpoint (the file's comment, step 4). */
HD__INLINE int round_newton(dd_t N, dd_t M, double *q, int fma) {
    if (!(N.h > 0 && M.h > 0) || N.e > N.h * 0x1p-60 || M.e > M.h * 0x1p-60) return 0;
    double q0 = sqrt(N.h / M.h);
    if (!(q0 >= 0x1p-400)) return 0;
    double qh, ql, ph, pe, s, sg;
    two_prod_x(q0, q0, &qh, &ql, fma);
    two_prod_x(qh, M.h, &ph, &pe, fma);
    two_sum(N.h, -ph, &s, &sg);
    double r = s + (((sg + N.l) - pe) - (qh * M.l + ql * M.h));
    double wr = (U * fabs(r) + 6 * U * U * (fabs(s) + N.h + 4 * fabs(ph)) + N.e +
                 qh * M.e * (1 + 2 * U)) * SLACK + TINY;
    double mu = (fabs(M.l) + M.e) / M.h * SLACK;
    double zeta = (fabs(r) + wr) / (2 * M.h * (1 - mu) * q0 * q0) * SLACK;
    if (!(mu < 0x1p-40 && zeta < 0x1p-40)) return 0;
    double d0 = 2 * q0 * M.h, corr = r / d0;
    double ez = ((wr + fabs(r) * (mu + zeta) * (1 + 0x1p-39)) / d0 + 2.02 * U * fabs(corr)) *
                (1 + 0x1p-37);
    double qq = q0 + corr, d = corr - (qq - q0);   /* both exact */
    int ex = binade(qq);
    double up = pow2(ex - 53), down = qq == pow2(ex) ? up / 2 : up;
    if (!(d + ez <= up * (1 - 0x1p-40) && ez - d <= down * (1 - 0x1p-40))) return 0;
    *q = qq;
    return 1;
}

/* The double nearest sqrt(N / M) into *q; 0 when not decided. */
static int round_sqrt(dd_t N, dd_t M, double *q) {
    if (!(N.h > 0 && M.h > 0) || N.e > N.h * 0x1p-60 || M.e > M.h * 0x1p-60) return 0;
    double q0 = sqrt(N.h / M.h);
    for (int step = 0; step < 4; step++) {
        if (!(q0 >= 0x1p-400)) return 0;
        int ex = binade(q0);
        double up = pow2(ex - 53);                           /* half the gap above */
        double down = q0 == pow2(ex) ? up / 2 : up;          /* half the gap below */
        dd_t v = residual(N, M, q0, 0, 0);
        double w = fabs(v.h) * (1 + 2 * U) + v.e;
        double dist = w / (M.h * 2 * q0) * (1 + 0x1p-40);   /* >= |t - q0| */
        if (dist < down * (1 - 0x1p-30)) { *q = q0; return 1; }
        int side = certain_sign(v);
        if (side == 0) return 0;
        double g = side > 0 ? up : down;
        int beyond = certain_sign(residual(N, M, q0, side, g));
        if (beyond == 0) return 0;
        if (beyond != side) { *q = q0; return 1; }
        q0 = nextafter(q0, side > 0 ? INFINITY : 0);
    }
    return 0;
}

/* ---- the call ------------------------------------------------------------ */

/* The weights of a, b and c; an edge's from its t in double-doubles, the
 * face's from Ericson's areas in doubles. */
static void weigh(hd__tri_near_t *out, const region_t *r, double t) {
    double *w = out->bary;
    w[0] = w[1] = w[2] = 0;
    switch (r->feature) {
    case HD__TRI_VERTEX_A: w[0] = 1; break;
    case HD__TRI_VERTEX_B: w[1] = 1; break;
    case HD__TRI_VERTEX_C: w[2] = 1; break;
    case HD__TRI_EDGE_AB: w[0] = 1 - t; w[1] = t; break;
    case HD__TRI_EDGE_BC: w[1] = 1 - t; w[2] = t; break;
    case HD__TRI_EDGE_CA: w[2] = 1 - t; w[0] = t; break;
    case HD__TRI_FACE: w[1] = r->s; w[2] = r->t; w[0] = 1 - r->s - r->t; break;
    }
}

/* Step 1.  A magnitude's bits order like the magnitude (NaN above infinity
 * above every finite value), so one pass of integer max and min finds the
 * largest magnitude and the smallest nonzero one (m - 1 wraps 0 to the top).
 * Coordinates whose largest magnitude is already in [2^-8, 2) are used as
 * they are (*use = in); otherwise *use = out, the copies scaled to put it in
 * [1, 2).  -1 outside the domain, 0 when a nonzero coordinate is or would
 * become subnormal (the exact path). */
int hd__tri_scale(const double *const in[4], double out[4][3], const double **use, int *s) {
    uint64_t big = 0, small = UINT64_MAX;
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) {
            uint64_t m;
            memcpy(&m, &in[i][k], sizeof m);
            m &= ~(UINT64_C(1) << 63);
            big = m > big ? m : big;
            small = m - 1 < small ? m - 1 : small;
        }
    if (big > UINT64_C(0x5fe0000000000000)) return -1;     /* beyond 2^511, or not a number */
    int eb = (int)(big >> 52) - 1023;
    double least, f;
    small += 1;
    memcpy(&least, &small, sizeof least);
    if (eb < -900) return 0;
    *s = eb >= -8 && eb <= 0 ? 0 : -eb;
    f = pow2(*s);                     /* -511 <= s <= 900: a normal double */
    if (least * f < 0x1p-1022) return 0;
    if (*s == 0) {
        for (int i = 0; i < 4; i++) use[i] = in[i];
        return 1;
    }
    for (int i = 0; i < 4; i++) {
        for (int k = 0; k < 3; k++) out[i][k] = in[i][k] * f;
        use[i] = out[i];
    }
    return 1;
}

/* Steps 3 and 4 on the scaled coordinates with the feature known: 1 and
 * *out but its weights when decided (unscaled), *t an edge's parameter. */
HD__INLINE int settle(const double *const sc[4], hd__tri_feature_t feature, int s, hd__tri_near_t *out,
                      int fma, double *t) {
    sqd_t f = {.t = 0};
    double q;
    feature_sqd(sc[0], sc[1], sc[2], sc[3], feature, &f, fma);
    if (!round_newton(f.N, f.M, &q, fma) && !round_sqrt(f.N, f.M, &q)) return 0;
    if (!(q * pow2(-s) >= 0x1p-1022)) return 0;
    out->d = q * pow2(-s);           /* exact: a normal result */
    out->feature = feature;
    out->exact = 0;
    for (int i = 0; i < 3; i++) out->point[i] = f.point[i] * pow2(-s);
    *t = f.t;
    return 1;
}

/* settle() with the weights of Ericson's region. */
HD__INLINE int decide(const double *const sc[4], const region_t *r, int s, hd__tri_near_t *out,
                      int fma) {
    double t;
    if (!settle(sc, r->feature, s, out, fma, &t)) return 0;
    weigh(out, r, t);
    return 1;
}

/* ---- the face first ------------------------------------------------------ */

HD__INLINE double max3(const double *x) {
    double m = fabs(x[0]) > fabs(x[1]) ? fabs(x[0]) : fabs(x[1]);
    return fabs(x[2]) > m ? fabs(x[2]) : m;
}

/* (x x y) . z in doubles for x and y within em + u |x| and u |y|, z within
 * u |z|, of exact vectors X, Y, Z (componentwise; xm = max |x_i|), and a
 * bound *e on its distance from (X x Y) . Z.  Each of the six monomials
 * of the computed value passes through five roundings (a product and a
 * difference in the cross product, a product and two sums in the dot
 * product), so it is within gamma_5 P of (x x y) . z, P the permanent
 * sum_i |z_i| (|x_j y_k| + |x_k y_j|).  The trilinear form changes by at
 * most perm(|X - x|, |Y|, |Z|) + perm(|x|, |Y - y|, |Z|) + perm(|x|, |y|,
 * |Z - z|) <= (1 + u)^2 (3u P + Q) from the inputs' errors, Q =
 * sum_i |z_i| em (|y_k| + |y_j|).  So 8.01u P + 1.01 Q bounds the error;
 * P <= 2 xm ym z1 and Q <= 2 em ym z1 (ym = max |y_i|, z1 = sum |z_i|),
 * and (32u xm + 4 em) ym z1, computed (a few roundings), with the factor
 * SLACK is above twice that; underflow loses at most 2^-1060, as a
 * product's or a difference's rounding is multiplied by at most |z_i| < 4
 * (coordinates below 2): TINY covers it. */
HD__INLINE double edge_term(const double *x, double xm, double em, const double *y, const double *z, double *e) {
    double v = 0;
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        v += (x[j] * y[k] - x[k] * y[j]) * z[i];
    }
    *e = (32 * U * xm + 4 * em) * max3(y) * (fabs(z[0]) + fabs(z[1]) + fabs(z[2])) * SLACK + TINY;
    return v;
}

/* The face decided first, on the scaled coordinates (sc, s as decide's).
 * With n = AB x AC, L_C = n . (AB x AP) = (n x AB) . AP,
 * L_B = n . (AP x AC) = -(n x AC) . AP and L_A = n . (BC x BP) =
 * (n x BC) . BP (they sum to |n|^2 and are |n|^2 times the weights of C,
 * B and A of p's projection p' on the plane, bounds.c), p' lies strictly
 * inside the triangle when the three are positive: then the triangle is
 * not degenerate (they sum to |n|^2 > 0), Ericson's tests evaluated
 * exactly name the face (a corner's region needs the dot products of its
 * two edges with p' non-positive, impossible inside by Cauchy-Schwarz; an
 * edge's needs its weight non-positive) and the squared distance is
 * (n . AP)^2 / |n|^2, face_sqd's N / M.  The signs are decided in plain
 * doubles: the differences are rounded once (within u of the exact ones),
 * n computed from them is within (gamma_3 + 2.01u) (|AB_j AC_k| +
 * |AB_k AC_j|) <= 5.1u 2 max|AB_i| max|AC_i| of AB x AC (three
 * roundings, two rounded factors), which em (16u of that product,
 * computed, plus TINY) covers; edge_term bounds each L.
 * Each L certainly positive: settle() on the face (face_sqd's N / M,
 * rounded by step 4); the weights are the L over their sum.  1 and *out when decided; 0 leaves the call to
 * Ericson's classification (a point near or beyond an edge, a distance
 * near a midpoint). */
HD__INLINE int face_first(const double *const sc[4], int s, hd__tri_near_t *out, int fma) {
    const double *p = sc[0], *a = sc[1], *b = sc[2], *c = sc[3];
    double ab[3], ac[3], ap[3], bc[3], bp[3], nr[3], L[3], e[3];
    for (int i = 0; i < 3; i++) ab[i] = b[i] - a[i], ac[i] = c[i] - a[i], ap[i] = p[i] - a[i];
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        nr[i] = ab[j] * ac[k] - ab[k] * ac[j];
    }
    double nm = max3(nr), em = 16 * U * max3(ab) * max3(ac) + TINY;
    L[2] = edge_term(nr, nm, em, ab, ap, &e[2]);
    if (!(L[2] > e[2])) return 0;
    L[1] = -edge_term(nr, nm, em, ac, ap, &e[1]);
    if (!(L[1] > e[1])) return 0;
    for (int i = 0; i < 3; i++) bc[i] = c[i] - b[i], bp[i] = p[i] - b[i];
    L[0] = edge_term(nr, nm, em, bc, bp, &e[0]);
    if (!(L[0] > e[0])) return 0;
    double t, sum = L[0] + L[1] + L[2];
    if (!settle(sc, HD__TRI_FACE, s, out, fma, &t)) return 0;
    for (int i = 0; i < 3; i++) out->bary[i] = L[i] / sum;
    return 1;
}


/* The fast path on the scaled coordinates: the face first, else Ericson's
 * classification and steps 3 and 4; 0 when not decided (exact.c). */
HD__INLINE int fast(const double *const sc[4], int s, hd__tri_near_t *out, int fma) {
    region_t r = {HD__TRI_FACE, 0, 0};
    if (face_first(sc, s, out, fma)) return 1;
    return classify(sc[0], sc[1], sc[2], sc[3], &r) && decide(sc, &r, s, out, fma);
}

static int fast_plain(const double *const sc[4], int s, hd__tri_near_t *out) { return fast(sc, s, out, 0); }

#if TRI_FMA_CLONE
__attribute__((target("fma")))
static int fast_fma(const double *const sc[4], int s, hd__tri_near_t *out) { return fast(sc, s, out, 1); }
#endif

int hd__tri_nearest_variant(const double p[3], const double a[3], const double b[3],
                            const double c[3], hd__tri_near_t *out, int fma) {
    const double *in[4] = {p, a, b, c}, *sc[4];
    double scaled[4][3];
    int s = 0, ok, sc_ok = hd__tri_scale(in, scaled, sc, &s);
    region_t r = {HD__TRI_FACE, 0, 0};
    if (sc_ok < 0) return HD_ERANGE;
    for (int i = 1; i < 4; i++)
        if (p[0] == in[i][0] && p[1] == in[i][1] && p[2] == in[i][2]) {
            r.feature = (hd__tri_feature_t)(HD__TRI_VERTEX_A + i - 1);
            out->d = 0;                 /* p is a corner */
            out->feature = r.feature;
            out->exact = 0;
            memcpy(out->point, p, sizeof out->point);
            weigh(out, &r, 0);
            return HD_OK;
        }
    if (!sc_ok) return hd__tri_nearest_exact(p, a, b, c, out);
#if TRI_FMA_CLONE
    ok = fma && __builtin_cpu_supports("fma") ? fast_fma(sc, s, out) : fast_plain(sc, s, out);
#else
    (void)fma;
    ok = fast_plain(sc, s, out);
#endif
    return ok ? HD_OK : hd__tri_nearest_exact(p, a, b, c, out);
}

int hd__tri_nearest(const double p[3], const double a[3], const double b[3],
                    const double c[3], hd__tri_near_t *out) {
    return hd__tri_nearest_variant(p, a, b, c, out, 1);
}
