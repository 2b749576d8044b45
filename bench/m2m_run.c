/*
 * m2m_run -- times hd_surface_hausdorff on one mesh pair for the
 * surface-to-surface benchmark (bench/m2m_bench.py runs it).
 *
 *   m2m_run A B TOLERANCE THREADS REPEATS [sym|ab] [within D]
 *
 * TOLERANCE is absolute (0: as tight as doubles allow); sym measures both
 * directions in one call, ab only h(A, B).  Runs the call REPEATS times
 * (reading the files is not timed; everything the call builds is) and
 * prints one JSON line: the median wall and processor seconds, each
 * direction's enclosure with its witness and counters (the last run's;
 * they are the same in every run).  With `within D` it times the
 * predicate hd_surface_within(A, B, D) instead (sym: H, ab: h(A, B)) and
 * adds its answer (1 within, 0 beyond, -1 undecided).
 */
#include "benchutil.h"

#include <hausdorff.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void print_enclosure(const char *name, const hd_enclosure_t *e) {
    /* the predicate may leave upper infinite: Python's json reads Infinity */
    printf("\"%s\": {\"lower\": %.17g, \"upper\": ", name, e->lower);
    if (isinf(e->upper)) printf("Infinity");
    else printf("%.17g", e->upper);
    printf(", \"tolerance\": %.17g, \"converged\": %d, ", e->tolerance, e->converged);
    printf("\"point_a\": [%.17g, %.17g, %.17g], \"witness_distance\": %.17g, \"witness_error\": %.17g, ",
           e->point_a[0], e->point_a[1], e->point_a[2], e->witness_distance, e->witness_error);
    printf("\"face_a\": %lld, \"faces_dropped\": %llu, \"faces_split\": %llu, \"kernel_calls\": %llu, "
           "\"seconds\": %.6g}",
           e->face_a == SIZE_MAX ? -1LL : (long long)e->face_a, (unsigned long long)e->faces_dropped,
           (unsigned long long)e->faces_split, (unsigned long long)e->kernel_calls, e->seconds);
}

int main(int argc, char **argv) {
    if (argc < 6 || (argc > 6 && strcmp(argv[6], "sym") && strcmp(argv[6], "ab")) ||
        (argc > 7 && (argc != 9 || strcmp(argv[7], "within")))) {
        fprintf(stderr, "usage: m2m_run A B TOLERANCE THREADS REPEATS [sym|ab] [within D]\n");
        return 2;
    }
    int within = argc == 9, answer = -1;
    double d = within ? atof(argv[8]) : 0;
    int both = argc <= 6 || !strcmp(argv[6], "sym");
    hd_mesh_file_t *fa = NULL, *fb = NULL;
    hd_error_t err;
    if (hd_read_mesh(argv[1], NULL, &fa, &err) || hd_read_mesh(argv[2], NULL, &fb, &err)) {
        fprintf(stderr, "m2m_run: %s\n", err.message);
        hd_mesh_file_free(fa);
        return 2;
    }
    hd_mesh_t A = hd_mesh_file_view(fa), B = hd_mesh_file_view(fb);
    hd_surface_options_t opt;
    hd_surface_options_init(&opt);
    opt.tolerance = atof(argv[3]);
    opt.relative = 0;
    opt.threads = atoi(argv[4]);
    int runs = atoi(argv[5]) > 0 ? atoi(argv[5]) : 1;
    double *wall = malloc(runs * sizeof *wall), *cpu = malloc(runs * sizeof *cpu);
    hd_enclosure_t ab, ba;
    int rc = 0;
    for (int r = 0; r < runs && !rc; r++) {
        double w0 = bench_now(), c0 = bench_cpu_now();
        if (within) rc = hd_surface_within(&A, &B, d, !both, &opt, &answer, &ab, &ba, &err);
        else rc = hd_surface_hausdorff(&A, &B, &opt, &ab, both ? &ba : NULL, &err);
        wall[r] = bench_now() - w0, cpu[r] = bench_cpu_now() - c0;
    }
    if (rc) {
        fprintf(stderr, "m2m_run: %s\n", err.message);
    } else {
        printf("{\"which\": \"%s\", \"threads\": %d, \"runs\": %d, \"seconds\": %.6g, \"cpu\": %.6g, ",
               both ? "sym" : "ab", opt.threads, runs, bench_median(wall, runs), bench_median(cpu, runs));
        if (within) printf("\"within\": %.17g, \"answer\": %d, ", d, answer);
        print_enclosure("ab", &ab);
        if (both) printf(", "), print_enclosure("ba", &ba);
        printf("}\n");
    }
    free(wall), free(cpu);
    hd_mesh_file_free(fa), hd_mesh_file_free(fb);
    return rc ? 1 : 0;
}
