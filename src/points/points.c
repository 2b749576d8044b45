/*
 * points.c -- views over caller memory, their validation, and packed copies.
 *
 * A view (hd_points_t) is a pointer, a count and two byte strides, so it can
 * describe packed xyz, a struct-of-points with other fields, a numpy array in
 * C or Fortran order, or a negative-stride slice, without copying.  Every
 * entry point validates its views once, in one pass that also computes the
 * bounding box: a set must be non-empty, finite, and within HD_MAX_COORD so
 * that no squared difference can overflow (3 * (2e153)^2 < DBL_MAX).
 * Validation messages name the set and the first offending point.
 */
#include "points/points.h"

#include <math.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
#include <stdlib.h>
#include <string.h>

hd_points_t hd_points_f64(const double *xyz, size_t count) {
    hd_points_t p;
    p.data = xyz;
    p.count = count;
    p.dtype = HD_FLOAT64;
    p.stride = 0;
    p.cstride = 0;
    return p;
}

hd_points_t hd_points_f32(const float *xyz, size_t count) {
    hd_points_t p = hd_points_f64(NULL, count);
    p.data = xyz;
    p.dtype = HD_FLOAT32;
    return p;
}

static void strides(const hd_points_t *p, ptrdiff_t *ps, ptrdiff_t *cs) {
    ptrdiff_t el = p->dtype == HD_FLOAT32 ? (ptrdiff_t)sizeof(float)
                                          : (ptrdiff_t)sizeof(double);
    *cs = p->cstride ? p->cstride : el;
    *ps = p->stride ? p->stride : 3 * el;
}

void hd_points_get(const hd_points_t *p, size_t k, double out[3]) {
    ptrdiff_t ps, cs;
    strides(p, &ps, &cs);
    const char *base = (const char *)p->data + (ptrdiff_t)k * ps;
    if (p->dtype == HD_FLOAT32) {
        for (int c = 0; c < 3; c++) {
            float v;
            memcpy(&v, base + c * cs, sizeof v);
            out[c] = (double)v;
        }
    } else {
        for (int c = 0; c < 3; c++) memcpy(&out[c], base + c * cs, sizeof(double));
    }
}

/* Four points (twelve doubles) a step, as six pairs of lanes: pair j
 * holds coordinates 2j and 2j + 1 of the step, so coordinate c of the
 * box is the bound over the lanes holding c.  _mm_min_pd(a, b) is a < b ?
 * a : b, lane by lane, as the scalar loop's select; |v| <= HD_MAX_COORD is
 * false for NaN and infinities.  The scalar loop, which the compiler does
 * not vectorise, takes more instructions a point (callgrind on hd_bench's
 * cases; the counts are in docs/benchmarks.md). */
HD__HOT int hd__box_checked(const double *xyz, size_t n, hd__box_t *out) {
    double lo[3] = {xyz[0], xyz[1], xyz[2]}, hi[3] = {xyz[0], xyz[1], xyz[2]};
    int ok = 1;
    size_t k = 0;
#ifdef __SSE2__
    if (n >= 4) {
        const __m128d sign = _mm_set1_pd(-0.0), top = _mm_set1_pd(HD_MAX_COORD);
        __m128d l[6], h[6], good = _mm_castsi128_pd(_mm_set1_epi32(-1));
        for (int j = 0; j < 6; j++) l[j] = h[j] = _mm_loadu_pd(xyz + 2 * j);
        for (; k + 4 <= n; k += 4) {
            const double *q = xyz + 3 * k;
            for (int j = 0; j < 6; j++) {
                __m128d v = _mm_loadu_pd(q + 2 * j);
                good = _mm_and_pd(good, _mm_cmple_pd(_mm_andnot_pd(sign, v), top));
                l[j] = _mm_min_pd(v, l[j]);
                h[j] = _mm_max_pd(v, h[j]);
            }
        }
        ok = _mm_movemask_pd(good) == 3;
        double L[12], H[12];
        for (int j = 0; j < 6; j++) _mm_storeu_pd(L + 2 * j, l[j]), _mm_storeu_pd(H + 2 * j, h[j]);
        for (int j = 0; j < 12; j++) {
            int c = j % 3;
            lo[c] = L[j] < lo[c] ? L[j] : lo[c];
            hi[c] = H[j] > hi[c] ? H[j] : hi[c];
        }
    }
#endif
    for (; k < n; k++)
        for (int c = 0; c < 3; c++) {
            double v = xyz[3 * k + (size_t)c];
            ok &= fabs(v) <= HD_MAX_COORD;
            lo[c] = v < lo[c] ? v : lo[c];
            hi[c] = v > hi[c] ? v : hi[c];
        }
    /* In locals until here: *out may alias xyz as far as the compiler knows. */
    for (int c = 0; c < 3; c++) out->lo[c] = lo[c], out->hi[c] = hi[c];
    return ok;
}

