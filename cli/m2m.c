/*
 * m2m.c -- `hausdorff --surface A B` with a mesh as A: the distance from
 * every point of A's surface, as an enclosure [lower, upper]
 * (hd_surface_hausdorff, or hd_surface_points_hausdorff when B is a point
 * set), its witness on A and the witness's nearest point on B; --within D
 * asks only whether the distance is at most D (hd_surface_within).
 *
 * A is read with hd_read_mesh; B is read as points first (hd_read_file)
 * and again as a mesh when it has faces.  The tolerance is --tolerance's
 * (absolute, or relative to the bounding-box diagonal with a 'd' suffix),
 * by default 1e-9 of the diagonal.  An empty point set B follows --empty.
 */
#include "cli.h"
#include "report.h"
#include "surface.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct sides {
    hd_mesh_file_t *ma, *mb; /* mb NULL: B is the point set cb */
    hd_cloud_t *cb;
    double read_s;
} sides_t;

static void sides_free(sides_t *s) {
    hd_mesh_file_free(s->ma);
    hd_mesh_file_free(s->mb);
    hd_cloud_free(s->cb);
}

static int read_sides(const cli_args_t *a, sides_t *s, hd_error_t *err) {
    hd_read_options_t ro = a->read;
    ro.mesh = HD_MESH_VERTICES;
    double t0 = cli_now();
    memset(s, 0, sizeof *s);
    ro.format = a->format_a ? a->format_a : a->read.format;
    int rc = hd_read_mesh(a->path_a, &ro, &s->ma, err);
    ro.format = a->format_b ? a->format_b : a->read.format;
    if (rc == HD_OK) rc = hd_read_file(a->path_b, &ro, &s->cb, err);
    if (rc == HD_OK && s->cb->n_faces > 0) {
        hd_cloud_free(s->cb);
        s->cb = NULL;
        rc = hd_read_mesh(a->path_b, &ro, &s->mb, err);
    }
    s->read_s = cli_now() - t0;
    return rc;
}

static void print_point(FILE *out, const double p[3]) {
    char b[3][NUM_TEXT];
    fprintf(out, "(%s, %s, %s)", num_text(p[0], b[0]), num_text(p[1], b[1]), num_text(p[2], b[2]));
}

static void json_triple(FILE *out, const double p[3]) {
    fprintf(out, "[");
    for (int c = 0; c < 3; c++) json_number(out, p[c]), fprintf(out, c < 2 ? ", " : "]");
}

static void json_index(FILE *out, size_t i) {
    if (i == SIZE_MAX) fprintf(out, "null");
    else fprintf(out, "%zu", i);
}

/* One side's description: "B: path (ply, 100 vertices, 196 triangles from
 * 196 faces, 0 degenerate)" or "(xyz, 50 points)". */
static void print_side(FILE *out, const char *name, const char *path, const hd_mesh_file_t *m,
                       const hd_cloud_t *c) {
    if (m)
        fprintf(out, "  %s: %s (%s, %zu vertices, %zu triangle%s from %zu face%s, %zu degenerate), measured as its "
                     "surface\n", name, path, m->format, m->n_vertices, m->n_triangles, plural(m->n_triangles),
                m->n_faces, plural(m->n_faces), m->n_degenerate);
    else
        fprintf(out, "  %s: %s (%s, %zu point%s)\n", name, path, c->format, c->count, plural(c->count));
}

/* One direction: "h(A, B) in [lo, hi]" and its witness.  X and Y name the
 * sides measured from and to. */
static void print_direction(FILE *out, const char *X, const char *Y, const hd_enclosure_t *e, int within) {
    char lo[NUM_TEXT], hi[NUM_TEXT], d[NUM_TEXT], w[3][NUM_TEXT];
    fprintf(out, "  h(%s, %s) in [%s, %s]%s\n", X, Y, num_text(e->lower, lo), num_text(e->upper, hi),
            within ? " (as far as the answer needed)"
                   : e->converged ? "" : " (not converged: a face reached the split limit)");
    if (e->face_a == SIZE_MAX && e->index_a == SIZE_MAX) return;
    if (e->face_a != SIZE_MAX)
        fprintf(out, "    witness on %s: triangle %zu, weights (%s, %s, %s), point ", X, e->face_a,
                num_text(e->bary_a[0], w[0]), num_text(e->bary_a[1], w[1]), num_text(e->bary_a[2], w[2]));
    else
        fprintf(out, "    witness on %s: point %zu ", X, e->index_a);
    print_point(out, e->point_a);
    fprintf(out, ", distance %s\n    nearest on %s: ", num_text(e->witness_distance, d), Y);
    if (e->face_b != SIZE_MAX) fprintf(out, "triangle %zu at ", e->face_b);
    else fprintf(out, "point %zu at ", e->index_b);
    print_point(out, e->point_b);
    fprintf(out, "\n");
}

