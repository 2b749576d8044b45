/*
 * m2m.c -- the public entry points for the distance between surfaces
 * (hd_surface_hausdorff, hd_surface_points_hausdorff, hd_surface_within,
 * hd_surface_face_maxima): the meshes checked and put in trees, the
 * tolerance made absolute, and each direction searched by mesh/m2m.c.
 *
 * A point set as the side measured to is a tree of point-triangles (a
 * point is the degenerate triangle q q q, whose distance the kernel rounds
 * correctly like any other); as the side measured from, its distance to a
 * surface is exact (hd_mesh_distances).
 */
#include "mesh/mesh.h"
#include "surface.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The tolerance 0 stands for the smallest that the rounding of the
 * computed points of X leaves meaningful: mesh/m2m.c's slack e of a face
 * is at most 6 u max|coordinate| + 24 u diagonal (plus 2^-1060), both
 * bounds carry it, so the width cannot go below about 2 e; the floor is
 * 2^-48 max|coordinate| + 2^-46 diagonal >= 4 e. */
#define FLOOR_COORD 0x1p-48
#define FLOOR_DIAG 0x1p-46

void hd_surface_options_init(hd_surface_options_t *opt) {
    if (!opt) return;
    memset(opt, 0, sizeof *opt);
    opt->tolerance = 1e-9;
    opt->relative = 1;
    opt->threads = 0;
    opt->max_splits = (uint64_t)1 << 20;
}

typedef struct side {
    hd__tri_t *tris; /* in index order */
    size_t n;
    hd__bvh_t bvh;
    int built;
    int points;      /* a point set */
    unsigned char *drop; /* faces shared with the other side (shared()) */
    size_t dropped;
    const hd_mesh_t *mesh; /* the mesh the triangles come from (NULL: points) */
    uint32_t *vert;      /* each corner's vertex index, once a search from
                          * this side needs it (side_vertices) */
    size_t n_vert;
} side_t;

static void side_free(side_t *s) {
    free(s->tris);
    free(s->drop);
    free(s->vert);
    if (s->built) hd__bvh_free(&s->bvh);
    memset(s, 0, sizeof *s);
}

static int side_tree(side_t *s, const char *name, hd_error_t *err) {
    hd__tri_t *copy = hd__malloc_array(s->n, sizeof *copy);
    if (!copy) return hd__err(err, HD_ENOMEM, "%s: out of memory for %zu triangles", name, s->n);
    memcpy(copy, s->tris, s->n * sizeof *copy);
    int rc = hd__bvh_build(&s->bvh, copy, s->n);
    if (rc) {
        free(copy);
        return hd__err(err, rc, "%s: cannot build the tree of %zu triangles", name, s->n);
    }
    s->built = 1;
    return HD_OK;
}

/* Each corner's vertex index (the indices were checked with the
 * triangles), so that the search orders vertices rather than corners
 * (mesh/m2m.c, corner_order); none for a point set or for 2^32 vertices
 * or more. */
static int side_vertices(side_t *s, hd_error_t *err) {
    const hd_mesh_t *M = s->mesh;
    if (s->vert || !M || M->vertices.count > UINT32_MAX || s->n > SIZE_MAX / 3) return HD_OK;
    s->vert = hd__malloc_array(3 * s->n, sizeof *s->vert);
    if (!s->vert) return hd__err(err, HD_ENOMEM, "out of memory for %zu triangles", s->n);
    const uint32_t *i32 = M->triangles;
    const uint64_t *i64 = M->triangles;
    for (size_t k = 0; k < 3 * s->n; k++)
        s->vert[k] = M->index_type == HD_INDEX_U32 ? i32[k] : (uint32_t)i64[k];
    s->n_vert = M->vertices.count;
    return HD_OK;
}

static int side_mesh(const hd_mesh_t *M, const char *name, side_t *s, hd_error_t *err) {
    memset(s, 0, sizeof *s);
    if (!M) return hd__err(err, HD_EINVAL, "mesh %s is NULL", name);
    size_t deg;
    int rc = hd__mesh_triangles(M, &s->tris, &deg, err);
    if (rc) {
        if (err) { /* name the mesh: "mesh A: ..." */
            char msg[sizeof err->message];
            memcpy(msg, err->message, sizeof msg);
            hd__err(err, rc, "%s %s", name, msg);
        }
        return rc;
    }
    s->n = M->n_triangles;
    s->mesh = M;
    return HD_OK;
}

