/*
 * check.c -- the runner behind check.h.
 */
#include "check.h"

#include <stdarg.h>
#include <stdlib.h>

#define MAX_TESTS 512

static struct {
    const char *name;
    hdt_fn fn;
} tests[MAX_TESTS];
static int n_tests;
static int current_failed;
static char context[512];

void hdt_register(const char *name, hdt_fn fn) {
    if (n_tests == MAX_TESTS) {
        fprintf(stderr, "too many tests\n");
        exit(2);
    }
    tests[n_tests].name = name;
    tests[n_tests].fn = fn;
    n_tests++;
}

void hdt_context(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(context, sizeof context, fmt, ap);
    va_end(ap);
}

void hdt_fail(const char *file, int line, const char *fmt, ...) {
    if (current_failed < 10) {
        va_list ap;
        va_start(ap, fmt);
        fprintf(stderr, "  %s:%d: ", file, line);
        vfprintf(stderr, fmt, ap);
        va_end(ap);
        if (context[0]) fprintf(stderr, "  [%s]", context);
        fputc('\n', stderr);
    }
    current_failed++;
}

int hdt_failed(void) { return current_failed != 0; }

int main(int argc, char **argv) {
    int passed = 0, failed = 0;
    for (int k = 0; k < n_tests; k++) {
        if (argc > 1 && !strstr(tests[k].name, argv[1])) continue;
        current_failed = 0;
        context[0] = '\0';
        tests[k].fn();
        if (current_failed) {
            failed++;
            fprintf(stderr, "FAIL %s\n", tests[k].name);
        } else {
            passed++;
            printf("ok   %s\n", tests[k].name);
        }
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
