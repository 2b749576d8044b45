/*
 * xsum.c -- exact sums of doubles, rounded once (base.h, "exact sums"), and
 * the summary figures derived from them.
 *
 * Why exact: a mean of per-point distances computed in one order (even
 * compensated, as Neumaier's summation was here) depends on that order in
 * its last bit, so the same distances split over MPI ranks, or over
 * threads, would give another mean.  The exact sum of the doubles is one
 * number whatever the order; rounded once to nearest even it is the
 * correctly rounded sum (what Python's math.fsum returns), at least as
 * accurate as any compensated sum.
 *
 * How: every finite double is m 2^(p - 1074) with an integer m < 2^53 and
 * 0 <= p <= 2045 (p = biased exponent - 1, 0 for subnormals), so every sum
 * of them is an integer multiple of 2^-1074: a fixed-point number.  It is
 * held in HD__XSUM_LIMBS int64 limbs of 32-bit digits (limb k weighs
 * 2^(32 k - 1074)); an addition splits m << (p mod 32) (at most 84 bits)
 * into its low 32 bits and the rest (< 2^52) and adds (or subtracts) them
 * to two neighbouring limbs, without a carry (Neal's "small
 * superaccumulator" does the same with other sizes): `pending` counts the
 * additions since the limbs were last normalised, which happens before any
 * limb can overflow (HD__XSUM_PENDING_MAX = 2^10 additions of less than
 * 2^52 each stay below 2^62).  A loop counts its additions a block of 512
 * at a time (hd__xsum_add_uncounted, hd__xsum_count), so the counter stays
 * in a register.  Normalising carries each limb's excess into the next
 * (the division by 2^32 is exact: v - (v mod 2^32)), every 512 additions:
 * 70 limbs, a fraction of an operation per addition.  The top limb keeps
 * the sign, and the 70 limbs reach 2^1166, so the sum of 2^64 doubles
 * (< 2^1088) never reaches it.  Cost: about 1-2 ns a value more than
 * Neumaier's summation (docs/benchmarks.md, "Exact sums").
 *
 * Rounding: the normalised limbs are a two's complement number; a negative
 * one is negated limb by limb and normalised again, so the magnitude is a
 * plain binary integer N (in units of 2^-1074).  With h its highest set
 * bit: h < 53 means N itself is a double's significand (the result is
 * N 2^-1074, exact: subnormal or the lowest binade of normals, where the
 * spacing is 2^-1074 too); otherwise the significand is bits h-52..h, the
 * rounding bit is bit h-53 and the sticky bit is any bit below it, rounded
 * to nearest, ties to even (a carry out of the significand moves h up by
 * one).  ldexp of the 53-bit significand is then exact, or infinite when
 * h >= 2098, i.e. the rounded value is 2^1024 or more (the sums from
 * 2^1024 - 2^970, halfway between DBL_MAX and 2^1024, round there: DBL_MAX's
 * significand is odd).  Infinities and NaN are counted apart and decide the
 * result as IEEE addition would (+inf and -inf together give NaN).
 *
 * The tests: tests/api/test_sums.c against Python's math.fsum (expected bits
 * written into the test when it was generated).
 */
#include "base/base.h"

#include <assert.h>
#include <math.h>
#include <string.h>

void hd__xsum_init(hd__xsum_t *s) {
    memset(s, 0, sizeof *s);
}

void hd__xsum_normalize(hd__xsum_t *s) {
    int64_t carry = 0;
    for (int k = 0; k < HD__XSUM_LIMBS - 1; k++) {
        int64_t v = s->limb[k] + carry;
        int64_t lo = v & (int64_t)0xffffffff;
        carry = (v - lo) / ((int64_t)1 << 32);
        s->limb[k] = lo;
    }
    s->limb[HD__XSUM_LIMBS - 1] += carry;
    s->pending = 1;
}

void hd__xsum_add_special(hd__xsum_t *s, double x) {
    if (isnan(x)) s->nan++;
    else if (x > 0) s->pinf++;
    else s->ninf++;
}

void hd__xsum_merge(hd__xsum_t *dst, const hd__xsum_t *src) {
    hd__xsum_t t = *src;
    hd__xsum_normalize(&t);
    if (dst->pending > HD__XSUM_PENDING_MAX / 2) hd__xsum_normalize(dst);
    for (int k = 0; k < HD__XSUM_LIMBS; k++) dst->limb[k] += t.limb[k];
    dst->pending += t.pending;
    dst->pinf += t.pinf;
    dst->ninf += t.ninf;
    dst->nan += t.nan;
}

/* Bit b of the normalised, non-negative limbs. */
static uint64_t bit_at(const int64_t *l, int b) {
    return ((uint64_t)l[b >> 5] >> (b & 31)) & 1;
}

