/*
 * test_sums.c -- hd_summarize's sums are correctly rounded: the exact sum
 * of the doubles (and of their squares x * x), rounded once to nearest
 * even, whatever the order.
 *
 * The references are Python's math.fsum, computed when the cases were
 * generated (tests/gen_sums.py writes tests/support/sums_cases.h: each case is a seed
 * and the parameters of a generator that this file and the script share,
 * and the expected bits), so the test needs no Python and cannot drift
 * from its reference: the generator builds each double from integer bits
 * (splitmix64), which C and Python compute alike.  Sums whose partial sums
 * overflow, which fsum refuses, were computed exactly with fractions.  The
 * edge cases below the table (overflow at exactly half an ulp above
 * DBL_MAX, ties to even, subnormals, infinities) are written out by hand.
 */
#include "check.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

typedef struct {
    const char *name;
    uint64_t seed;
    size_t n;
    unsigned emin, emax, mode;
    uint64_t sum, sum2, neumaier; /* math.fsum of x and of x * x; Neumaier's sum */
} sum_case_t;

#include "sums_cases.h"

static uint64_t next(uint64_t *s) { /* splitmix64, as gen_sums.py */
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static double from_bits(uint64_t u) {
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

/* gen_sums.py's draw(): mode bit 0 random signs, bit 1 odd values cancel
 * the previous one but for their 8 lowest bits, bit 2 every value equal. */
static double *draw(const sum_case_t *c) {
    uint64_t *u = malloc(c->n * sizeof *u), s = c->seed;
    for (size_t k = 0; k < c->n; k++) {
        uint64_t mant = next(&s) & ((1ULL << 52) - 1);
        uint64_t e = c->emin + next(&s) % (c->emax - c->emin + 1);
        uint64_t sign = c->mode & 1 ? next(&s) >> 63 : 0;
        u[k] = sign << 63 | e << 52 | mant;
        if ((c->mode & 2) && k % 2 == 1) u[k] = (u[k - 1] ^ (1ULL << 63)) ^ (next(&s) & 0xff);
        if ((c->mode & 4) && k > 0) u[k] = u[0];
    }
    double *v = malloc(c->n * sizeof *v);
    for (size_t k = 0; k < c->n; k++) v[k] = from_bits(u[k]);
    free(u);
    return v;
}

static double neumaier(const double *d, size_t n) {
    double s = 0.0, c = 0.0;
    for (size_t k = 0; k < n; k++) {
        double t = s + d[k];
        if (fabs(s) >= fabs(d[k])) c += (s - t) + d[k];
        else c += (d[k] - t) + s;
        s = t;
    }
    return s + c;
}

TEST(sums_are_math_fsum_to_the_bit) {
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const sum_case_t *c = &cases[i];
        CONTEXT("case %s (seed %llu, %zu values)", c->name, (unsigned long long)c->seed, c->n);
        double *v = draw(c);
        hd_summary_t s;
        CHECK_RC(hd_summarize(v, c->n, NULL, 0, &s, NULL), HD_OK);
        CHECK_BITS(s.sum_ab, from_bits(c->sum));
        CHECK_BITS(s.sum2_ab, from_bits(c->sum2));
        /* the generator's doubles are the script's: Neumaier agrees too
         * (where it is not NaN) */
        if (!isnan(from_bits(c->neumaier))) CHECK_BITS(neumaier(v, c->n), from_bits(c->neumaier));
        free(v);
    }
}

TEST(the_neumaier_case_really_differs_from_the_correctly_rounded_sum) {
    const sum_case_t *c = &cases[sizeof cases / sizeof cases[0] - 1];
    CHECK(strcmp(c->name, "neumaier_is_one_ulp_off") == 0);
    double *v = draw(c);
    CHECK(neumaier(v, c->n) != from_bits(c->sum));
    CHECK(nextafter(from_bits(c->sum), neumaier(v, c->n)) == neumaier(v, c->n)); /* one ulp */
    free(v);
}

TEST(sums_do_not_depend_on_the_order_nor_on_the_split) {
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const sum_case_t *c = &cases[i];
        CONTEXT("case %s (seed %llu)", c->name, (unsigned long long)c->seed);
        double *v = draw(c);
        for (size_t k = 0; k < c->n / 2; k++) {
            double t = v[k];
            v[k] = v[c->n - 1 - k];
            v[c->n - 1 - k] = t;
        }
        hd_summary_t s;
        CHECK_RC(hd_summarize(v, c->n, NULL, 0, &s, NULL), HD_OK);
        CHECK_BITS(s.sum_ab, from_bits(c->sum));
        if (c->n >= 2) { /* A's and B's halves: chamfer_sum adds the two rounded sums */
            CHECK_RC(hd_summarize(v, c->n, v, c->n, &s, NULL), HD_OK);
            CHECK_BITS(s.sum_ba, from_bits(c->sum));
            CHECK_BITS(s.sum2_ba, from_bits(c->sum2));
        }
        free(v);
    }
}

