/*
 * analysis.c -- the command line's analysis options (options.c parses them): running
 * them after the Hausdorff distance, and reporting them for a person or in
 * the JSON object.
 *
 * Everything is computed by the library from one array of per-point
 * distances per direction (hd_distances): the percentile figures
 * (hd_percentile_of: "ab", "ba", "symmetric" = max of the two as MONAI,
 * "pooled" = both directions together as medpy), the means and Chamfer
 * distances (hd_summarize), the histograms (hd_histogram, numpy's bins),
 * the scores at tolerances (--tau: hd_tolerance_scores, precision, recall,
 * F-score, NSD) and DTU's capped means (--dtu-cap: hd_capped_means).
 * The tool only adds files (writers.c, render.c) and text.  The per-point
 * distances are computed once, and only when an option needs them, so a
 * plain run costs exactly what it did before.
 *
 * Empty sets: by default an empty file or mask is an error (exit 2) with a
 * message that names the file and the --empty option.  With --empty
 * inf|nan|zero every distance figure becomes that value instead, because
 * users disagree: MONAI returns NaN or inf, medpy raises, some pipelines
 * count a miss as 0.  JSON has no inf or NaN, so those are written as null
 * and "empty" says which policy produced them.
 *
 * Files (--distances, its _b file, --render, --histogram-png) are written
 * here but appear only at the end: each goes to a temporary that main
 * renames into place, all together, once the report has reached standard
 * output (output.c).  A write that fails returns OUT_EFAIL (exit 3), and
 * the files written before it are removed with the rest.
 */
#include "analysis.h"
#include "cli.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int scores_figures(const analysis_args_t *an, const double *d_ab, size_t n_a, const double *d_ba,
                          size_t n_b, analysis_result_t *r, hd_error_t *err);
static void print_scores(FILE *out, const analysis_args_t *an, const analysis_result_t *r, const char *unit);

/* ---- options -------------------------------------------------------------- */

void analysis_args_init(analysis_args_t *an) {
    memset(an, 0, sizeof *an);
    an->percentile = 95.0;
    an->bins = 20;
    an->mask_points = MASK_SURFACE;
    an->connectivity = 1;
    an->mask_dims = 0;
    an->empty = HD_EMPTY_ERROR;
}

render_notes_t analysis_notes(const analysis_args_t *an, const analysis_result_t *r) {
    return (render_notes_t){analysis_units(an), an->percentile_on, r->pct, r->surface};
}

const char *analysis_units(const analysis_args_t *an) {
    if (an->units) return an->units;
    for (int k = 0; k < 2; k++)
        if (an->mask[k].is_mask && an->mask[k].unit_known) return "mm";
    return NULL;
}

int analysis_active(const analysis_args_t *an) {
    return an->percentile_on || an->mean || an->chamfer || an->histogram || an->distances_out ||
           an->render_out || an->histogram_png || an->n_taus || an->dtu_cap > 0 || an->subset[0].on || an->subset[1].on;
}

int analysis_percentile_only(const analysis_args_t *an) {
    return an->percentile_on && !an->mean && !an->chamfer && !an->histogram && !an->distances_out &&
           !an->render_out && !an->histogram_png && !an->subset[0].on && !an->subset[1].on;
}

/* Only the percentile and the histogram asked for (the text or JSON
 * histogram, not its picture): the library gives both without every
 * distance. */
static int analysis_from_bounds(const analysis_args_t *an) {
    return (an->percentile_on || an->histogram) && !an->mean && !an->chamfer && !an->distances_out &&
           !an->render_out && !an->histogram_png && !an->n_taus && an->dtu_cap <= 0;
}

/* ---- empty sets ------------------------------------------------------------ */

static int alloc_fail(hd_error_t *err, size_t n) {
    snprintf(err->message, sizeof err->message, "out of memory for %zu per-point distances", n);
    return err->code = HD_ENOMEM;
}



typedef struct {
    const char *key;
    double value;
} member_t;

/* `, "key": value` for each member, NaN as null. */
static void json_object_members(FILE *out, const member_t *m, size_t n) {
    for (size_t k = 0; k < n; k++) {
        fprintf(out, ", \"%s\": ", m[k].key);
        json_number(out, m[k].value);
    }
}

/* `, "name": {head, "key": value, ...}` with NaN as null. */
static void json_object(FILE *out, const char *name, const char *head,
                        const member_t *m, size_t n) {
    fprintf(out, ", \"%s\": {%s", name, head ? head : "");
    for (size_t k = 0; k < n; k++) {
        fprintf(out, "%s\"%s\": ", k || head ? ", " : "", m[k].key);
        json_number(out, m[k].value);
    }
    fputc('}', out);
}

