/*
 * exact.c -- the point-to-triangle distance in exact integer arithmetic:
 * the kernel's fallback, and the reference its fast path is tested against.
 *
 * Every coordinate is an integer times 2^e0 (mesh_int.h).  With integers the
 * region of the closest point and the squared distance N / M are exact:
 *
 *   - n = AB x AC.  When n != 0 the triangle spans a plane, and p projects
 *     into the closed triangle iff the three signed areas n . (AB x AP),
 *     n . (BC x BP), n . (CA x CP) are all >= 0; then the squared distance is
 *     (n . AP)^2 / (n . n).
 *   - Otherwise (p projects outside, or the triangle is a segment or a
 *     point) the closest point lies on the boundary, the union of the three
 *     closed edges, and the squared distance is the least of the three edge
 *     distances.  For the edge XY with XY != 0: t = XP . XY / XY . XY
 *     clamped to [0, 1]; at 0 the distance is |XP|^2, at 1 |YP|^2, inside
 *     |XP x XY|^2 / |XY|^2 (Lagrange's identity).  An edge of length 0 is
 *     its point X.
 *
 * The distance 2^e0 sqrt(N / M) is then rounded to the nearest double by
 * comparing it with the midpoints between consecutive doubles, each
 * comparison exact: t < K 2^F  <=>  N 2^(2 e0) < K^2 M 2^(2 F).
 */
#include <math.h>
#include <string.h>

#include "mesh/mesh_int.h"

/* ---- integers ------------------------------------------------------------ */

static void big_trim(hd__big_t *r) {
    while (r->n > 0 && r->w[r->n - 1] == 0) r->n--;
    if (r->n == 0) r->neg = 0;
}

void hd__big_set_u64(hd__big_t *r, uint64_t v) {
    r->neg = 0;
    r->w[0] = (uint32_t)v;
    r->w[1] = (uint32_t)(v >> 32);
    r->n = 2;
    big_trim(r);
}

/* |x| = m 2^e with m odd (x != 0, finite). */
static uint64_t split_double(double x, int *e) {
    int k;
    double f = frexp(fabs(x), &k);        /* |x| = f 2^k, f in [0.5, 1) */
    uint64_t m = (uint64_t)ldexp(f, 53);  /* exact: a double's significand */
    *e = k - 53;
    while ((m & 1) == 0) { m >>= 1; (*e)++; }
    return m;
}

int hd__ulp_exp(double x) {
    int e;
    split_double(x, &e);
    return e;
}

void hd__big_set_double(hd__big_t *r, double x, int e0) {
    r->n = 0;
    r->neg = 0;
    if (x == 0) return;
    int e;
    uint64_t m = split_double(x, &e);
    hd__big_t t;
    hd__big_set_u64(&t, m);
    /* x = m 2^e and e >= e0 by the choice of e0. */
    hd__big_shl(r, &t, e - e0);
    r->neg = x < 0;
}

static int mag_cmp(const hd__big_t *a, const hd__big_t *b) {
    if (a->n != b->n) return a->n < b->n ? -1 : 1;
    for (int i = a->n - 1; i >= 0; i--)
        if (a->w[i] != b->w[i]) return a->w[i] < b->w[i] ? -1 : 1;
    return 0;
}

/* |r| = |a| + |b|; r may be a or b. */
static void mag_add(hd__big_t *r, const hd__big_t *a, const hd__big_t *b) {
    int n = a->n > b->n ? a->n : b->n;
    uint64_t carry = 0;
    for (int i = 0; i < n; i++) {
        uint64_t s = carry + (i < a->n ? a->w[i] : 0) + (i < b->n ? b->w[i] : 0);
        r->w[i] = (uint32_t)s;
        carry = s >> 32;
    }
    r->n = n;
    /* The domain bound (mesh_int.h) keeps every sum inside the array. */
    if (carry && n < HD__BIG_LIMBS) r->w[r->n++] = (uint32_t)carry;
}

/* |r| = |a| - |b| for |a| >= |b|; r may be a or b. */
static void mag_sub(hd__big_t *r, const hd__big_t *a, const hd__big_t *b) {
    int64_t borrow = 0;
    for (int i = 0; i < a->n; i++) {
        int64_t s = (int64_t)a->w[i] - (i < b->n ? b->w[i] : 0) - borrow;
        borrow = s < 0;
        r->w[i] = (uint32_t)(s + (borrow << 32));
    }
    r->n = a->n;
}

