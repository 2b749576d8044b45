/*
 * labels.c -- `hausdorff --labels all|L[,L...] pred.nii.gz ref.nii.gz`: every
 * label of two NIfTI label maps measured in one call (hd_label_map), printed
 * as a table for a person, as CSV (--csv) or as one JSON object (--json);
 * with --components CONN, each connected component of each label of each
 * side after the labels.  The figures and the conventions each follows:
 * docs/analysis.md, "Label maps".
 */
#include "cli.h"
#include "labels.h"
#include "report.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

/* The labels of v ("all": NULL, every label) into *out (malloc'd), *n of
 * them; -1 when v is neither (or out of memory, with *out NULL). */
static int parse_list(const char *v, int64_t **out, size_t *n) {
    *out = NULL;
    *n = 0;
    if (strcmp(v, "all") == 0) return 0;
    size_t cap = 1;
    for (const char *p = v; *p; p++) cap += *p == ',';
    int64_t *l = malloc(cap * sizeof *l);
    if (!l) return -1;
    for (const char *p = v;;) {
        char *e;
        errno = 0;
        long long x = strtoll(p, &e, 10);
        if (e == p || errno || (*e != ',' && *e) || (*p != '-' && (*p < '0' || *p > '9'))) {
            free(l);
            return -1;
        }
        l[(*n)++] = x;
        if (!*e) break;
        p = e + 1;
    }
    *out = l;
    return 0;
}

int labels_list_ok(const char *v) {
    int64_t *l;
    size_t n;
    if (parse_list(v, &l, &n) < 0) return 0;
    free(l);
    return 1;
}

/* One row's columns: name, and whether the figure is a count. */
typedef struct {
    const char *name;
    int count;
} column_t;

static const column_t columns[] = {
    {"label", 1}, {"empty", 1}, {"voxels_a", 1}, {"voxels_b", 1}, {"overlap", 1}, {"dice", 0},
    {"points_a", 1}, {"points_b", 1}, {"hausdorff", 0}, {"hd_ab", 0}, {"hd_ba", 0}, {"hd_p", 0},
    {"hd_p_pooled", 0}, {"assd", 0}, {"asd_ab", 0}, {"asd_ba", 0}, {"nsd", 0}, {"surfels_a", 1},
    {"surfels_b", 1}, {"area_a", 0}, {"area_b", 0}, {"nsd_surfel", 0}, {"overlap_ab", 0}, {"overlap_ba", 0},
    {"hd_surfel", 0}, {"asd_surfel_ab", 0}, {"asd_surfel_ba", 0}, {"components_a", 1}, {"components_b", 1},
};
enum { N_COLUMNS = sizeof columns / sizeof columns[0] };

/* Column c of row r as a double (counts are exact below 2^53). */
static double cell(const hd_label_row_t *r, int c) {
    const double v[N_COLUMNS] = {
        (double)r->label, r->empty, (double)r->voxels_a, (double)r->voxels_b, (double)r->overlap, r->dice,
        (double)r->points_a, (double)r->points_b, r->hausdorff, r->hd_ab, r->hd_ba, r->hd_p, r->hd_p_pooled, r->assd,
        r->asd_ab, r->asd_ba, r->nsd, (double)r->surfels_a, (double)r->surfels_b, r->area_a, r->area_b,
        r->nsd_surfel, r->overlap_ab, r->overlap_ba, r->hd_surfel, r->asd_surfel_ab, r->asd_surfel_ba,
        (double)r->components_a, (double)r->components_b};
    return v[c];
}

static void put_cell(FILE *out, const hd_label_row_t *r, int c, int json) {
    char b[NUM_TEXT];
    if (columns[c].count) fprintf(out, "%lld", c == 0 ? (long long)r->label : (long long)cell(r, c));
    else if (json) json_number(out, cell(r, c));
    else fputs(num_text(cell(r, c), b), out);
}

static const char *const comp_columns[] = {"label", "side", "index", "voxels", "overlap", "points",
                                           "hausdorff", "hd_p", "nearest", "detected"};

static void put_component(FILE *out, const hd_label_component_t *c, int json, const char *sep) {
    char b[3][NUM_TEXT];
    if (json) {
        fprintf(out, "{\"label\": %lld, \"side\": \"%c\", \"index\": %zu, \"voxels\": %zu, \"overlap\": %zu, "
                     "\"points\": %zu, \"hausdorff\": ",
                (long long)c->label, "AB"[c->side], c->index, c->voxels, c->overlap, c->points);
        json_number(out, c->hausdorff);
        fputs(", \"hd_p\": ", out);
        json_number(out, c->hd_p);
        fputs(", \"nearest\": ", out);
        json_number(out, c->nearest);
        fprintf(out, ", \"detected\": %s}", c->detected ? "true" : "false");
        return;
    }
    fprintf(out, "%lld%s%c%s%zu%s%zu%s%zu%s%zu%s%s%s%s%s%s%s%d\n", (long long)c->label, sep, "AB"[c->side], sep,
            c->index, sep, c->voxels, sep, c->overlap, sep, c->points, sep, num_text(c->hausdorff, b[0]), sep,
            num_text(c->hd_p, b[1]), sep, num_text(c->nearest, b[2]), sep, c->detected);
}