/* The percentile, mean and Chamfer members asked for, from r->pct and
 * r->sum. */
static void json_figures(FILE *out, const analysis_args_t *an,
                         const analysis_result_t *r) {
    const hd_percentile_t *p = &r->pct;
    const hd_summary_t *s = &r->sum;
    if (an->percentile_on) {
        member_t m[] = {{"p", p->p}, {"ab", p->ab}, {"ba", p->ba}, {"symmetric", p->symmetric},
                        {"pooled", p->pooled}};
        json_object(out, "percentile", NULL, m, sizeof m / sizeof m[0]);
    }
    if (an->mean) {
        member_t m[] = {{"ab", s->mean_ab}, {"ba", s->mean_ba}, {"symmetric", s->mean_symmetric},
                        {"average", s->mean_average}, {"pooled", s->mean_pooled}};
        json_object(out, "mean", NULL, m, sizeof m / sizeof m[0]);
    }
    if (an->n_taus) {
        fprintf(out, ", \"tolerance\": {\"rule\": \"%s\", \"scores\": [", an->tau_rule == HD_BELOW ? "d < tau" : "d <= tau");
        for (size_t k = 0; k < an->n_taus; k++) {
            const hd_tolerance_t *t = &r->tol[k];
            fputs(k ? ", {\"tau\": " : "{\"tau\": ", out);
            json_number(out, an->taus[k]);
            member_t m[] = {{"precision", t->precision}, {"recall", t->recall}, {"fscore", t->fscore}, {"nsd", t->nsd}};
            for (size_t q = 0; q < sizeof m / sizeof m[0]; q++) {
                fprintf(out, ", \"%s\": ", m[q].key);
                json_number(out, m[q].value);
            }
            fprintf(out, ", \"within_ab\": %zu, \"within_ba\": ", t->count_ab);
            if (r->directed) fputs("null}", out);
            else fprintf(out, "%zu}", t->count_ba);
        }
        fputs("]}", out);
    }
    if (an->dtu_cap > 0) {
        member_t m[] = {{"accuracy", r->dtu.accuracy}, {"completeness", r->dtu.completeness}, {"overall", r->dtu.overall},
                        {"kept_ab", (double)r->dtu.kept_ab}, {"kept_ba", r->directed ? NAN : (double)r->dtu.kept_ba}};
        fputs(", \"dtu\": {\"cap\": ", out);
        json_number(out, an->dtu_cap);
        json_object_members(out, m, sizeof m / sizeof m[0]);
        fputc('}', out);
    }
    if (an->chamfer) {
        member_t m[] = {{"value", r->directed ? s->mean2_ab : s->chamfer}, {"mean_squared", s->chamfer},
                        {"sum_squared", s->chamfer_sum2}, {"mean", s->chamfer_mean}, {"sum", s->chamfer_sum},
                        {"mean_squared_ab", s->mean2_ab}, {"mean_squared_ba", s->mean2_ba}};
        json_object(out, "chamfer", "\"definition\": \"mean_squared\"", m, sizeof m / sizeof m[0]);
    }
}

/* --distances as tables (writers.c) for each side whose file is not
 * written back into its own format (writeback.c): A's to OUT, B's (unless
 * directed) to OUT_b.EXT; surf: A's distances are to a surface. */
static int distance_tables(const analysis_args_t *an, const hd_points_t *A, const hd_points_t *B, const char *path_a,
                           const char *path_b, const double *d_ab, const size_t *j_ab, const double *d_ba,
                           const size_t *j_ba, const surface_columns_t *surf, double scale, int directed,
                           analysis_result_t *r, hd_error_t *err) {
    if (!an->distances_out) return HD_OK;
    int rc = HD_OK;
    if (!analysis_writes_back(an, 0, an->distances_out, path_a)) {
        r->dist_path_a = an->distances_out;
        rc = surf ? write_surface_distances(r->dist_path_a, A, d_ab, surf, scale, err)
                  : write_distances(r->dist_path_a, A, d_ab, j_ab, scale, err);
        if (rc) return rc;
    }
    if (directed) return HD_OK;
    char *out_b = path_with_suffix(an->distances_out, "_b");
    if (!out_b) return alloc_fail(err, B->count);
    if (analysis_writes_back(an, 1, out_b, path_b)) {
        free(out_b);
        return HD_OK;
    }
    r->dist_path_b = out_b;
    return write_distances(out_b, B, d_ba, j_ba, scale, err);
}