/* r = a + (neg_b ? -b : b), signs and magnitudes. */
static void big_addsigned(hd__big_t *r, const hd__big_t *a, const hd__big_t *b, int neg_b) {
    int na = a->neg;
    if (na == neg_b) {
        mag_add(r, a, b);
        r->neg = na;
    } else if (mag_cmp(a, b) >= 0) {
        mag_sub(r, a, b);
        r->neg = na;
    } else {
        mag_sub(r, b, a);
        r->neg = neg_b;
    }
    big_trim(r);
}

void hd__big_add(hd__big_t *r, const hd__big_t *a, const hd__big_t *b) {
    big_addsigned(r, a, b, b->neg);
}

void hd__big_sub(hd__big_t *r, const hd__big_t *a, const hd__big_t *b) {
    big_addsigned(r, a, b, !b->neg && b->n > 0);
}

void hd__big_mul(hd__big_t *r, const hd__big_t *a, const hd__big_t *b) {
    int n = a->n + b->n;
    if (a->n == 0 || b->n == 0) { r->n = 0; r->neg = 0; return; }
    if (n > HD__BIG_LIMBS) n = HD__BIG_LIMBS;   /* unreachable in the domain */
    memset(r->w, 0, (size_t)n * sizeof r->w[0]);
    for (int i = 0; i < a->n; i++) {
        uint64_t carry = 0, ai = a->w[i];
        for (int j = 0; j < b->n && i + j < n; j++) {
            uint64_t t = ai * b->w[j] + r->w[i + j] + carry;
            r->w[i + j] = (uint32_t)t;
            carry = t >> 32;
        }
        if (i + b->n < n) r->w[i + b->n] = (uint32_t)carry;
    }
    r->n = n;
    r->neg = a->neg != b->neg;
    big_trim(r);
}

void hd__big_shl(hd__big_t *r, const hd__big_t *a, int bits) {
    int limbs = bits / 32, s = bits % 32, n = a->n + limbs + 1;
    if (a->n == 0) { r->n = 0; r->neg = 0; return; }
    if (n > HD__BIG_LIMBS) n = HD__BIG_LIMBS;   /* unreachable in the domain */
    uint32_t out[HD__BIG_LIMBS];
    memset(out, 0, (size_t)n * sizeof out[0]);
    for (int i = 0; i < a->n && i + limbs < n; i++) {
        uint64_t v = (uint64_t)a->w[i] << s;
        out[i + limbs] |= (uint32_t)v;
        if (i + limbs + 1 < n) out[i + limbs + 1] |= (uint32_t)(v >> 32);
    }
    memcpy(r->w, out, (size_t)n * sizeof out[0]);
    r->n = n;
    r->neg = a->neg;
    big_trim(r);
}

int hd__big_sign(const hd__big_t *a) { return a->n == 0 ? 0 : a->neg ? -1 : 1; }

int hd__big_cmp(const hd__big_t *a, const hd__big_t *b) {
    int sa = hd__big_sign(a), sb = hd__big_sign(b);
    if (sa != sb) return sa < sb ? -1 : 1;
    int m = mag_cmp(a, b);
    return sa < 0 ? -m : m;
}

double hd__big_frexp(const hd__big_t *a, int *k) {
    if (a->n == 0) { *k = 0; return 0; }
    int top = 31;
    while (!(a->w[a->n - 1] >> top)) top--;
    int bits = (a->n - 1) * 32 + top + 1;     /* a in [2^(bits-1), 2^bits) */
    uint64_t m = 0;
    for (int i = bits - 1, j = 0; i >= 0 && j < 64; i--, j++)
        m = (m << 1) | ((a->w[i / 32] >> (i % 32)) & 1);
    int got = bits < 64 ? bits : 64;
    *k = bits;
    double f = ldexp((double)m, -got);        /* in [0.5, 1], rounded */
    return a->neg ? -f : f;
}

/* ---- vectors of integers ------------------------------------------------ */

typedef struct { hd__big_t x[3]; } vec_t;

static void v_sub(vec_t *r, const vec_t *a, const vec_t *b) {
    for (int i = 0; i < 3; i++) hd__big_sub(&r->x[i], &a->x[i], &b->x[i]);
}

static void v_dot(hd__big_t *r, const vec_t *a, const vec_t *b) {
    hd__big_t t;
    hd__big_mul(r, &a->x[0], &b->x[0]);
    hd__big_mul(&t, &a->x[1], &b->x[1]);
    hd__big_add(r, r, &t);
    hd__big_mul(&t, &a->x[2], &b->x[2]);
    hd__big_add(r, r, &t);
}

static void v_cross(vec_t *r, const vec_t *a, const vec_t *b) {
    hd__big_t s, t;
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        hd__big_mul(&s, &a->x[j], &b->x[k]);
        hd__big_mul(&t, &a->x[k], &b->x[j]);
        hd__big_sub(&r->x[i], &s, &t);
    }
}