static int side_points(const hd_points_t *P, side_t *s, hd_error_t *err) {
    memset(s, 0, sizeof *s);
    if (!P) return hd__err(err, HD_EINVAL, "point set B is NULL");
    hd__box_t box;
    int rc = hd__points_check(P, "B", &box, err);
    if (rc) return rc;
    s->tris = hd__malloc_array(P->count, sizeof *s->tris);
    if (!s->tris) return hd__err(err, HD_ENOMEM, "out of memory for %zu points", P->count);
    for (size_t k = 0; k < P->count; k++) {
        hd_points_get(P, k, s->tris[k].v[0]);
        memcpy(s->tris[k].v[1], s->tris[k].v[0], sizeof s->tris[k].v[0]);
        memcpy(s->tris[k].v[2], s->tris[k].v[0], sizeof s->tris[k].v[0]);
        s->tris[k].index = k;
    }
    s->n = P->count;
    s->points = 1;
    return HD_OK;
}

static int check_options(const hd_surface_options_t *opt, hd_surface_options_t *o, hd_error_t *err) {
    if (opt) *o = *opt;
    else hd_surface_options_init(o);
    if (!(o->tolerance >= 0) || !isfinite(o->tolerance))
        return hd__err(err, HD_EINVAL, "tolerance must be finite and >= 0, not %g", o->tolerance);
    if (o->threads < 0) return hd__err(err, HD_EINVAL, "threads must be >= 0, not %d", o->threads);
    return HD_OK;
}

/* The absolute tolerance: the option made absolute (relative: times the
 * diagonal of both sides' box), and never below the floor. */
static double tolerance_of(const hd_surface_options_t *o, const side_t *x, const side_t *y) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, big;
    const side_t *s2[2] = {x, y};
    for (int s = 0; s < 2; s++) /* the corners are finite (checked): plain comparisons */
        for (size_t k = 0; k < s2[s]->n; k++)
            for (int j = 0; j < 3; j++)
                for (int d = 0; d < 3; d++) {
                    double v = s2[s]->tris[k].v[j][d];
                    lo[d] = v < lo[d] ? v : lo[d], hi[d] = v > hi[d] ? v : hi[d];
                }
    big = fmax(fmax(fmax(-lo[0], hi[0]), fmax(-lo[1], hi[1])), fmax(-lo[2], hi[2]));
    double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    double diag = sqrt(dx * dx + dy * dy + dz * dz);
    double floor_ = big * FLOOR_COORD + diag * FLOOR_DIAG + 0x1p-1000;
    double tol = o->relative ? o->tolerance * diag : o->tolerance;
    return fmax(tol, floor_);
}

static void enclosure_init(hd_enclosure_t *e) {
    memset(e, 0, sizeof *e);
    e->face_a = e->index_a = e->face_b = e->index_b = SIZE_MAX;
}

/* What one directed search asks, besides the sides. */
typedef struct ask {
    double tol, done_below, stop_above;
    int per_face, threads;
    uint64_t max_splits;
    double *face_lower, *face_upper;
} ask_t;

/* Both meshes' shared faces at once (a table of y's faces, x's looked up
 * in it), unless already known or a side is a point set. */
static int shared(side_t *x, side_t *y, hd_error_t *err) {
    if (x->drop || x->points || y->points) return HD_OK;
    x->drop = malloc(x->n ? x->n : 1);
    y->drop = malloc(y->n ? y->n : 1);
    if (!x->drop || !y->drop ||
        hd__m2m_shared(x->tris, x->n, y->tris, y->n, x->drop, y->drop, &x->dropped, &y->dropped)) {
        free(x->drop), free(y->drop);
        x->drop = y->drop = NULL;
        return hd__err(err, HD_ENOMEM, "out of memory comparing the faces of the meshes");
    }
    return HD_OK;
}

