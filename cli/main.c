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
#include "tiles.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Library codes to exit codes; an output failure (OUT_EFAIL) is 3. */
static int exit_for(int code) {
    switch (code) {
    case HD_EIO: case HD_EFORMAT: case HD_EUNSUPPORTED: case HD_EEMPTY:
    case HD_ENONFINITE: case HD_ERANGE: case HD_EOVERFLOW:
        return EXIT_BADINPUT;
    default:
        return EXIT_FAILURE_;
    }
}

static void witness_json(FILE *out, const hd_result_t *r) {
    fprintf(out, "[%zu, %zu]", r->i, r->j);
}

/* Where point g of a side is: its file and its index there. */
static void where_json(FILE *out, const tiles_t *t, size_t g) {
    size_t local;
    const tile_t *f = &t->t[tiles_locate(t, g, &local)];
    fprintf(out, "{\"file\": ");
    json_string(out, f->path);
    fprintf(out, ", \"index\": %zu, \"global\": %zu}", local, g);
}

/* The witness's points as files and indices: [point of P, point of Q]. */
static void witness_files_json(FILE *out, const hd_result_t *r, const tiles_t *p, const tiles_t *q) {
    fputc('[', out);
    where_json(out, p, r->i);
    fputs(", ", out);
    where_json(out, q, r->j);
    fputc(']', out);
}

/* A side of many files: each with its first global index and count, and
 * what a directory skipped. */
static void tiles_json(FILE *out, const char *key, const tiles_t *t) {
    if (t->kind == TILES_FILE) return;
    fprintf(out, ", \"tiles_%s\": [", key);
    for (size_t k = 0; k < t->n; k++) {
        fprintf(out, "%s{\"file\": ", k ? ", " : "");
        json_string(out, t->t[k].path);
        fprintf(out, ", \"first\": %zu, \"count\": %zu}", t->t[k].first, t->t[k].count);
    }
    fprintf(out, "], \"skipped_%s\": [", key);
    for (size_t k = 0; k < t->n_skipped; k++) {
        fprintf(out, "%s{\"name\": ", k ? ", " : "");
        json_string(out, t->skipped[k].name);
        fprintf(out, ", \"reason\": ");
        json_string(out, t->skipped[k].reason);
        fputc('}', out);
    }
    fputc(']', out);
}

/* "A: scan.ply (650 points, ply, 1300 faces)", with the files of a side of many. */
static void side_line(FILE *out, char name, const tiles_t *t, const hd_cloud_t *c, int sampled) {
    fprintf(out, "%c: %s (%zu points, %s", name, t->arg, c->count, c->format);
    if (c->n_faces) fprintf(out, "%s %zu faces", sampled ? " sampled from" : ",", c->n_faces);
    if (t->kind != TILES_FILE) {
        char skipped[512];
        tiles_skipped_text(t, skipped, sizeof skipped);
        fprintf(out, ", %zu file%s%s%s", t->n, t->n == 1 ? "" : "s", skipped[0] ? "; " : "", skipped);
    }
    fprintf(out, ")\n");
}

/* " = dir/t2.xyz[3]" for a point of a side of many files, else nothing. */
static void where_text(FILE *out, const tiles_t *t, size_t g) {
    if (t->kind == TILES_FILE) return;
    size_t local, k = tiles_locate(t, g, &local);
    fprintf(out, " = %s[%zu]", t->t[k].path, local);
}

static void print_point(FILE *out, const hd_points_t *p, size_t k) {
    double q[3];
    hd_points_get(p, k, q);
    char x[NUM_TEXT], y[NUM_TEXT], z[NUM_TEXT];
    fprintf(out, "(%s, %s, %s)", num_text(q[0], x), num_text(q[1], y), num_text(q[2], z));
}

static void stats_json(FILE *out, const hd_stats_t *s) {
    fprintf(out, "{\"distance_evals\": %llu, \"nodes_visited\": %llu, \"points_culled\": %llu}",
            (unsigned long long)s->distance_evals, (unsigned long long)s->nodes_visited,
            (unsigned long long)s->points_culled);
}

/* Stop a run that failed: no file of it appears. */
static int failed(int code) {
    out_discard();
    return code;
}

/* Refuse an output that would overwrite an input (any tile, or a list of
 * them) or another output. */
