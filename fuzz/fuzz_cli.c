/*
 * fuzz_cli.c -- a libFuzzer target for the command line's argument parser,
 * cli_parse() (cli/options.c: one table and one parser for every option,
 * the analysis options included).
 *
 * The input is split at NUL bytes into arguments (at most 64) after
 * argv[0] = "hausdorff"; a seed file is a command line written as
 * `printf -- '--sample\0100\0a.ply\0b.ply'`.  What cli_parse prints
 * (usage, --formats, --version, error lines) goes to /dev/null: stdout and
 * stderr are pointed at it around the call.
 *
 * The target checks cli_parse's contract: it returns -1 (go on), 0 (after
 * --help, --version, --formats) or 1 (a usage error); on -1 both paths are
 * arguments that were given and every option holds a value its parser
 * accepts: threads 0..1024, depth 1..21, lambda in (0, 1], theta in [0, 1],
 * a known algorithm and format, sampling with 1..2^40 points, the sampling
 * seed equal to --seed, percentile in [0, 100], bins 1..100000, a
 * non-negative --max-distance, known --mask-points and --empty values, a
 * --distances path whose extension names a table or a write-back format,
 * --connectivity 1..3, --mask-dims auto, 2 or 3, picture names a PNG may
 * have, a --units label of 1 to 16 characters.
 */
#include "cli.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define MAX_ARGS 64

static FILE *devnull;

int LLVMFuzzerInitialize(int *argc, char ***argv) {
    (void)argc, (void)argv;
    devnull = fopen("/dev/null", "w");
    if (!devnull) abort();
    return 0;
}

/* 1 when the n bytes at p name the reader `format` in any case: its name,
 * or for xyz one of the text extensions csv, txt, pts, asc. */
static int names(const char *p, size_t n, const char *format) {
    static const char *const text_aliases[] = {"csv", "txt", "pts", "asc", NULL};
    if (strlen(format) == n && strncasecmp(p, format, n) == 0) return 1;
    if (strcmp(format, "xyz") != 0) return 0;
    for (const char *const *f = text_aliases; *f; f++)
        if (strlen(*f) == n && strncasecmp(p, *f, n) == 0) return 1;
    return 0;
}

/* s is an argument, or the path after a "FORMAT:" prefix of one (then
 * `format` is the reader that prefix names). */
static int given(char **argv, int argc, const char *s, const char *format) {
    for (int k = 1; k < argc; k++) {
        if (argv[k] == s && !format) return 1;
        const char *colon = strchr(argv[k], ':');
        if (format && colon && s == colon + 1 && names(argv[k], (size_t)(colon - argv[k]), format)) return 1;
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *buf = malloc(size + 1);
    if (!buf) return 0;
    if (size) memcpy(buf, data, size);
    buf[size] = '\0';
    static char name[] = "hausdorff";
    char *argv[MAX_ARGS + 2];
    int argc = 0;
    argv[argc++] = name;
    for (size_t k = 0; k <= size && argc <= MAX_ARGS;) {
        argv[argc++] = buf + k;
        k += strlen(buf + k) + 1;
    }
    if (size == 0) argc = 1; /* no input: no arguments */
    argv[argc] = NULL;

    cli_args_t a;
    FILE *out = stdout, *err = stderr;
    stdout = devnull;
    stderr = devnull;
    int rc = cli_parse(argc, argv, &a);
    stdout = out;
    stderr = err;

    if (rc != -1 && rc != EXIT_OK && rc != EXIT_USAGE) abort();
    if (rc == -1) {
        const hd_options_t *o = &a.opt;
        const hd_read_options_t *r = &a.read;
        const analysis_args_t *an = &a.an;
        if (!a.path_a || !a.path_b || !given(argv, argc, a.path_a, a.format_a) ||
            !given(argv, argc, a.path_b, a.format_b))
            abort();
        if ((a.format_a && !hd_format_description(a.format_a)) || (a.format_b && !hd_format_description(a.format_b)))
            abort();
        if (o->threads < 0 || o->threads > 1024 || o->depth < 1 || o->depth > 21) abort();
        if (!(o->lambda > 0 && o->lambda <= 1) || !(o->theta >= 0 && o->theta <= 1)) abort();
        hd_algorithm_t alg;
        if (hd_algorithm_from_name(hd_algorithm_name(o->algorithm), &alg) != HD_OK || alg != o->algorithm) abort();
        if (r->format && !hd_format_description(r->format)) abort();
        if (r->dtype != HD_FLOAT64 && r->dtype != HD_FLOAT32) abort();
        if (r->mesh == HD_MESH_SAMPLE ? r->sample < 1 || r->sample > (size_t)1 << 40 : r->mesh != HD_MESH_VERTICES)
            abort();
        if (r->seed != o->seed) abort();
        if (!(an->percentile >= 0 && an->percentile <= 100) || an->bins < 1 || an->bins > 100000) abort();
        if (!(an->max_distance >= 0) || !isfinite(an->max_distance)) abort();
        if (an->mask_points != MASK_SURFACE && an->mask_points != MASK_ALL) abort();
        if (an->empty != HD_EMPTY_ERROR && an->empty != HD_EMPTY_INF && an->empty != HD_EMPTY_NAN && an->empty != HD_EMPTY_ZERO &&
            an->empty != HD_EMPTY_MONAI)
            abort();
        if (an->distances_out && !distances_format_known(an->distances_out) &&
            !analysis_writeback_format_known(an->distances_out))
            abort();
        if (an->connectivity < 1 || an->connectivity > 3) abort();
        if (an->mask_dims != 0 && an->mask_dims != 2 && an->mask_dims != 3) abort();
        if ((an->render_out && !render_path_ok(an->render_out)) ||
            (an->histogram_png && !render_path_ok(an->histogram_png)))
            abort();
        if (an->units && (!an->units[0] || strlen(an->units) > 16)) abort();
    }
    free(buf);
    return 0;
}
