/*
 * surface.c -- the public entry points for triangle meshes: reading a
 * mesh's faces (hd_read_mesh) and the distance from every point of a cloud
 * to the surface (hd_mesh_distances).
 *
 * hd_mesh_distances checks everything first (points, indices, corners),
 * copies each triangle's corners into a bounding-volume hierarchy
 * (mesh/bvh.c), sorts the points along a Morton curve and answers them in
 * runs of RUN consecutive points, each run a task of the thread pool: a
 * point's search starts from its predecessor's nearest triangle.  Every
 * answer is the brute force's (bvh.c proves it for any seed), so neither
 * the runs nor the threads change a bit of the result; the witness of the
 * maximum is merged in run order with the smallest-index rule.
 */
#include "io/io.h"
#include "mesh/mesh.h"
#include "surface.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RUN 512
#define GROUP_POINTS 16
#define LIST 64

/* ---- reading ------------------------------------------------------------ */

/* STL stores each facet's corners: merge those with bit-equal coordinates
 * into the first of them, renumbering in order of first appearance.  The
 * corners are sorted by their bytes (any total order groups equal ones)
 * and then by number. */
typedef struct {
    double xyz[3];
    size_t k;
} corner_t;

static int cmp_corner(const void *x, const void *y) {
    const corner_t *a = x, *b = y;
    int c = memcmp(a->xyz, b->xyz, sizeof a->xyz);
    return c ? c : (a->k > b->k) - (a->k < b->k);
}

static int merge_equal(hd_mesh_file_t *m, const char *name, hd_error_t *err) {
    size_t n = m->n_vertices;
    corner_t *c = hd__malloc_array(n, sizeof *c);
    size_t *map = hd__malloc_array(n, sizeof *map);
    if (!c || !map) {
        free(c);
        free(map);
        return hd__err(err, HD_ENOMEM, "%s: out of memory merging %zu corners", name, n);
    }
    for (size_t k = 0; k < n; k++) {
        memcpy(c[k].xyz, m->vertices + 3 * k, sizeof c[k].xyz);
        c[k].k = k;
    }
    qsort(c, n, sizeof *c, cmp_corner);
    for (size_t a = 0; a < n;) { /* map[k] = the first corner bit-equal to k */
        size_t b = a + 1;
        while (b < n && memcmp(c[a].xyz, c[b].xyz, sizeof c[a].xyz) == 0) b++;
        for (size_t k = a; k < b; k++) map[c[k].k] = c[a].k;
        a = b;
    }
    free(c);
    size_t kept = 0;
    for (size_t k = 0; k < n; k++) /* first corners move down, in order */
        if (map[k] == k) {
            memmove(m->vertices + 3 * kept, m->vertices + 3 * k, 3 * sizeof(double));
            map[k] = kept++;
        } else {
            map[k] = map[map[k]]; /* map[k] < k: already renumbered */
        }
    for (size_t t = 0; t < 3 * m->n_triangles; t++) m->triangles[t] = map[m->triangles[t]];
    m->n_merged = n - kept;
    m->n_vertices = kept;
    free(map);
    return HD_OK;
}

/* Every index in range (the readers check it too; a reader's error names
 * the line), and the degenerate triangles counted. */
static int check_faces(hd_mesh_file_t *m, const char *name, hd_error_t *err) {
    for (size_t t = 0; t < m->n_triangles; t++) {
        const uint64_t *f = m->triangles + 3 * t;
        for (int j = 0; j < 3; j++)
            if (f[j] >= m->n_vertices)
                return hd__err(err, HD_EFORMAT, "%s: triangle %zu (faces split into fans) refers to vertex %llu, "
                               "but the file has %zu vertices", name, t, (unsigned long long)f[j], m->n_vertices);
        m->n_degenerate += (size_t)hd__tri_degenerate(m->vertices + 3 * f[0], m->vertices + 3 * f[1],
                                                      m->vertices + 3 * f[2]);
    }
    return HD_OK;
}

