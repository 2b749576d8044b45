/*
 * select.c -- the k-th smallest of n doubles without sorting them all
 * (introselect), and percentiles with numpy's default interpolation.
 *
 * A percentile of per-point distances needs the values of one or two ranks,
 * not the whole order: quickselect finds a rank in expected linear time.
 * Two things make the plain algorithm unsafe here, and both are handled:
 *  - Ties.  Distances between lattice points or voxel centres repeat
 *    massively (a mask's surface has a few dozen distinct distances for a
 *    million points).  A two-way partition degrades to quadratic time on
 *    such input, so every partition here is three-way (Dijkstra's "Dutch
 *    national flag"): values below, equal to and above the pivot.  A rank
 *    that falls into the equal block is answered at once.
 *  - Adversarial order.  The pivot is the median of three (the ninther on
 *    large ranges), deterministic, so some inputs could still defeat it.
 *    As in Musser's introselect, after 2*log2(n) partitions that did not
 *    settle the rank the remaining range is sorted (qsort), which bounds the
 *    worst case by O(n log n).
 * Invariant after hd__select(v, n, k): v is a permutation of its input,
 * v[i] <= v[k] for i < k and v[i] >= v[k] for i > k.  NaN has no rank; the
 * callers refuse it before selecting.
 *
 * The percentile follows numpy.percentile(v, p) with method "linear"
 * (Hyndman & Fan's definition 7) to the bit, as numpy 1.22+ computes it:
 * q = p / 100, pos = (n - 1) * q, lo = floor(pos), t = pos - lo, and the
 * value between the ranks lo and lo + 1 is interpolated by numpy's _lerp:
 * a + (b - a) * t, or b - (b - a) * (1 - t) when t >= 0.5 (numpy's way of
 * making the result monotone in t).  When pos >= n - 1 the result is the
 * maximum.  Nothing here follows the paper, which has no percentiles.
 */
#include "base/base.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int cmp_double(const void *x, const void *y) {
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

HD__INLINE void swap(double *v, size_t i, size_t j) {
    double t = v[i];
    v[i] = v[j];
    v[j] = t;
}

static double median3(double a, double b, double c) {
    if (a < b) {
        if (b < c) return b;
        return a < c ? c : a;
    }
    if (a < c) return a;
    return b < c ? c : b;
}

/* Pivot value for v[lo..hi): median of three, ninther above 128 values. */
static double pivot_of(const double *v, size_t lo, size_t hi) {
    size_t n = hi - lo, mid = lo + n / 2;
    if (n < 128) return median3(v[lo], v[mid], v[hi - 1]);
    size_t s = n / 8;
    return median3(median3(v[lo], v[lo + s], v[lo + 2 * s]),
                   median3(v[mid - s], v[mid], v[mid + s]),
                   median3(v[hi - 1 - 2 * s], v[hi - 1 - s], v[hi - 1]));
}

void hd__select(double *v, size_t n, size_t k) {
    size_t lo = 0, hi = n;
    int budget = 2;
    for (size_t m = n; m > 1; m >>= 1) budget += 2;
    while (hi - lo > 1) {
        if (budget-- == 0) {
            qsort(v + lo, hi - lo, sizeof *v, cmp_double);
            return;
        }
        double p = pivot_of(v, lo, hi);
        /* three-way partition: [lo,lt) < p, [lt,gt) == p, [gt,hi) > p */
        size_t lt = lo, i = lo, gt = hi;
        while (i < gt) {
            if (v[i] < p) swap(v, lt++, i++);
            else if (v[i] > p) swap(v, i, --gt);
            else i++;
        }
        if (k < lt) hi = lt;
        else if (k >= gt) lo = gt;
        else return;
    }
}

/* numpy's _lerp, including its correction for t >= 0.5. */
double hd__lerp(double a, double b, double t) {
    double d = b - a;
    if (t >= 0.5) return b - d * (1.0 - t);
    return a + d * t;
}