static int directed(side_t *x, side_t *y, const ask_t *q, hd_enclosure_t *out, hd_error_t *err) {
    double t0 = hd__now();
    int rc = shared(x, y, err);
    if (rc) return rc;
    const unsigned char *drop = x->drop;
    size_t dropped = x->dropped;
    if (dropped == x->n) { /* every face of X is a face of Y: h = 0, no tree needed */
        for (size_t k = 0; k < x->n; k++) {
            if (q->face_lower) q->face_lower[k] = 0;
            if (q->face_upper) q->face_upper[k] = 0;
        }
        enclosure_init(out);
        out->tolerance = q->tol;
        out->converged = 1;
        out->faces_dropped = dropped;
        out->seconds = hd__now() - t0;
        return HD_OK;
    }
    if (!y->built && (rc = side_tree(y, y->points ? "points" : "mesh", err))) return rc;
    if ((rc = side_vertices(x, err))) return rc;
    /* no face dropped: no table to read (mesh/m2m.c skips its checks) */
    hd__m2m_job_t J = {.from = x->tris, .n_from = x->n, .to = &y->bvh, .drop = dropped ? drop : NULL,
                       .vertex = x->vert, .n_vertices = x->n_vert, .tol = q->tol,
                       .done_below = q->done_below, .stop_above = q->stop_above, .per_face = q->per_face,
                       .max_splits = q->max_splits, .face_lower = q->face_lower, .face_upper = q->face_upper};
    J.threads = hd__thread_count(q->threads, x->n);
    hd__m2m_result_t R;
    rc = hd__m2m_run(&J, &R);
    if (rc) return hd__err(err, rc, "out of memory refining %zu triangles", x->n);
    enclosure_init(out);
    out->lower = R.lower;
    out->upper = R.upper;
    out->tolerance = q->tol;
    out->converged = !R.capped && R.upper - R.lower <= q->tol;
    if (R.face != SIZE_MAX) {
        out->face_a = R.face;
        memcpy(out->bary_a, R.bary, sizeof R.bary);
        memcpy(out->point_a, R.point, sizeof R.point);
        out->witness_distance = R.witness_distance;
        out->witness_error = R.witness_error;
        if (y->points) out->index_b = R.face_b;
        else out->face_b = R.face_b;
        memcpy(out->point_b, R.point_b, sizeof R.point_b);
    }
    out->faces_dropped = R.dropped;
    out->faces_split = R.splits;
    out->kernel_calls = R.kernel_calls;
    out->seconds = hd__now() - t0;
    return HD_OK;
}

/* Every entry point's first steps: the options checked, A's triangles,
 * B's (a mesh, or the point set P when B is NULL), and what a search asks
 * by default.  On failure nothing is left to free. */
static int open_sides(const hd_surface_options_t *opt, const hd_mesh_t *A, const hd_mesh_t *B,
                      const hd_points_t *P, side_t *a, side_t *b, ask_t *q, hd_error_t *err) {
    hd__err_clear(err);
    hd_surface_options_t o;
    int rc = check_options(opt, &o, err);
    if (rc || (rc = side_mesh(A, "A", a, err))) return rc;
    if ((rc = B || !P ? side_mesh(B, "B", b, err) : side_points(P, b, err))) {
        side_free(a);
        return rc;
    }
    ask_t d = {tolerance_of(&o, a, b), -INFINITY, INFINITY, 0, o.threads, o.max_splits, NULL, NULL};
    *q = d;
    return HD_OK;
}

static void close_sides(side_t *a, side_t *b) {
    side_free(a);
    side_free(b);
}

int hd_surface_hausdorff(const hd_mesh_t *A, const hd_mesh_t *B, const hd_surface_options_t *opt,
                         hd_enclosure_t *ab, hd_enclosure_t *ba, hd_error_t *err) {
    side_t a, b;
    ask_t q;
    if (!ab && !ba) return hd__err(err, HD_EINVAL, "both outputs are NULL");
    int rc = open_sides(opt, A, B, NULL, &a, &b, &q, err);
    if (rc) return rc;
    if (ab) rc = directed(&a, &b, &q, ab, err);
    if (ba && rc == HD_OK) rc = directed(&b, &a, &q, ba, err);
    close_sides(&a, &b);
    return rc;
}