/* The per-point files of a run with an empty set (analysis.h). */
int analysis_empty_files(const analysis_args_t *an, const hd_points_t *A, const hd_points_t *B, int directed,
                         double v, const char *path_a, const char *path_b, analysis_result_t *r, hd_error_t *err) {
    if (!an->distances_out && !an->subset[0].on && !an->subset[1].on) return HD_OK;
    size_t n = A->count > B->count ? A->count : B->count;
    double *d = malloc((n ? n : 1) * sizeof *d);
    if (!d) return alloc_fail(err, n);
    for (size_t k = 0; k < n; k++) d[k] = v;
    writeback_side_t side[2] = {{d, A->count, NULL, NULL}, {d, B->count, NULL, NULL}};
    int rc = analysis_write_back(an, path_a, path_b, side, directed, 0, r, err);
    if (rc == HD_OK) rc = distance_tables(an, A, B, path_a, path_b, d, NULL, d, NULL, NULL, 1.0, directed, r, err);
    free(d);
    return rc;
}

/* --tau and --dtu-cap when a set is empty: the other set's points have
 * nothing to be near (distance +inf), so none is within any tolerance: the
 * NSD is 0 with one set empty and NaN with both (MONAI's), a share of no
 * points NaN, and a capped mean of no values NaN. */
static int empty_scores(const analysis_args_t *an, size_t n_a, size_t n_b, int directed, analysis_result_t *r,
                        hd_error_t *err) {
    if (!an->n_taus && !(an->dtu_cap > 0)) return HD_OK;
    size_t n = n_a > n_b ? n_a : n_b;
    double *inf = malloc((n ? n : 1) * sizeof *inf);
    if (!inf) return alloc_fail(err, n);
    for (size_t k = 0; k < n; k++) inf[k] = INFINITY;
    int rc = scores_figures(an, inf, n_a, directed ? NULL : inf, n_b, r, err);
    free(inf);
    return rc;
}

int analysis_empty(const analysis_args_t *an, size_t n_a, size_t n_b, int directed, hd_symmetric_t *s,
                   analysis_result_t *r, hd_error_t *err) {
    double v = hd_empty_value(an->empty, n_a, n_b), w = directed ? NAN : v;
    memset(s, 0, sizeof *s);
    s->distance = s->ab.distance = v;
    s->ba.distance = w;
    if (an->render_out || an->histogram_png)
        fprintf(stderr, "%s: no picture drawn: %s is empty\n", cli_prog(), n_a ? "B" : "A");
    memset(r, 0, sizeof *r);
    r->empty = 1;
    r->directed = directed;
    r->n_a = n_a;
    r->n_b = n_b;
    r->pct = (hd_percentile_t){an->percentile, v, w, w, w};
    r->sum.mean_ab = r->sum.mean2_ab = v;
    r->sum.mean_ba = r->sum.mean_symmetric = r->sum.mean_average = r->sum.mean_pooled = w;
    r->sum.mean2_ba = r->sum.chamfer = r->sum.chamfer_sum2 = r->sum.chamfer_mean = r->sum.chamfer_sum = w;
    return empty_scores(an, n_a, n_b, directed, r, err);
}

/* ---- the run ----------------------------------------------------------------- */

/* The last component of a path, without the '/' that may end a directory's
 * ("tiles/" -> "tiles"), into buf. */
static const char *last_name(const char *path, char buf[256]) {
    size_t n = strlen(path);
    while (n > 1 && path[n - 1] == '/') n--;
    size_t k = n;
    while (k > 0 && path[k - 1] != '/') k--;
    snprintf(buf, 256, "%.*s", (int)(n - k < 255 ? n - k : 255), path + k);
    return buf;
}

/* Values beyond the histogram's range: the distances are never negative
 * nor NaN (a NaN was refused by the summary), so every value not counted
 * lies above it. */
static size_t beyond(const uint64_t *counts, size_t bins, size_t n) {
    uint64_t in = 0;
    for (size_t k = 0; k < bins; k++) in += counts[k];
    return n - (size_t)in;
}

/* --tau and --dtu-cap from the per-point distances (d_ba NULL: directed,
 * and then every figure that needs B's distances is NaN). */