static int check_outputs(const cli_args_t *a, const tiles_t side[2]) {
    char path_b[4096];
    const char *outs[4] = {a->an.distances_out, NULL, a->an.render_out, a->an.histogram_png};
    const char *const what[4] = {"--distances", "--distances (B's rows)", "--render", "--histogram-png"};
    if (a->an.distances_out && !a->directed) {
        path_with_suffix(a->an.distances_out, "_b", path_b, sizeof path_b);
        outs[1] = path_b;
    }
    if (!outs[0] && !outs[2] && !outs[3]) return 0;
    size_t n = side[0].n + side[1].n + 2, m = 0;
    const char **in = malloc(n * sizeof *in);
    char *which = malloc(n);
    if (!in || !which) {
        free(in);
        free(which);
        fprintf(stderr, "hausdorff: out of memory\n");
        return EXIT_FAILURE_;
    }
    for (int w = 0; w < 2; w++) {
        if (side[w].kind == TILES_LIST) in[m] = side[w].arg + 1, which[m++] = "AB"[w];
        for (size_t k = 0; k < side[w].n; k++) in[m] = side[w].t[k].path, which[m++] = "AB"[w];
    }
    int rc = out_check_paths(outs, what, 4, in, which, m);
    free(in);
    free(which);
    return rc;
}

