/*
 * report.h -- the result as the tools print it (report.c): the report for a
 * person and the JSON object, shared by `hausdorff` (main.c) and
 * `hausdorff-mpi` (mpi/main.c), which fill a report_t each in their own way
 * (one process holds every point; many processes hold a share each) and
 * print the same thing.
 */
#ifndef HD_CLI_REPORT_H
#define HD_CLI_REPORT_H

#include "cli.h"
#include "tiles.h"

typedef struct report {
    const cli_args_t *a;
    const hd_symmetric_t *s;   /* with --directed only s->ab, alpha, disjoint */
    const tiles_t *side;       /* [2]: A's and B's files, with every tile's
                                  first and count filled */
    size_t n[2];               /* points of A and B */
    const char *format[2];     /* the formats read ("mixed" for tiles of several) */
    size_t faces[2];
    double wp[3], wq[3];       /* the points of the witness report_witness names */
    double read_seconds;
    int single[2];             /* A's, B's coordinates came from float32 data
                                  (report_single): printed as floats */
    int empty;                 /* A or B is empty (--empty): s holds the
                                  policy's values (analysis_empty), no
                                  witness, nothing computed */
} report_t;

/* The witness a person is shown: h(A,B)'s with --directed or when it is the
 * larger, else h(B,A)'s; *from_a says which (its i indexes A when 1). */
const hd_result_t *report_witness(const cli_args_t *a, const hd_symmetric_t *s, int *from_a);

/* The JSON object's opening and its fields up to the analysis (the caller
 * adds its own fields, then "}\n"). */
void report_json(FILE *out, const report_t *r);

/* The report for a person, up to the analysis lines. */
void report_text(FILE *out, const report_t *r);

/* The whole report: report_json and analysis_json (an NULL: no analysis)
 * closed by "}", or report_text and analysis_print; more (may be NULL)
 * adds the caller's own JSON members or lines after the analysis. */
typedef void (*report_more_t)(FILE *out, int json, const void *ctx);
void report_print(FILE *out, const report_t *r, const analysis_result_t *an, report_more_t more, const void *ctx);

/* 1 when a side's coordinates came from float32 data, so that the report
 * prints them as the shortest text of the float: stored as float
 * (--float32), a NIfTI-1 mask (its transform is float32; m may be NULL),
 * or every coordinate of p a float (a binary STL, a float PLY, PCD or NPY
 * read into doubles; vacuously when p is empty).  Reads p to its first
 * coordinate that is not a float. */
int report_single(const hd_points_t *p, const mask_info_t *m);

/* Library codes to exit codes: bad input 2, anything else 3. */
int cli_exit_for(int code);

#endif
