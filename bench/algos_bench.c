/*
 * algos_bench.c -- times the paper's algorithms on two seeded Gaussian pairs
 * (docs/algorithms.md, "Measurements").
 *
 * Pair "overlapping": A and B both ~ N(0, I), drawn with different seeds.
 * Pair "disjoint":    A ~ N(0, I), B ~ N((20, 0, 0), I), so the bounding
 *                     boxes are apart and the framework picks NOHD.
 * Pair "identical":   B is a copy of A (h = 0: nothing can be pruned
 *                     strictly); only run when asked for with --pairs.
 * For each algorithm, hd_hausdorff (both directions) is run --runs times and
 * the median wall-clock time of the call is printed, with the counters of
 * the last run summed over both directions.  NAIVEHDD does |A||B| distances
 * per direction, so it runs only --naive-runs times.  Every run's distance
 * must equal the first algorithm's bit for bit, or the program fails.
 *
 * usage: algos_bench [--n N] [--runs R] [--naive-runs K] [--threads T]
 *                    [--algorithms a,b,...] [--pairs overlapping,disjoint,identical]
 * Defaults: N = 100000, R = 5, K = 1, T = 1, every algorithm, both pairs.
 * Output: one markdown table row per (pair, algorithm).
 */
#include "benchutil.h"
#include "gen.h"

#include <hausdorff.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

int main(int argc, char **argv) {
    size_t n = 100000;
    int runs = 5, naive_runs = 1, threads = 1;
    const char *algs = NULL, *pairs = NULL;
    for (int k = 1; k < argc; k++) {
        const char *v = k + 1 < argc ? argv[k + 1] : NULL;
        if (!strcmp(argv[k], "--n") && v) n = (size_t)strtoull(v, NULL, 10), k++;
        else if (!strcmp(argv[k], "--runs") && v) runs = atoi(v), k++;
        else if (!strcmp(argv[k], "--naive-runs") && v) naive_runs = atoi(v), k++;
        else if (!strcmp(argv[k], "--threads") && v) threads = atoi(v), k++;
        else if (!strcmp(argv[k], "--algorithms") && v) algs = v, k++;
        else if (!strcmp(argv[k], "--pairs") && v) pairs = v, k++;
        else {
            fprintf(stderr, "usage: %s [--n N] [--runs R] [--naive-runs K] [--threads T] "
                            "[--algorithms a,b] [--pairs overlapping,disjoint,identical]\n", argv[0]);
            return 2;
        }
    }
    if (n == 0 || runs < 1 || naive_runs < 1 || threads < 0) {
        fprintf(stderr, "algos_bench: bad arguments\n");
        return 2;
    }
    double *a = malloc(3 * n * sizeof *a), *b = malloc(3 * n * sizeof *b);
    double *times = malloc((size_t)(runs > naive_runs ? runs : naive_runs) * sizeof *times);
    if (!a || !b || !times) {
        fprintf(stderr, "algos_bench: out of memory\n");
        return 1;
    }
    static const hd_algorithm_t order[] = {HD_ALG_NAIVE, HD_ALG_EARLYBREAK, HD_ALG_INC,
                                           HD_ALG_NOHD,  HD_ALG_OHD,        HD_ALG_FRAMEWORK,
                                           HD_ALG_KDTREE, HD_ALG_AUTO};
    static const char *const pair_names[] = {"overlapping", "disjoint", "identical"};
    printf("| pair | algorithm (ran) | median s | runs | H | distance evals | nodes visited "
           "| points culled |\n");
    printf("| --- | --- | ---: | ---: | --- | ---: | ---: | ---: |\n");
    int status = 0;
    for (int p = 0; p < 3; p++) {
        /* "identical" runs only when named. */
        if (p == 2 ? !pairs || !bench_listed(pairs, pair_names[p]) : !bench_listed(pairs, pair_names[p]))
            continue;
        gen_rng_t g;
        double m0[3] = {0, 0, 0}, m1[3] = {p ? 20.0 : 0.0, 0, 0};
        gen_seed(&g, 2017 + (uint64_t)p);
        gen_gauss(&g, a, n, m0, 1.0);
        if (p == 2) memcpy(b, a, 3 * n * sizeof *b);
        else gen_gauss(&g, b, n, m1, 1.0);
        hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
        double reference = -1.0;
        for (size_t k = 0; k < sizeof order / sizeof order[0]; k++) {
            const char *name = hd_algorithm_name(order[k]);
            if (!bench_listed(algs, name)) continue;
            hd_options_t o;
            hd_options_init(&o);
            o.algorithm = order[k];
            o.threads = threads;
            int r_count = order[k] == HD_ALG_NAIVE ? naive_runs : runs;
            hd_symmetric_t s;
            hd_error_t e;
            for (int r = 0; r < r_count; r++) {
                double t0 = bench_now();
                if (hd_hausdorff(&A, &B, &o, &s, &e) != HD_OK) {
                    fprintf(stderr, "algos_bench: %s: %s\n", name, e.message);
                    return 1;
                }
                times[r] = bench_now() - t0;
                if (reference < 0) reference = s.distance;
                if (s.distance != reference) {
                    fprintf(stderr, "algos_bench: %s gave %.17g, expected %.17g\n", name,
                            s.distance, reference);
                    status = 1;
                }
            }
            double med = bench_median(times, r_count);
            char ran[64];
            const char *ra = hd_algorithm_name(s.ab.algorithm), *rb = hd_algorithm_name(s.ba.algorithm);
            if (s.ab.algorithm == s.ba.algorithm) snprintf(ran, sizeof ran, "%s", ra);
            else snprintf(ran, sizeof ran, "%s/%s", ra, rb);
            printf("| %s %zuK/%zuK | %s (%s) | %.3f | %d | %.17g | %llu | %llu | %llu |\n",
                   pair_names[p], n / 1000, n / 1000, name, ran, med, r_count, s.distance,
                   (unsigned long long)(s.ab.stats.distance_evals + s.ba.stats.distance_evals),
                   (unsigned long long)(s.ab.stats.nodes_visited + s.ba.stats.nodes_visited),
                   (unsigned long long)(s.ab.stats.points_culled + s.ba.stats.points_culled));
            fflush(stdout);
        }
    }
    free(a);
    free(b);
    free(times);
    return status;
}
