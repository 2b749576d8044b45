/*
 * percentile_bench.c -- percentile Hausdorff distances (HD95) without every
 * distance, against every distance then a selection (docs/benchmarks.md,
 * "Percentiles").
 *
 * The five cases of issue 39 (bench/support/field_cases.h).
 * For each, median of RUNS alternated runs at THREADS threads:
 *   H       hd_hausdorff (auto engine): the Hausdorff distance alone
 *   all     hd_distances (both directions, no indices) then hd_percentile_of
 *   band    hd_hausdorff_percentile (the bands of nearest/percentile.c)
 * and it checks that "all" and "band" give the same four figures to the
 * bit.  With --write DIR it also writes each case as DIR/<case>_A.bin and
 * _B.bin (raw float64 triples) for the peer programs
 * (bench/peers/nanoflann_hd: tree + 1-NN of every point, both directions).
 *
 * With --case NAME only that case runs; with --band-only only "band" runs
 * (no check), so that a callgrind run (--toggle-collect=
 * hd_hausdorff_percentile) spends its time on the call it measures.
 *
 * usage: percentile_bench [N] [RUNS] [THREADS] [P] [--write DIR] [--case NAME] [--band-only]
 *        (default 1000000 5 1 95)
 */
#include "benchutil.h"
#include "field_cases.h"

#include <hausdorff.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int same_bits(double x, double y) { return memcmp(&x, &y, sizeof x) == 0; }

static int write_bin(const char *dir, const char *name, const char *side, const double *p, size_t n) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s_%s.bin", dir, name, side);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(p, 24, n, f) != n) return 1;
    return fclose(f) != 0;
}

int main(int argc, char **argv) {
    const char *dir = NULL, *only = NULL;
    int pos = 0, band_only = 0;
    double arg[4] = {1000000, 5, 1, 95};
    for (int k = 1; k < argc; k++) {
        if (!strcmp(argv[k], "--write") && k + 1 < argc) dir = argv[++k];
        else if (!strcmp(argv[k], "--case") && k + 1 < argc) only = argv[++k];
        else if (!strcmp(argv[k], "--band-only")) band_only = 1;
        else if (pos < 4) arg[pos++] = atof(argv[k]);
    }
    size_t n = (size_t)arg[0];
    int runs = (int)arg[1], threads = (int)arg[2];
    double p = arg[3];
    if (runs < 1 || runs > 50) runs = 5;
    double *a = malloc(24 * n), *b = malloc(24 * n), *dab = malloc(8 * n), *dba = malloc(8 * n);
    if (!a || !b || !dab || !dba) return 1;
    const char *const *cases = field_case_names;
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    hd_error_t err;
    printf("| case | |A| | |B| | H | all + selection | bands | all / bands | bands / H |\n|---|---|---|---|---|---|---|---|\n");
    for (int c = 0; c < FIELD_CASES; c++) {
        if (only && strcmp(only, cases[c])) continue;
        size_t nb;
        field_case(c, n, a, b, &nb);
        if (dir && (write_bin(dir, cases[c], "A", a, n) || write_bin(dir, cases[c], "B", b, nb))) {
            fprintf(stderr, "percentile_bench: cannot write %s\n", dir);
            return 1;
        }
        hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, nb);
        double th[50], ta[50], tb[50];
        for (int r = 0; r < runs; r++) {
            hd_symmetric_t s;
            hd_percentile_t pa, pb;
            double t0 = bench_now();
            th[r] = ta[r] = 0;
            if (!band_only) {
                if (hd_hausdorff(&A, &B, &o, &s, &err)) goto fail;
                th[r] = bench_now() - t0;
                t0 = bench_now();
                if (hd_distances(&A, &B, &o, dab, NULL, dba, NULL, &err) ||
                    hd_percentile_of(dab, n, dba, nb, p, &pa, &err))
                    goto fail;
                ta[r] = bench_now() - t0;
                t0 = bench_now();
            }
            if (hd_hausdorff_percentile(&A, &B, &o, p, &pb, &err)) goto fail;
            tb[r] = bench_now() - t0;
            if (!band_only && (!same_bits(pa.ab, pb.ab) || !same_bits(pa.ba, pb.ba) ||
                               !same_bits(pa.pooled, pb.pooled) || !same_bits(pa.symmetric, pb.symmetric))) {
                fprintf(stderr, "%s: the figures differ: %.17g %.17g %.17g / %.17g %.17g %.17g\n", cases[c], pa.ab,
                        pa.ba, pa.pooled, pb.ab, pb.ba, pb.pooled);
                return 2;
            }
        }
        double mh = bench_median(th, runs), ma = bench_median(ta, runs), mb = bench_median(tb, runs);
        if (band_only)
            printf("| %s | %zu | %zu | - | - | %.4f s | - | - |\n", cases[c], n, nb, mb);
        else
            printf("| %s | %zu | %zu | %.4f s | %.4f s | %.4f s | %.1fx | %.1fx |\n", cases[c], n, nb, mh, ma, mb,
                   ma / mb, mb / mh);
        fflush(stdout);
    }
    free(a), free(b), free(dab), free(dba);
    return 0;
fail:
    fprintf(stderr, "percentile_bench: %s\n", err.message);
    return 1;
}
