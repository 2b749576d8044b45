/*
 * test_io_number.c -- the text-to-double conversion every text reader uses
 * returns exactly what strtod returns (so the fast path is never allowed to
 * differ by an ulp), and the LZF decoder behind PCD binary_compressed
 * reproduces hand-made streams and refuses corrupt ones.
 */
#include "check.h"
#include "gen.h"
#include "io/io.h"

#include <locale.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void check_like_strtod(const char *s) {
    double got = 0, want;
    char *e;
    want = strtod(s, &e);
    int ok = hd__parse_double(s, s + strlen(s), &got);
    int want_ok = *s && *e == '\0';
    if (ok != want_ok) {
        hdt_fail(__FILE__, __LINE__, "'%s': accepted %d, strtod accepts %d", s, ok, want_ok);
        return;
    }
    if (ok && memcmp(&got, &want, sizeof got) != 0)
        hdt_fail(__FILE__, __LINE__, "'%s': %a, strtod gives %a", s, got, want);
}

TEST(parse_double_agrees_with_strtod_on_random_decimals) {
    gen_rng_t r;
    gen_seed(&r, 2024);
    CONTEXT("seed 2024");
    char buf[128];
    for (int k = 0; k < 300000 && !hdt_failed(); k++) {
        int len = 0;
        if (gen_u64(&r) % 3 == 0) buf[len++] = gen_u64(&r) % 2 ? '-' : '+';
        int int_digits = (int)(gen_u64(&r) % 12), frac_digits = (int)(gen_u64(&r) % 24);
        if (int_digits + frac_digits == 0) int_digits = 1;
        for (int d = 0; d < int_digits; d++) buf[len++] = (char)('0' + gen_u64(&r) % 10);
        if (frac_digits || gen_u64(&r) % 4 == 0) buf[len++] = '.';
        for (int d = 0; d < frac_digits; d++) buf[len++] = (char)('0' + gen_u64(&r) % 10);
        if (gen_u64(&r) % 2) len += snprintf(buf + len, sizeof buf - (size_t)len, "%c%d", gen_u64(&r) % 2 ? 'e' : 'E',
                                             (int)(gen_u64(&r) % 70) - 35);
        buf[len] = '\0';
        check_like_strtod(buf);
    }
}

TEST(parse_double_agrees_with_strtod_on_printed_doubles_and_edge_cases) {
    gen_rng_t r;
    gen_seed(&r, 7);
    CONTEXT("seed 7");
    char buf[64];
    for (int k = 0; k < 200000 && !hdt_failed(); k++) {
        uint64_t bits = gen_u64(&r);
        double v;
        memcpy(&v, &bits, sizeof v);
        static const char *const fmt[] = {"%.17g", "%.15g", "%.6f", "%.9e", "%.3g", "%.16g"};
        snprintf(buf, sizeof buf, fmt[k % 6], v);
        check_like_strtod(buf);
    }
    static const char *const edge[] = {
        "0", "-0", "+0", "0.0e0", "00000", "9007199254740992", "9007199254740993", "9007199254740994", "18446744073709551615",
        "18446744073709551616", "1e22", "1e23", "1e-22", "1e-23", "9999999999999999e22", "123456789012345678", "1234567890123456789",
        "12345678901234567890", "0.000000000000000000000000000001", "1e-400", "1e400", "4.9406564584124654e-324",
        "2.4703282292062327e-324", "2.4703282292062328e-324", "1.7976931348623157e308", "1.7976931348623159e308",
        "inf", "-Infinity", "nan", "NaN(123)", "0x1p-2", "0X1.8P+3", "1e", "1e+", "e5", ".", "-.", "+", "-", "1.2.3", "1e5x",
        "12 ", " 12", "", "1_000", "1,5", "0.1", "0.30000000000000004", "5e-1", "00.5e1", "1e0000000000000000000000001",
        "1e-99999999999999999999", "0e99999999999"};
    for (size_t k = 0; k < sizeof edge / sizeof edge[0]; k++) check_like_strtod(edge[k]);
}

