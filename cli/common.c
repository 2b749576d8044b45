/*
 * common.c -- the program's name, the clock and output paths (common.h).
 */
#include "common.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char *prog_name = "hausdorff";

const char *cli_prog(void) { return prog_name; }

void cli_set_prog(const char *argv0) {
    if (!argv0 || !argv0[0]) return;
    const char *slash = strrchr(argv0, '/');
    prog_name = slash && slash[1] ? slash + 1 : argv0;
}

double cli_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

char *path_with_suffix(const char *path, const char *suffix) {
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash)) dot = path + strlen(path);
    size_t stem = (size_t)(dot - path), tail = strlen(dot), add = strlen(suffix);
    char *out = malloc(stem + add + tail + 1);
    if (!out) return NULL;
    memcpy(out, path, stem);
    memcpy(out + stem, suffix, add);
    memcpy(out + stem + add, dot, tail + 1);
    return out;
}