static int read_mesh(const char *path, const hd_read_options_t *opt, hd_mesh_file_t *m, hd_error_t *err) {
    hd__sink_t verts;
    hd__tris_t tris;
    hd__sink_init(&verts, HD_FLOAT64);
    hd__tris_init(&tris);
    const char *format = "";
    const char *name = strcmp(path, "-") == 0 ? "(standard input)" : path;
    int rc = hd__read_faces(path, opt, &verts, &tris, &m->n_faces, &format, err);
    m->vertices = verts.data;
    m->n_vertices = verts.count;
    m->triangles = tris.v;
    m->n_triangles = tris.count;
    snprintf(m->format, sizeof m->format, "%s", format);
    if (rc) return rc;
    if (verts.count == 0) return hd__err(err, HD_EEMPTY, "%s: no vertices", name);
    if (tris.count == 0)
        return hd__err(err, HD_EEMPTY, "%s: no faces (%zu vertices and no triangle to measure)", name, verts.count);
    if (strcmp(format, "stl") == 0 && (rc = merge_equal(m, name, err))) return rc;
    return check_faces(m, name, err);
}

int hd_read_mesh(const char *path, const hd_read_options_t *opt, hd_mesh_file_t **out, hd_error_t *err) {
    hd__err_clear(err);
    if (!path || !out) return hd__err(err, HD_EINVAL, "path or result pointer is NULL");
    *out = NULL;
    hd_read_options_t o;
    if (opt) o = *opt;
    else hd_read_options_init(&o);
    if (o.range_count || o.range_first)
        return hd__err(err, HD_EINVAL, "%s: a mesh is read whole (no point range)", path);
    o.dtype = HD_FLOAT64;
    o.mesh = HD_MESH_VERTICES;
    hd_mesh_file_t *m = calloc(1, sizeof *m);
    if (!m) return hd__err(err, HD_ENOMEM, "%s: out of memory", path);
    int rc = read_mesh(path, &o, m, err);
    if (rc) {
        hd_mesh_file_free(m);
        return rc;
    }
    *out = m;
    return HD_OK;
}

void hd_mesh_file_free(hd_mesh_file_t *mesh) {
    if (!mesh) return;
    free(mesh->vertices);
    free(mesh->triangles);
    free(mesh);
}

hd_mesh_t hd_mesh_file_view(const hd_mesh_file_t *mesh) {
    hd_mesh_t v;
    memset(&v, 0, sizeof v);
    v.vertices = hd_points_f64(NULL, 0);
    v.index_type = HD_INDEX_U64;
    if (!mesh) return v;
    v.vertices = hd_points_f64(mesh->vertices, mesh->n_vertices);
    v.triangles = mesh->triangles;
    v.n_triangles = mesh->n_triangles;
    return v;
}

/* ---- distances ---------------------------------------------------------- */

/* The triangles copied corner by corner, each index and coordinate checked
 * where it is read, so that the error names the first triangle and corner
 * at fault (a vertex no triangle uses is never an error). */
static int copy_checked(const hd_mesh_t *M, const hd__src_t *src, hd__tri_t *t, hd_error_t *err) {
    const hd_points_t *V = &M->vertices;
    for (size_t k = 0; k < M->n_triangles; k++)
        for (int j = 0; j < 3; j++) {
            uint64_t v = M->index_type == HD_INDEX_U32 ? ((const uint32_t *)M->triangles)[3 * k + j]
                                                       : ((const uint64_t *)M->triangles)[3 * k + j];
            if (v >= V->count)
                return hd__err(err, HD_EINVAL, "mesh: triangle %zu refers to vertex %llu, but there are %zu vertices",
                               k, (unsigned long long)v, V->count);
            hd__src_get(src, (size_t)v, t[k].v[j]);
            for (int c = 0; c < 3; c++)
                if (!(fabs(t[k].v[j][c]) <= HD_MAX_COORD)) {
                    int nonfinite = !isfinite(t[k].v[j][c]);
                    return hd__err(err, nonfinite ? HD_ENONFINITE : HD_ERANGE,
                                   "mesh: triangle %zu, corner %d (vertex %llu): a coordinate is %s", k, j,
                                   (unsigned long long)v, nonfinite ? "NaN or infinite" : "beyond the limit 1e153");
                }
        }
    return HD_OK;
}

/* Whether every vertex is within the checked range (finite, at most
 * HD_MAX_COORD): then a corner needs no check of its own. */
static int vertices_in_range(const hd_points_t *V, const hd__src_t *src) {
    for (size_t i = 0; i < V->count; i++) {
        double q[3];
        hd__src_get(src, i, q);
        if (!(fabs(q[0]) <= HD_MAX_COORD && fabs(q[1]) <= HD_MAX_COORD && fabs(q[2]) <= HD_MAX_COORD)) return 0;
    }
    return 1;
}

