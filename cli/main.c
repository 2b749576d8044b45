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

int main(int argc, char **argv) {
    out_guard_std();
    cli_args_t a;
    int rc = cli_parse(argc, argv, &a);
    if (rc >= 0) return rc == EXIT_OK ? out_finish() : rc; /* --help, --version, --formats printed */
    if (a.surface) {
        rc = surface_run(&a);
        return rc == EXIT_OK ? out_finish() : failed(rc);
    }

    hd_error_t err;
    /* each side's files (one, a directory's or a list's), before anything
     * is read, so outputs are checked against every one of them */
    tiles_t side[2];
    memset(side, 0, sizeof side);
    if ((rc = tiles_expand(a.path_a, a.format_a, &side[0], &err)) != HD_OK ||
        (rc = tiles_expand(a.path_b, a.format_b, &side[1], &err)) != HD_OK) {
        fprintf(stderr, "%s: %s\n", cli_prog(), safe_text(err.message));
        tiles_free(&side[0]);
        return cli_exit_for(rc);
    }
    if ((rc = out_check_outputs(&a, side)) != 0) {
        tiles_free(&side[0]);
        tiles_free(&side[1]);
        return rc;
    }

    hd_cloud_t *ca = NULL, *cb = NULL;
    double t0 = cli_now();
    /* progress by phase (read A, read B, compute), only for a person */
    progress_start(!a.quiet && !a.json && isatty(2), 3);
    char files[2][32] = {"", ""};
    for (int w = 0; w < 2; w++)
        if (side[w].kind != TILES_FILE)
            snprintf(files[w], sizeof files[w], " (%zu file%s)", side[w].n, plural(side[w].n));
    progress_phase("reading A: %s%s", safe_text(a.path_a), files[0]);
    if ((rc = tiles_read(&side[0], 0, side[0].n, &a.read, &a.an, 0, &ca, &err)) != HD_OK ||
        (progress_phase("reading B: %s%s", safe_text(a.path_b), files[1]),
         rc = tiles_read(&side[1], 0, side[1].n, &a.read, &a.an, 1, &cb, &err)) != HD_OK) {
        progress_stop();
        fprintf(stderr, "%s: %s\n", cli_prog(), safe_text(err.message));
        hd_cloud_free(ca);
        tiles_free(&side[0]);
        tiles_free(&side[1]);
        return failed(cli_exit_for(rc));
    }
    double read_seconds = cli_now() - t0;
    hd_points_t A = hd_cloud_points(ca), B = hd_cloud_points(cb);
    progress_phase("computing (%zu x %zu points)", A.count, B.count);
    if ((rc = analysis_handle_empty(&a.an, a.path_a, a.path_b, &A, &B, a.directed, a.json)) >= 0) {
        progress_stop();
        hd_cloud_free(ca);
        hd_cloud_free(cb);
        tiles_free(&side[0]);
        tiles_free(&side[1]);
        return rc == EXIT_OK ? out_finish() : failed(rc);
    }

    hd_symmetric_t s;
    memset(&s, 0, sizeof s);
    if (a.directed) {
        rc = hd_directed(&A, &B, &a.opt, &s.ab, &err);
        if (rc == HD_OK) {
            s.distance = s.ab.distance;
            s.seconds = s.ab.seconds;
            rc = hd_overlap(&A, &B, &s.alpha, &s.disjoint, &err);
        }
    } else {
        rc = hd_hausdorff(&A, &B, &a.opt, &s, &err);
    }
    analysis_result_t an;
    if (rc == HD_OK && (rc = analysis_run(&a.an, &a.opt, &A, &B, &s, a.directed, a.path_a, a.path_b, &an,
                                          &err)) != HD_OK)
        analysis_free(&an);
    progress_stop();
    if (rc != HD_OK) {
        fprintf(stderr, "%s: %s\n", cli_prog(), safe_text(err.message));
        hd_cloud_free(ca);
        hd_cloud_free(cb);
        tiles_free(&side[0]);
        tiles_free(&side[1]);
        return failed(cli_exit_for(rc));
    }

    FILE *out = stdout;
    report_t r = {&a, &s, side, {A.count, B.count}, {ca->format, cb->format}, {ca->n_faces, cb->n_faces},
                  {0, 0, 0}, {0, 0, 0}, read_seconds, {0, 0}};
    if (!a.json) { /* only the text prints coordinates */
        r.single[0] = report_single(&A, &a.an.mask[0]);
        r.single[1] = report_single(&B, &a.an.mask[1]);
    }
    int from_a;
    const hd_result_t *w = report_witness(&a, &s, &from_a);
    hd_points_get(from_a ? &A : &B, w->i, r.wp);
    hd_points_get(from_a ? &B : &A, w->j, r.wq);
    if (a.json) {
        report_json(out, &r);
        analysis_json(out, &a.an, &an);
        fprintf(out, "}\n");
    } else {
        report_text(out, &r);
        analysis_print(out, &a.an, &an);
    }
    analysis_free(&an);
    hd_cloud_free(ca);
    hd_cloud_free(cb);
    tiles_free(&side[0]);
    tiles_free(&side[1]);
    return out_finish();
}