static void print_csv(FILE *out, const hd_label_table_t *t) {
    for (int c = 0; c < N_COLUMNS; c++) fprintf(out, "%s%s", c ? "," : "", columns[c].name);
    fputc('\n', out);
    for (size_t k = 0; k < t->n_rows; k++)
        for (int c = 0; c < N_COLUMNS; c++) {
            put_cell(out, &t->rows[k], c, 0);
            fputc(c + 1 < N_COLUMNS ? ',' : '\n', out);
        }
    if (!t->n_components) return;
    fputc('\n', out);
    for (size_t c = 0; c < sizeof comp_columns / sizeof *comp_columns; c++)
        fprintf(out, "%s%s", c ? "," : "", comp_columns[c]);
    fputc('\n', out);
    for (size_t k = 0; k < t->n_components; k++) put_component(out, &t->components[k], 0, ",");
}

static void print_json(FILE *out, const hd_label_table_t *t, const hd_label_options_t *o, const char *unit) {
    fputs("{\"percentile\": ", out);
    json_number(out, o->percentile);
    fputs(", \"tau\": ", out);
    json_number(out, o->tau);
    fprintf(out, ", \"tau_rule\": \"%s\", \"empty\": \"%s\", \"unit\": ", o->rule == HD_BELOW ? "d < tau" : "d <= tau",
            hd_empty_policy_name(o->empty));
    json_string(out, unit);
    fputs(", \"labels\": [", out);
    for (size_t k = 0; k < t->n_rows; k++) {
        fputs(k ? ", {" : "{", out);
        for (int c = 0; c < N_COLUMNS; c++) {
            fprintf(out, "%s\"%s\": ", c ? ", " : "", columns[c].name);
            put_cell(out, &t->rows[k], c, 1);
        }
        fputc('}', out);
    }
    fputs("], \"components\": [", out);
    for (size_t k = 0; k < t->n_components; k++) {
        if (k) fputs(", ", out);
        put_component(out, &t->components[k], 1, NULL);
    }
    fputs("]}\n", out);
}

/* For a person: the figures most reported, one label a line, each column
 * as wide as its widest cell. */
enum { TEXT_COLUMNS = 11 };

static void text_cells(const hd_label_row_t *r, char cell[TEXT_COLUMNS][NUM_TEXT]) {
    snprintf(cell[0], NUM_TEXT, "%lld", (long long)r->label);
    snprintf(cell[1], NUM_TEXT, "%zu", r->voxels_a);
    snprintf(cell[2], NUM_TEXT, "%zu", r->voxels_b);
    num_ratio(r->dice, cell[3]);
    num_text(r->hausdorff, cell[4]);
    num_text(r->hd_p, cell[5]);
    num_text(r->hd_p_pooled, cell[6]);
    num_text(r->assd, cell[7]);
    num_ratio(r->nsd, cell[8]);
    num_ratio(r->nsd_surfel, cell[9]);
    num_text(r->hd_surfel, cell[10]);
}

static void print_text(FILE *out, const hd_label_table_t *t, const hd_label_options_t *o, const char *unit) {
    char p[NUM_TEXT], tau[NUM_TEXT], head[TEXT_COLUMNS][NUM_TEXT + 16];
    num_text(o->percentile, p);
    num_text(o->tau, tau);
    fprintf(out, "labels: %zu (A: prediction, B: reference; distances in %s; NSD within %s, %s)\n", t->n_rows, unit,
            tau, o->rule == HD_BELOW ? "d < tau" : "d <= tau");
    static const char *const fixed[TEXT_COLUMNS] = {"label", "voxels_A", "voxels_B", "Dice", "HD", NULL, NULL,
                                                    "ASSD", "NSD", "NSD_surfel", NULL};
    for (int c = 0; c < TEXT_COLUMNS; c++)
        if (fixed[c]) snprintf(head[c], sizeof head[c], "%s", fixed[c]);
    snprintf(head[5], sizeof head[5], "HD%s", p);
    snprintf(head[6], sizeof head[6], "HD%s_pooled", p);
    snprintf(head[10], sizeof head[10], "HD%s_surfel", p);
    int width[TEXT_COLUMNS];
    for (int c = 0; c < TEXT_COLUMNS; c++) width[c] = (int)strlen(head[c]);
    for (size_t k = 0; k < t->n_rows; k++) {
        char cell[TEXT_COLUMNS][NUM_TEXT];
        text_cells(&t->rows[k], cell);
        for (int c = 0; c < TEXT_COLUMNS; c++)
            if ((int)strlen(cell[c]) > width[c]) width[c] = (int)strlen(cell[c]);
    }
    for (int c = 0; c < TEXT_COLUMNS; c++) fprintf(out, "%s%*s", c ? "  " : "", width[c], head[c]);
    fputc('\n', out);
    for (size_t k = 0; k < t->n_rows; k++) {
        const hd_label_row_t *r = &t->rows[k];
        char cell[TEXT_COLUMNS][NUM_TEXT];
        text_cells(r, cell);
        for (int c = 0; c < TEXT_COLUMNS; c++) fprintf(out, "%s%*s", c ? "  " : "", width[c], cell[c]);
        fputs(r->empty == 3 ? "  (in neither)" : r->empty == 1 ? "  (not in A)" : r->empty == 2 ? "  (not in B)" : "",
              out);
        fputc('\n', out);
    }
    if (!t->n_components) return;
    fprintf(out, "components: %zu (label side index voxels overlap surface_voxels HD HD%s nearest detected)\n",
            t->n_components, p);
    for (size_t k = 0; k < t->n_components; k++) put_component(out, &t->components[k], 0, " ");
}