void hd__box_of(const double *xyz, size_t n, hd__box_t *out) { (void)hd__box_checked(xyz, n, out); }

int hd__points_aligned(const hd_points_t *p, const char *what, hd_error_t *err) {
    hd__src_t s;
    hd__src_init(&s, p, NULL);
    size_t el = p->dtype == HD_FLOAT32 ? sizeof(float) : sizeof(double);
    if (s.kind != HD__SRC_ANY && (uintptr_t)p->data % el != 0)
        return hd__err(err, HD_EINVAL,
                       "point set %s: packed %s data must be aligned to %zu bytes (its address is not a "
                       "multiple of %zu)",
                       what, p->dtype == HD_FLOAT32 ? "float" : "double", el, el);
    return HD_OK;
}

int hd__points_check(const hd_points_t *p, const char *what, hd__box_t *box,
                     hd_error_t *err) {
    if (!p) return hd__err(err, HD_EINVAL, "point set %s is NULL", what);
    if (p->count == 0) return hd__err(err, HD_EEMPTY, "point set %s is empty", what);
    if (!p->data) return hd__err(err, HD_EINVAL, "point set %s has no data", what);
    if (p->dtype != HD_FLOAT64 && p->dtype != HD_FLOAT32)
        return hd__err(err, HD_EINVAL, "point set %s has an unknown element type", what);
    int rc = hd__points_aligned(p, what, err);
    if (rc) return rc;
    hd__box_t b;
    for (size_t k = 0; k < p->count; k++) {
        double q[3];
        hd_points_get(p, k, q);
        for (int c = 0; c < 3; c++) {
            if (!isfinite(q[c]))
                return hd__err(err, HD_ENONFINITE,
                               "point set %s: point %zu has %s coordinate", what,
                               k, isnan(q[c]) ? "a NaN" : "an infinite");
            if (fabs(q[c]) > HD_MAX_COORD)
                return hd__err(err, HD_ERANGE,
                               "point set %s: point %zu has coordinate %g, beyond "
                               "the limit 1e153 where squared distances could "
                               "overflow",
                               what, k, q[c]);
        }
        if (k == 0) {
            for (int c = 0; c < 3; c++) b.lo[c] = b.hi[c] = q[c];
        } else {
            for (int c = 0; c < 3; c++) {
                if (q[c] < b.lo[c]) b.lo[c] = q[c];
                if (q[c] > b.hi[c]) b.hi[c] = q[c];
            }
        }
    }
    if (box) *box = b;
    return HD_OK;
}

int hd__points_f64(const hd_points_t *p, const hd_transform_t *T,
                   double **owned, const double **xyz, hd_error_t *err) {
    *owned = NULL;
    ptrdiff_t ps, cs;
    strides(p, &ps, &cs);
    if (!T && p->dtype == HD_FLOAT64 && ps == 3 * (ptrdiff_t)sizeof(double) &&
        cs == (ptrdiff_t)sizeof(double)) {
        *xyz = p->data;
        return HD_OK;
    }
    double *c = hd__malloc_array(p->count, 3 * sizeof(double));
    if (!c) return hd__err(err, HD_ENOMEM, "cannot allocate %zu points", p->count);
    for (size_t k = 0; k < p->count; k++) {
        double q[3];
        hd_points_get(p, k, q);
        if (T) hd__transform_apply(T, q, c + 3 * k);
        else memcpy(c + 3 * k, q, sizeof q);
    }
    *owned = c;
    *xyz = c;
    return HD_OK;
}

void hd_transform_identity(hd_transform_t *T) {
    memset(T, 0, sizeof *T);
    T->r[0] = T->r[4] = T->r[8] = 1.0;
}
