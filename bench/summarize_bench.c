/*
 * summarize_bench.c -- what hd_summarize costs per value (docs/benchmarks.md,
 * "Analysis"): its sums are exact (base/xsum.c), and this measures them
 * against a plain loop over the same values in the same run (the memory
 * floor of reading them once).
 *
 * The values are n distances, half A->B and half B->A, drawn with a fixed
 * seed from |N(0, 1)| * 10^k with k uniform in [-3, 3] (magnitudes spread
 * over the accumulator's chunks, as distances of a scan at mm and m scales
 * are).  Median of RUNS runs; prints ns per value for hd_summarize (both
 * sums and both sums of squares of each value: four accumulations) and for
 * the plain loop (the same four sums, rounded at every step).
 *
 * usage: summarize_bench [N] [RUNS]   (default 10000000 5)
 */
#include "benchutil.h"

#include <hausdorff.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

static uint64_t next(uint64_t *s) { /* splitmix64 */
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static double unit(uint64_t *s) { return (double)(next(s) >> 11) * 0x1p-53; }

int main(int argc, char **argv) {
    size_t n = argc > 1 ? strtoull(argv[1], NULL, 10) : 10000000;
    int runs = argc > 2 ? atoi(argv[2]) : 5;
    if (n < 2 || runs < 1 || runs > 50) {
        fprintf(stderr, "usage: summarize_bench [N >= 2] [RUNS 1..50]\n");
        return 2;
    }
    double *d = malloc(n * sizeof *d);
    if (!d) {
        fprintf(stderr, "out of memory for %zu values\n", n);
        return 1;
    }
    uint64_t seed = 20261123;
    for (size_t k = 0; k < n; k++) {
        double u1 = unit(&seed) + 0x1p-60, u2 = unit(&seed);
        d[k] = fabs(sqrt(-2 * log(u1)) * cos(6.283185307179586 * u2)) * pow(10.0, floor(unit(&seed) * 7) - 3);
    }
    size_t na = n / 2, nb = n - na;
    double t_sum[50], t_loop[50], plain = 0;
    volatile double sink = 0; /* keeps every sum of the plain loop */
    hd_summary_t s;
    hd_error_t err;
    for (int r = 0; r < runs; r++) {
        double t0 = bench_now();
        if (hd_summarize(d, na, d + na, nb, &s, &err)) {
            fprintf(stderr, "hd_summarize: %s\n", err.message);
            return 1;
        }
        t_sum[r] = bench_now() - t0;
        t0 = bench_now();
        double p[4] = {0, 0, 0, 0};
        for (size_t k = 0; k < na; k++) p[0] += d[k], p[1] += d[k] * d[k];
        for (size_t k = na; k < n; k++) p[2] += d[k], p[3] += d[k] * d[k];
        t_loop[r] = bench_now() - t0;
        plain = p[0];
        sink += p[1] + p[2] + p[3];
    }
    printf("n = %zu, %d runs (median): hd_summarize %.2f ns/value, plain loop %.2f ns/value "
           "(sum_ab %.17g, plain %.17g)\n",
           n, runs, 1e9 * bench_median(t_sum, runs) / (double)n, 1e9 * bench_median(t_loop, runs) / (double)n,
           s.sum_ab, plain);
    free(d);
    return 0;
}
