/*
 * report.c -- the result as both tools print it (report.h): one function
 * for the JSON fields and one for the report a person reads, so that
 * `hausdorff` and `hausdorff-mpi` cannot drift apart.
 */
#include "report.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Library codes to exit codes; an output failure (OUT_EFAIL) is 3. */
int cli_exit_for(int code) {
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
static void side_line(FILE *out, const report_t *r, int w) {
    const tiles_t *t = &r->side[w];
    int sampled = r->a->read.mesh == HD_MESH_SAMPLE;
    fprintf(out, "%c: %s (%zu point%s", "AB"[w], safe_text(t->arg), r->n[w], plural(r->n[w]));
    if (r->n[w]) fprintf(out, ", %s", r->format[w]); /* an empty side has no format to tell */
    if (r->faces[w])
        fprintf(out, "%s %zu face%s", sampled ? " sampled from" : ",", r->faces[w], plural(r->faces[w]));
    if (t->kind != TILES_FILE) {
        char skipped[512];
        tiles_skipped_text(t, skipped, sizeof skipped);
        fprintf(out, ", %zu file%s%s%s", t->n, t->n == 1 ? "" : "s", skipped[0] ? "; " : "", safe_text(skipped));
    }
    fprintf(out, ")\n");
    if (w == 1 && r->faces[w] && !sampled) fprintf(out, "   B is a mesh read as its vertices: --surface measures its triangles\n");
}

/* " = dir/t2.xyz[3]" for a point of a side of many files, else nothing. */
static void where_text(FILE *out, const tiles_t *t, size_t g) {
    if (t->kind == TILES_FILE) return;
    size_t local, k = tiles_locate(t, g, &local);
    fprintf(out, " = %s[%zu]", safe_text(t->t[k].path), local);
}

/* A point of a side: each coordinate as the shortest text of its double,
 * or of its float when the side's data was float32 (single). */
static void print_point(FILE *out, const double *q, int single) {
    char c[3][NUM_TEXT];
    for (int k = 0; k < 3; k++) {
        if (single) num_text_single(q[k], c[k]);
        else num_text(q[k], c[k]);
    }
    fprintf(out, "(%s, %s, %s)", c[0], c[1], c[2]);
}

int report_single(const hd_points_t *p, const mask_info_t *m) {
    if (p->dtype == HD_FLOAT32 || (m && m->is_mask && m->nifti_version == 1)) return 1;
    for (size_t i = 0; i < p->count; i++) {
        double q[3];
        hd_points_get(p, i, q);
        for (int k = 0; k < 3; k++)
            if (fabs(q[k]) > FLT_MAX || (double)(float)q[k] != q[k]) return 0;
    }
    return 1;
}

static void stats_json(FILE *out, const hd_stats_t *s) {
    fprintf(out, "{\"distance_evals\": %llu, \"nodes_visited\": %llu, \"points_culled\": %llu, \"peak_bytes\": %llu}",
            (unsigned long long)s->distance_evals, (unsigned long long)s->nodes_visited,
            (unsigned long long)s->points_culled, (unsigned long long)s->peak_bytes);
}


const hd_result_t *report_witness(const cli_args_t *a, const hd_symmetric_t *s, int *from_a) {
    const hd_result_t *w = (a->directed || s->ab.distance2 >= s->ba.distance2) ? &s->ab : &s->ba;
    *from_a = w == &s->ab;
    return w;
}

/* The witnesses, the algorithms and the overlap of a computed run. */
static void witnesses_json(FILE *out, const report_t *r) {
    const cli_args_t *a = r->a;
    const hd_symmetric_t *s = r->s;
    const tiles_t *side = r->side;
    fprintf(out, ", \"witness_ab\": ");
    witness_json(out, &s->ab);
    fprintf(out, ", \"witness_ba\": ");
    if (a->directed) fputs("null", out);
    else witness_json(out, &s->ba);
    fprintf(out, ", \"witness_ab_files\": ");
    witness_files_json(out, &s->ab, &side[0], &side[1]);
    fprintf(out, ", \"witness_ba_files\": ");
    if (a->directed) fputs("null", out);
    else witness_files_json(out, &s->ba, &side[1], &side[0]);
    fprintf(out, ", \"algorithm\": ");
    if (a->directed || s->ab.algorithm == s->ba.algorithm) {
        json_string(out, hd_algorithm_name(s->ab.algorithm));
    } else {
        fprintf(out, "{\"ab\": ");
        json_string(out, hd_algorithm_name(s->ab.algorithm));
        fprintf(out, ", \"ba\": ");
        json_string(out, hd_algorithm_name(s->ba.algorithm));
        fputc('}', out);
    }
    fprintf(out, ", \"requested_algorithm\": ");
    json_string(out, hd_algorithm_name(a->opt.algorithm));
    fprintf(out, ", \"alpha\": ");
    json_number(out, s->alpha);
    fprintf(out, ", \"disjoint\": %s", s->disjoint ? "true" : "false");
}

void report_json(FILE *out, const report_t *r) {
    const cli_args_t *a = r->a;
    const hd_symmetric_t *s = r->s;
    const tiles_t *side = r->side;
    /* with --directed H(A,B) is not computed: null, like directed_ba
     * (it once held h(A,B), which a script could take for H) */
    fprintf(out, "{\"hausdorff\": ");
    if (a->directed) fputs("null", out);
    else json_number(out, s->distance);
    fprintf(out, ", \"directed_ab\": ");
    json_number(out, s->ab.distance);
    fprintf(out, ", \"directed_ba\": ");
    if (a->directed) fputs("null", out);
    else json_number(out, s->ba.distance);
    if (r->empty) {
        fprintf(out, ", \"witness_ab\": null, \"witness_ba\": null, \"witness_ab_files\": null, "
                     "\"witness_ba_files\": null, \"empty\": {\"a\": %s, \"b\": %s, \"policy\": \"%s\"}",
                r->n[0] ? "false" : "true", r->n[1] ? "false" : "true", hd_empty_policy_name(a->an.empty));
    } else {
        witnesses_json(out, r);
    }
    fprintf(out, ", \"n_a\": %zu, \"n_b\": %zu", r->n[0], r->n[1]);
    fprintf(out, ", \"file_a\": ");
    json_string(out, a->path_a);
    fprintf(out, ", \"file_b\": ");
    json_string(out, a->path_b);
    tiles_json(out, "a", &side[0]);
    tiles_json(out, "b", &side[1]);
    if (r->empty) return; /* nothing computed: no times, no counters */
    /* times are measurements: to the microsecond, then shortest */
    fprintf(out, ", \"seconds\": ");
    json_number(out, round(s->seconds * 1e6) / 1e6);
    fprintf(out, ", \"read_seconds\": ");
    json_number(out, round(r->read_seconds * 1e6) / 1e6);
    fprintf(out, ", \"stats_ab\": ");
    stats_json(out, &s->ab.stats);
    fprintf(out, ", \"stats_ba\": ");
    if (a->directed) fputs("null", out);
    else stats_json(out, &s->ba.stats);
}

void report_text(FILE *out, const report_t *r) {
    const cli_args_t *a = r->a;
    const hd_symmetric_t *s = r->s;
    side_line(out, r, 0);
    side_line(out, r, 1);
    char d[NUM_TEXT];
    const char *unit = analysis_units(&a->an); /* " mm" after each distance, when known */
    const char *sp = unit ? " " : "";
    if (!unit) unit = "";
    if (r->empty) {
        const char *which = !r->n[0] && !r->n[1] ? "A and B are" : !r->n[0] ? "A is" : "B is";
        fprintf(out, "%s = %s%s%s   (%s empty; --empty %s)\n", a->directed ? "h(A,B)" : "Hausdorff distance H(A,B)",
                num_text(s->ab.distance, d), sp, unit, which, hd_empty_policy_name(a->an.empty));
        return;
    }
    if (a->directed) {
        fprintf(out, "h(A,B) = %s%s%s\n", num_text(s->ab.distance, d), sp, unit);
    } else {
        fprintf(out, "Hausdorff distance H(A,B) = %s%s%s\n", num_text(s->distance, d), sp, unit);
        fprintf(out, "  h(A,B) = %s%s%s   [%s]\n", num_text(s->ab.distance, d), sp, unit,
                hd_algorithm_name(s->ab.algorithm));
        fprintf(out, "  h(B,A) = %s%s%s   [%s]\n", num_text(s->ba.distance, d), sp, unit,
                hd_algorithm_name(s->ba.algorithm));
    }
    int from_a;
    const hd_result_t *w = report_witness(a, s, &from_a);
    const tiles_t *TP = &r->side[!from_a], *TQ = &r->side[from_a];
    fprintf(out, "witness: %s[%zu] ", from_a ? "A" : "B", w->i);
    print_point(out, r->wp, r->single[!from_a]);
    where_text(out, TP, w->i);
    fprintf(out, "\n     to  %s[%zu] ", from_a ? "B" : "A", w->j);
    print_point(out, r->wq, r->single[from_a]);
    where_text(out, TQ, w->j);
    fprintf(out, "\n");
    char al[NUM_TEXT], tc[NUM_TEXT], tr[NUM_TEXT];
    fprintf(out, "overlap alpha = %s%s; algorithm %s\n", num_ratio(s->alpha, al),
            s->disjoint ? " (disjoint boxes)" : "", hd_algorithm_name(a->opt.algorithm));
    fprintf(out, "time: %s s computing, %s s reading\n", num_seconds(s->seconds, tc),
            num_seconds(r->read_seconds, tr));
}

void report_print(FILE *out, const report_t *r, const analysis_result_t *an, report_more_t more, const void *ctx) {
    const analysis_args_t *args = &r->a->an;
    if (r->a->json) {
        report_json(out, r);
        if (an) analysis_json(out, args, an);
        if (more) more(out, 1, ctx);
        fprintf(out, "}\n");
    } else {
        report_text(out, r);
        if (an) analysis_print(out, args, an);
        if (more) more(out, 0, ctx);
    }
}