static int scores_figures(const analysis_args_t *an, const double *d_ab, size_t n_a, const double *d_ba,
                          size_t n_b, analysis_result_t *r, hd_error_t *err) {
    if (!d_ba) n_b = 0;
    int rc = HD_OK;
    if (an->n_taus)
        rc = hd_tolerance_scores(d_ab, NULL, n_a, d_ba, NULL, n_b, an->taus, an->n_taus, an->tau_rule, r->tol, err);
    for (size_t k = 0; rc == HD_OK && !d_ba && k < an->n_taus; k++)
        r->tol[k].recall = r->tol[k].fscore = r->tol[k].nsd = NAN;
    if (rc == HD_OK && an->dtu_cap > 0) {
        rc = hd_capped_means(d_ab, n_a, d_ba, n_b, an->dtu_cap, &r->dtu, err);
        if (!d_ba) r->dtu.completeness = r->dtu.overall = NAN;
    }
    return rc;
}

double analysis_scale(const analysis_args_t *an, const analysis_result_t *r) {
    double largest = r->directed || r->sum.max_ab >= r->sum.max_ba ? r->sum.max_ab : r->sum.max_ba;
    return an->max_distance > 0 ? an->max_distance : largest;
}

int analysis_figures(const analysis_args_t *an, const analysis_ops_t *ops, const double *d_ab, size_t n_a,
                     const double *d_ba, size_t n_b, analysis_result_t *r, hd_error_t *err) {
    int rc;
    if ((rc = ops->summarize(d_ab, n_a, r->directed ? NULL : d_ba, n_b, &r->sum, err))) return rc;
    /* one process's distances only: hausdorff-mpi refuses --tau and --dtu-cap when parsing (options.c) */
    if ((an->n_taus || an->dtu_cap > 0) &&
        (rc = scores_figures(an, d_ab, n_a, r->directed ? NULL : d_ba, n_b, r, err)))
        return rc;
    if (an->percentile_on &&
        (rc = ops->percentile_of(d_ab, n_a, r->directed ? NULL : d_ba, n_b, an->percentile, &r->pct, err)))
        return rc;
    if (!an->histogram && !an->histogram_png) return HD_OK;
    double scale = analysis_scale(an, r);
    r->hist_lo = 0.0;
    r->hist_hi = scale;
    if (!r->hist_ab) r->hist_ab = calloc(an->bins, sizeof *r->hist_ab); /* or the caller's */
    if (!r->hist_ab) return alloc_fail(err, an->bins);
    if ((rc = ops->histogram(d_ab, n_a, 0.0, scale, an->bins, r->hist_ab, err))) return rc;
    r->above_ab = beyond(r->hist_ab, an->bins, r->n_a);
    if (!r->directed) {
        if (!r->hist_ba) r->hist_ba = calloc(an->bins, sizeof *r->hist_ba);
        if (!r->hist_ba) return alloc_fail(err, an->bins);
        if ((rc = ops->histogram(d_ba, n_b, 0.0, scale, an->bins, r->hist_ba, err))) return rc;
        r->above_ba = beyond(r->hist_ba, an->bins, r->n_b);
    }
    return HD_OK;
}

void analysis_render_title(const char *path_a, size_t n_a, const char *path_b, char *title, size_t size) {
    char base[256], base_b[256];
    snprintf(title, size, "%s (%zu points) coloured by distance to %s", last_name(path_a, base), n_a,
             last_name(path_b, base_b));
}

/* --histogram (with or without --percentile) from the library's bounds
 * instead of every distance: the range's top is --max-distance or the
 * Hausdorff distance s, the largest distance of either direction. */
static int histogram_from_bounds(const analysis_args_t *an, const hd_options_t *opt, const hd_points_t *A,
                                 const hd_points_t *B, const hd_symmetric_t *s, analysis_result_t *r,
                                 hd_error_t *err) {
    double t0 = cli_now();
    int rc = HD_OK;
    if (an->percentile_on) rc = hd_hausdorff_percentile(A, B, opt, an->percentile, &r->pct, err);
    double largest = s->ab.distance >= s->ba.distance ? s->ab.distance : s->ba.distance;
    r->hist_lo = 0.0;
    r->hist_hi = an->max_distance > 0 ? an->max_distance : largest;
    r->hist_ab = calloc(an->bins, sizeof *r->hist_ab);
    r->hist_ba = calloc(an->bins, sizeof *r->hist_ba);
    if (rc == HD_OK && (!r->hist_ab || !r->hist_ba)) rc = alloc_fail(err, an->bins);
    if (rc == HD_OK)
        rc = hd_hausdorff_histogram(A, B, opt, an->bins, r->hist_lo, r->hist_hi, r->hist_ab, r->hist_ba, err);
    r->seconds = cli_now() - t0;
    if (rc) return rc;
    r->above_ab = beyond(r->hist_ab, an->bins, r->n_a);
    r->above_ba = beyond(r->hist_ba, an->bins, r->n_b);
    return HD_OK;
}

