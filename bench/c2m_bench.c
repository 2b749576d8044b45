/*
 * c2m_bench -- times hd_mesh_distances (cloud to mesh) on a mesh file,
 * optionally subdivided, against near and far query clouds.
 *
 *   c2m_bench MESH LEVELS N near|far THREADS [REPEATS] [OUT.bin]
 *             [--perturb] [--check K] [--json]
 *
 * LEVELS: each triangle is split into four (edge midpoints) that many
 * times; --perturb moves each new midpoint by up to 1 % of its edge's
 * length in a direction drawn from its own bits (so the two triangles of
 * an edge move it alike: no cracks, and no longer coplanar).  --check K:
 * K points spread over the cloud are also answered by a brute force over
 * every triangle with the same kernel, and the answers compared (distance
 * bits and triangle).  --json: one JSON object instead of the text line.  near: points uniform by area on the surface plus uniform noise
 * of 1e-3 of the box's diagonal; far: uniform in the box grown three times
 * about its centre.  Seeded (seed 1).  Prints the triangle count, the
 * median wall time of REPEATS calls (tree build included) and their median
 * processor time (all threads: on a loaded host the steadier figure), the
 * counters, and
 * writes the query points and distances to OUT.bin when given (for the
 * peers' comparison: n, then 3n doubles of points, then n distances).
 */
#include "benchutil.h"
#include "mesh/mesh.h"

#include <hausdorff.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static uint64_t rng = 0x9e3779b97f4a7c15u;
static double unit(void) {
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (double)(rng >> 11) * 0x1p-53;
}

typedef struct {
    double *v;
    uint64_t *t;
    size_t nv, nt;
} mesh_t;

/* A value in [-0.5, 0.5) from the bits of a point and a salt. */
static double jitter(const double *x, int salt) {
    uint64_t h = 0x9e3779b97f4a7c15u * (uint64_t)(salt + 1);
    for (int c = 0; c < 3; c++) {
        uint64_t b;
        memcpy(&b, &x[c], sizeof b);
        h ^= b + 0x9e3779b97f4a7c15u + (h << 6) + (h >> 2);
        h *= 0xff51afd7ed558ccdu;
    }
    h ^= h >> 33;
    return (double)(h >> 11) * 0x1p-53 - 0.5;
}