int main(int argc, char **argv) {
    out_guard_std();
    cli_args_t a;
    int rc = cli_parse(argc, argv, &a);
    if (rc >= 0) return rc == EXIT_OK ? out_finish() : rc; /* --help, --version, --formats printed */

    hd_error_t err;
    /* each side's files (one, a directory's or a list's), before anything
     * is read, so outputs are checked against every one of them */
    tiles_t side[2];
    memset(side, 0, sizeof side);
    if ((rc = tiles_expand(a.path_a, a.format_a, &side[0], &err)) != HD_OK ||
        (rc = tiles_expand(a.path_b, a.format_b, &side[1], &err)) != HD_OK) {
        fprintf(stderr, "hausdorff: %s\n", err.message);
        tiles_free(&side[0]);
        return exit_for(rc);
    }
    if ((rc = check_outputs(&a, side)) != 0) {
        tiles_free(&side[0]);
        tiles_free(&side[1]);
        return rc;
    }

    hd_cloud_t *ca = NULL, *cb = NULL;
    double t0 = now();
    /* progress by phase (read A, read B, compute), only for a person */
    progress_start(!a.quiet && !a.json && isatty(2), 3);
    char files[2][32] = {"", ""};
    for (int w = 0; w < 2; w++)
        if (side[w].kind != TILES_FILE) snprintf(files[w], sizeof files[w], " (%zu files)", side[w].n);
    progress_phase("reading A: %s%s", a.path_a, files[0]);
    if ((rc = tiles_read(&side[0], 0, side[0].n, &a.read, &a.an, 0, &ca, &err)) != HD_OK ||
        (progress_phase("reading B: %s%s", a.path_b, files[1]),
         rc = tiles_read(&side[1], 0, side[1].n, &a.read, &a.an, 1, &cb, &err)) != HD_OK) {
        progress_stop();
        fprintf(stderr, "hausdorff: %s\n", err.message);
        hd_cloud_free(ca);
        tiles_free(&side[0]);
        tiles_free(&side[1]);
        return failed(exit_for(rc));
    }
    double read_seconds = now() - t0;
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
        fprintf(stderr, "hausdorff: %s\n", err.message);
        hd_cloud_free(ca);
        hd_cloud_free(cb);
        tiles_free(&side[0]);
        tiles_free(&side[1]);
        return failed(exit_for(rc));
    }

    FILE *out = stdout;
    if (a.json) {
        /* with --directed H(A,B) is not computed: null, like directed_ba
         * (it once held h(A,B), which a script could take for H) */
        fprintf(out, "{\"hausdorff\": ");
        if (a.directed) fputs("null", out);
        else json_number(out, s.distance);
        fprintf(out, ", \"directed_ab\": ");
        json_number(out, s.ab.distance);
        fprintf(out, ", \"directed_ba\": ");
        if (a.directed) fputs("null", out);
        else json_number(out, s.ba.distance);
        fprintf(out, ", \"witness_ab\": ");
        witness_json(out, &s.ab);
        fprintf(out, ", \"witness_ba\": ");
        if (a.directed) fputs("null", out);
        else witness_json(out, &s.ba);
        fprintf(out, ", \"witness_ab_files\": ");
        witness_files_json(out, &s.ab, &side[0], &side[1]);
        fprintf(out, ", \"witness_ba_files\": ");
        if (a.directed) fputs("null", out);
        else witness_files_json(out, &s.ba, &side[1], &side[0]);
        fprintf(out, ", \"algorithm\": ");
        if (a.directed || s.ab.algorithm == s.ba.algorithm) {
            json_string(out, hd_algorithm_name(s.ab.algorithm));
        } else {
            fprintf(out, "{\"ab\": ");
            json_string(out, hd_algorithm_name(s.ab.algorithm));
            fprintf(out, ", \"ba\": ");
            json_string(out, hd_algorithm_name(s.ba.algorithm));
            fputc('}', out);
        }
        fprintf(out, ", \"requested_algorithm\": ");
        json_string(out, hd_algorithm_name(a.opt.algorithm));
        fprintf(out, ", \"alpha\": ");
        json_number(out, s.alpha);
        fprintf(out, ", \"disjoint\": %s", s.disjoint ? "true" : "false");
        fprintf(out, ", \"n_a\": %zu, \"n_b\": %zu", A.count, B.count);
        fprintf(out, ", \"file_a\": ");
        json_string(out, a.path_a);
        fprintf(out, ", \"file_b\": ");
        json_string(out, a.path_b);
        tiles_json(out, "a", &side[0]);
        tiles_json(out, "b", &side[1]);
        /* times are measurements: to the microsecond, then shortest */
        fprintf(out, ", \"seconds\": ");
        json_number(out, round(s.seconds * 1e6) / 1e6);
        fprintf(out, ", \"read_seconds\": ");
        json_number(out, round(read_seconds * 1e6) / 1e6);
        fprintf(out, ", \"stats_ab\": ");
        stats_json(out, &s.ab.stats);
        fprintf(out, ", \"stats_ba\": ");
        if (a.directed) fputs("null", out);
        else stats_json(out, &s.ba.stats);
        analysis_json(out, &a.an, &an);
        fprintf(out, "}\n");
    } else {
        side_line(out, 'A', &side[0], ca, a.read.mesh == HD_MESH_SAMPLE);
        side_line(out, 'B', &side[1], cb, a.read.mesh == HD_MESH_SAMPLE);
        const char *unit = analysis_units(&a.an); /* " mm" after each distance, when known */
        const char *sp = unit ? " " : "";
        if (!unit) unit = "";
        if (a.directed) {
            char d[NUM_TEXT];
            fprintf(out, "h(A,B) = %s%s%s\n", num_text(s.ab.distance, d), sp, unit);
        } else {
            char d[NUM_TEXT];
            fprintf(out, "Hausdorff distance H(A,B) = %s%s%s\n", num_text(s.distance, d), sp, unit);
            fprintf(out, "  h(A,B) = %s%s%s   [%s]\n", num_text(s.ab.distance, d), sp, unit,
                    hd_algorithm_name(s.ab.algorithm));
            fprintf(out, "  h(B,A) = %s%s%s   [%s]\n", num_text(s.ba.distance, d), sp, unit,
                    hd_algorithm_name(s.ba.algorithm));
        }
        const hd_result_t *w = (a.directed || s.ab.distance2 >= s.ba.distance2) ? &s.ab : &s.ba;
        int from_a = w == &s.ab;
        const hd_points_t *P = from_a ? &A : &B, *Q = from_a ? &B : &A;
        const tiles_t *TP = &side[!from_a], *TQ = &side[from_a];
        fprintf(out, "witness: %s[%zu] ", from_a ? "A" : "B", w->i);
        print_point(out, P, w->i);
        where_text(out, TP, w->i);
        fprintf(out, "\n     to  %s[%zu] ", from_a ? "B" : "A", w->j);
        print_point(out, Q, w->j);
        where_text(out, TQ, w->j);
        fprintf(out, "\n");
        fprintf(out, "overlap alpha = %.3f%s; algorithm %s\n", s.alpha, s.disjoint ? " (disjoint boxes)" : "",
                hd_algorithm_name(a.opt.algorithm));
        fprintf(out, "time: %.6f s computing, %.6f s reading\n", s.seconds, read_seconds);
        analysis_print(out, &a.an, &an);
    }
    analysis_free(&an);
    hd_cloud_free(ca);
    hd_cloud_free(cb);
    tiles_free(&side[0]);
    tiles_free(&side[1]);
    return out_finish();
}