/* The triangles copied with their indices checked alone (every vertex in
 * range); 0 at the first index out of range, which copy_checked then
 * reports.  u32: the index type (a constant where inlined, so that each
 * index type and the plain array of doubles get a loop of their own). */
HD__INLINE int copy_fast_as(const hd_mesh_t *M, const hd__src_t *src, hd__tri_t *t, int u32, int f64) {
    size_t n = M->vertices.count;
    const uint32_t *i32 = M->triangles;
    const uint64_t *i64 = M->triangles;
    for (size_t k = 0; k < M->n_triangles; k++)
        for (int j = 0; j < 3; j++) {
            uint64_t v = u32 ? i32[3 * k + j] : i64[3 * k + j];
            if (v >= n) return 0;
            if (f64) memcpy(t[k].v[j], src->base + (ptrdiff_t)v * 24, sizeof t[k].v[j]);
            else hd__src_get(src, (size_t)v, t[k].v[j]);
        }
    return 1;
}

static int copy_fast(const hd_mesh_t *M, const hd__src_t *src, hd__tri_t *t) {
    int u32 = M->index_type == HD_INDEX_U32, f64 = src->kind == HD__SRC_F64 && !src->T;
    if (u32) return f64 ? copy_fast_as(M, src, t, 1, 1) : copy_fast_as(M, src, t, 1, 0);
    return f64 ? copy_fast_as(M, src, t, 0, 1) : copy_fast_as(M, src, t, 0, 0);
}

/* The mesh's triangles as the tree stores them, every index and corner
 * checked; *n_degenerate counted. */
int hd__mesh_triangles(const hd_mesh_t *M, hd__tri_t **out, size_t *n_degenerate, hd_error_t *err) {
    const hd_points_t *V = &M->vertices;
    if (M->index_type != HD_INDEX_U32 && M->index_type != HD_INDEX_U64)
        return hd__err(err, HD_EINVAL, "mesh: unknown index type %d", (int)M->index_type);
    if (M->n_triangles == 0) return hd__err(err, HD_EEMPTY, "mesh: no triangles");
    if (V->count == 0) return hd__err(err, HD_EEMPTY, "mesh: %zu triangles but no vertices", M->n_triangles);
    if (!M->triangles || !V->data) return hd__err(err, HD_EINVAL, "mesh: NULL triangles or vertices");
    if (V->dtype != HD_FLOAT64 && V->dtype != HD_FLOAT32)
        return hd__err(err, HD_EINVAL, "mesh: the vertices have an unknown element type");
    size_t isz = M->index_type == HD_INDEX_U32 ? sizeof(uint32_t) : sizeof(uint64_t);
    if ((uintptr_t)M->triangles % isz)
        return hd__err(err, HD_EINVAL, "mesh: the triangle indices are not aligned to their %zu bytes", isz);
    int rc = hd__points_aligned(V, "of the mesh vertices", err);
    if (rc) return rc;
    hd__tri_t *t = hd__malloc_array(M->n_triangles, sizeof *t);
    if (!t) return hd__err(err, HD_ENOMEM, "mesh: out of memory for %zu triangles", M->n_triangles);
    hd__src_t src;
    hd__src_init(&src, V, NULL);
    if (!(vertices_in_range(V, &src) && copy_fast(M, &src, t)) && (rc = copy_checked(M, &src, t, err))) {
        free(t);
        return rc;
    }
    *n_degenerate = 0;
    for (size_t k = 0; k < M->n_triangles; k++) {
        t[k].index = k;
        *n_degenerate += (size_t)hd__tri_degenerate(t[k].v[0], t[k].v[1], t[k].v[2]);
    }
    *out = t;
    return HD_OK;
}

/* The farthest point of a run, by the witness rule. */
typedef struct {
    double d;
    size_t i, tri;
} far_t;

typedef struct {
    const hd__bvh_t *bvh;
    hd__src_t src;
    const size_t *order; /* points in Morton order */
    size_t n;
    double *dist, *closest, *bary;
    size_t *triangle;
    far_t *far;             /* one per run */
    hd__bvh_stats_t *stats; /* one per worker */
} job_t;