static void json_direction(FILE *out, const hd_enclosure_t *e) {
    fprintf(out, "{\"lower\": ");
    json_number(out, e->lower);
    fprintf(out, ", \"upper\": ");
    json_number(out, e->upper);
    fprintf(out, ", \"converged\": %s, \"witness\": {\"a\": {\"face\": ", e->converged ? "true" : "false");
    json_index(out, e->face_a);
    fprintf(out, ", \"index\": ");
    json_index(out, e->index_a);
    fprintf(out, ", \"bary\": ");
    json_triple(out, e->bary_a);
    fprintf(out, ", \"point\": ");
    json_triple(out, e->point_a);
    fprintf(out, ", \"distance\": ");
    json_number(out, e->witness_distance);
    fprintf(out, ", \"error\": ");
    json_number(out, e->witness_error);
    fprintf(out, "}, \"b\": {\"face\": ");
    json_index(out, e->face_b);
    fprintf(out, ", \"index\": ");
    json_index(out, e->index_b);
    fprintf(out, ", \"point\": ");
    json_triple(out, e->point_b);
    fprintf(out, "}}, \"faces_dropped\": %llu, \"faces_split\": %llu, \"kernel_calls\": %llu, \"seconds\": ",
            (unsigned long long)e->faces_dropped, (unsigned long long)e->faces_split,
            (unsigned long long)e->kernel_calls);
    json_number(out, e->seconds);
    fprintf(out, "}");
}

static void json_side(FILE *out, const char *path, const hd_mesh_file_t *m, const hd_cloud_t *c) {
    fprintf(out, "{\"path\": ");
    json_string(out, path);
    fprintf(out, ", \"format\": ");
    json_string(out, m ? m->format : c->format);
    if (m)
        fprintf(out, ", \"vertices\": %zu, \"triangles\": %zu, \"faces\": %zu, \"degenerate\": %zu}", m->n_vertices,
                m->n_triangles, m->n_faces, m->n_degenerate);
    else
        fprintf(out, ", \"points\": %zu}", c->count);
}

/* The result: both directions (ba NULL when directed), the predicate's
 * answer (-2 when not asked). */
typedef struct result {
    const hd_enclosure_t *ab, *ba;
    int within;
} result_t;

static const hd_enclosure_t *top_of(const result_t *r) {
    return r->ba && r->ba->lower > r->ab->lower ? r->ba : r->ab;
}

static void print_text(FILE *out, const cli_args_t *a, const sides_t *s, const result_t *r) {
    char lo[NUM_TEXT], hi[NUM_TEXT], tol[NUM_TEXT], t[2][NUM_TEXT], d[NUM_TEXT];
    double lower = r->ab->lower, upper = r->ab->upper, secs = r->ab->seconds;
    if (r->ba) lower = fmax(lower, r->ba->lower), upper = fmax(upper, r->ba->upper), secs += r->ba->seconds;
    const char *H = a->directed ? "h(A, B)" : "H(A, B)";
    if (r->within != -2)
        fprintf(out, "%s <= %s: %s\n", H, num_text(a->within, d),
                r->within == 1 ? "yes" : r->within == 0 ? "no" : "undecided (within the tolerance)");
    else fprintf(out, "%s in [%s, %s]\n", H, num_text(lower, lo), num_text(upper, hi));
    print_direction(out, "A", "B", r->ab, r->within != -2);
    if (r->ba) print_direction(out, "B", "A", r->ba, r->within != -2);
    print_side(out, "A", a->path_a, s->ma, NULL);
    print_side(out, "B", a->path_b, s->mb, s->cb);
    fprintf(out, "  enclosure: every point of the surfaces counts, so the distance is a supremum, in general not a "
                 "rational number; the true value lies in [lower, upper] (upper rounded outward, lower the distance "
                 "of the witness point)");
    if (r->within == -2) fprintf(out, ", upper - lower <= %s", num_text(r->ab->tolerance, tol));
    fprintf(out, "\n");
    fprintf(out, "  work: %llu triangles split, %llu distance calls\n",
            (unsigned long long)(r->ab->faces_split + (r->ba ? r->ba->faces_split : 0)),
            (unsigned long long)(r->ab->kernel_calls + (r->ba ? r->ba->kernel_calls : 0)));
    fprintf(out, "  time: read %s s, compute %s s\n", num_seconds(s->read_s, t[0]), num_seconds(secs, t[1]));
}

