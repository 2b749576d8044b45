/*
 * signed_bench.c -- the cost of the sign (hd_mesh_signed_distances) on a
 * closed torus mesh of 2 NU NV triangles (gen_torus_mesh) against N points,
 * one thread: the closedness check and the winding tree (hd__solid_build),
 * the winding number per point (hd__solid_winding), and the whole call
 * beside hd_mesh_distances.  Two clouds: "box", uniform in the torus's box
 * grown by a fifth, and "near", on the smooth torus with a normal offset of
 * up to 10^-3 of the minor radius.  CPU seconds of this process, medians.
 *
 * usage: signed_bench N NU NV [REPEATS] [box|near|both]
 */
#include "benchutil.h"
#include "gen.h"
#include "mesh/mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define R_MAJOR 1.0
#define R_MINOR 0.4

static void cloud(int near, size_t n, double *p) {
    gen_rng_t r;
    gen_seed(&r, near ? 2 : 1);
    if (!near) {
        for (size_t i = 0; i < n; i++) {
            double *q = p + 3 * i;
            q[0] = 1.2 * (R_MAJOR + R_MINOR) * (2 * gen_unit(&r) - 1);
            q[1] = 1.2 * (R_MAJOR + R_MINOR) * (2 * gen_unit(&r) - 1);
            q[2] = 1.2 * R_MINOR * (2 * gen_unit(&r) - 1);
        }
        return;
    }
    gen_torus(&r, p, n, R_MAJOR, R_MINOR);
    for (size_t i = 0; i < n; i++) { /* along the tube's normal */
        double *q = p + 3 * i, rho = hypot(q[0], q[1]), c[3] = {q[0] / rho * R_MAJOR, q[1] / rho * R_MAJOR, 0};
        double off = 1e-3 * R_MINOR * (2 * gen_unit(&r) - 1);
        for (int k = 0; k < 3; k++) q[k] += off * (q[k] - c[k]) / R_MINOR;
    }
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: signed_bench N NU NV [REPEATS] [box|near|both]\n");
        return 2;
    }
    size_t n = (size_t)atof(argv[1]);
    int nu = atoi(argv[2]), nv = atoi(argv[3]), reps = argc > 4 ? atoi(argv[4]) : 3;
    const char *which = argc > 5 ? argv[5] : "both";
    double *v;
    uint64_t *t;
    gen_torus_mesh(R_MAJOR, R_MINOR, nu, nv, &v, &t);
    size_t nt = 2 * (size_t)nu * (size_t)nv;
    hd__wtri_t *w = malloc(nt * sizeof *w);
    for (size_t k = 0; k < nt; k++)
        for (int j = 0; j < 3; j++) {
            w[k].vi[j] = t[3 * k + j];
            memcpy(w[k].v[j], v + 3 * t[3 * k + j], sizeof w[k].v[j]);
        }
    double *p = malloc(3 * n * sizeof *p), *d = malloc(n * sizeof *d);
    int8_t *s = malloc(n);
    double *build = malloc((size_t)reps * sizeof *build), *wind = malloc((size_t)reps * sizeof *wind),
           *plain = malloc((size_t)reps * sizeof *plain), *sgn = malloc((size_t)reps * sizeof *sgn);
    hd_mesh_t M = {hd_points_f64(v, (size_t)nu * (size_t)nv), t, nt, HD_INDEX_U64};
    hd_options_t opt;
    hd_options_init(&opt);
    opt.threads = 1;
    hd_error_t err;
    for (int near = 0; near <= 1; near++) {
        if (strcmp(which, "both") && strcmp(which, near ? "near" : "box")) continue;
        cloud(near, n, p);
        hd_points_t P = hd_points_f64(p, n);
        long inside = 0;
        for (int r = 0; r < reps; r++) {
            double c0 = bench_cpu_now();
            hd__solid_t *S;
            if (hd__solid_build(&S, w, nt, &err)) {
                fprintf(stderr, "%s\n", err.message);
                return 1;
            }
            double c1 = bench_cpu_now();
            inside = 0;
            for (size_t i = 0; i < n; i++) {
                int on;
                inside += hd__solid_winding(S, p + 3 * i, &on) != 0;
            }
            double c2 = bench_cpu_now();
            hd__solid_free(S);
            build[r] = c1 - c0, wind[r] = c2 - c1;
            c0 = bench_cpu_now();
            if (hd_mesh_distances(&P, &M, &opt, d, NULL, NULL, NULL, NULL, &err)) return 1;
            c1 = bench_cpu_now();
            if (hd_mesh_signed_distances(&P, &M, &opt, d, NULL, NULL, NULL, s, NULL, &err)) return 1;
            c2 = bench_cpu_now();
            plain[r] = c1 - c0, sgn[r] = c2 - c1;
        }
        printf("%s cloud, %zu points, torus of %zu triangles, 1 thread, CPU medians of %d: "
               "check + winding tree %.1f ms (%.0f ns a triangle); winding number %.0f ns a point "
               "(%ld inside); hd_mesh_distances %.0f ns a point, hd_mesh_signed_distances %.0f ns a point\n",
               near ? "near" : "box", n, nt, reps, 1e3 * bench_median(build, reps),
               1e9 * bench_median(build, reps) / (double)nt, 1e9 * bench_median(wind, reps) / (double)n, inside,
               1e9 * bench_median(plain, reps) / (double)n, 1e9 * bench_median(sgn, reps) / (double)n);
    }
    free(v), free(t), free(w), free(p), free(d), free(s), free(build), free(wind), free(plain), free(sgn);
    return 0;
}