TEST(parse_u64_takes_plain_digits_up_to_the_largest_value) {
    uint64_t v = 0;
    const char *s = "18446744073709551615";
    CHECK(hd__parse_u64(s, s + strlen(s), &v) && v == UINT64_MAX);
    s = "18446744073709551616";
    CHECK(!hd__parse_u64(s, s + strlen(s), &v));
    s = "-1";
    CHECK(!hd__parse_u64(s, s + strlen(s), &v));
    s = "12a";
    CHECK(!hd__parse_u64(s, s + strlen(s), &v));
    CHECK(!hd__parse_u64(s, s, &v));
}

TEST(lzf_literals_and_overlapping_back_references_decode) {
    /* "abcabcabcabcX": literal "abc", a reference of 9 bytes at distance 3
     * (overlapping: it repeats the pattern), literal "X" */
    const unsigned char in[] = {2, 'a', 'b', 'c', (7 << 5) | 0, 9 - 2 - 7, 2, 0, 'X'};
    unsigned char out[13];
    size_t bad = 0;
    CHECK_EQ(hd__lzf_decompress(in, sizeof in, out, sizeof out, &bad), 0);
    CHECK(memcmp(out, "abcabcabcabcX", 13) == 0);
    /* a long reference: length 7 + 255 + 2 = 264 copies of one byte */
    const unsigned char run[] = {0, 'z', (7 << 5) | 0, 255, 0};
    unsigned char big[265];
    CHECK_EQ(hd__lzf_decompress(run, sizeof run, big, sizeof big, &bad), 0);
    for (int k = 0; k < 265; k++) CHECK(big[k] == 'z');
}

TEST(lzf_corrupt_streams_are_refused_at_the_bad_command) {
    unsigned char out[16];
    size_t bad = 99;
    const unsigned char before_start[] = {0, 'a', (1 << 5) | 0, 5};
    CHECK_EQ(hd__lzf_decompress(before_start, sizeof before_start, out, 4, &bad), -1);
    CHECK_EQ(bad, 2);
    const unsigned char short_literal[] = {5, 'a', 'b'};
    CHECK_EQ(hd__lzf_decompress(short_literal, sizeof short_literal, out, 6, &bad), -1);
    CHECK_EQ(bad, 0);
    const unsigned char too_long[] = {3, 'a', 'b', 'c', 'd'};
    CHECK_EQ(hd__lzf_decompress(too_long, sizeof too_long, out, 3, &bad), -1);
    const unsigned char cut_reference[] = {0, 'a', (7 << 5)};
    CHECK_EQ(hd__lzf_decompress(cut_reference, sizeof cut_reference, out, 10, &bad), -1);
    CHECK_EQ(bad, 2);
    const unsigned char short_output[] = {1, 'a', 'b'};
    CHECK_EQ(hd__lzf_decompress(short_output, sizeof short_output, out, 3, &bad), -1);
    CHECK_EQ(bad, 3);
}

/* A German locale (decimal comma) compiled into a temporary LOCPATH with
 * localedef from Debian's locales package: the program's locale must not
 * change how numbers in files read.  Fails (never skips) when the locale
 * cannot be made: `make test` installs the package. */
TEST(parse_double_ignores_the_program_locale_on_its_slow_path) {
    char dir[] = "/tmp/hd-locale-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char cmd[512];
    snprintf(cmd, sizeof cmd, "localedef -i de_DE -f UTF-8 %s/de_DE.UTF-8 >/dev/null 2>&1", dir);
    int made = system(cmd);
    setenv("LOCPATH", dir, 1);
    const char *set = setlocale(LC_ALL, "de_DE.UTF-8");
    if (!set) hdt_fail(__FILE__, __LINE__, "cannot make the de_DE.UTF-8 locale (localedef exit %d; install 'locales')", made);
    /* in this locale strtod itself stops at the '.' */
    char *e;
    const char *tok = "1.0000000000000000000000001";
    (void)strtod(tok, &e);
    CHECK(*e == '.');
    double v = 0;
    CHECK(hd__parse_double(tok, tok + strlen(tok), &v));
    CHECK_BITS(v, 1.0);
    const char *big = "123456789012345678901234.5";
    CHECK(hd__parse_double(big, big + strlen(big), &v));
    CHECK_BITS(v, 123456789012345678901234.5);
    setlocale(LC_ALL, "C");
    unsetenv("LOCPATH");
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}
