/*
 * field_histogram_bench.c -- histograms of the per-point distances from
 * bounds (hd_hausdorff_histogram) against every distance then hd_histogram
 * (docs/benchmarks.md, "Histograms without every distance").
 *
 * The five cases of issue 39 (bench/support/field_cases.h), the range
 * [0, H] as `hausdorff --histogram` takes it (H from hd_hausdorff, not
 * timed).  For each, median of RUNS alternated runs at THREADS threads:
 *   all     hd_distances (both directions, no indices) then hd_histogram twice
 *   bounds  hd_hausdorff_histogram
 * and it checks that both give the same counts.  CASE (a-e) runs one case
 * only, as a callgrind run wants (--toggle-collect=hd_distances and
 * hd_histogram, or hd_hausdorff_histogram).
 *
 * usage: field_histogram_bench [N] [RUNS] [THREADS] [BINS] [CASE]
 *        (default 1000000 5 1 20, every case)
 */
#include "benchutil.h"
#include "field_cases.h"

#include <hausdorff.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv) {
    size_t n = argc > 1 ? (size_t)atof(argv[1]) : 1000000, bins = argc > 4 ? (size_t)atof(argv[4]) : 20;
    int runs = argc > 2 ? atoi(argv[2]) : 5, threads = argc > 3 ? atoi(argv[3]) : 1;
    int only = argc > 5 ? argv[5][0] - 'a' : -1;
    if (runs < 1 || runs > 50) runs = 5;
    if (bins < 1) bins = 20;
    double *a = malloc(24 * n), *b = malloc(24 * n), *dab = malloc(8 * n), *dba = malloc(8 * n);
    uint64_t *want = malloc(16 * bins), *got = malloc(16 * bins);
    if (!a || !b || !dab || !dba || !want || !got) return 1;
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    hd_error_t err;
    printf("| case | |A| | |B| | bins | all + hd_histogram | bounds | all / bounds |\n|---|---|---|---|---|---|---|\n");
    for (int c = 0; c < FIELD_CASES; c++) {
        if (only >= 0 && c != only) continue;
        size_t nb;
        field_case(c, n, a, b, &nb);
        hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, nb);
        hd_symmetric_t s;
        if (hd_hausdorff(&A, &B, &o, &s, &err)) goto fail;
        double hi = s.distance, ta[50], tb[50];
        for (int r = 0; r < runs; r++) {
            double t0 = bench_now();
            if (hd_distances(&A, &B, &o, dab, NULL, dba, NULL, &err) ||
                hd_histogram(dab, n, 0.0, hi, bins, want, &err) ||
                hd_histogram(dba, nb, 0.0, hi, bins, want + bins, &err))
                goto fail;
            ta[r] = bench_now() - t0;
            t0 = bench_now();
            if (hd_hausdorff_histogram(&A, &B, &o, bins, 0.0, hi, got, got + bins, &err)) goto fail;
            tb[r] = bench_now() - t0;
            if (memcmp(want, got, 16 * bins)) {
                fprintf(stderr, "%s: the counts differ\n", field_case_names[c]);
                return 2;
            }
        }
        double ma = bench_median(ta, runs), mb = bench_median(tb, runs);
        printf("| %s | %zu | %zu | %zu | %.4f s | %.4f s | %.1fx |\n", field_case_names[c], n, nb, bins, ma, mb,
               ma / mb);
        fflush(stdout);
    }
    free(a), free(b), free(dab), free(dba), free(want), free(got);
    return 0;
fail:
    fprintf(stderr, "field_histogram_bench: %s\n", err.message);
    return 1;
}
