/*
 * cli_numtext_unit.c -- the numbers a person reads (cli/numtext.c): a
 * distance as the shortest text of its double, a coordinate of a float32
 * input as the shortest text of its float, ratios to four significant
 * digits, times in seconds to three, never in exponent form, and counts
 * singular for one.  The report that uses them is tests/cli_report.py's.
 */
#include "check.h"
#include "cli.h"

#include <math.h>
#include <stdlib.h>

#define CHECK_TEXT(got, want)                                                                     \
    do {                                                                                          \
        const char *hdt_g = (got);                                                                \
        if (strcmp(hdt_g, want) != 0) hdt_fail(__FILE__, __LINE__, "%s: '%s', not '%s'", #got, hdt_g, want); \
    } while (0)

TEST(a_distance_keeps_the_shortest_text_that_reads_back) {
    char b[NUM_TEXT];
    CHECK_TEXT(num_text(0.14468150162771326, b), "0.14468150162771326");
    CHECK_TEXT(num_text(0.1, b), "0.1");
    CHECK_TEXT(num_text(7.8208679782962498e-08, b), "7.82086797829625e-08");
}

TEST(a_float32_coordinate_prints_as_the_shortest_text_of_its_float) {
    char b[NUM_TEXT];
    CHECK_TEXT(num_text_single(0.800000011920929, b), "0.8");            /* a NIfTI-1 pixdim */
    CHECK_TEXT(num_text_single(11.200000166893005, b), "11.2");          /* 14 voxels of it, in double */
    CHECK_TEXT(num_text_single((double)3.3f, b), "3.3");
    CHECK_TEXT(num_text_single(-2.5, b), "-2.5");
    CHECK_TEXT(num_text_single(0, b), "0");
    CHECK_TEXT(num_text_single((double)16777217.0f, b), "16777216");
    CHECK_TEXT(num_text_single(1e300, b), "1e+300"); /* beyond a float: its double's text */
    /* every float's text reads back as that float */
    uint64_t s = 12345;
    for (int k = 0; k < 100000; k++) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        uint32_t bits = (uint32_t)(s >> 32);
        float f;
        memcpy(&f, &bits, sizeof f);
        if (!isfinite(f)) continue;
        CONTEXT("bits 0x%08x (seed 12345, draw %d)", (unsigned)bits, k);
        CHECK(strtof(num_text_single((double)f, b), NULL) == f);
    }
}

typedef struct {
    double v;
    const char *text;
} case_t;

static void check_cases(const char *(*fn)(double, char *), const char *name, const case_t *c, size_t n) {
    char b[NUM_TEXT];
    for (size_t k = 0; k < n; k++) {
        CONTEXT("%s(%.17g)", name, c[k].v);
        CHECK_TEXT(fn(c[k].v, b), c[k].text);
    }
}

TEST(a_ratio_prints_four_significant_digits) {
    static const case_t c[] = {{0.7989368316712996, "0.7989"}, {1.0124645892351274, "1.012"}, {1, "1"},
                               {0, "0"}, {39.7284, "39.73"}};
    check_cases(num_ratio, "num_ratio", c, sizeof c / sizeof c[0]);
}

TEST(times_print_in_seconds_to_three_digits_never_in_exponent_form_nor_with_trailing_zeros) {
    static const case_t c[] = {{0.000614, "0.000614"}, {9.8e-05, "0.000098"}, {3e-07, "0"},
                               {0, "0"}, {0.013149, "0.0131"}, {1.2549, "1.25"}, {0.017, "0.017"},
                               {2.001, "2"}, {125.3, "125"}, {4321.9, "4322"},
                               {0.0011999, "0.0012"}, {1.2, "1.2"}};
    check_cases(num_seconds, "num_seconds", c, sizeof c / sizeof c[0]);
}

TEST(counts_are_singular_for_one) {
    CHECK_TEXT(plural(1), "");
    CHECK_TEXT(plural(0), "s");
    CHECK_TEXT(plural(2), "s");
}
