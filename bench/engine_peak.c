/*
 * engine_peak.c -- the default engine's memory peak and time on one
 * process, call after call (docs/benchmarks.md, "The engine's quantised
 * copies in one block"):
 *     build/bench/engine_peak [--points N] [--other M] [--calls R]
 *                             [--copy] [--threads T] [--seed S]
 * A: N points uniform in the unit cube; B: M (default N) more, or with
 * --copy A moved by noise of 1e-5 and shuffled (a copy in another order:
 * the tree path).  Each of R calls of hd_hausdorff prints its wall time,
 * the engine's peak (stats.peak_bytes) per point of A + B, the distance
 * and h(A,B)'s witness.  The engine frees everything between calls, so every
 * call maps its memory afresh, as a process that computes one distance
 * does.
 *
 * Comparing two builds on this machine (2 virtual cores): run them
 * alternately, one process each, and pin them to one core (taskset -c 1):
 * while the host slowed one core (an hour on 2026-11-29), the same
 * unpinned process took 33 or 49 ms by the core it landed on, which hides
 * differences of a few per cent.
 */
#include <hausdorff.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "benchutil.h"
#include "gen.h"

int main(int argc, char **argv) {
    size_t n = 250000, m = 0;
    int calls = 5, copy = 0, threads = 1;
    uint64_t seed = 1;
    for (int k = 1; k < argc; k++) {
        const char *a = argv[k];
        if (strcmp(a, "--copy") == 0) copy = 1;
        else if (k + 1 < argc && strcmp(a, "--points") == 0) n = strtoull(argv[++k], NULL, 10);
        else if (k + 1 < argc && strcmp(a, "--other") == 0) m = strtoull(argv[++k], NULL, 10);
        else if (k + 1 < argc && strcmp(a, "--calls") == 0) calls = atoi(argv[++k]);
        else if (k + 1 < argc && strcmp(a, "--threads") == 0) threads = atoi(argv[++k]);
        else if (k + 1 < argc && strcmp(a, "--seed") == 0) seed = strtoull(argv[++k], NULL, 10);
        else {
            fprintf(stderr, "engine_peak: unknown argument %s\n", a);
            return 2;
        }
    }
    if (m == 0 || copy) m = n;
    if (n == 0 || calls < 1) {
        fprintf(stderr, "engine_peak: --points and --calls must be positive\n");
        return 2;
    }
    double *a = malloc(3 * n * sizeof *a), *b = malloc(3 * m * sizeof *b);
    if (!a || !b) {
        fprintf(stderr, "engine_peak: out of memory\n");
        return 1;
    }
    gen_rng_t g;
    gen_seed(&g, seed);
    gen_cube(&g, a, n, 0, 1);
    if (copy) {
        for (size_t k = 0; k < 3 * n; k++) b[k] = a[k] + (gen_unit(&g) - 0.5) * 1e-5;
        for (size_t k = n - 1; k > 0; k--) gen_swap(b, k, (size_t)(gen_u64(&g) % (k + 1)));
    } else {
        gen_cube(&g, b, m, 0, 1);
    }
    hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, m);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    printf("# engine_peak: %zu + %zu points, %s, %d thread(s), seed %llu\n# call  ms  peak_B/pt  H  i(AB)  j(AB)\n", n, m,
           copy ? "shuffled copy" : "uniform", threads, (unsigned long long)seed);
    for (int r = 0; r < calls; r++) {
        hd_symmetric_t s;
        hd_error_t e;
        double t0 = bench_now();
        if (hd_hausdorff(&A, &B, &o, &s, &e) != HD_OK) {
            fprintf(stderr, "engine_peak: %s\n", e.message);
            return 1;
        }
        double t1 = bench_now();
        printf("%d %.3f %.3f %.17g %zu %zu\n", r, (t1 - t0) * 1e3, (double)s.ab.stats.peak_bytes / (double)(n + m),
               s.distance, s.ab.i, s.ab.j);
    }
    free(a);
    free(b);
    return 0;
}
