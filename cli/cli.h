/*
 * cli.h -- the command-line tool's parts.  The tool uses the public API
 * only (hausdorff.h); nothing here reaches into src/.
 */
#ifndef HD_CLI_H
#define HD_CLI_H

#include <hausdorff.h>
#include <stdio.h>

#include "analysis.h"
#include "common.h"

/* Exit codes: the contract scripts rely on. */
enum { EXIT_OK = 0, EXIT_USAGE = 1, EXIT_BADINPUT = 2, EXIT_FAILURE_ = 3 };

typedef struct cli_args {
    const char *path_a, *path_b;
    /* the format of each file when its path was written FORMAT:PATH
     * ("xyz:-", "ply:scan.dat"), else NULL: --format, extension, content */
    const char *format_a, *format_b;
    hd_options_t opt;
    hd_read_options_t read;
    int directed;
    int json;
    int quiet;
    int surface; /* --surface: B measured as its triangles (surface.c) */
    double tolerance;       /* --tolerance: the enclosure's (m2m.c) */
    int tolerance_set, tolerance_relative; /* given; with the 'd' suffix */
    double within;          /* --within D: is the distance <= D? */
    int within_set;
    int signed_distance; /* --signed: with --surface, each distance's sign */
    analysis_args_t an; /* analysis options (analysis.h) */
} cli_args_t;

/* Parse argv.  Returns -1 to go on, or an exit code (after --help,
 * --version, or a usage error, which it has reported). */
int cli_parse(int argc, char **argv, cli_args_t *a);
void cli_usage(FILE *out);
/* The usage text is hausdorff-mpi's (its usage line, description and
 * examples) and --version prints with version(out): hausdorff-mpi calls
 * this before cli_parse. */
void cli_set_mpi(void (*version)(FILE *out));
/* The formats the reader knows, one per line (--formats). */
void cli_formats(FILE *out);

#endif
