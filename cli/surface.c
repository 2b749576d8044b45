/*
 * surface.c -- `hausdorff --surface A B`: the distance from every point of
 * A to the surface of the mesh B (hd_mesh_distances), and h(A, surface of
 * B) with its witness: the point, its nearest triangle and the closest
 * point on it.
 *
 * A is read as points (hd_read_file); a mesh as A is refused, since the
 * direction from a surface is a supremum over the whole surface (mesh to
 * mesh is a later piece of work).  B is read with hd_read_mesh: its
 * polygons as fans, an STL's equal corners merged, degenerate triangles
 * counted and measured as their hulls.  A side given as tiles and the
 * analysis options are not yet measured against a surface: refused with
 * that reason, never answered by the vertices.
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

static void print_text(FILE *out, const cli_args_t *a, const hd_cloud_t *ca, const hd_mesh_file_t *m,
                       const hd_surface_result_t *r, const double *wp, const double *cp, double read_s) {
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
    fprintf(out, "\n  distances: correctly rounded (the true distance to the nearest double)\n");
    fprintf(out, "  time: read %s s, compute %s s\n", num_seconds(read_s, t[0]), num_seconds(r->seconds, t[1]));
}

static void print_json(FILE *out, const cli_args_t *a, const hd_cloud_t *ca, const hd_mesh_file_t *m,
                       const hd_surface_result_t *r, const double *wp, const double *cp, double read_s) {
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
    for (int c = 0; c < 3; c++) json_number(out, cp[c]), fprintf(out, c < 2 ? ", " : "]}");
    fprintf(out, ", \"kernel_calls\": %llu, \"exact_calls\": %llu, \"read_seconds\": ",
            (unsigned long long)r->kernel_calls, (unsigned long long)r->exact_calls);
    json_number(out, read_s);
    fprintf(out, ", \"seconds\": ");
    json_number(out, r->seconds);
    fprintf(out, "}\n");
}

static int is_tiles(const char *path) {
    return path[0] == '@' || (strcmp(path, "-") != 0 && hd_format_of_path(path) == NULL);
}

int surface_run(const cli_args_t *a) {
    if (analysis_active(&a->an))
        return refuse("measures h(A, surface of B) only: the analysis options are not yet computed on surface "
                      "distances");
    if (a->read.mesh == HD_MESH_SAMPLE) return refuse("and --sample measure B in two different ways: choose one");
    if (is_tiles(a->path_a) || is_tiles(a->path_b))
        return refuse("reads one file a side: tiles (a directory or @LIST) are not yet measured against a surface");
    hd_error_t err;
    hd_read_options_t ro = a->read;
    ro.format = a->format_a ? a->format_a : a->read.format;
    double t0 = cli_now();
    hd_cloud_t *ca = NULL;
    hd_mesh_file_t *m = NULL;
    int rc = hd_read_file(a->path_a, &ro, &ca, &err);
    if (rc == HD_OK && ca->n_faces > 0) {
        fprintf(stderr, "%s: --surface: A (%s) is a mesh with %zu faces: the distance from a surface is a supremum "
                        "over the whole surface (mesh to mesh), not yet measured; give A as points, or drop "
                        "--surface to compare the vertices\n", cli_prog(), a->path_a, ca->n_faces);
        hd_cloud_free(ca);
        return EXIT_USAGE;
    }
    ro.format = a->format_b ? a->format_b : a->read.format;
    if (rc == HD_OK) rc = hd_read_mesh(a->path_b, &ro, &m, &err);
    double read_s = cli_now() - t0;
    hd_surface_result_t r;
    hd_points_t A = hd_cloud_points(ca);
    hd_mesh_t M = hd_mesh_file_view(m);
    double *cp = rc == HD_OK ? malloc(3 * ca->count * sizeof *cp) : NULL;
    if (rc == HD_OK && !cp) rc = HD_ENOMEM, snprintf(err.message, sizeof err.message, "out of memory");
    if (rc == HD_OK) rc = hd_mesh_distances(&A, &M, &a->opt, NULL, NULL, cp, NULL, &r, &err);
    if (rc != HD_OK) {
        fprintf(stderr, "%s: %s\n", cli_prog(), err.message);
    } else {
        double wp[3];
        hd_points_get(&A, r.i, wp);
        if (a->json) print_json(stdout, a, ca, m, &r, wp, cp + 3 * r.i, read_s);
        else print_text(stdout, a, ca, m, &r, wp, cp + 3 * r.i, read_s);
    }
    free(cp);
    hd_cloud_free(ca);
    hd_mesh_file_free(m);
    return rc == HD_OK ? EXIT_OK : cli_exit_for(rc);
}
