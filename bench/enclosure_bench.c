/*
 * enclosure_bench.c -- hd_surface_hausdorff on a model against a copy made
 * from it, both directions, at one tolerance and thread count:
 *
 *   enclosure_bench MODEL cluster CELL TOL THREADS   (CELL: a fraction of the
 *       diagonal; every vertex moves to the mean of its grid cell's, faces
 *       that collapse are dropped: a coarser mesh, vertex clustering)
 *   enclosure_bench MODEL perturb AMP TOL THREADS    (every vertex moved by
 *       up to AMP/2 of the diagonal on each axis, seeded; same faces)
 *
 * TOL is relative to the diagonal of both meshes' box.  Prints each
 * direction's enclosure, width, splits, kernel calls and seconds.
 */
#include <hausdorff.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    long long k[3];
    size_t i;
} cell_t;

static int cmp_cell(const void *x, const void *y) { return memcmp(((const cell_t *)x)->k, ((const cell_t *)y)->k, sizeof ((const cell_t *)x)->k); }

static double unit(uint64_t *s) {
    *s ^= *s << 13, *s ^= *s >> 7, *s ^= *s << 17;
    return (double)(*s >> 11) * 0x1p-53;
}

/* The copy's vertices and faces; returns its face count. */
static size_t make_copy(const hd_mesh_file_t *m, const char *mode, double param, double diag, const double lo[3],
                        double *v2, uint64_t *t2, size_t *nv2) {
    size_t nv = m->n_vertices, nt = m->n_triangles, n = 0;
    if (strcmp(mode, "perturb") == 0) {
        uint64_t s = 88172645463325252ull;
        for (size_t i = 0; i < 3 * nv; i++) v2[i] = m->vertices[i] + (unit(&s) - 0.5) * param * diag;
        memcpy(t2, m->triangles, 3 * nt * sizeof *t2);
        *nv2 = nv;
        return nt;
    }
    double c = param * diag;
    cell_t *K = malloc(nv * sizeof *K);
    size_t *cell = malloc(nv * sizeof *cell), nc = 0;
    if (!K || !cell) exit(3);
    for (size_t i = 0; i < nv; i++) {
        for (int d = 0; d < 3; d++) K[i].k[d] = (long long)floor((m->vertices[3 * i + d] - lo[d]) / c);
        K[i].i = i;
    }
    qsort(K, nv, sizeof *K, cmp_cell);
    for (size_t a = 0; a < nv; nc++) {
        size_t b = a;
        double sum[3] = {0, 0, 0};
        for (; b < nv && memcmp(K[a].k, K[b].k, sizeof K[a].k) == 0; b++)
            for (int d = 0; d < 3; d++) sum[d] += m->vertices[3 * K[b].i + d];
        for (int d = 0; d < 3; d++) v2[3 * nc + d] = sum[d] / (double)(b - a);
        for (size_t j = a; j < b; j++) cell[K[j].i] = nc;
        a = b;
    }
    for (size_t t = 0; t < nt; t++) {
        uint64_t x = cell[m->triangles[3 * t]], y = cell[m->triangles[3 * t + 1]], z = cell[m->triangles[3 * t + 2]];
        if (x != y && y != z && x != z) t2[3 * n] = x, t2[3 * n + 1] = y, t2[3 * n + 2] = z, n++;
    }
    free(K);
    free(cell);
    *nv2 = nc;
    return n;
}

static void show(const char *name, const hd_enclosure_t *e) {
    printf("  %s [%.17g, %.17g] width %.3g converged %d splits %llu kernel %llu %.3f s\n", name, e->lower, e->upper,
           e->upper - e->lower, e->converged, (unsigned long long)e->faces_split,
           (unsigned long long)e->kernel_calls, e->seconds);
}

int main(int argc, char **argv) {
    if (argc != 6) {
        fprintf(stderr, "usage: %s MODEL cluster|perturb PARAM TOL THREADS\n", argv[0]);
        return 2;
    }
    hd_mesh_file_t *m;
    hd_error_t err;
    if (hd_read_mesh(argv[1], NULL, &m, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, d2 = 0;
    for (size_t i = 0; i < m->n_vertices; i++)
        for (int d = 0; d < 3; d++) lo[d] = fmin(lo[d], m->vertices[3 * i + d]), hi[d] = fmax(hi[d], m->vertices[3 * i + d]);
    for (int d = 0; d < 3; d++) d2 += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    double *v2 = malloc(3 * m->n_vertices * sizeof *v2);
    uint64_t *t2 = malloc(3 * m->n_triangles * sizeof *t2);
    if (!v2 || !t2) return 3;
    size_t nv2, nt2 = make_copy(m, argv[2], atof(argv[3]), sqrt(d2), lo, v2, t2, &nv2);
    hd_mesh_t A = hd_mesh_file_view(m), B = {hd_points_f64(v2, nv2), t2, nt2, HD_INDEX_U64};
    hd_surface_options_t o;
    hd_surface_options_init(&o);
    o.tolerance = atof(argv[4]);
    o.threads = atoi(argv[5]);
    hd_enclosure_t ab, ba;
    if (hd_surface_hausdorff(&A, &B, &o, &ab, &ba, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    printf("%s %s %s: A %zu triangles, B %zu, tolerance %s of the diagonal, %d threads\n", argv[1], argv[2], argv[3],
           m->n_triangles, nt2, argv[4], o.threads);
    show("h(A,B)", &ab);
    show("h(B,A)", &ba);
    free(v2);
    free(t2);
    hd_mesh_file_free(m);
    return 0;
}