int analysis_run(const analysis_args_t *an, const hd_options_t *opt,
                 const hd_points_t *A, const hd_points_t *B,
                 const hd_symmetric_t *s, int directed, const char *path_a,
                 const char *path_b, analysis_result_t *r, hd_error_t *err) {
    memset(r, 0, sizeof *r);
    r->active = analysis_active(an);
    r->directed = directed;
    r->n_a = A->count;
    r->n_b = B->count;
    if (!r->active) return HD_OK;
    if (!directed && analysis_percentile_only(an)) { /* the library's selection without every distance */
        double t0 = cli_now();
        int rc = hd_hausdorff_percentile(A, B, opt, an->percentile, &r->pct, err);
        r->seconds = cli_now() - t0;
        return rc;
    }
    if (!directed && analysis_from_bounds(an)) return histogram_from_bounds(an, opt, A, B, s, r, err);
    r->d_ab = malloc(A->count * sizeof *r->d_ab);
    r->j_ab = malloc(A->count * sizeof *r->j_ab);
    if (!r->d_ab || !r->j_ab) return alloc_fail(err, A->count);
    if (!directed) {
        r->d_ba = malloc(B->count * sizeof *r->d_ba);
        r->j_ba = malloc(B->count * sizeof *r->j_ba);
        if (!r->d_ba || !r->j_ba) return alloc_fail(err, B->count);
    }
    double t0 = cli_now();
    int rc = hd_distances(A, B, opt, r->d_ab, r->j_ab, r->d_ba, r->j_ba, err);
    r->seconds = cli_now() - t0;
    if (rc) return rc;
    return analysis_finish(an, A, B, s, NULL, path_a, path_b, NULL, r, err);
}

int analysis_finish(const analysis_args_t *an, const hd_points_t *A, const hd_points_t *B,
                    const hd_symmetric_t *s, const double *wq, const char *path_a, const char *path_b,
                    const surface_columns_t *surf, analysis_result_t *r, hd_error_t *err) {
    int rc, directed = r->directed;
    static const analysis_ops_t here = {hd_summarize, hd_percentile_of, hd_histogram};
    if ((rc = analysis_figures(an, &here, r->d_ab, A->count, r->d_ba, directed ? 0 : B->count, r, err))) return rc;
    double scale = analysis_scale(an, r);
    /* files written back into the sides' formats, then the tables */
    writeback_side_t side[2] = {{r->d_ab, A->count, r->j_ab, surf ? surf->sign : NULL},
                                {r->d_ba, directed ? 0 : B->count, r->j_ba, NULL}};
    if ((rc = analysis_write_back(an, path_a, path_b, side, directed, surf != NULL, r, err)) ||
        (rc = distance_tables(an, A, B, path_a, path_b, r->d_ab, r->j_ab, r->d_ba, r->j_ba,
                              surf && an->distances_out ? surf : NULL, scale, directed, r, err)))
        return rc;
    render_notes_t notes = analysis_notes(an, r);
    if (an->render_out) {
        char title[640];
        analysis_render_title(path_a, A->count, path_b, title, sizeof title);
        if ((rc = render_distances(an->render_out, A, B, r->d_ab, scale, s, wq, directed, &notes, title, r->markers,
                                   &r->n_markers, &r->render, &r->render_w, &r->render_h, err)))
            return rc;
    }
    if (an->histogram_png && (rc = render_histogram(an->histogram_png, r, &notes, an->bins, r->hist_markers,
                                                    &r->n_hist_markers, err)))
        return rc;
    return HD_OK;
}

void analysis_free(analysis_result_t *r) {
    free(r->d_ab);
    free(r->d_ba);
    free(r->j_ab);
    free(r->j_ba);
    free(r->hist_ab);
    free(r->hist_ba);
    free(r->dist_path_b);
    for (int k = 0; k < 3; k++) free(r->wb_path_b[k]);
    memset(r, 0, sizeof *r);
}

/* ---- reports ------------------------------------------------------------------ */

static void json_counts(FILE *out, const uint64_t *c, size_t n) {
    fputc('[', out);
    for (size_t k = 0; k < n; k++) fprintf(out, "%s%llu", k ? ", " : "", (unsigned long long)c[k]);
    fputc(']', out);
}

