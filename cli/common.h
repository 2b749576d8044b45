/*
 * common.h -- the tool's leaf: what every part of cli/ may use and that
 * uses nothing of cli/ (common.c, numtext.c, json.c): the program's name,
 * the clock, output paths, numbers as text, JSON.  Nothing here includes
 * another header of cli/, so the files of cli/ form no cycle
 * (scripts/check_layers.py --cli).
 */
#ifndef HD_CLI_COMMON_H
#define HD_CLI_COMMON_H

#include <hausdorff.h>
#include <stdio.h>

/* The program's name for messages ("hausdorff", "hausdorff-mpi"): the last
 * part of argv[0] once cli_set_prog has seen it, "hausdorff" before. */
const char *cli_prog(void);
void cli_set_prog(const char *argv0);

/* Seconds on a monotonic clock (common.c). */
double cli_now(void);

/* OUT.ext -> OUT_b.ext (suffix "_b"), from malloc (the caller frees it);
 * NULL when out of memory. */
char *path_with_suffix(const char *path, const char *suffix);

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
