/*
 * surface.c -- `hausdorff --surface A B`: the distance from every point of
 * A to the surface of the mesh B (hd_mesh_distances), and h(A, surface of
 * B) with its witness: the point, its nearest triangle and the closest
 * point on it.
 *
 * A is read as points (hd_read_file); a mesh as A goes to m2m.c (the
 * distance from a surface, enclosed).  B is read with hd_read_mesh: its
 * polygons as fans, an STL's equal corners merged, degenerate triangles
 * counted and measured as their hulls.  With --signed, each distance's
 * sign comes from B's winding number (hd_mesh_signed_distances; B must be
 * closed).  The per-point distances go to the same analysis as point sets
 * (analysis_finish: --percentile, --mean, --histogram, --distances with the
 * surface's columns, --render), as the directed h(A, surface of B).  A side
 * given as tiles is not yet measured against a surface: refused with that
 * reason, never answered by the vertices.
 */
#include "cli.h"
#include "report.h"
#include "surface.h"

#include <stdlib.h>
#include <string.h>

static int refuse(const char *why) {
    fprintf(stderr, "%s: --surface %s\n", cli_prog(), why);
    return EXIT_USAGE;
}

static void print_point(FILE *out, const double p[3]) {
    char b[3][NUM_TEXT];
    fprintf(out, "(%s, %s, %s)", num_text(p[0], b[0]), num_text(p[1], b[1]), num_text(p[2], b[2]));
}

/* The counts of each sign (--signed). */
typedef struct {
    size_t inside, outside, on;
} signs_t;

static void print_text(FILE *out, const cli_args_t *a, const hd_cloud_t *ca, const hd_mesh_file_t *m,
                       const hd_surface_result_t *r, const double *wp, const double *cp, const int8_t *sign,
                       const signs_t *ns, double read_s) {
    char d[NUM_TEXT], t[2][NUM_TEXT];
    fprintf(out, "h(A, surface of B) = %s\n", num_text(r->distance, d));
    fprintf(out, "  A: %s (%s, %zu point%s)\n", a->path_a, ca->format, ca->count, plural(ca->count));
    fprintf(out, "  B: %s (%s, %zu vertices, %zu triangle%s from %zu face%s, %zu degenerate), measured as its "
                 "surface\n", a->path_b, m->format, m->n_vertices, m->n_triangles, plural(m->n_triangles),
            m->n_faces, plural(m->n_faces), m->n_degenerate);
    fprintf(out, "  witness: A[%zu] ", r->i);
    print_point(out, wp);
    fprintf(out, " to triangle %zu at ", r->triangle);
    print_point(out, cp);
    if (sign) fprintf(out, ", %s", sign[r->i] < 0 ? "inside" : sign[r->i] > 0 ? "outside" : "on the surface");
    fprintf(out, "\n  distances: correctly rounded (the true distance to the nearest double)\n");
    if (sign)
        fprintf(out, "  signs (B's winding number, exact): %zu inside (-1), %zu outside (+1), %zu on the surface "
                     "(0)\n", ns->inside, ns->outside, ns->on);
    fprintf(out, "  time: read %s s, compute %s s\n", num_seconds(read_s, t[0]), num_seconds(r->seconds, t[1]));
}