double hd__percentile_pos(size_t n, double p) {
    double q = p / 100.0;
    return (double)(n - 1) * q;
}

void hd__percentile_ranks(size_t n, double p, size_t *lo, size_t *hi, double *t) {
    double pos = hd__percentile_pos(n, p);
    if (pos >= (double)(n - 1)) {
        /* numpy takes the last element twice, weight pos - (-1) */
        *lo = *hi = n - 1;
        *t = pos + 1.0;
    } else {
        double f = floor(pos);
        *lo = (size_t)f;
        *hi = *lo + 1;
        *t = pos - f;
    }
}

int hd__nan_check(const double *d, size_t n, size_t first, const char *what, hd_error_t *err) {
    for (size_t i = 0; i < n; i++)
        if (isnan(d[i])) return hd__err(err, HD_ENONFINITE, "distance %zu of %s is NaN", first + i, what);
    return HD_OK;
}

int hd__percentile_check(double p, hd_error_t *err) {
    if (!(p >= 0.0 && p <= 100.0))
        return hd__err(err, HD_EINVAL, "percentile must be in [0, 100], not %g", p);
    return HD_OK;
}

/* Percentiles of v[0..n) (n > 0, no NaN), reordering v.  The requests
 * are answered in increasing order of rank; selecting a rank leaves every
 * larger rank in v[rank..n), so each later selection works on that tail
 * only. */
typedef struct {
    double pos;
    size_t slot;
} request_t;

static int cmp_request(const void *x, const void *y) {
    const request_t *a = x, *b = y;
    return (a->pos > b->pos) - (a->pos < b->pos);
}

int hd__percentiles_inplace(double *v, size_t n, const double *p, size_t np,
                            double *out, hd_error_t *err) {
    request_t *req = hd__malloc_array(np, sizeof *req);
    if (!req) return hd__err(err, HD_ENOMEM, "out of memory for %zu percentiles", np);
    for (size_t r = 0; r < np; r++) {
        req[r].pos = hd__percentile_pos(n, p[r]);
        req[r].slot = r;
    }
    qsort(req, np, sizeof *req, cmp_request);
    size_t base = 0;
    for (size_t r = 0; r < np; r++) {
        size_t k, k1;
        double t;
        hd__percentile_ranks(n, p[req[r].slot], &k, &k1, &t);
        hd__select(v + base, n - base, k - base);
        base = k;
        double a = v[k], b = a;
        if (k1 > k) { /* the smallest of the values above rank k */
            b = v[k + 1];
            for (size_t i = k + 2; i < n; i++)
                if (v[i] < b) b = v[i];
        }
        out[req[r].slot] = hd__lerp(a, b, t);
    }
    free(req);
    return HD_OK;
}

int hd_percentiles(const double *values, size_t n, const double *p, size_t np,
                   double *out, hd_error_t *err) {
    hd__err_clear(err);
    if (!values || !p || !out) return hd__err(err, HD_EINVAL, "values, percentiles or result pointer is NULL");
    if (n == 0) return hd__err(err, HD_EEMPTY, "no values to take a percentile of");
    for (size_t r = 0; r < np; r++) {
        int rc = hd__percentile_check(p[r], err);
        if (rc) return rc;
    }
    double *v = hd__malloc_array(n, sizeof *v);
    if (!v) return hd__err(err, HD_ENOMEM, "cannot copy %zu values", n);
    for (size_t i = 0; i < n; i++) {
        if (isnan(values[i])) {
            free(v);
            return hd__err(err, HD_ENONFINITE, "value %zu is NaN", i);
        }
        v[i] = values[i];
    }
    int rc = hd__percentiles_inplace(v, n, p, np, out, err);
    free(v);
    return rc;
}

int hd_percentile(const double *values, size_t n, double p, double *out,
                  hd_error_t *err) {
    return hd_percentiles(values, n, &p, 1, out, err);
}