static double sum_of(const double *v, size_t n) {
    hd_summary_t s;
    if (hd_summarize(v, n, NULL, 0, &s, NULL) != HD_OK) return -1.0;
    return s.sum_ab;
}

TEST(overflow_is_decided_by_the_exact_sum_at_half_an_ulp_above_dbl_max) {
    /* DBL_MAX's ulp is 2^971: from DBL_MAX + 2^970 (a tie; DBL_MAX's
     * significand is odd, so it rounds up) the sum is inf */
    double tie[2] = {DBL_MAX, 0x1p970};
    CHECK_BITS(sum_of(tie, 2), INFINITY);
    double below[3] = {DBL_MAX, 0x1p970, -0x1p-1074}; /* below the tie by the least subnormal */
    CHECK_BITS(sum_of(below, 3), DBL_MAX);
    double back[3] = {DBL_MAX, DBL_MAX, -DBL_MAX}; /* a partial sum past DBL_MAX, the total not */
    CHECK_BITS(sum_of(back, 3), DBL_MAX);
    double neg[2] = {-DBL_MAX, -0x1p970};
    CHECK_BITS(sum_of(neg, 2), -INFINITY);
}

TEST(ties_round_to_even_and_far_bits_break_them) {
    double t1[2] = {1.0, 0x1p-53}; /* half an ulp of 1: to 1 (even) */
    CHECK_BITS(sum_of(t1, 2), 1.0);
    double t2[3] = {1.0, 0x1p-53, 0x1p-1074}; /* just above the tie */
    CHECK_BITS(sum_of(t2, 3), 1.0 + 0x1p-52);
    double t3[2] = {1.0 + 0x1p-52, 0x1p-53}; /* a tie from an odd significand: up */
    CHECK_BITS(sum_of(t3, 2), 1.0 + 0x1p-51);
    double t4[3] = {0x1p-1074, 1e300, -1e300}; /* the least subnormal survives */
    CHECK_BITS(sum_of(t4, 3), 0x1p-1074);
}

TEST(subnormal_sums_are_exact_and_cross_into_the_normals) {
    double two[2] = {0x1p-1074, 0x1p-1074};
    CHECK_BITS(sum_of(two, 2), 0x1p-1073);
    double up[2] = {0x1.ffffffffffffep-1023, 0x0.0000000000002p-1022}; /* largest subnormal + 2 ulps */
    CHECK_BITS(sum_of(up, 2), 0x1.0000000000000p-1022 + 0x0.0000000000001p-1022);
    double cancel[2] = {0x1p-1070, -0x1p-1070};
    CHECK_BITS(sum_of(cancel, 2), 0.0); /* an exact zero is +0 */
}

TEST(infinities_decide_the_sum_as_ieee_addition_does) {
    double p[3] = {1.0, INFINITY, -DBL_MAX};
    CHECK_BITS(sum_of(p, 3), INFINITY);
    double m[2] = {-INFINITY, 5.0};
    CHECK_BITS(sum_of(m, 2), -INFINITY);
    double both[2] = {INFINITY, -INFINITY};
    CHECK(isnan(sum_of(both, 2)));
}

TEST(a_million_equal_values_are_summed_exactly) {
    /* 10^6 copies of the double 0.1 (0.1000000000000000055511...) sum
     * exactly to 100000.0000000000055511..., which is within half an ulp
     * (7.3e-12) of 100000: math.fsum gives 100000.0; a plain loop gives
     * 100000.00000133288.  The accumulator is normalised every 512
     * additions, about 2000 times here. */
    size_t n = 1000000;
    double *v = malloc(n * sizeof *v);
    for (size_t k = 0; k < n; k++) v[k] = 0.1;
    CHECK_BITS(sum_of(v, n), 100000.0);
    free(v);
}

/* What the figures are without an exponent limit: x computed at 2^-128
 * (exact there) and scaled back. */
static double mean_unlimited(double each, size_t copies) {
    double scaled = ldexp(each, -128) * (double)copies; /* the exact sum, rounded once */
    return ldexp(scaled / (double)copies, 128);
}