static int refuse(const char *why) {
    fprintf(stderr, "%s: --labels %s\nTry '%s --help'.\n", cli_prog(), why, cli_prog());
    return EXIT_USAGE;
}

/* The options that mean nothing for a label map: a usage error naming it. */
static int check_args(const cli_args_t *a) {
    const analysis_args_t *an = &a->an;
    if (a->directed || a->surface) return refuse("measures both directions of two label maps: not with --directed or --surface");
    if (an->mean || an->chamfer || an->histogram || an->distances_out || an->render_out || an->histogram_png ||
        an->dtu_cap > 0)
        return refuse("prints a table of figures per label; --mean, --chamfer, --histogram, --distances, "
                      "--render, --histogram-png and --dtu-cap are not computed for it");
    if (an->mask_points == MASK_ALL) return refuse("measures surfaces: not with --mask-points all");
    if (an->n_taus > 1) return refuse("takes one tolerance (--tau T)");
    if (a->json && an->csv) return refuse("prints one table: --json or --csv, not both");
    return 0;
}

static int say(int rc, const hd_error_t *err) {
    fprintf(stderr, "%s: %s\n", cli_prog(), safe_text(err->message));
    return cli_exit_for(rc);
}

int labels_run(const cli_args_t *a) {
    int rc = check_args(a);
    if (rc) return rc;
    const analysis_args_t *an = &a->an;
    hd_label_options_t o;
    hd_label_options_init(&o);
    int64_t *list = NULL;
    if (parse_list(an->labels, &list, &o.n_labels) < 0) {
        fprintf(stderr, "%s: out of memory\n", cli_prog());
        return EXIT_FAILURE_;
    }
    o.labels = list;
    if (an->percentile_on) o.percentile = an->percentile;
    if (an->n_taus) o.tau = an->taus[0];
    o.rule = an->tau_rule;
    o.connectivity = an->connectivity;
    o.dims = an->mask_dims;
    o.empty = an->empty;
    o.components = an->components;
    o.threads = a->opt.threads;
    nifti_labels_t map[2];
    memset(map, 0, sizeof map);
    hd_label_table_t *t = NULL;
    hd_error_t err;
    const char *paths[2] = {a->path_a, a->path_b};
    for (int w = 0; w < 2 && rc == HD_OK; w++) rc = nifti_read_labels(paths[w], &map[w], &err);
    int code = EXIT_OK;
    const size_t *na = map[0].img.n, *nb = map[1].img.n;
    if (rc == HD_OK && (na[0] != nb[0] || na[1] != nb[1] || na[2] != nb[2])) {
        fprintf(stderr, "%s: %s has %zu x %zu x %zu voxels and %s %zu x %zu x %zu: label maps are compared voxel "
                        "by voxel\n", cli_prog(), safe_text(paths[0]), na[0], na[1], na[2], safe_text(paths[1]), nb[0],
                nb[1], nb[2]);
        code = EXIT_BADINPUT;
    } else if (rc == HD_OK) {
        rc = hd_label_map(&map[0].img, &map[1].img, &o, &t, &err);
    }
    if (rc != HD_OK) code = say(rc, &err);
    else if (code == EXIT_OK) {
        const char *unit = an->units ? an->units : map[0].info.unit_known ? "mm" : "voxel units";
        if (a->json) print_json(stdout, t, &o, unit);
        else if (an->csv) print_csv(stdout, t);
        else print_text(stdout, t, &o, unit);
    }
    hd_label_table_free(t);
    nifti_labels_free(&map[0]);
    nifti_labels_free(&map[1]);
    free(list);
    return code;
}