static void subdivide(mesh_t *m, int perturb) {
    double *v = malloc((m->nv + 3 * m->nt) * 3 * sizeof *v);
    uint64_t *t = malloc(12 * m->nt * sizeof *t);
    memcpy(v, m->v, 3 * m->nv * sizeof *v);
    size_t nv = m->nv;
    for (size_t k = 0; k < m->nt; k++) {
        const uint64_t *f = m->t + 3 * k;
        uint64_t mid[3];
        for (int e = 0; e < 3; e++) {
            const double *a = m->v + 3 * f[e], *b = m->v + 3 * f[(e + 1) % 3];
            double *o = v + 3 * nv, len = 0;
            for (int c = 0; c < 3; c++) o[c] = (a[c] + b[c]) / 2, len += (b[c] - a[c]) * (b[c] - a[c]);
            if (perturb) {
                double mid[3] = {o[0], o[1], o[2]};
                for (int c = 0; c < 3; c++) o[c] += 0.02 * sqrt(len) * jitter(mid, c);
            }
            mid[e] = nv++;
        }
        uint64_t q[12] = {f[0], mid[0], mid[2], mid[0], f[1], mid[1], mid[2], mid[1], f[2], mid[0], mid[1], mid[2]};
        memcpy(t + 12 * k, q, sizeof q);
    }
    free(m->v), free(m->t);
    m->v = v, m->t = t, m->nv = nv, m->nt *= 4;
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The brute force over every triangle for k points spread over the cloud:
 * the number of points whose distance bits or triangle differ. */
static size_t brute_check(const mesh_t *m, const double *p, size_t n, const double *d, const size_t *tri, size_t k) {
    size_t bad = 0;
    for (size_t j = 0; j < k && j < n; j++) {
        size_t i = k >= n ? j : j * (n / k);
        double best = INFINITY;
        size_t bt = 0;
        for (size_t t = 0; t < m->nt; t++) {
            hd__tri_near_t r;
            const uint64_t *f = m->t + 3 * t;
            hd__tri_nearest(p + 3 * i, m->v + 3 * f[0], m->v + 3 * f[1], m->v + 3 * f[2], &r);
            if (r.d < best) best = r.d, bt = t;
        }
        bad += memcmp(&best, &d[i], sizeof best) != 0 || bt != tri[i];
    }
    return bad;
}

int main(int argc, char **argv) {
    int perturb = 0, json = 0;
    size_t check = 0;
    char *pos[8];
    int np = 0;
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--perturb") == 0) perturb = 1;
        else if (strcmp(argv[a], "--json") == 0) json = 1;
        else if (strcmp(argv[a], "--check") == 0 && a + 1 < argc) check = (size_t)atof(argv[++a]);
        else if (np < 8) pos[np++] = argv[a];
    }
    if (np < 5) {
        fprintf(stderr, "usage: c2m_bench MESH LEVELS N near|far THREADS [REPEATS] [OUT.bin] [--perturb] "
                        "[--check K] [--json]\n");
        return 2;
    }
    argc = np + 1;
    argv = pos - 1;
    hd_mesh_file_t *f;
    hd_error_t err;
    if (hd_read_mesh(argv[1], NULL, &f, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    mesh_t m = {malloc(3 * f->n_vertices * sizeof(double)), malloc(3 * f->n_triangles * sizeof(uint64_t)),
                f->n_vertices, f->n_triangles};
    memcpy(m.v, f->vertices, 3 * m.nv * sizeof(double));
    memcpy(m.t, f->triangles, 3 * m.nt * sizeof(uint64_t));
    hd_mesh_file_free(f);
    for (int l = atoi(argv[2]); l > 0; l--) subdivide(&m, perturb);
    size_t n = (size_t)atof(argv[3]);
    int far = strcmp(argv[4], "far") == 0, threads = atoi(argv[5]), reps = argc > 6 ? atoi(argv[6]) : 3;
    double lo[3], hi[3];
    for (int c = 0; c < 3; c++) lo[c] = hi[c] = m.v[c];
    for (size_t k = 0; k < m.nv; k++)
        for (int c = 0; c < 3; c++) lo[c] = fmin(lo[c], m.v[3 * k + c]), hi[c] = fmax(hi[c], m.v[3 * k + c]);
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    double *cum = malloc(m.nt * sizeof *cum), total = 0;
    for (size_t k = 0; k < m.nt; k++) {
        const double *a = m.v + 3 * m.t[3 * k], *b = m.v + 3 * m.t[3 * k + 1], *c = m.v + 3 * m.t[3 * k + 2];
        double u[3], w[3];
        for (int i = 0; i < 3; i++) u[i] = b[i] - a[i], w[i] = c[i] - a[i];
        double x = u[1] * w[2] - u[2] * w[1], y = u[2] * w[0] - u[0] * w[2], z = u[0] * w[1] - u[1] * w[0];
        total += sqrt(x * x + y * y + z * z);
        cum[k] = total;
    }
    double *p = malloc(3 * n * sizeof *p);
    for (size_t i = 0; i < n; i++) {
        if (far) {
            for (int c = 0; c < 3; c++) p[3 * i + c] = lo[c] - (hi[c] - lo[c]) + 3 * (hi[c] - lo[c]) * unit();
            continue;
        }
        double x = unit() * total;
        size_t a = 0, b = m.nt - 1;
        while (a < b) {
            size_t mid = (a + b) / 2;
            if (cum[mid] > x) b = mid;
            else a = mid + 1;
        }
        double su = sqrt(unit()), v = unit();
        const uint64_t *t = m.t + 3 * a;
        for (int c = 0; c < 3; c++)
            p[3 * i + c] = (1 - su) * m.v[3 * t[0] + c] + su * (1 - v) * m.v[3 * t[1] + c] +
                           su * v * m.v[3 * t[2] + c] + 1e-3 * diag * (unit() - 0.5);
    }
    hd_points_t P = hd_points_f64(p, n);
    hd_mesh_t M = {hd_points_f64(m.v, m.nv), m.t, m.nt, HD_INDEX_U64};
    hd_options_t opt;
    hd_options_init(&opt);
    opt.threads = threads;
    double *d = malloc(n * sizeof *d), *times = malloc((size_t)reps * sizeof *times);
    double *cpu = malloc((size_t)reps * sizeof *cpu);
    size_t *tri = malloc(n * sizeof *tri);
    hd_surface_result_t r;
    for (int k = 0; k < reps; k++) {
        clock_t c0 = clock();
        if (hd_mesh_distances(&P, &M, &opt, d, tri, NULL, NULL, &r, &err)) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        times[k] = r.seconds;
        cpu[k] = (double)(clock() - c0) / CLOCKS_PER_SEC;
    }
    qsort(times, (size_t)reps, sizeof *times, cmp_double);
    qsort(cpu, (size_t)reps, sizeof *cpu, cmp_double);
    size_t bad = check ? brute_check(&m, p, n, d, tri, check) : 0;
    double fn = (double)n;
    if (json)
        printf("{\"mesh\": \"%s\", \"levels\": %s, \"perturb\": %d, \"triangles\": %zu, \"points\": %zu, "
               "\"cloud\": \"%s\", \"threads\": %d, \"runs\": %d, \"wall\": %.6g, \"cpu\": %.6g, "
               "\"h\": %.17g, \"kernel\": %.4g, \"exact\": %llu, \"bounded\": %.4g, \"nodes\": %.4g, "
               "\"checked\": %zu, \"check_differ\": %zu}\n",
               argv[1], argv[2], perturb, m.nt, n, far ? "far" : "near", threads, reps, times[reps / 2], cpu[reps / 2],
               r.distance, (double)r.kernel_calls / fn, (unsigned long long)r.exact_calls,
               (double)r.triangles_bounded / fn, (double)r.nodes_visited / fn, check < n ? check : n, bad);
    else
        printf("%s levels %s: %zu triangles, %zu %s points, %d threads: median %.3f s of %d (cpu %.3f s); "
               "h = %.17g; kernel %.2f a point (exact %llu), bounded %.1f, nodes %.1f%s\n",
               argv[1], argv[2], m.nt, n, far ? "far" : "near", threads, times[reps / 2], reps, cpu[reps / 2],
               r.distance, (double)r.kernel_calls / fn, (unsigned long long)r.exact_calls,
               (double)r.triangles_bounded / fn, (double)r.nodes_visited / fn,
               check ? (bad ? "; BRUTE FORCE DIFFERS" : "; brute force agrees") : "");
    if (argc > 7) {
        FILE *o = fopen(argv[7], "wb");
        uint64_t nn = n;
        fwrite(&nn, sizeof nn, 1, o);
        fwrite(p, sizeof *p, 3 * n, o);
        fwrite(d, sizeof *d, n, o);
        uint64_t nv = m.nv, nt = m.nt;
        fwrite(&nv, sizeof nv, 1, o);
        fwrite(m.v, sizeof *m.v, 3 * m.nv, o);
        fwrite(&nt, sizeof nt, 1, o);
        fwrite(m.t, sizeof *m.t, 3 * m.nt, o);
        fclose(o);
    }
    free(p), free(d), free(tri), free(times), free(cpu), free(cum), free(m.v), free(m.t);
    return bad ? 1 : 0;
}