/* The JSON object's members up to the analysis (the caller closes it). */
static void print_json(FILE *out, const cli_args_t *a, const hd_cloud_t *ca, const hd_mesh_file_t *m,
                       const hd_surface_result_t *r, const double *wp, const double *cp, const int8_t *sign,
                       const signs_t *ns, double read_s) {
    fprintf(out, "{\"surface\": true, \"distance\": ");
    json_number(out, r->distance);
    fprintf(out, ", \"a\": {\"path\": ");
    json_string(out, a->path_a);
    fprintf(out, ", \"format\": ");
    json_string(out, ca->format);
    fprintf(out, ", \"points\": %zu}, \"b\": {\"path\": ", ca->count);
    json_string(out, a->path_b);
    fprintf(out, ", \"format\": ");
    json_string(out, m->format);
    fprintf(out, ", \"vertices\": %zu, \"triangles\": %zu, \"faces\": %zu, \"degenerate\": %zu}", m->n_vertices,
            m->n_triangles, m->n_faces, m->n_degenerate);
    fprintf(out, ", \"witness\": {\"i\": %zu, \"triangle\": %zu, \"point\": [", r->i, r->triangle);
    for (int c = 0; c < 3; c++) json_number(out, wp[c]), fprintf(out, c < 2 ? ", " : "], \"closest\": [");
    for (int c = 0; c < 3; c++) json_number(out, cp[c]), fprintf(out, c < 2 ? ", " : "]");
    if (sign) fprintf(out, ", \"sign\": %d", sign[r->i]);
    fputc('}', out);
    if (sign)
        fprintf(out, ", \"signs\": {\"inside\": %zu, \"outside\": %zu, \"on\": %zu}", ns->inside, ns->outside, ns->on);
    fprintf(out, ", \"kernel_calls\": %llu, \"exact_calls\": %llu, \"read_seconds\": ",
            (unsigned long long)r->kernel_calls, (unsigned long long)r->exact_calls);
    json_number(out, read_s);
    fprintf(out, ", \"seconds\": ");
    json_number(out, r->seconds);
}

static int is_tiles(const char *path) {
    return path[0] == '@' || (strcmp(path, "-") != 0 && hd_format_of_path(path) == NULL);
}

/* What a run holds, freed in one place. */
typedef struct {
    hd_cloud_t *ca;
    hd_mesh_file_t *m;
    double *closest, *bary;
    int8_t *sign;
    analysis_result_t an; /* owns the distances (d_ab) and faces (j_ab) */
    hd_surface_result_t r;
    double read_s;
} surf_run_t;

static void surf_free(surf_run_t *s) {
    hd_cloud_free(s->ca);
    hd_mesh_file_free(s->m);
    free(s->closest), free(s->bary), free(s->sign);
    analysis_free(&s->an);
}

/* Read A as points and B as a mesh. */
static int read_sides(const cli_args_t *a, surf_run_t *s, hd_error_t *err) {
    hd_read_options_t ro = a->read;
    ro.format = a->format_a ? a->format_a : a->read.format;
    double t0 = cli_now();
    int rc = hd_read_file(a->path_a, &ro, &s->ca, err);
    if (rc == HD_OK && s->ca->n_faces > 0) return HD_OK; /* refused by the caller */
    ro.format = a->format_b ? a->format_b : a->read.format;
    if (rc == HD_OK) rc = hd_read_mesh(a->path_b, &ro, &s->m, err);
    s->read_s = cli_now() - t0;
    return rc;
}

/* Every point's distance (and what the options ask for beside it). */
static int measure(const cli_args_t *a, surf_run_t *s, hd_error_t *err) {
    size_t n = s->ca->count;
    int per_point = analysis_active(&a->an);
    analysis_result_t *r = &s->an;
    r->active = per_point, r->directed = 1, r->surface = 1, r->n_a = n, r->n_b = s->m->n_vertices;
    s->closest = malloc(3 * n * sizeof *s->closest);
    if (per_point) r->d_ab = malloc(n * sizeof *r->d_ab), r->j_ab = malloc(n * sizeof *r->j_ab);
    if (a->an.distances_out) s->bary = malloc(3 * n * sizeof *s->bary);
    if (a->signed_distance) s->sign = malloc(n ? n : 1);
    if (!s->closest || (per_point && (!r->d_ab || !r->j_ab)) || (a->an.distances_out && !s->bary) ||
        (a->signed_distance && !s->sign)) {
        snprintf(err->message, sizeof err->message, "out of memory for the distances of %zu points", n);
        return err->code = HD_ENOMEM;
    }
    hd_points_t A = hd_cloud_points(s->ca);
    hd_mesh_t M = hd_mesh_file_view(s->m);
    int rc = a->signed_distance
                 ? hd_mesh_signed_distances(&A, &M, &a->opt, r->d_ab, r->j_ab, s->closest, s->bary, s->sign, &s->r, err)
                 : hd_mesh_distances(&A, &M, &a->opt, r->d_ab, r->j_ab, s->closest, s->bary, &s->r, err);
    r->seconds = s->r.seconds;
    return rc;
}