static void print_json(FILE *out, const cli_args_t *a, const sides_t *s, const result_t *r) {
    const hd_enclosure_t *w = top_of(r);
    double lower = r->ab->lower, upper = r->ab->upper;
    if (r->ba) lower = fmax(lower, r->ba->lower), upper = fmax(upper, r->ba->upper);
    fprintf(out, "{\"surface\": true, \"lower\": ");
    json_number(out, lower);
    fprintf(out, ", \"upper\": ");
    json_number(out, upper);
    fprintf(out, ", \"tolerance\": ");
    json_number(out, r->ab->tolerance);
    if (r->within != -2) {
        fprintf(out, ", \"within\": {\"d\": ");
        json_number(out, a->within);
        fprintf(out, ", \"answer\": %s}", r->within == 1 ? "true" : r->within == 0 ? "false" : "null");
    }
    fprintf(out, ", \"witness\": {\"direction\": \"%s\", \"a\": {\"face\": ", w == r->ab ? "ab" : "ba");
    json_index(out, w->face_a);
    fprintf(out, ", \"bary\": ");
    json_triple(out, w->bary_a);
    fprintf(out, ", \"point\": ");
    json_triple(out, w->point_a);
    fprintf(out, "}, \"b\": {\"face\": ");
    json_index(out, w->face_b);
    fprintf(out, ", \"point\": ");
    json_triple(out, w->point_b);
    fprintf(out, "}}, \"ab\": ");
    json_direction(out, r->ab);
    fprintf(out, ", \"ba\": ");
    if (r->ba) json_direction(out, r->ba);
    else fprintf(out, "null");
    fprintf(out, ", \"a\": ");
    json_side(out, a->path_a, s->ma, NULL);
    fprintf(out, ", \"b\": ");
    json_side(out, a->path_b, s->mb, s->cb);
    fprintf(out, ", \"read_seconds\": ");
    json_number(out, s->read_s);
    fprintf(out, "}\n");
}

/* B empty under an --empty policy other than error: every figure is the
 * policy's value. */
static int print_empty(const cli_args_t *a, const sides_t *s) {
    size_t nb = s->cb ? s->cb->count : 0;
    double v = hd_empty_value(a->an.empty, s->ma->n_triangles, nb);
    char t[NUM_TEXT];
    if (a->json) {
        fprintf(stdout, "{\"surface\": true, \"empty\": true, \"lower\": ");
        json_number(stdout, v);
        fprintf(stdout, ", \"upper\": ");
        json_number(stdout, v);
        fprintf(stdout, "}\n");
    } else {
        fprintf(stdout, "%s(A, B) = %s (B is empty: --empty %s)\n", a->directed ? "h" : "H", num_text(v, t),
                hd_empty_policy_name(a->an.empty));
    }
    return EXIT_OK;
}

static int compute(const cli_args_t *a, const sides_t *s, hd_enclosure_t *ab, hd_enclosure_t *ba, int *within,
                   hd_error_t *err) {
    hd_surface_options_t o;
    hd_surface_options_init(&o);
    o.threads = a->opt.threads;
    if (a->tolerance_set) o.tolerance = a->tolerance, o.relative = a->tolerance_relative;
    hd_mesh_t A = hd_mesh_file_view(s->ma), B = hd_mesh_file_view(s->mb);
    *within = -2;
    if (a->within_set) {
        if (!s->mb) {
            snprintf(err->message, sizeof err->message, "--within needs B as a mesh too (%s has no faces)", a->path_b);
            return HD_EINVAL;
        }
        return hd_surface_within(&A, &B, a->within, a->directed, &o, within, ab, ba, err);
    }
    if (s->mb) return hd_surface_hausdorff(&A, &B, &o, ab, a->directed ? NULL : ba, err);
    hd_points_t P = hd_cloud_points(s->cb);
    return hd_surface_points_hausdorff(&A, &P, &o, ab, a->directed ? NULL : ba, err);
}

int m2m_run(const cli_args_t *a) {
    hd_error_t err;
    sides_t s;
    int rc = read_sides(a, &s, &err);
    if (rc == HD_EEMPTY && s.ma && !s.mb && a->an.empty != HD_EMPTY_ERROR) { /* B without points */
        rc = print_empty(a, &s);
        sides_free(&s);
        return rc;
    }
    hd_enclosure_t ab, ba;
    result_t r = {&ab, NULL, -2};
    if (rc == HD_OK) rc = compute(a, &s, &ab, &ba, &r.within, &err);
    if (rc != HD_OK) {
        fprintf(stderr, "%s: %s\n", cli_prog(), err.message);
        sides_free(&s);
        return rc == HD_EINVAL ? EXIT_USAGE : cli_exit_for(rc);
    }
    if (!a->directed && !(r.within == 0 && ba.upper == INFINITY)) r.ba = &ba;
    if (a->json) print_json(stdout, a, &s, &r);
    else print_text(stdout, a, &s, &r);
    sides_free(&s);
    return EXIT_OK;
}