static void json_mask(FILE *out, const mask_info_t *m) {
    if (!m->is_mask) {
        fputs("null", out);
        return;
    }
    fprintf(out, "{\"nifti\": %d, \"dim\": [%lld, %lld, %lld], \"spacing\": [", m->nifti_version, m->dim[0],
            m->dim[1], m->dim[2]);
    for (int c = 0; c < 3; c++) {
        if (c) fputs(", ", out);
        json_number(out, m->spacing[c]);
    }
    fprintf(out, "], \"transform\": \"%s\", \"to_mm\": ", m->transform);
    json_number(out, m->to_mm);
    fprintf(out, ", \"unit_known\": %s, \"foreground_voxels\": %lld, \"points\": %zu", m->unit_known ? "true" : "false",
            m->foreground, m->points);
    if (m->surface_dims || m->connectivity)
        fprintf(out, ", \"surface_dims\": %d, \"connectivity\": %d", m->surface_dims, m->connectivity);
    fputc('}', out);
}

void analysis_json(FILE *out, const analysis_args_t *an,
                   const analysis_result_t *r) {
    const char *units = analysis_units(an);
    int masks = an->mask[0].is_mask || an->mask[1].is_mask;
    if (units || masks) {
        fprintf(out, ", \"units\": ");
        if (units) json_string(out, units);
        else fputs("null", out);
    }
    if (masks) {
        fprintf(out, ", \"mask_points\": \"%s\", \"connectivity\": %d, \"mask_dims\": ",
                an->mask_points == MASK_ALL ? "all" : "surface", an->connectivity);
        if (an->mask_dims) fprintf(out, "%d", an->mask_dims);
        else fputs("\"auto\"", out);
        fprintf(out, ", \"masks\": {\"a\": ");
        json_mask(out, &an->mask[0]);
        fprintf(out, ", \"b\": ");
        json_mask(out, &an->mask[1]);
        fputc('}', out);
    }
    if (r->empty) { /* nothing measured: the policy's figures */
        json_figures(out, an, r);
        return;
    }
    if (!r->active) return;
    fprintf(out, ", \"distances_seconds\": "); /* to the microsecond, as "seconds" */
    json_number(out, round(r->seconds * 1e6) / 1e6);
    json_figures(out, an, r);
    if (r->hist_ab) {
        fprintf(out, ", \"histogram\": {\"bins\": %zu, \"range\": [", an->bins);
        json_number(out, hd_histogram_edge(r->hist_lo, r->hist_hi, an->bins, 0));
        fputs(", ", out);
        json_number(out, hd_histogram_edge(r->hist_lo, r->hist_hi, an->bins, an->bins));
        fprintf(out, "], \"ab\": ");
        json_counts(out, r->hist_ab, an->bins);
        fprintf(out, ", \"ba\": ");
        if (r->hist_ba) json_counts(out, r->hist_ba, an->bins);
        else fputs("null", out);
        fprintf(out, ", \"above_ab\": %zu, \"above_ba\": ", r->above_ab);
        if (r->hist_ba) fprintf(out, "%zu", r->above_ba);
        else fputs("null", out);
        fputc('}', out);
    }
    analysis_write_back_json(out, an, r);
    if (an->distances_out && (r->dist_path_a || r->dist_path_b)) {
        fprintf(out, ", \"distances_file\": {\"a\": ");
        if (r->dist_path_a) json_string(out, r->dist_path_a);
        else fputs("null", out);
        fprintf(out, ", \"b\": ");
        if (r->dist_path_b) json_string(out, r->dist_path_b);
        else fputs("null", out);
        fputc('}', out);
    }
    if (an->render_out) {
        fprintf(out, ", \"render\": {\"file\": ");
        json_string(out, an->render_out);
        fprintf(out, ", \"width\": %d, \"height\": %d, \"bar_title\": ", r->render_w, r->render_h);
        json_string(out, r->render.bar_title);
        fprintf(out, ", \"caption\": [");
        for (int k = 0; k < 3 && r->render.caption[k][0]; k++) {
            if (k) fputs(", ", out);
            json_string(out, r->render.caption[k]);
        }
        fprintf(out, "], \"percentile_mark\": ");
        if (r->render.pct_y >= 0)
            fprintf(out, "{\"y\": %d, \"x0\": %d, \"x1\": %d}", r->render.pct_y, r->render.pct_x0, r->render.pct_x1);
        else
            fputs("null", out);
        fprintf(out, ", \"witness_markers\": [");
        for (int k = 0; k < r->n_markers; k++) {
            const render_marker_t *m = &r->markers[k];
            fprintf(out, "%s{\"view\": \"%s\", \"set\": \"%c\", \"index\": %zu, \"x\": %d, \"y\": %d}",
                    k ? ", " : "", m->view == 0 ? "front" : m->view == 1 ? "side" : "top", m->set, m->index,
                    m->x, m->y);
        }
        fputs("]}", out);
    }
    if (an->histogram_png) {
        fprintf(out, ", \"histogram_png\": ");
        json_string(out, an->histogram_png);
        fprintf(out, ", \"histogram_markers\": [");
        for (int k = 0; k < r->n_hist_markers; k++) {
            const hist_marker_t *m = &r->hist_markers[k];
            fprintf(out, "%s{\"line\": \"%s\", \"direction\": \"%s\", \"x\": %d, \"y0\": %d, \"y1\": %d, "
                    "\"rgb\": [%d, %d, %d]}", k ? ", " : "", m->kind == 'm' ? "mean" : "percentile",
                    m->dir ? "ba" : "ab", m->x, m->y0, m->y1, m->rgb[0], m->rgb[1], m->rgb[2]);
        }
        fputc(']', out);
    }
}