/* An r2 for hd__bvh_collect over the box B of a group of points, one of
 * which (p0) is at rounded distance d0 from the mesh: every q in B has
 * t*(q) <= t*(p0) + |q - p0| <= d0 (1 + u) + |B| (1 + u)^5 (|B| the
 * diagonal, computed with five roundings), so its rounded distance d*(q)
 * and the double after it are at most (d0 + |B|) (1 + u)^9; the computed
 * (d0 + |B|) (1 + 2^-48), squared and grown once more, is above
 * next(d*(q))^2.  Below 2^-495 the floor 2^-980 is above it. */
static double group_r2(double d0, const hd__box_t *B) {
    double x = B->hi[0] - B->lo[0], y = B->hi[1] - B->lo[1], z = B->hi[2] - B->lo[2];
    double r = (d0 + sqrt(x * x + y * y + z * z)) * (1.0 + 0x1p-48);
    double r2 = r * r * (1.0 + 0x1p-48);
    return r2 > 0x1p-980 ? r2 : 0x1p-980;
}

static void keep(job_t *J, size_t i, const hd__tri_near_t *best, size_t index, far_t *far) {
    if (J->dist) J->dist[i] = best->d;
    if (J->triangle) J->triangle[i] = index;
    if (J->closest) memcpy(J->closest + 3 * i, best->point, sizeof best->point);
    if (J->bary) memcpy(J->bary + 3 * i, best->bary, sizeof best->bary);
    if (best->d > far->d || (best->d == far->d && i < far->i)) *far = (far_t){best->d, i, index};
}

/* Points [lo, hi) of the Morton order as groups of up to GROUP_POINTS:
 * the group's first point searches the tree, the others search the list
 * of the triangles that may be nearest to some point of the group's box
 * (hd__bvh_collect), or the tree when that list is longer than LIST; after
 * a list too long, the next groups (1, 2, 4 .. 64 of them) do not try. */
static void run(void *ctx, size_t task, int worker) {
    job_t *J = ctx;
    size_t lo = task * RUN, hi = lo + RUN < J->n ? lo + RUN : J->n, seed = SIZE_MAX;
    int corner = 0; /* the previous answer was at a corner */
    size_t skip = 0, backoff = 0;
    far_t far = {-1.0, SIZE_MAX, SIZE_MAX};
    hd__bvh_stats_t st = {0, 0, 0, 0, 0, 0};
    uint32_t list[LIST];
    for (size_t g = lo; g < hi; g += GROUP_POINTS) {
        size_t end = g + GROUP_POINTS < hi ? g + GROUP_POINTS : hi, index, n_list = SIZE_MAX;
        double p[GROUP_POINTS][3];
        hd__box_t B;
        for (size_t r = g; r < end; r++) {
            hd__src_get(&J->src, J->order ? J->order[r] : r, p[r - g]);
            if (r == g) memcpy(B.lo, p[0], sizeof B.lo), memcpy(B.hi, p[0], sizeof B.hi);
            for (int c = 0; c < 3; c++) {
                B.lo[c] = p[r - g][c] < B.lo[c] ? p[r - g][c] : B.lo[c];
                B.hi[c] = p[r - g][c] > B.hi[c] ? p[r - g][c] : B.hi[c];
            }
        }
        for (size_t r = g; r < end; r++) {
            hd__tri_near_t best;
            if (n_list == SIZE_MAX) {
                seed = hd__bvh_nearest(J->bvh, p[r - g], seed, corner, &best, &index, &st);
                if (r == g && end - g > 1 && skip == 0) {
                    n_list = hd__bvh_collect(J->bvh, &B, group_r2(best.d, &B), list, LIST);
                    /* a list too long: the next 1, 2, 4 .. 64 groups search the tree */
                    backoff = n_list == SIZE_MAX ? (backoff ? (backoff < 64 ? 2 * backoff : 64) : 1) : 0;
                    skip = backoff;
                } else if (r == g && skip > 0) {
                    skip--;
                }
            } else {
                seed = hd__bvh_nearest_in(J->bvh, p[r - g], list, n_list, seed, corner, &best, &index, &st);
            }
            corner = best.feature >= HD__TRI_VERTEX_A;
            keep(J, J->order ? J->order[r] : r, &best, index, &far);
        }
    }
    J->far[task] = far;
    hd__bvh_stats_t *w = &J->stats[worker];
    w->nodes += st.nodes, w->bounded += st.bounded, w->kernel += st.kernel, w->exact += st.exact;
    w->listed += st.listed;
}

/* The points' Morton order (NULL when there are too many to key; any
 * order is correct). */
