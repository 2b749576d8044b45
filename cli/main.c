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
 * refuses outputs that would overwrite an input before anything is read
 * (exit 1), lets every file be written to a temporary, and ends a run that
 * succeeded with out_finish (standard output flushed and closed, checked;
 * then the files renamed into place, all or none; exit 3 when either
 * fails) and a run that failed with out_discard (no file appears).
 */
#include "cli.h"

#include <math.h>
#include "output.h"
#include "progress.h"

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

/* Refuse an output that would overwrite an input or another output. */
static int check_outputs(const cli_args_t *a) {
    char path_b[4096];
    const char *outs[4] = {a->an.distances_out, NULL, a->an.render_out, a->an.histogram_png};
    const char *const what[4] = {"--distances", "--distances (B's rows)", "--render", "--histogram-png"};
    if (a->an.distances_out && !a->directed) {
        path_with_suffix(a->an.distances_out, "_b", path_b, sizeof path_b);
        outs[1] = path_b;
    }
    return out_check_paths(outs, what, 4, a->path_a, a->path_b);
}

int main(int argc, char **argv) {
    out_guard_std();
    cli_args_t a;
    int rc = cli_parse(argc, argv, &a);
    if (rc >= 0) return rc == EXIT_OK ? out_finish() : rc; /* --help, --version, --formats printed */
    if ((rc = check_outputs(&a)) != 0) return rc;

    hd_error_t err;
    hd_cloud_t *ca = NULL, *cb = NULL;
    double t0 = now();
    /* progress by phase (read A, read B, compute), only for a person */
    progress_start(!a.quiet && !a.json && isatty(2), 3);
    hd_read_options_t read_a = a.read, read_b = a.read; /* FORMAT:PATH wins over --format */
    if (a.format_a) read_a.format = a.format_a;
    if (a.format_b) read_b.format = a.format_b;
    progress_phase("reading A: %s", a.path_a);
    if ((rc = cli_read_points(a.path_a, &read_a, &a.an, 0, &ca, &err)) != HD_OK ||
        (progress_phase("reading B: %s", a.path_b),
         rc = cli_read_points(a.path_b, &read_b, &a.an, 1, &cb, &err)) != HD_OK) {
        progress_stop();
        fprintf(stderr, "hausdorff: %s\n", err.message);
        hd_cloud_free(ca);
        return failed(exit_for(rc));
    }
    double read_seconds = now() - t0;
    hd_points_t A = hd_cloud_points(ca), B = hd_cloud_points(cb);
    progress_phase("computing (%zu x %zu points)", A.count, B.count);
    if ((rc = analysis_handle_empty(&a.an, a.path_a, a.path_b, &A, &B, a.directed, a.json)) >= 0) {
        progress_stop();
        hd_cloud_free(ca);
        hd_cloud_free(cb);
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
        const char *how = a.read.mesh == HD_MESH_SAMPLE ? " sampled from" : ",";
        fprintf(out, "A: %s (%zu points, %s", a.path_a, A.count, ca->format);
        if (ca->n_faces) fprintf(out, "%s %zu faces", how, ca->n_faces);
        fprintf(out, ")\nB: %s (%zu points, %s", a.path_b, B.count, cb->format);
        if (cb->n_faces) fprintf(out, "%s %zu faces", how, cb->n_faces);
        fprintf(out, ")\n");
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
        fprintf(out, "witness: %s[%zu] ", from_a ? "A" : "B", w->i);
        print_point(out, P, w->i);
        fprintf(out, "\n     to  %s[%zu] ", from_a ? "B" : "A", w->j);
        print_point(out, Q, w->j);
        fprintf(out, "\n");
        fprintf(out, "overlap alpha = %.3f%s; algorithm %s\n", s.alpha, s.disjoint ? " (disjoint boxes)" : "",
                hd_algorithm_name(a.opt.algorithm));
        fprintf(out, "time: %.6f s computing, %.6f s reading\n", s.seconds, read_seconds);
        analysis_print(out, &a.an, &an);
    }
    analysis_free(&an);
    hd_cloud_free(ca);
    hd_cloud_free(cb);
    return out_finish();
}
