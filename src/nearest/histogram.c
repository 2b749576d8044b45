/*
 * histogram.c -- numpy.histogram's rule for placing a value in a bin, and
 * when an interval of values is placed alike (the histogram of the nearest
 * distances from bounds, allnearest.c's hd__an_hist).
 *
 * The rule (numpy.histogram(values, bins, range=(lo, hi)), numpy's
 * _search_sorted-free path): edges k * ((hi - lo) / bins) + lo, the last hi
 * itself; a value x in [lo, hi] gets the guess g = floor((x - lo) * norm),
 * clamped to bins - 1, then one correction: g - 1 when x < edge g, g + 1
 * when g is not the last bin and x >= edge g + 1.  On a subnormal range
 * (norm infinite) the bin is the last whose lower edge is at most x.
 *
 * Why an interval [l, u] decided by its ends is decided throughout: the
 * guess is a composition of rounded subtraction, rounded multiplication by
 * a positive number, floor and clamping, each non-decreasing, so every x
 * in [l, u] has a guess between those of l and u, the same g when theirs
 * are equal.  For that fixed g the corrected bin is non-decreasing in x
 * (the edges are non-decreasing), so it equals the common bin of l and u.
 * On a subnormal range the bin (the guess) is itself non-decreasing.
 * Being inside [lo, hi] is an interval condition, so l and u both inside,
 * both below lo or both above hi decide x alike too.
 */
#include "nearest/nearest.h"

#include <math.h>
#include <string.h>

int hd__hist_init(hd__hist_t *h, double lo, double hi, size_t bins, hd_error_t *err) {
    if (bins == 0) return hd__err(err, HD_EINVAL, "a histogram needs at least one bin");
    if (!isfinite(lo) || !isfinite(hi) || lo > hi)
        return hd__err(err, HD_EINVAL, "histogram range [%g, %g] is not a finite interval", lo, hi);
    if (lo == hi) lo = lo - 0.5, hi = hi + 0.5; /* numpy widens an empty range */
    if (!isfinite(hi - lo)) return hd__err(err, HD_ERANGE, "histogram range [%g, %g] is too wide", lo, hi);
    h->lo = lo, h->hi = hi, h->bins = bins;
    h->norm = (double)bins / (hi - lo);
    return HD_OK;
}

double hd__hist_edge(const hd__hist_t *h, size_t k) {
    if (k >= h->bins) return h->hi;
    double delta = h->hi - h->lo, step = delta / (double)h->bins;
    if (step == 0.0) return (double)k / (double)h->bins * delta + h->lo;
    return (double)k * step + h->lo;
}

size_t hd__hist_place(const hd__hist_t *h, double x, size_t *guess) {
    size_t bins = h->bins, b;
    *guess = SIZE_MAX;
    if (!(x >= h->lo && x <= h->hi)) return SIZE_MAX; /* outside, or NaN */
    if (isinf(h->norm)) { /* numpy's product is NaN or inf here: bisection of the edges */
        size_t top = bins - 1;
        b = 0;
        while (b < top) {
            size_t mid = b + (top - b + 1) / 2;
            if (x >= hd__hist_edge(h, mid)) b = mid;
            else top = mid - 1;
        }
        *guess = b;
        return b;
    }
    double f = (x - h->lo) * h->norm;
    b = f >= (double)bins ? bins : (size_t)f;
    if (b == bins) b--;
    *guess = b;
    /* numpy's corrections for values that rounding put in a neighbour */
    if (x < hd__hist_edge(h, b)) b--;
    else if (b != bins - 1 && x >= hd__hist_edge(h, b + 1)) b++;
    return b;
}

int hd__hist_decided(const hd__hist_t *h, double l, double u, size_t *bin) {
    if (u < h->lo || l > h->hi) {
        *bin = SIZE_MAX;
        return 1;
    }
    size_t gl, gu, bl = hd__hist_place(h, l, &gl), bu = hd__hist_place(h, u, &gu);
    *bin = bl;
    return bl != SIZE_MAX && bl == bu && gl == gu;
}