/* The analysis of the distances: figures, files, pictures. */
static int analyse(const cli_args_t *a, surf_run_t *s, hd_error_t *err) {
    if (!s->an.active) return HD_OK;
    hd_points_t A = hd_cloud_points(s->ca), B = hd_points_f64(s->m->vertices, s->m->n_vertices);
    hd_symmetric_t w;
    memset(&w, 0, sizeof w);
    w.distance = w.ab.distance = s->r.distance;
    w.ab.distance2 = s->r.distance * s->r.distance;
    w.ab.i = s->r.i;
    w.ab.j = s->r.triangle;
    surface_columns_t cols = {s->an.j_ab, s->closest, s->bary, s->sign};
    return analysis_finish(&a->an, &A, &B, &w, s->closest + 3 * s->r.i, a->path_a, a->path_b, &cols, &s->an, err);
}

static void report(const cli_args_t *a, const surf_run_t *s) {
    signs_t ns = {0, 0, 0};
    for (size_t k = 0; s->sign && k < s->ca->count; k++)
        ns.inside += s->sign[k] < 0, ns.outside += s->sign[k] > 0, ns.on += s->sign[k] == 0;
    double wp[3];
    hd_points_t A = hd_cloud_points(s->ca);
    hd_points_get(&A, s->r.i, wp);
    const double *cp = s->closest + 3 * s->r.i;
    if (a->json) {
        print_json(stdout, a, s->ca, s->m, &s->r, wp, cp, s->sign, &ns, s->read_s);
        analysis_json(stdout, &a->an, &s->an);
        fprintf(stdout, "}\n");
    } else {
        print_text(stdout, a, s->ca, s->m, &s->r, wp, cp, s->sign, &ns, s->read_s);
        analysis_print(stdout, &a->an, &s->an);
    }
}

int surface_run(const cli_args_t *a) {
    if (a->read.mesh == HD_MESH_SAMPLE) return refuse("and --sample measure B in two different ways: choose one");
    if (is_tiles(a->path_a) || is_tiles(a->path_b))
        return refuse("reads one file a side: tiles (a directory or @LIST) are not yet measured against a surface");
    surf_run_t s;
    memset(&s, 0, sizeof s);
    hd_error_t err;
    if (analysis_check_outputs(&a->an, a->path_a, a->path_b, 1, &err) != HD_OK) { /* A's file only */
        fprintf(stderr, "%s: %s\n", cli_prog(), safe_text(err.message));
        return EXIT_USAGE;
    }
    int rc = read_sides(a, &s, &err);
    if (rc == HD_OK && s.ca->n_faces > 0) { /* a surface measured from: an enclosure (m2m.c) */
        surf_free(&s);
        if (analysis_active(&a->an) || a->signed_distance)
            return refuse("with a mesh as A gives the distance from its surface as an enclosure: the analysis "
                          "options and --signed are not computed there");
        return m2m_run(a);
    }
    if (rc == HD_OK && (a->tolerance_set || a->within_set)) {
        surf_free(&s);
        return refuse(a->within_set ? "--within needs a mesh as A (h(points, surface) is exact: compare it)"
                                    : "--tolerance needs a mesh as A (h(points, surface) is exact, correctly rounded)");
    }
    int bad_mesh = 0;
    if (rc == HD_OK) bad_mesh = (rc = measure(a, &s, &err)) == HD_EINVAL; /* B's faces: not closed, say */
    if (rc == HD_OK) rc = analyse(a, &s, &err);
    if (rc == HD_OK) report(a, &s);
    else fprintf(stderr, "%s: %s\n", cli_prog(), safe_text(err.message));
    surf_free(&s);
    return rc == HD_OK ? EXIT_OK : bad_mesh ? EXIT_BADINPUT : cli_exit_for(rc);
}
