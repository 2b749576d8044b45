/*
 * field_bench.c -- the per-point distance field (every point's exact nearest
 * distance and index, both directions: hd_distances) on issue 39's cases
 * a-e (bench/support/field_cases.h), phase by phase (docs/benchmarks.md,
 * "Per-point work").
 *
 * For each case, median of RUNS runs at THREADS threads:
 *   H        hd_hausdorff (auto engine)
 *   field    hd_distances, both directions, distances and indices
 *   build    the two structures (hd__an_build_pair, after the validation)
 *   A->B     hd__an_nearest of A's points in B's structure
 *   B->A     the reverse
 * and it checks that the field's largest values equal H's to the bit.
 * With CASES (a comma-free string of case letters, "ad") only those run;
 * one run of one case under callgrind counts the instructions of each
 * phase (the bench is its own harness: the phases are separate calls).
 *
 * With --routes after CASES it also prints how each direction's queries
 * were answered (hd__an_counts_t: partners, window, far groups, solo, point
 * lists).  With --field instead, each run calls
 * hd_distances only (no H, no phases, no check), timed in processor
 * seconds (the process's, one thread: the load of other processes counts
 * little); one call under callgrind with --toggle-collect=hd_distances
 * counts just the field.
 *
 * usage: field_bench [N] [RUNS] [THREADS] [CASES] [--routes | --field]   (default 1000000 5 1 abcde)
 */
#include "benchutil.h"
#include "field_cases.h"
#include "nearest/nearest.h"

#include <hausdorff.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The process's processor time in seconds. */
static double cpu_now(void) {
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double max_of(const double *v, size_t n) {
    double m = 0;
    for (size_t k = 0; k < n; k++) m = v[k] > m ? v[k] : m;
    return m;
}

/* The phases of hd_distances, each timed: build, A->B, B->A. */
static int phases(const hd_points_t *A, const hd_points_t *B, int threads, double *dab, size_t *jab, double *dba,
                  size_t *jba, double t[3], hd__an_counts_t counts[2], hd_error_t *err) {
    hd__box_t ba, bb;
    threads = hd__thread_count(threads, A->count > B->count ? A->count : B->count);
    if (hd__points_scan(A, "A", threads, &ba, err) || hd__points_scan(B, "B", threads, &bb, err)) return 1;
    hd__box_merge(&ba, &bb);
    hd__an_t s[2];
    double t0 = bench_now();
    if (hd__an_build_pair(A, B, &ba, threads, s, err)) return 1;
    double t1 = bench_now();
    int same = A->count == B->count;
    int rc = hd__an_nearest(&s[0], &s[1], same ? B : NULL, threads, dab, jab, &counts[0], err);
    double t2 = bench_now();
    if (!rc) rc = hd__an_nearest(&s[1], &s[0], same ? A : NULL, threads, dba, jba, &counts[1], err);
    double t3 = bench_now();
    hd__an_free(&s[0]);
    hd__an_free(&s[1]);
    t[0] = t1 - t0, t[1] = t2 - t1, t[2] = t3 - t2;
    return rc != 0;
}

int main(int argc, char **argv) {
    size_t n = argc > 1 ? strtoull(argv[1], NULL, 10) : 1000000;
    int runs = argc > 2 ? atoi(argv[2]) : 5;
    int threads = argc > 3 ? atoi(argv[3]) : 1;
    const char *which = argc > 4 ? argv[4] : "abcde";
    int routes = argc > 5 && !strcmp(argv[5], "--routes");
    int field_only = argc > 5 && !strcmp(argv[5], "--field");
    if (runs < 1 || runs > 50) runs = 5;
    double *a = malloc(24 * n), *b = malloc(24 * n), *dab = malloc(8 * n), *dba = malloc(8 * n);
    size_t *jab = malloc(sizeof(size_t) * n), *jba = malloc(sizeof(size_t) * n);
    if (!a || !b || !dab || !dba || !jab || !jba) return 1;
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    hd_error_t err;
    printf("| case | |A| | |B| | H | field | build | A->B | B->A | field / H |\n|---|---|---|---|---|---|---|---|---|\n");
    for (int c = 0; c < FIELD_CASES; c++) {
        if (!strchr(which, 'a' + c)) continue;
        size_t nb;
        field_case(c, n, a, b, &nb);
        hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, nb);
        double th[50], tf[50], tp[3][50];
        hd__an_counts_t counts[2];
        hd_symmetric_t s;
        for (int r = 0; r < runs && field_only; r++) {
            double t0 = cpu_now();
            if (hd_distances(&A, &B, &o, dab, jab, dba, jba, &err)) goto fail;
            tf[r] = cpu_now() - t0;
        }
        if (field_only) {
            printf("| %s | %zu | %zu | | %.4f s CPU | | | | |\n", field_case_names[c], n, nb, bench_median(tf, runs));
            continue;
        }
        for (int r = 0; r < runs; r++) {
            double t0 = bench_now();
            if (hd_hausdorff(&A, &B, &o, &s, &err)) goto fail;
            th[r] = bench_now() - t0;
            t0 = bench_now();
            if (hd_distances(&A, &B, &o, dab, jab, dba, jba, &err)) goto fail;
            tf[r] = bench_now() - t0;
            double t[3];
            if (phases(&A, &B, threads, dab, jab, dba, jba, t, counts, &err)) goto fail;
            for (int k = 0; k < 3; k++) tp[k][r] = t[k];
        }
        if (max_of(dab, n) != s.ab.distance || max_of(dba, nb) != s.ba.distance) {
            fprintf(stderr, "%s: the field's maxima differ from H\n", field_case_names[c]);
            return 2;
        }
        double mh = bench_median(th, runs), mf = bench_median(tf, runs);
        printf("| %s | %zu | %zu | %.4f s | %.4f s | %.4f s | %.4f s | %.4f s | %.1fx |\n", field_case_names[c], n, nb,
               mh, mf, bench_median(tp[0], runs), bench_median(tp[1], runs), bench_median(tp[2], runs), mf / mh);
        for (int d = 0; d < 2 && routes; d++)
            printf("|   %s: groups paired %zu, windowed %zu, far %zu, shared %zu; queries apart %zu, solo %zu, "
                   "from point lists %zu |\n",
                   d ? "B->A" : "A->B", counts[d].paired, counts[d].windowed, counts[d].far, counts[d].shared, counts[d].apart,
                   counts[d].solo, counts[d].pointed);
        fflush(stdout);
    }
    free(a), free(b), free(dab), free(dba), free(jab), free(jba);
    return 0;
fail:
    fprintf(stderr, "field_bench: %s\n", err.message);
    return 1;
}
