/*
 * cli.h -- the command-line tool's parts.  The tool uses the public API
 * only (hausdorff.h); nothing here reaches into src/.
 */
#ifndef HD_CLI_H
#define HD_CLI_H

#include <hausdorff.h>
#include <stdio.h>

#include "analysis.h"

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
    analysis_args_t an; /* analysis options (analysis.h) */
} cli_args_t;

/* Parse argv.  Returns -1 to go on, or an exit code (after --help,
 * --version, or a usage error, which it has reported). */
int cli_parse(int argc, char **argv, cli_args_t *a);
void cli_usage(FILE *out);
/* The usage text is hausdorff-mpi's (its usage line, description and
 * examples): hausdorff-mpi calls this before cli_parse. */
void cli_set_mpi(void);
/* The program's name for messages ("hausdorff", "hausdorff-mpi"), from
 * argv[0] once cli_parse has run. */
const char *cli_prog(void);
/* The formats the reader knows, one per line (--formats). */
void cli_formats(FILE *out);

/* A double as the shortest text that reads back as the same double
 * ("0.1", "5.9296880000000001" only when needed; numtext.c). */
enum { NUM_TEXT = 32 };
const char *num_text(double v, char buf[NUM_TEXT]);
void num_print(FILE *out, double v);
/* For a person (numtext.c): a coordinate of a float32 input as the
 * shortest text of the float nearest it ("11.2" for 11.200000166893005
 * from a NIfTI-1 header); a ratio to four significant digits ("0.7989");
 * seconds to three significant digits, never in exponent form
 * ("0.000098", "0.0131", "1.25"). */
const char *num_text_single(double v, char buf[NUM_TEXT]);
const char *num_ratio(double v, char buf[NUM_TEXT]);
const char *num_seconds(double s, char buf[NUM_TEXT]);
/* "s" after a count other than one: "%zu point%s", n, plural(n). */
static inline const char *plural(unsigned long long n) { return n == 1 ? "" : "s"; }

/* JSON output helpers: numbers as num_text prints them (null when not
 * finite); strings escaped (bytes that are not UTF-8 as \udcXX, control
 * characters as \u00XX: json.c). */
void json_number(FILE *out, double v);
void json_string(FILE *out, const char *s);
/* s for a person to read: s itself when it holds no control character and
 * only valid UTF-8, else a copy with those bytes as \xXX (valid until four
 * more calls; not thread-safe). */
const char *safe_text(const char *s);

#endif
