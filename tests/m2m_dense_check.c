/*
 * m2m_dense_check.c -- the dense check of m2m_dense_check.h.
 */
#include "m2m_dense_check.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int m2m_dense_level(size_t n_triangles, size_t samples) {
    /* A level-k grid has (k + 1)(k + 2) / 2 points a triangle, about k^2 / 2. */
    if (n_triangles == 0) return 1;
    double k = sqrt(2.0 * (double)samples / (double)n_triangles);
    return k < 1 ? 1 : k > 4096 ? 4096 : (int)k;
}

static size_t corner(const hd_mesh_t *M, size_t k, int c) {
    if (M->index_type == HD_INDEX_U32) return ((const uint32_t *)M->triangles)[3 * k + c];
    return (size_t)((const uint64_t *)M->triangles)[3 * k + c];
}

/* The samples of A: its used vertices first (face SIZE_MAX), then each
 * triangle's grid points without its corners.  Returns the count, or 0
 * when memory fails.  The caller frees *xyz and *face. */
static size_t samples_of(const hd_mesh_t *A, int level, double **xyz, size_t **face) {
    size_t nv = A->vertices.count, per = (size_t)(level + 1) * (size_t)(level + 2) / 2 - 3;
    char *used = calloc(nv ? nv : 1, 1);
    size_t cap = nv + A->n_triangles * per;
    *xyz = malloc(3 * (cap ? cap : 1) * sizeof **xyz);
    *face = malloc((cap ? cap : 1) * sizeof **face);
    if (!used || !*xyz || !*face) {
        free(used), free(*xyz), free(*face);
        *xyz = NULL, *face = NULL;
        return 0;
    }
    size_t n = 0;
    for (size_t k = 0; k < A->n_triangles; k++)
        for (int c = 0; c < 3; c++) {
            size_t v = corner(A, k, c);
            if (v >= nv || used[v]) continue;
            used[v] = 1;
            hd_points_get(&A->vertices, v, *xyz + 3 * n);
            (*face)[n++] = SIZE_MAX;
        }
    free(used);
    for (size_t k = 0; k < A->n_triangles; k++) {
        double p[3][3];
        int inside = 1;
        for (int c = 0; c < 3 && inside; c++) {
            size_t v = corner(A, k, c);
            if ((inside = v < nv)) hd_points_get(&A->vertices, v, p[c]);
        }
        if (!inside) continue; /* hd_mesh_distances refuses A and says why */
        for (int i = 0; i <= level; i++)
            for (int j = 0; i + j <= level; j++) {
                int l = level - i - j;
                if (i == level || j == level || l == level) continue;
                double wa = (double)l / level, wb = (double)i / level, wc = (double)j / level;
                for (int c = 0; c < 3; c++) (*xyz)[3 * n + c] = wa * p[0][c] + wb * p[1][c] + wc * p[2][c];
                (*face)[n++] = k;
            }
    }
    return n;
}

/* The rigorous lower bound of one sample (see the header). */
static double bound(double to_b, double to_a, int vertex) {
    if (vertex) return to_b;
    double b = nextafter(to_b, 0), a = to_a > 0 ? nextafter(to_a, INFINITY) : 0;
    double d = b - a;
    return d > 0 ? nextafter(d, -INFINITY) : 0;
}

int m2m_dense_run(const hd_mesh_t *A, const hd_mesh_t *B, int level, int threads, m2m_dense_t *out,
                  hd_error_t *err) {
    double *xyz;
    size_t *face;
    if (level < 1) level = 1;
    size_t n = samples_of(A, level, &xyz, &face);
    double *to_b = n ? malloc(n * sizeof *to_b) : NULL, *to_a = n ? malloc(n * sizeof *to_a) : NULL;
    if (!n || !to_b || !to_a) {
        free(xyz), free(face), free(to_b), free(to_a);
        err->code = HD_ENOMEM;
        snprintf(err->message, sizeof err->message, "dense check: no memory for the samples at level %d", level);
        return HD_ENOMEM;
    }
    hd_options_t opt;
    hd_options_init(&opt);
    opt.threads = threads;
    hd_points_t P = hd_points_f64(xyz, n);
    int rc = hd_mesh_distances(&P, B, &opt, to_b, NULL, NULL, NULL, NULL, err);
    if (!rc) rc = hd_mesh_distances(&P, A, &opt, to_a, NULL, NULL, NULL, NULL, err);
    if (!rc) {
        *out = (m2m_dense_t){-1, {0, 0, 0}, SIZE_MAX, 0, n, level};
        for (size_t k = 0; k < n; k++) {
            double lb = bound(to_b[k], to_a[k], face[k] == SIZE_MAX);
            if (lb > out->largest) {
                out->largest = lb, out->face = face[k], out->off = to_a[k];
                for (int c = 0; c < 3; c++) out->at[c] = xyz[3 * k + c];
            }
        }
    }
    free(xyz), free(face), free(to_b), free(to_a);
    return rc;
}

double m2m_dense_point(const double w[3], const hd_mesh_t *M, int threads, hd_error_t *err) {
    hd_options_t opt;
    hd_options_init(&opt);
    opt.threads = threads;
    hd_points_t P = hd_points_f64(w, 1);
    double d;
    return hd_mesh_distances(&P, M, &opt, &d, NULL, NULL, NULL, NULL, err) ? NAN : d;
}