static int morton_order(const hd_points_t *P, const hd__box_t *box, int threads, size_t **out) {
    *out = NULL;
    size_t n = P->count;
    if (n > UINT32_MAX) return HD_OK;
    uint64_t *keys = hd__malloc_array(n, sizeof *keys), *tmp = hd__malloc_array(n, sizeof *tmp);
    size_t *order = hd__malloc_array(n, sizeof *order);
    int rc = keys && tmp && order ? HD_OK : HD_ENOMEM;
    if (rc == HD_OK) {
        hd__src_t src;
        hd__src_init(&src, P, NULL);
        hd__keygrid_t g;
        hd__keygrid_init(&g, box);
        hd__src_keys(&src, &g, 0, n, keys);
        rc = hd__radix_sort(&keys, &tmp, n, threads);
    }
    if (rc == HD_OK)
        for (size_t k = 0; k < n; k++) order[k] = (size_t)(keys[k] & 0xffffffffu);
    free(keys);
    free(tmp);
    if (rc) free(order);
    else *out = order;
    return rc;
}

static int answer(const hd_points_t *P, const hd__bvh_t *bvh, const hd__box_t *box, int threads, job_t *J,
                  hd_surface_result_t *res, hd_error_t *err) {
    size_t n = P->count, runs = (n + RUN - 1) / RUN;
    size_t *order = NULL;
    int rc = morton_order(P, box, threads, &order);
    J->bvh = bvh;
    hd__src_init(&J->src, P, NULL);
    J->order = order;
    J->n = n;
    J->far = hd__malloc_array(runs, sizeof *J->far);
    J->stats = hd__calloc_array((size_t)threads, sizeof *J->stats);
    if (rc || !J->far || !J->stats) {
        free(order);
        free(J->far);
        free(J->stats);
        return hd__err(err, HD_ENOMEM, "out of memory for the order of %zu points", n);
    }
    hd__parallel_for(threads, runs, run, J);
    far_t far = {-1.0, SIZE_MAX, SIZE_MAX};
    for (size_t k = 0; k < runs; k++)
        if (J->far[k].d > far.d || (J->far[k].d == far.d && J->far[k].i < far.i)) far = J->far[k];
    res->distance = far.d;
    res->i = far.i;
    res->triangle = far.tri;
    for (int w = 0; w < threads; w++) {
        res->nodes_visited += J->stats[w].nodes;
        res->triangles_bounded += J->stats[w].bounded;
        res->kernel_calls += J->stats[w].kernel;
        res->exact_calls += J->stats[w].exact;
    }
    free(order);
    free(J->far);
    free(J->stats);
    return HD_OK;
}

int hd_mesh_distances(const hd_points_t *P, const hd_mesh_t *M, const hd_options_t *opt, double *dist,
                      size_t *triangle, double *closest, double *bary, hd_surface_result_t *out,
                      hd_error_t *err) {
    hd__err_clear(err);
    double t0 = hd__now();
    hd_surface_result_t res;
    memset(&res, 0, sizeof res);
    if (out) *out = res;
    if (!P || !M) return hd__err(err, HD_EINVAL, "point set or mesh is NULL");
    if (opt && opt->threads < 0) return hd__err(err, HD_EINVAL, "threads must be >= 0, not %d", opt->threads);
    hd__box_t box;
    int rc = hd__points_check(P, "P", &box, err);
    hd__tri_t *tris = NULL;
    if (rc || (rc = hd__mesh_triangles(M, &tris, &res.n_degenerate, err))) return rc;
    hd__bvh_t bvh;
    if ((rc = hd__bvh_build_threads(&bvh, tris, M->n_triangles, hd__thread_count(opt ? opt->threads : 0, SIZE_MAX)))) {
        free(tris);
        return hd__err(err, rc, "mesh: cannot build the tree of %zu triangles", M->n_triangles);
    }
    (void)hd__bvh_frames(&bvh); /* optional: without frames the search is as exact */
    int threads = hd__thread_count(opt ? opt->threads : 0, (P->count + RUN - 1) / RUN);
    job_t J = {.dist = dist, .closest = closest, .bary = bary, .triangle = triangle};
    rc = answer(P, &bvh, &box, threads, &J, &res, err);
    hd__bvh_free(&bvh);
    res.seconds = hd__now() - t0;
    if (rc == HD_OK && out) *out = res;
    return rc;
}