/* ---- the squared distance ------------------------------------------------ */

/* A squared distance N / M with the feature it belongs to and the parameter
 * that places the closest point on it (num / den: t on an edge). */
typedef struct {
    hd__big_t N, M;
    hd__tri_feature_t feature;
    double t;
} sqd_t;

static double ratio(const hd__big_t *a, const hd__big_t *b) {
    int ka, kb;
    double fa = hd__big_frexp(a, &ka), fb = hd__big_frexp(b, &kb);
    return fb == 0 ? 0 : ldexp(fa / fb, ka - kb);
}

static void set_vertex(sqd_t *r, const vec_t *xp, hd__tri_feature_t f) {
    v_dot(&r->N, xp, xp);
    hd__big_set_u64(&r->M, 1);
    r->feature = f;
    r->t = 0;
}

/* The edge from X to Y, given XP = P - X, YP = P - Y and XY = Y - X. */
static void edge(sqd_t *r, const vec_t *xp, const vec_t *yp, const vec_t *xy,
                 hd__tri_feature_t fe, hd__tri_feature_t fx, hd__tri_feature_t fy) {
    hd__big_t num, den;
    v_dot(&den, xy, xy);
    v_dot(&num, xp, xy);
    if (hd__big_sign(&den) == 0 || hd__big_sign(&num) <= 0) { set_vertex(r, xp, fx); return; }
    if (hd__big_cmp(&num, &den) >= 0) { set_vertex(r, yp, fy); return; }
    vec_t c;
    v_cross(&c, xp, xy);
    v_dot(&r->N, &c, &c);
    r->M = den;
    r->feature = fe;
    r->t = ratio(&num, &den);
}

/* a < b for squared distances N / M (M > 0). */
static int sqd_less(const sqd_t *a, const sqd_t *b) {
    hd__big_t l, r;
    hd__big_mul(&l, &a->N, &b->M);
    hd__big_mul(&r, &b->N, &a->M);
    return hd__big_cmp(&l, &r) < 0;
}

typedef struct {
    vec_t p, a, b, c;
} ipts_t;

/* The closest feature and its squared distance (the file's comment). */
static void nearest(const ipts_t *q, sqd_t *best, double w[3]) {
    vec_t ab, ac, bc, ca, ap, bp, cp, n, t;
    hd__big_t nn, s, g;
    v_sub(&ab, &q->b, &q->a);
    v_sub(&ac, &q->c, &q->a);
    v_sub(&bc, &q->c, &q->b);
    v_sub(&ca, &q->a, &q->c);
    v_sub(&ap, &q->p, &q->a);
    v_sub(&bp, &q->p, &q->b);
    v_sub(&cp, &q->p, &q->c);
    v_cross(&n, &ab, &ac);
    v_dot(&nn, &n, &n);
    if (hd__big_sign(&nn) > 0) {
        /* Signed areas: n.(BC x BP) weighs A, n.(CA x CP) B, n.(AB x AP) C. */
        const vec_t *e[3] = {&bc, &ca, &ab}, *o[3] = {&bp, &cp, &ap};
        int inside = 1;
        for (int i = 0; i < 3 && inside; i++) {
            v_cross(&t, e[i], o[i]);
            v_dot(&s, &n, &t);
            inside = hd__big_sign(&s) >= 0;
            w[i] = ratio(&s, &nn);
        }
        if (inside) {
            v_dot(&g, &n, &ap);
            hd__big_mul(&best->N, &g, &g);
            best->M = nn;
            best->feature = HD__TRI_FACE;
            return;
        }
    }
    sqd_t cand;
    edge(best, &ap, &bp, &ab, HD__TRI_EDGE_AB, HD__TRI_VERTEX_A, HD__TRI_VERTEX_B);
    edge(&cand, &bp, &cp, &bc, HD__TRI_EDGE_BC, HD__TRI_VERTEX_B, HD__TRI_VERTEX_C);
    if (sqd_less(&cand, best)) *best = cand;
    edge(&cand, &cp, &ap, &ca, HD__TRI_EDGE_CA, HD__TRI_VERTEX_C, HD__TRI_VERTEX_A);
    if (sqd_less(&cand, best)) *best = cand;
}

/* ---- rounding ------------------------------------------------------------- */

/* The sign of t - K 2^F, t = 2^e0 sqrt(N / M). */
static int cmp_mid(const sqd_t *d, int e0, uint64_t K, int F) {
    hd__big_t k, k2, rhs, lhs;
    hd__big_set_u64(&k, K);
    hd__big_mul(&k2, &k, &k);
    hd__big_mul(&rhs, &k2, &d->M);
    int sh = 2 * e0 - 2 * F;
    if (sh >= 0) {
        hd__big_shl(&lhs, &d->N, sh);
        return hd__big_cmp(&lhs, &rhs);
    }
    hd__big_shl(&lhs, &rhs, -sh);
    return hd__big_cmp(&d->N, &lhs);
}

