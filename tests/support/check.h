/*
 * check.h -- the project's small test harness.
 *
 * A test file defines behaviours with TEST(name) { ... } and checks them
 * with CHECK(cond) and friends; a failing check prints the file, the line,
 * the expression and the current context (set with CONTEXT(...), typically
 * the seed and the case), so a failure can be reproduced.  The runner (in
 * check.c) runs every TEST of the executable, or only those whose names
 * contain argv[1], and ends with "N passed, M failed".
 */
#ifndef HD_TEST_CHECK_H
#define HD_TEST_CHECK_H

#include <hausdorff.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

typedef void (*hdt_fn)(void);
void hdt_register(const char *name, hdt_fn fn);
void hdt_fail(const char *file, int line, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
void hdt_context(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

#define TEST(name)                                                         \
    static void name(void);                                                \
    __attribute__((constructor)) static void hdt_reg_##name(void) {       \
        hdt_register(#name, name);                                         \
    }                                                                      \
    static void name(void)

#define CONTEXT(...) hdt_context(__VA_ARGS__)

#define CHECK(cond)                                                        \
    do {                                                                   \
        if (!(cond)) hdt_fail(__FILE__, __LINE__, "CHECK(%s)", #cond);     \
    } while (0)

/* Integers compared as long long. */
#define CHECK_EQ(a, b)                                                     \
    do {                                                                   \
        long long hdt_a = (long long)(a), hdt_b = (long long)(b);          \
        if (hdt_a != hdt_b)                                                \
            hdt_fail(__FILE__, __LINE__, "%s == %s: %lld != %lld", #a, #b, \
                     hdt_a, hdt_b);                                        \
    } while (0)

/* Doubles compared bit for bit. */
#define CHECK_BITS(a, b)                                                   \
    do {                                                                   \
        double hdt_x = (a), hdt_y = (b);                                   \
        if (memcmp(&hdt_x, &hdt_y, sizeof hdt_x) != 0)                     \
            hdt_fail(__FILE__, __LINE__, "%s == %s bitwise: %.17g != %.17g", \
                     #a, #b, hdt_x, hdt_y);                                \
    } while (0)

/* A library call expected to return `code`. */
#define CHECK_RC(call, code)                                               \
    do {                                                                   \
        int hdt_rc = (call);                                               \
        if (hdt_rc != (code))                                              \
            hdt_fail(__FILE__, __LINE__, "%s returned %s, expected %s", #call, \
                     hd_err_name(hdt_rc), hd_err_name(code));              \
    } while (0)

/* Nonzero when the running test has failed so far (to stop early). */
int hdt_failed(void);

#endif