static void print_histogram(FILE *out, const analysis_args_t *an,
                            const analysis_result_t *r) {
    uint64_t top = 1;
    for (size_t k = 0; k < an->bins; k++) {
        if (r->hist_ab[k] > top) top = r->hist_ab[k];
        if (r->hist_ba && r->hist_ba[k] > top) top = r->hist_ba[k];
    }
    fprintf(out, "histogram of distances (%zu bin%s; bar = share of the largest bin):\n", an->bins, plural(an->bins));
    fprintf(out, "  %-25s %10s %-20s%s\n", "bin", "A->B", "", r->hist_ba ? "      B->A" : "");
    for (size_t k = 0; k < an->bins; k++) {
        double lo = hd_histogram_edge(r->hist_lo, r->hist_hi, an->bins, k);
        double hi = hd_histogram_edge(r->hist_lo, r->hist_hi, an->bins, k + 1);
        char bin[64], bar[21];
        snprintf(bin, sizeof bin, "[%.4g, %.4g%c", lo, hi, k + 1 == an->bins ? ']' : ')');
        int len = (int)(20.0 * (double)r->hist_ab[k] / (double)top + 0.5);
        memset(bar, '#', (size_t)len);
        bar[len] = '\0';
        fprintf(out, "  %-25s %10llu %-20s", bin, (unsigned long long)r->hist_ab[k], bar);
        if (r->hist_ba) {
            len = (int)(20.0 * (double)r->hist_ba[k] / (double)top + 0.5);
            memset(bar, '#', (size_t)len);
            bar[len] = '\0';
            fprintf(out, " %10llu %s", (unsigned long long)r->hist_ba[k], bar);
        }
        fputc('\n', out);
    }
    if (r->above_ab || r->above_ba) {
        fprintf(out, "  beyond the range: %zu (A->B)", r->above_ab);
        if (r->hist_ba) fprintf(out, ", %zu (B->A)", r->above_ba);
        fputc('\n', out);
    }
}

/* The --tau and --dtu-cap lines; unit is "" or " (mm)". */
static void print_scores(FILE *out, const analysis_args_t *an, const analysis_result_t *r, const char *unit) {
    char t[4][NUM_TEXT];
    for (size_t k = 0; k < an->n_taus; k++) {
        const hd_tolerance_t *tl = &r->tol[k];
        fprintf(out, "at tolerance %s%s (%s): precision %s", num_text(an->taus[k], t[0]), unit,
                an->tau_rule == HD_BELOW ? "d < tau" : "d <= tau", num_text(tl->precision, t[1]));
        if (!r->directed)
            fprintf(out, ", recall %s, F-score %s, NSD %s", num_text(tl->recall, t[1]), num_text(tl->fscore, t[2]),
                    num_text(tl->nsd, t[3]));
        fputc('\n', out);
    }
    if (an->dtu_cap > 0) {
        fprintf(out, "DTU (distances below %s%s): accuracy %s", num_text(an->dtu_cap, t[0]), unit,
                num_text(r->dtu.accuracy, t[1]));
        if (!r->directed)
            fprintf(out, ", completeness %s, overall %s", num_text(r->dtu.completeness, t[2]),
                    num_text(r->dtu.overall, t[3]));
        fputc('\n', out);
    }
}

