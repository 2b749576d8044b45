/*
 * main.c -- `hausdorff A B`: read two files, compute the exact Hausdorff
 * distance, print it for a person or as JSON for a script.
 *
 * Reading time and computation time are measured separately (read_seconds,
 * seconds), so a benchmark of the tool can tell them apart.  Errors from the
 * library already carry the file and line or byte offset; the tool prefixes
 * "hausdorff: " and maps them to exit codes: bad input 2, other failure 3.
 *
 * Output is part of the result (output.c): a run succeeds only when its
 * report reached standard output and every file it was asked to write is in
 * place.  So main guards descriptors 0-2 before anything opens a file,
 * expands each side into its files (tiles.c: one file, a directory or a
 * list, read as one point set whose indices run across the files), then
 * refuses outputs that would overwrite any input before anything is read
 * (exit 1), lets every file be written to a temporary, and ends a run that
 * succeeded with out_finish (standard output flushed and closed, checked;
 * then the files renamed into place, all or none; exit 3 when either
 * fails) and a run that failed with out_discard (no file appears).
 */
#include "cli.h"

#include <math.h>
#include "output.h"
#include "progress.h"
#include "labels.h"
#include "report.h"
#include "surface.h"
#include "tiles.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* Stop a run that failed: no file of it appears. */
static int failed(int code) {
    out_discard();
    return code;
}

/* A library failure's message and exit code. */
static int say(int rc, const hd_error_t *err) {
    fprintf(stderr, "%s: %s\n", cli_prog(), safe_text(err->message));
    return cli_exit_for(rc);
}

/* What a run holds, freed in one place (run_free) whatever way it ends. */
typedef struct run {
    cli_args_t a;
    tiles_t side[2];
    hd_cloud_t *cloud[2];
    analysis_result_t an;
    double read_seconds;
} run_t;

static void run_free(run_t *r) {
    analysis_free(&r->an);
    for (int w = 0; w < 2; w++) {
        hd_cloud_free(r->cloud[w]);
        tiles_free(&r->side[w]);
    }
}

/* Read A and B, each a phase of the progress line. */
static int read_sides(run_t *r, hd_error_t *err) {
    const cli_args_t *a = &r->a;
    const char *paths[2] = {a->path_a, a->path_b};
    double t0 = cli_now();
    for (int w = 0; w < 2; w++) {
        char files[32] = "";
        if (r->side[w].kind != TILES_FILE)
            snprintf(files, sizeof files, " (%zu file%s)", r->side[w].n, plural(r->side[w].n));
        progress_phase("reading %c: %s%s", "AB"[w], safe_text(paths[w]), files);
        int rc = tiles_read(&r->side[w], 0, r->side[w].n, &a->read, &r->a.an, w, &r->cloud[w], err);
        if (rc != HD_OK) return rc;
    }
    r->read_seconds = cli_now() - t0;
    return HD_OK;
}

/* The distance (h(A,B) with --directed) and the analysis asked for. */
static int compute(run_t *r, const hd_points_t *A, const hd_points_t *B, hd_symmetric_t *s, hd_error_t *err) {
    const cli_args_t *a = &r->a;
    int rc;
    memset(s, 0, sizeof *s);
    if (a->directed) {
        rc = hd_directed(A, B, &a->opt, &s->ab, err);
        if (rc == HD_OK) {
            s->distance = s->ab.distance;
            s->seconds = s->ab.seconds;
            rc = hd_overlap(A, B, &s->alpha, &s->disjoint, err);
        }
    } else {
        rc = hd_hausdorff(A, B, &a->opt, s, err);
    }
    if (rc == HD_OK) rc = analysis_run(&a->an, &a->opt, A, B, s, a->directed, a->path_a, a->path_b, &r->an, err);
    return rc;
}

/* A or B empty (only under --empty: reading refuses it otherwise): the
 * policy's values in s and the analysis, its files written. */
static int compute_empty(run_t *r, const hd_points_t *A, const hd_points_t *B, hd_symmetric_t *s, hd_error_t *err) {
    const cli_args_t *a = &r->a;
    int rc = analysis_empty(&a->an, A->count, B->count, a->directed, s, &r->an, err);
    return rc == HD_OK ? analysis_empty_files(&a->an, A, B, a->directed, s->ab.distance, a->path_a, a->path_b, &r->an, err)
                       : rc;
}

/* The report, for a person or as JSON. */
static void print_report(const run_t *r, const hd_points_t *A, const hd_points_t *B, const hd_symmetric_t *s) {
    const cli_args_t *a = &r->a;
    const hd_cloud_t *ca = r->cloud[0], *cb = r->cloud[1];
    report_t rep = {a, s, r->side, {A->count, B->count}, {ca->format, cb->format}, {ca->n_faces, cb->n_faces},
                    {0, 0, 0}, {0, 0, 0}, r->read_seconds, {0, 0}, r->an.empty};
    if (!rep.empty) {
        if (!a->json) { /* only the text prints coordinates */
            rep.single[0] = report_single(A, &a->an.mask[0]);
            rep.single[1] = report_single(B, &a->an.mask[1]);
        }
        int from_a;
        const hd_result_t *w = report_witness(a, s, &from_a);
        hd_points_get(from_a ? A : B, w->i, rep.wp);
        hd_points_get(from_a ? B : A, w->j, rep.wq);
    }
    report_print(stdout, &rep, &r->an, NULL, NULL);
}

/* The run after parsing: its exit status. */
static int run(run_t *r) {
    cli_args_t *a = &r->a;
    hd_error_t err;
    int rc;
    /* each side's files (one, a directory's or a list's), before anything
     * is read, so outputs are checked against every one of them */
    if ((rc = tiles_expand(a->path_a, a->format_a, &r->side[0], &err)) != HD_OK ||
        (rc = tiles_expand(a->path_b, a->format_b, &r->side[1], &err)) != HD_OK)
        return say(rc, &err);
    if ((rc = out_check_outputs(a, r->side)) != 0) return rc;
    if (analysis_check_outputs(&a->an, a->path_a, a->path_b, a->directed, &err) != HD_OK) {
        fprintf(stderr, "%s: %s\n", cli_prog(), safe_text(err.message));
        return EXIT_USAGE;
    }

    /* progress by phase (read A, read B, compute), only for a person */
    progress_start(!a->quiet && !a->json && isatty(2), 3);
    hd_symmetric_t s;
    if ((rc = read_sides(r, &err)) == HD_OK) {
        hd_points_t A = hd_cloud_points(r->cloud[0]), B = hd_cloud_points(r->cloud[1]);
        progress_phase("computing (%zu x %zu points)", A.count, B.count);
        int empty = !A.count || !B.count;
        rc = empty ? compute_empty(r, &A, &B, &s, &err) : compute(r, &A, &B, &s, &err);
        if (rc == HD_OK) {
            progress_stop();
            print_report(r, &A, &B, &s);
            return out_finish();
        }
    }
    progress_stop();
    return failed(say(rc, &err));
}

int main(int argc, char **argv) {
    out_guard_std();
    static run_t r; /* zero: run_free frees what was made */
    int rc = cli_parse(argc, argv, &r.a);
    if (rc >= 0) return rc == EXIT_OK ? out_finish() : rc; /* --help, --version, --formats printed */
    if (r.a.an.labels) {
        rc = labels_run(&r.a);
        return rc == EXIT_OK ? out_finish() : failed(rc);
    }
    if (r.a.surface) {
        rc = surface_run(&r.a);
        return rc == EXIT_OK ? out_finish() : failed(rc);
    }
    rc = run(&r);
    run_free(&r);
    return rc;
}