TEST(chamfer_is_finite_when_the_sum_of_squares_overflows_within_the_1e153_domain) {
    /* 100 points at (1e153, 1e153, 1e153) against one at -1e153: every
     * distance is sqrt(3) 2e153, its square 1.2e307, 100 squares 1.2e309
     * (beyond DBL_MAX), their mean 1.2e307 again */
    double d = sqrt(3.0 * 2e153 * 2e153);
    double ab[100], ba[1] = {d};
    for (int k = 0; k < 100; k++) ab[k] = d;
    hd_summary_t s;
    CHECK_RC(hd_summarize(ab, 100, ba, 1, &s, NULL), HD_OK);
    CHECK_BITS(s.sum2_ab, INFINITY); /* a sum truly beyond DBL_MAX */
    CHECK_BITS(s.chamfer_sum2, INFINITY);
    CHECK_BITS(s.mean2_ab, mean_unlimited(d * d, 100));
    CHECK_BITS(s.mean2_ba, d * d);
    CHECK_BITS(s.chamfer, mean_unlimited(d * d, 100) + d * d);
    CHECK(isfinite(s.chamfer) && s.chamfer > 2.39e307 && s.chamfer < 2.41e307);
    CHECK_BITS(s.mean_ab, mean_unlimited(d, 100)); /* sums of distances never overflow there */
    CHECK_BITS(s.sum_ab, 100 * d);
    CHECK_BITS(s.chamfer_mean, s.mean_ab + d);
}

TEST(means_are_finite_when_their_sum_overflows) {
    /* distances given by the caller may be anything finite: the mean of
     * DBL_MAX and DBL_MAX is DBL_MAX, though their sum is not a double */
    double a[2] = {DBL_MAX, DBL_MAX}, b[1] = {DBL_MAX};
    hd_summary_t s;
    CHECK_RC(hd_summarize(a, 2, b, 1, &s, NULL), HD_OK);
    CHECK_BITS(s.sum_ab, INFINITY);
    CHECK_BITS(s.mean_ab, DBL_MAX);
    CHECK_BITS(s.mean_ba, DBL_MAX);
    CHECK_BITS(s.mean_symmetric, DBL_MAX);
    CHECK_BITS(s.mean_average, DBL_MAX);
    CHECK_BITS(s.mean_pooled, DBL_MAX);
    CHECK_BITS(s.chamfer_mean, INFINITY); /* 2 DBL_MAX: beyond, and said so */
    CHECK_BITS(s.mean2_ab, INFINITY);     /* DBL_MAX * DBL_MAX is inf itself */
    /* a sum past DBL_MAX with a mean at the top of the range: each mean is
     * the exact sum rounded once, then divided */
    double c[3] = {DBL_MAX, DBL_MAX, 0x1p1000};
    CHECK_RC(hd_summarize(c, 3, NULL, 0, &s, NULL), HD_OK);
    CHECK_BITS(s.mean_ab, ldexp((ldexp(DBL_MAX, -128) * 2 + 0x1p872) / 3, 128));
    CHECK(isnan(s.mean_pooled)); /* no B: still NaN */
}

TEST(pooled_figures_round_the_sum_of_both_sets_once) {
    /* B's sum 2^-53 + 2^-106 rounds to 2^-53 (a tie, to even), and 1 + 2^-53
     * is a tie again: adding the two rounded sums gives 1, while the exact
     * sum of all three distances is above the tie and rounds to 1 + 2^-52
     * (math.fsum([1.0, 2**-53, 2**-106]) == 1 + 2**-52). */
    double a[1] = {1.0}, b[2] = {0x1p-53, 0x1p-106};
    hd_summary_t s;
    CHECK_RC(hd_summarize(a, 1, b, 2, &s, NULL), HD_OK);
    CHECK_BITS(s.sum_ba, 0x1p-53);
    CHECK_BITS(s.chamfer_sum, 1.0 + 0x1p-52);
    CHECK_BITS(s.mean_pooled, (1.0 + 0x1p-52) / 3.0);
    /* squares 1 and 2^-54, 2^-54, 2^-106: the same two ties */
    double e[3] = {0x1p-27, 0x1p-27, 0x1p-53};
    CHECK_RC(hd_summarize(a, 1, e, 3, &s, NULL), HD_OK);
    CHECK_BITS(s.sum2_ba, 0x1p-53);
    CHECK_BITS(s.chamfer_sum2, 1.0 + 0x1p-52);
}