/* q = Q 2^g with Q < 2^53 (Q < 2^52 only for subnormals and zero). */
static void decompose(double q, uint64_t *Q, int *g) {
    if (q == 0) { *Q = 0; *g = -1074; return; }
    int k;
    double f = frexp(q, &k);
    if (k - 53 < -1074) { *Q = (uint64_t)ldexp(q, 1074); *g = -1074; return; }
    *Q = (uint64_t)ldexp(f, 53);
    *g = k - 53;
}

/* The double nearest 2^e0 sqrt(N / M), ties to even. */
static double round_sqrt(const sqd_t *d, int e0) {
    if (hd__big_sign(&d->N) == 0) return 0;
    int kn, km;
    double fn = hd__big_frexp(&d->N, &kn), fm = hd__big_frexp(&d->M, &km);
    int E = kn - km;
    if (E & 1) { fn *= 2; E--; }
    double q = ldexp(sqrt(fn / fm), E / 2 + e0);
    for (;;) {
        uint64_t Q;
        int g;
        decompose(q, &Q, &g);
        int hi = cmp_mid(d, e0, 2 * Q + 1, g - 1);
        if (hi > 0) { q = nextafter(q, INFINITY); continue; }
        if (hi == 0) return (Q & 1) ? nextafter(q, INFINITY) : q;
        if (Q == 0) return q;
        int lo = (Q == (UINT64_C(1) << 52) && g > -1074) ? cmp_mid(d, e0, 4 * Q - 1, g - 2)
                                                          : cmp_mid(d, e0, 2 * Q - 1, g - 1);
        if (lo < 0) { q = nextafter(q, 0); continue; }
        if (lo == 0) return (Q & 1) ? nextafter(q, 0) : q;
        return q;
    }
}

/* ---- the closest point ---------------------------------------------------- */

static void place(hd__tri_near_t *out, const double *p, const double *a, const double *b,
                  const double *c, const double w[3], double t) {
    const double *x = a, *y = b;
    double wa = 0, wb = 0, wc = 0;
    switch (out->feature) {
    case HD__TRI_FACE: {
        double s = w[0] + w[1] + w[2];
        wa = w[0] / s; wb = w[1] / s; wc = w[2] / s;
        for (int i = 0; i < 3; i++) out->point[i] = wa * a[i] + wb * b[i] + wc * c[i];
        break;
    }
    case HD__TRI_VERTEX_A: wa = 1; memcpy(out->point, a, sizeof out->point); break;
    case HD__TRI_VERTEX_B: wb = 1; memcpy(out->point, b, sizeof out->point); break;
    case HD__TRI_VERTEX_C: wc = 1; memcpy(out->point, c, sizeof out->point); break;
    case HD__TRI_EDGE_AB: x = a; y = b; wa = 1 - t; wb = t; break;
    case HD__TRI_EDGE_BC: x = b; y = c; wb = 1 - t; wc = t; break;
    case HD__TRI_EDGE_CA: x = c; y = a; wc = 1 - t; wa = t; break;
    }
    if (out->feature >= HD__TRI_EDGE_AB && out->feature <= HD__TRI_EDGE_CA)
        for (int i = 0; i < 3; i++) out->point[i] = x[i] + t * (y[i] - x[i]);
    out->bary[0] = wa;
    out->bary[1] = wb;
    out->bary[2] = wc;
    (void)p;
}

int hd__tri_nearest_exact(const double p[3], const double a[3], const double b[3],
                          const double c[3], hd__tri_near_t *out) {
    const double *pts[4] = {p, a, b, c};
    int e0 = 0, any = 0;
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) {
            double x = pts[i][k];
            if (!(fabs(x) <= 0x1p511)) return HD_ERANGE;
            if (x == 0) continue;
            int e = hd__ulp_exp(x);
            if (!any || e < e0) e0 = e;
            any = 1;
        }
    ipts_t q;
    vec_t *v[4] = {&q.p, &q.a, &q.b, &q.c};
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) hd__big_set_double(&v[i]->x[k], pts[i][k], e0);
    sqd_t best;
    double w[3] = {0, 0, 0};
    best.t = 0;
    nearest(&q, &best, w);
    out->d = round_sqrt(&best, e0);
    out->feature = best.feature;
    out->exact = 1;
    place(out, p, a, b, c, w, best.t);
    return HD_OK;
}
