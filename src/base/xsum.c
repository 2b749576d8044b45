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
 * (< 2^1088) never reaches it.  Its cost against Neumaier's summation is
 * measured by bench/summarize_bench.c (docs/benchmarks.md, "Exact sums").
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
 * Scaled rounding (hd__xsum_round_scaled): the sum times 2^-k rounded once,
 * the same rule with the significand's lowest bit at least bit k (the
 * scaled value's smallest subnormal).  Where no subnormal is involved this
 * is hd__xsum_round's result times 2^-k exactly: scaling by a power of two
 * commutes with rounding.
 *
 * Figures beyond the exponent range: a sum of squared distances within the
 * 1e153 coordinate domain can exceed DBL_MAX (each square is below 1.2e307,
 * so 15 of them can), while the mean of those squares (a Chamfer distance)
 * cannot.  hd__summary_derive computes every figure from the rounded sums;
 * a figure that comes out infinite is computed again from the sums rounded
 * at 2^-SCALE and scaled back.  Every sum of doubles is below 2^1088 (2^64
 * values below 2^1024), so the scaled sums and everything computed from
 * them stay below 2^961, and a figure that overflowed involves a value of
 * at least 2^1023, far above the subnormals, where any smaller operand's
 * scaled rounding is too small to change a result: the figure is the one
 * doubles without an exponent limit would give, the same operations on
 * the same rounded sums, to the bit.  Figures that stay finite are the
 * plain computation's; a figure beyond DBL_MAX stays infinite.
 *
 * The tests: tests/api/test_sums.c against Python's math.fsum (expected bits
 * written into the test when it was generated).
 */
#include "base/base.h"

#include <assert.h>
#include <math.h>
#include <string.h>

/* hd__summary_derive's second computation: sums scaled by 2^-SCALE. */
#define SCALE 128

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

double hd__xsum_round_scaled(const hd__xsum_t *s, int k) {
    assert(k >= 0 && k < 32 * HD__XSUM_LIMBS - 53);
    if (s->nan || (s->pinf && s->ninf)) return NAN;
    if (s->pinf) return INFINITY;
    if (s->ninf) return -INFINITY;
    hd__xsum_t t = *s;
    hd__xsum_normalize(&t);
    double sign = 1.0;
    if (t.limb[HD__XSUM_LIMBS - 1] < 0) {
        for (int j = 0; j < HD__XSUM_LIMBS; j++) t.limb[j] = -t.limb[j];
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
    /* the significand's lowest bit: 53 bits below h + 1, or the scaled
     * value's smallest subnormal, bit k, whichever is higher */
    int lo = h - 52 > k ? h - 52 : k;
    uint64_t m = bits53(t.limb, lo);
    if (lo > 0 && bit_at(t.limb, lo - 1) && ((m & 1) || any_below(t.limb, lo - 1))) {
        m++;
        if (m == (uint64_t)1 << 53) {
            m >>= 1;
            lo++;
        }
    }
    return sign * ldexp((double)m, lo - k - 1074);
}

double hd__xsum_round(const hd__xsum_t *s) { return hd__xsum_round_scaled(s, 0); }

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

/* The figures from sums given scaled by 2^-k (sum[0..3]: A's sum and sum
 * of squares, then B's; sum[4..5]: the sum and the sum of squares of both
 * sets' distances together, each rounded once), each figure scaled back by
 * 2^k.  The pooled figures come from sum[4..5], not from sum[0] + sum[2]:
 * adding two rounded sums rounds twice, and the pooled mean would then differ
 * from math.fsum of all the distances over their count. */
static void figures(hd_summary_t *out, size_t n_a, size_t n_b, const double sum[6], int k) {
    out->n_ab = n_a;
    out->n_ba = n_b;
    out->sum_ab = ldexp(sum[0], k);
    out->sum2_ab = ldexp(sum[1], k);
    out->mean_ab = ldexp(sum[0] / (double)n_a, k);
    out->mean2_ab = ldexp(sum[1] / (double)n_a, k);
    out->max_ba = out->sum_ba = out->sum2_ba = out->mean_ba = out->mean2_ba = NAN;
    out->mean_symmetric = out->mean_average = out->mean_pooled = NAN;
    out->chamfer = out->chamfer_sum2 = out->chamfer_mean = out->chamfer_sum = NAN;
    if (n_b == 0) return;
    double mean_ab = sum[0] / (double)n_a, mean2_ab = sum[1] / (double)n_a;
    double mean_ba = sum[2] / (double)n_b, mean2_ba = sum[3] / (double)n_b;
    out->sum_ba = ldexp(sum[2], k);
    out->sum2_ba = ldexp(sum[3], k);
    out->mean_ba = ldexp(mean_ba, k);
    out->mean2_ba = ldexp(mean2_ba, k);
    out->mean_symmetric = ldexp(mean_ab >= mean_ba ? mean_ab : mean_ba, k);
    out->mean_average = ldexp((mean_ab + mean_ba) / 2.0, k);
    out->mean_pooled = ldexp(sum[4] / ((double)n_a + (double)n_b), k);
    out->chamfer = ldexp(mean2_ab + mean2_ba, k);
    out->chamfer_sum2 = ldexp(sum[5], k);
    out->chamfer_mean = ldexp(mean_ab + mean_ba, k);
    out->chamfer_sum = ldexp(sum[4], k);
}

/* The figures of hd_summary_t that are computed, in the struct's order. */
#define FIGURES(X)                                                                                          \
    X(sum_ab) X(sum_ba) X(sum2_ab) X(sum2_ba) X(mean_ab) X(mean_ba) X(mean2_ab) X(mean2_ba)                 \
    X(mean_symmetric) X(mean_average) X(mean_pooled) X(chamfer) X(chamfer_sum2) X(chamfer_mean) X(chamfer_sum)

void hd__summary_derive(hd_summary_t *out, size_t n_a, double max_ab, size_t n_b, double max_ba,
                        const hd__xsum_t sums[4]) {
    hd__xsum_t both[2] = {sums[0], sums[1]};
    if (n_b) {
        hd__xsum_merge(&both[0], &sums[2]);
        hd__xsum_merge(&both[1], &sums[3]);
    }
    const hd__xsum_t *all[6] = {&sums[0], &sums[1], &sums[2], &sums[3], &both[0], &both[1]};
    double r[6];
    for (int j = 0; j < 6; j++) r[j] = j < 2 || n_b ? hd__xsum_round(all[j]) : NAN;
    figures(out, n_a, n_b, r, 0);
    int overflowed = 0;
#define HD__INF(f) overflowed |= isinf(out->f);
    FIGURES(HD__INF)
#undef HD__INF
    if (overflowed) {
        /* Some figure overflowed: computed again from the sums scaled by
         * 2^-SCALE, it is what doubles without an exponent limit give (see
         * above); a figure still infinite is beyond DBL_MAX (or a sum
         * holds an infinity). */
        hd_summary_t big;
        for (int j = 0; j < 6; j++) r[j] = j < 2 || n_b ? hd__xsum_round_scaled(all[j], SCALE) : NAN;
        figures(&big, n_a, n_b, r, SCALE);
#define HD__FINITE(f) if (isinf(out->f)) out->f = big.f;
        FIGURES(HD__FINITE)
#undef HD__FINITE
    }
    out->max_ab = max_ab;
    out->max_ba = n_b ? max_ba : NAN;
}
