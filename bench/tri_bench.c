/*
 * tri_bench.c -- what one point-to-triangle distance costs (src/mesh/): the
 * kernel (fast path with its exact fallback) and the exact path alone, on
 * seeded cases of three kinds: corners of a unit cube's worth of random
 * triangles and points (most answers at a corner or an edge), points near
 * the face (offsets of 1e-3 of the triangle's size: the face region), and
 * points near an edge (the same offsets, off the plane too).  CPU time of
 * this thread, median of R runs of N calls, for the kernel, the exact path
 * alone (on N/20 calls), the plain-double bounds (hd__tri_bounds) and the
 * same from prepared triangles (hd__tri_bounds_prep, the preparation not
 * counted), both over the first HOT cases again and again, as a search
 * meets its triangles in cache; the share of calls the exact path decided.
 * KIND (0, 1 or 2) runs one kind only (for instruction counts under
 * callgrind).
 *
 *     build/bench/tri_bench [N [R [KIND]]]
 */
#include "benchutil.h"
#include "gen.h"
#include "mesh/mesh.h"

#include <stdio.h>
#include <stdlib.h>

enum { K_RANDOM, K_NEAR_FACE, K_NEAR_EDGE, K_COUNT };
enum { HOT = 4096 };
static const char *const kind_name[K_COUNT] = {"random", "near face (1e-3)", "near edge (1e-3)"};

static void make(gen_rng_t *g, int kind, double *v) {
    for (int i = 0; i < 12; i++) v[i] = gen_unit(g) * 2 - 1;
    double *p = v, *a = v + 3, *b = v + 6, *c = v + 9;
    double s = gen_unit(g), t = gen_unit(g) * (1 - s), h = 1e-3 * (gen_unit(g) - 0.5);
    double n[3] = {(b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]),
                   (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]),
                   (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])};
    if (kind == K_NEAR_FACE)
        for (int i = 0; i < 3; i++) p[i] = a[i] + s * (b[i] - a[i]) + t * (c[i] - a[i]) + h * n[i];
    double w = 1e-3 * (gen_unit(g) - 0.5);      /* off the face's boundary plane too */
    if (kind == K_NEAR_EDGE)
        for (int i = 0; i < 3; i++) p[i] = a[i] + s * (b[i] - a[i]) + h * n[i] + w * (c[i] - a[i]);
}

int main(int argc, char **argv) {
    size_t n = argc > 1 ? (size_t)atol(argv[1]) : 1000000;
    int runs = argc > 2 ? atoi(argv[2]) : 5, only = argc > 3 ? atoi(argv[3]) : -1;
    double *v = malloc(n * 12 * sizeof *v), *fast = malloc((size_t)runs * sizeof *fast),
           *exact = malloc((size_t)runs * sizeof *exact), *bnd = malloc((size_t)runs * sizeof *bnd),
           *pbnd = malloc((size_t)runs * sizeof *pbnd);
    size_t hot = n < HOT ? n : HOT;
    hd__tri_prep_t *prep = malloc(hot * sizeof *prep);
    if (!v || !fast || !exact || !bnd || !pbnd || !prep || runs < 1) return 1;
    printf("| kind | calls | kernel, ns a call | exact path alone, ns a call | bounds, ns a call "
           "| prepared bounds, ns a call | exact path decided |\n");
    printf("|---|---|---|---|---|---|---|\n");
    for (int k = 0; k < K_COUNT; k++) {
        if (only >= 0 && k != only) continue;
        gen_rng_t g;
        gen_seed(&g, 42 + (uint64_t)k);
        for (size_t i = 0; i < n; i++) {
            make(&g, k, v + 12 * i);
            if (i < hot) hd__tri_prep(v + 12 * i + 3, v + 12 * i + 6, v + 12 * i + 9, &prep[i]);
        }
        size_t fallback = 0, ne = n / 20 ? n / 20 : 1;
        double sink = 0;
        for (int r = 0; r < runs; r++) {
            hd__tri_near_t o;
            double t0 = bench_cpu_now();
            fallback = 0;
            for (size_t i = 0; i < n; i++) {
                const double *c = v + 12 * i;
                hd__tri_nearest(c, c + 3, c + 6, c + 9, &o);
                fallback += (size_t)o.exact;
                sink += o.d;
            }
            double t1 = bench_cpu_now();
            for (size_t i = 0; i < ne; i++) {
                const double *c = v + 12 * i;
                hd__tri_nearest_exact(c, c + 3, c + 6, c + 9, &o);
                sink += o.d;
            }
            double t2 = bench_cpu_now();
            for (size_t i = 0, j = 0; i < n; i++, j = j + 1 < hot ? j + 1 : 0) {
                const double *c = v + 12 * j;
                double lo2, hi2;
                hd__tri_bounds(c, c + 3, c + 6, c + 9, &lo2, &hi2);
                sink += lo2 + hi2;
            }
            double t3 = bench_cpu_now();
            for (size_t i = 0, j = 0; i < n; i++, j = j + 1 < hot ? j + 1 : 0) {
                double lo2, hi2;
                hd__tri_bounds_prep(v + 12 * j, &prep[j], &lo2, &hi2);
                sink += lo2 + hi2;
            }
            fast[r] = (t1 - t0) / (double)n * 1e9;
            exact[r] = (t2 - t1) / (double)ne * 1e9;
            bnd[r] = (t3 - t2) / (double)n * 1e9;
            pbnd[r] = (bench_cpu_now() - t3) / (double)n * 1e9;
        }
        printf("| %s | %zu | %.0f | %.0f | %.0f | %.0f | %.3f %% |\n", kind_name[k], n,
               bench_median(fast, runs), bench_median(exact, runs), bench_median(bnd, runs),
               bench_median(pbnd, runs), 100.0 * (double)fallback / (double)n);
        if (sink < 0) return 1;
    }
    free(v); free(fast); free(exact); free(bnd); free(pbnd); free(prep);
    return 0;
}