/* h(points B, surface A), exact, as an enclosure of width 0. */
static int points_to_surface(const hd_points_t *B, const hd_mesh_t *A, const side_t *a, const ask_t *q,
                             hd_enclosure_t *out, hd_error_t *err) {
    hd_options_t po;
    hd_options_init(&po);
    po.threads = q->threads;
    hd_surface_result_t r;
    int rc = hd_mesh_distances(B, A, &po, NULL, NULL, NULL, NULL, &r, err);
    if (rc) return rc;
    enclosure_init(out);
    out->lower = out->upper = out->witness_distance = r.distance;
    out->tolerance = q->tol;
    out->converged = 1;
    out->index_a = r.i;
    out->face_b = r.triangle;
    hd_points_get(B, r.i, out->point_a);
    hd__tri_near_t near;
    const hd__tri_t *t = &a->tris[r.triangle];
    hd__tri_nearest(out->point_a, t->v[0], t->v[1], t->v[2], &near);
    memcpy(out->point_b, near.point, sizeof near.point);
    out->kernel_calls = r.kernel_calls;
    out->seconds = r.seconds;
    return HD_OK;
}

int hd_surface_points_hausdorff(const hd_mesh_t *A, const hd_points_t *B, const hd_surface_options_t *opt,
                                hd_enclosure_t *ab, hd_enclosure_t *ba, hd_error_t *err) {
    side_t a, b;
    ask_t q;
    if (!ab && !ba) return hd__err(err, HD_EINVAL, "both outputs are NULL");
    if (!B) return hd__err(err, HD_EINVAL, "point set B is NULL");
    int rc = open_sides(opt, A, NULL, B, &a, &b, &q, err);
    if (rc) return rc;
    if (ab) rc = directed(&a, &b, &q, ab, err);
    if (ba && rc == HD_OK) rc = points_to_surface(B, A, &a, &q, ba, err);
    close_sides(&a, &b);
    return rc;
}

int hd_surface_within(const hd_mesh_t *A, const hd_mesh_t *B, double d, int directed_only,
                      const hd_surface_options_t *opt, int *answer, hd_enclosure_t *ab, hd_enclosure_t *ba,
                      hd_error_t *err) {
    side_t a, b;
    ask_t q;
    if (!answer) return hd__err(err, HD_EINVAL, "answer is NULL");
    *answer = -1;
    if (!(d >= 0)) return hd__err(err, HD_EINVAL, "the distance must be >= 0, not %g", d);
    int rc = open_sides(opt, A, B, NULL, &a, &b, &q, err);
    if (rc) return rc;
    q.done_below = d;
    q.stop_above = d;
    hd_enclosure_t e[2];
    rc = directed(&a, &b, &q, &e[0], err);
    int sides = 1;
    if (rc == HD_OK && !directed_only && !(e[0].lower > d)) {
        rc = directed(&b, &a, &q, &e[1], err);
        sides = 2;
    }
    if (rc == HD_OK) {
        double lower = e[0].lower, upper = e[0].upper;
        if (sides == 2) lower = fmax(lower, e[1].lower), upper = fmax(upper, e[1].upper);
        *answer = lower > d ? 0 : upper <= d ? 1 : -1;
        if (ab) *ab = e[0];
        if (ba) {
            if (sides == 2) *ba = e[1];
            else enclosure_init(ba), ba->upper = INFINITY, ba->tolerance = q.tol;
        }
    }
    close_sides(&a, &b);
    return rc;
}

int hd_surface_face_maxima(const hd_mesh_t *A, const hd_mesh_t *B, const hd_surface_options_t *opt,
                           double *face_lower, double *face_upper, hd_enclosure_t *ab, hd_error_t *err) {
    side_t a, b;
    ask_t q;
    if (!face_lower && !face_upper) return hd__err(err, HD_EINVAL, "both face arrays are NULL");
    int rc = open_sides(opt, A, B, NULL, &a, &b, &q, err);
    if (rc) return rc;
    q.per_face = 1;
    q.face_lower = face_lower;
    q.face_upper = face_upper;
    hd_enclosure_t e;
    rc = directed(&a, &b, &q, &e, err);
    if (rc == HD_OK && ab) *ab = e;
    close_sides(&a, &b);
    return rc;
}