void analysis_print(FILE *out, const analysis_args_t *an,
                    const analysis_result_t *r) {
    char unit[40] = "";
    if (analysis_units(an)) snprintf(unit, sizeof unit, " (%s)", analysis_units(an));
    for (int k = 0; k < 2; k++) {
        const mask_info_t *m = &an->mask[k];
        if (!m->is_mask) continue;
        char how[96] = "";
        if (an->mask_points == MASK_SURFACE)
            snprintf(how, sizeof how, " (%d-D, connectivity %d)", m->surface_dims, m->connectivity);
        char sp[3][NUM_TEXT]; /* NIfTI-1 stores the spacing as float32 */
        for (int c = 0; c < 3; c++) {
            if (m->nifti_version == 1) num_text_single(m->spacing[c], sp[c]);
            else num_text(m->spacing[c], sp[c]);
        }
        fprintf(out, "%c: NIfTI-%d mask %lldx%lldx%lld, spacing %s x %s x %s%s, %s; %lld foreground voxel%s, "
                     "%zu %s point%s%s\n",
                k ? 'B' : 'A', m->nifti_version, m->dim[0], m->dim[1], m->dim[2], sp[0], sp[1], sp[2],
                m->unit_known ? "" : " (unit not given: taken as mm)", m->transform, m->foreground,
                plural((unsigned long long)m->foreground), m->points,
                an->mask_points == MASK_ALL ? "foreground" : "surface", plural(m->points), how);
    }
    char t[4][NUM_TEXT]; /* shortest text of each figure (numtext.c) */
    if (r->empty) { /* nothing measured: each figure asked for is the policy's value */
        num_text(r->sum.mean_ab, t[0]);
        if (an->percentile_on) fprintf(out, "percentile %s: %s\n", num_text(an->percentile, t[1]), t[0]);
        if (an->mean) fprintf(out, "mean distance: %s\n", t[0]);
        if (an->chamfer) fprintf(out, "Chamfer distance: %s\n", t[0]);
        print_scores(out, an, r, "");
        return;
    }
    if (!r->active) return;
    if (an->percentile_on) {
        fprintf(out, "percentile P = %s of the per-point distances%s:\n", num_text(r->pct.p, t[1]), unit);
        fprintf(out, "  A->B %s\n", num_text(r->pct.ab, t[0]));
        if (!r->directed) {
            fprintf(out, "  B->A %s\n", num_text(r->pct.ba, t[0]));
            fprintf(out, "  symmetric = max (MONAI) %s\n", num_text(r->pct.symmetric, t[0]));
            fprintf(out, "  pooled (medpy)          %s\n", num_text(r->pct.pooled, t[0]));
        }
    }
    if (an->mean) {
        fprintf(out, "mean distance%s: A->B %s", unit, num_text(r->sum.mean_ab, t[0]));
        if (!r->directed)
            fprintf(out, ", B->A %s\n  max (average Hausdorff) %s, average %s, pooled %s",
                    num_text(r->sum.mean_ba, t[0]), num_text(r->sum.mean_symmetric, t[1]), num_text(r->sum.mean_average, t[2]),
                    num_text(r->sum.mean_pooled, t[3]));
        fputc('\n', out);
    }
    if (an->chamfer) {
        if (r->directed)
            fprintf(out, "Chamfer distance, A->B only (mean squared distance): %s\n", num_text(r->sum.mean2_ab, t[0]));
        else
            fprintf(out, "Chamfer distance (mean squared A->B + mean squared B->A) = %s\n"
                         "  summed squares %s; unsquared: mean %s, sum %s\n",
                    num_text(r->sum.chamfer, t[0]), num_text(r->sum.chamfer_sum2, t[1]),
                    num_text(r->sum.chamfer_mean, t[2]), num_text(r->sum.chamfer_sum, t[3]));
    }
    print_scores(out, an, r, unit);
    if (an->histogram) print_histogram(out, an, r);
    analysis_write_back_print(out, an, r);
    if (an->distances_out && (r->dist_path_a || r->dist_path_b)) {
        fprintf(out, "per-point distances written to %s", safe_text(r->dist_path_a ? r->dist_path_a : r->dist_path_b));
        if (r->dist_path_a && r->dist_path_b) fprintf(out, " and %s", safe_text(r->dist_path_b));
        fputc('\n', out);
    }
    if (an->render_out) fprintf(out, "picture written to %s (%dx%d)\n", safe_text(an->render_out), r->render_w, r->render_h);
    if (an->histogram_png) fprintf(out, "histogram picture written to %s\n", safe_text(an->histogram_png));
    fprintf(out, "time: %s s for per-point distances\n", num_seconds(r->seconds, t[0]));
}