/* Bits lo .. lo + 52 (at most 53; those above the limbs are 0). */
static uint64_t bits53(const int64_t *l, int lo) {
    int w = lo >> 5, sh = lo & 31;
    uint64_t x = (uint64_t)l[w] >> sh;
    if (w + 1 < HD__XSUM_LIMBS) x |= (uint64_t)l[w + 1] << (32 - sh);
    if (sh && w + 2 < HD__XSUM_LIMBS) x |= (uint64_t)l[w + 2] << (64 - sh);
    return x & (((uint64_t)1 << 53) - 1);
}

/* Any bit below b set? */
static int any_below(const int64_t *l, int b) {
    int w = b >> 5;
    for (int k = 0; k < w; k++)
        if (l[k]) return 1;
    return ((uint64_t)l[w] & (((uint64_t)1 << (b & 31)) - 1)) != 0;
}

double hd__xsum_round(const hd__xsum_t *s) {
    if (s->nan || (s->pinf && s->ninf)) return NAN;
    if (s->pinf) return INFINITY;
    if (s->ninf) return -INFINITY;
    hd__xsum_t t = *s;
    hd__xsum_normalize(&t);
    double sign = 1.0;
    if (t.limb[HD__XSUM_LIMBS - 1] < 0) {
        for (int k = 0; k < HD__XSUM_LIMBS; k++) t.limb[k] = -t.limb[k];
        hd__xsum_normalize(&t);
        sign = -1.0;
    }
    int top = HD__XSUM_LIMBS - 1;
    while (top >= 0 && t.limb[top] == 0) top--;
    if (top < 0) return 0.0;
    /* the top limb of a sum of doubles is far below it: < 2^32 */
    assert(top < HD__XSUM_LIMBS - 1 && t.limb[top] < ((int64_t)1 << 32));
    int h = 32 * top + 31;
    while (!bit_at(t.limb, h)) h--;
    if (h < 53) return sign * ldexp((double)bits53(t.limb, 0), -1074);
    uint64_t m = bits53(t.limb, h - 52);
    if (bit_at(t.limb, h - 53) && ((m & 1) || any_below(t.limb, h - 53))) {
        m++;
        if (m == (uint64_t)1 << 53) {
            m >>= 1;
            h++;
        }
    }
    return sign * ldexp((double)m, h - 52 - 1074);
}

double hd__xsum_values(hd__xsum_t *sum, hd__xsum_t *sum2, const double *d, size_t n, double m) {
    enum { BLOCK = HD__XSUM_PENDING_MAX / 2 };
    for (size_t k0 = 0; k0 < n; k0 += BLOCK) {
        size_t k1 = n - k0 < BLOCK ? n : k0 + BLOCK;
        for (size_t k = k0; k < k1; k++) {
            double x = d[k];
            m = x > m ? x : m;
            hd__xsum_add_uncounted(sum, x);
            hd__xsum_add_uncounted(sum2, x * x);
        }
        hd__xsum_count(sum, (int64_t)(k1 - k0));
        hd__xsum_count(sum2, (int64_t)(k1 - k0));
    }
    return m;
}

void hd__summary_derive(hd_summary_t *out, size_t n_a, double max_ab, double sum_ab, double sum2_ab,
                        size_t n_b, double max_ba, double sum_ba, double sum2_ba) {
    out->n_ab = n_a;
    out->n_ba = n_b;
    out->max_ab = max_ab;
    out->sum_ab = sum_ab;
    out->sum2_ab = sum2_ab;
    out->mean_ab = sum_ab / (double)n_a;
    out->mean2_ab = sum2_ab / (double)n_a;
    out->max_ba = out->sum_ba = out->sum2_ba = out->mean_ba = out->mean2_ba = NAN;
    out->mean_symmetric = out->mean_average = out->mean_pooled = NAN;
    out->chamfer = out->chamfer_sum2 = out->chamfer_mean = out->chamfer_sum = NAN;
    if (n_b == 0) return;
    out->max_ba = max_ba;
    out->sum_ba = sum_ba;
    out->sum2_ba = sum2_ba;
    out->mean_ba = sum_ba / (double)n_b;
    out->mean2_ba = sum2_ba / (double)n_b;
    out->mean_symmetric = out->mean_ab >= out->mean_ba ? out->mean_ab : out->mean_ba;
    out->mean_average = (out->mean_ab + out->mean_ba) / 2.0;
    out->mean_pooled = (sum_ab + sum_ba) / ((double)n_a + (double)n_b);
    out->chamfer = out->mean2_ab + out->mean2_ba;
    out->chamfer_sum2 = sum2_ab + sum2_ba;
    out->chamfer_mean = out->mean_ab + out->mean_ba;
    out->chamfer_sum = sum_ab + sum_ba;
}
