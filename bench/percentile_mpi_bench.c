/*
 * percentile_mpi_bench.c -- hausdorff-mpi's percentile without every
 * distance (hd_mpi_hausdorff_percentile, src/mpi/select.c) against what it
 * replaced, every per-point distance over the ranks (hd_mpi_distances, both
 * directions) then hd_mpi_percentile_of (docs/benchmarks.md, "Percentiles
 * without every distance", the MPI part).  Run under mpirun.
 *
 * The five cases of issue 39 (bench/support/field_cases.h), each rank
 * passing a block of each set by index.  For each case, median of RUNS
 * alternated runs at THREADS threads a rank: the wall time of the call (a
 * barrier before, the slowest rank's), the CPU seconds of every rank
 * added, and the points whose exact distance some rank computed
 * (stats.shell_points) over all points.  It checks that both ways give the
 * four figures to the bit.
 *
 * usage: mpirun -n K percentile_mpi_bench [N] [RUNS] [THREADS] [P] [CASES]
 *        (default 1000000 3 1 95 abcde)
 */
#include "benchutil.h"
#include "field_cases.h"

#include <hausdorff_mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int same_bits(double x, double y) { return memcmp(&x, &y, sizeof x) == 0; }

static int same(const hd_percentile_t *x, const hd_percentile_t *y) {
    return same_bits(x->ab, y->ab) && same_bits(x->ba, y->ba) && same_bits(x->symmetric, y->symmetric) &&
           same_bits(x->pooled, y->pooled);
}

typedef struct {
    double wall, cpu;
} cost_t;

/* One call's cost: the slowest rank's wall time, every rank's CPU added. */
static cost_t measure(double w0, double c0) {
    double mine[2] = {bench_now() - w0, bench_cpu_now() - c0}, out[2];
    MPI_Allreduce(&mine[0], &out[0], 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(&mine[1], &out[1], 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return (cost_t){out[0], out[1]};
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    int rank, K;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &K);
    size_t n = argc > 1 ? (size_t)atof(argv[1]) : 1000000;
    int runs = argc > 2 ? atoi(argv[2]) : 3, threads = argc > 3 ? atoi(argv[3]) : 1;
    double p = argc > 4 ? atof(argv[4]) : 95;
    const char *which = argc > 5 ? argv[5] : "abcde";
    if (runs < 1 || runs > 50) runs = 3;
    double *a = malloc(24 * n), *b = malloc(24 * n), *dab = malloc(8 * n), *dba = malloc(8 * n);
    if (!a || !b || !dab || !dba) return 1;
    hd_mpi_options_t o;
    hd_mpi_options_init(&o);
    o.engine.threads = threads;
    hd_error_t err;
    int bad = 0;
    if (rank == 0)
        printf("%d ranks, %d thread(s) each, P%g, median of %d\n"
               "| case | |A| | |B| | every distance: wall, CPU | selection: wall, CPU | wall ratio | CPU ratio | "
               "exact distances |\n|---|---|---|---|---|---|---|---|\n",
               K, threads, p, runs);
    for (int c = 0; c < FIELD_CASES; c++) {
        if (!strchr(which, 'a' + c)) continue;
        size_t nb;
        field_case(c, n, a, b, &nb);
        size_t a0 = n * (size_t)rank / (size_t)K, a1 = n * (size_t)(rank + 1) / (size_t)K;
        size_t b0 = nb * (size_t)rank / (size_t)K, b1 = nb * (size_t)(rank + 1) / (size_t)K;
        hd_mpi_part_t pa = {hd_points_f64(a + 3 * a0, a1 - a0), a0}, pb = {hd_points_f64(b + 3 * b0, b1 - b0), b0};
        double w_all[50], c_all[50], w_sel[50], c_sel[50], exact = 0;
        for (int r = 0; r < runs; r++) {
            hd_percentile_t x, y;
            hd_mpi_stats_t st;
            MPI_Barrier(MPI_COMM_WORLD);
            double w0 = bench_now(), c0 = bench_cpu_now();
            int rc = hd_mpi_distances(MPI_COMM_WORLD, &pa, 1, &pb, 1, &o, dab, NULL, dba, NULL, NULL, &err);
            if (rc == HD_OK) rc = hd_mpi_percentile_of(MPI_COMM_WORLD, dab, a1 - a0, dba, b1 - b0, p, &x, &err);
            cost_t k1 = measure(w0, c0);
            MPI_Barrier(MPI_COMM_WORLD);
            w0 = bench_now(), c0 = bench_cpu_now();
            if (rc == HD_OK) rc = hd_mpi_hausdorff_percentile(MPI_COMM_WORLD, &pa, 1, &pb, 1, &o, p, &y, &st, &err);
            cost_t k2 = measure(w0, c0);
            if (rc != HD_OK) {
                if (rank == 0) fprintf(stderr, "%s: %s\n", field_case_names[c], err.message);
                MPI_Abort(MPI_COMM_WORLD, 1);
            }
            if (!same(&x, &y)) {
                bad = 1;
                if (rank == 0)
                    fprintf(stderr, "%s: MISMATCH %.17g/%.17g %.17g/%.17g\n", field_case_names[c], x.ab, y.ab, x.pooled,
                            y.pooled);
            }
            w_all[r] = k1.wall, c_all[r] = k1.cpu, w_sel[r] = k2.wall, c_sel[r] = k2.cpu;
            exact = (double)st.shell_points / (double)(n + nb);
        }
        double wa = bench_median(w_all, runs), ca = bench_median(c_all, runs);
        double ws = bench_median(w_sel, runs), cs = bench_median(c_sel, runs);
        if (rank == 0)
            printf("| %s | %zu | %zu | %.3f s, %.3f s | %.3f s, %.3f s | %.1fx | %.1fx | %.1f%% |\n", field_case_names[c],
                   n, nb, wa, ca, ws, cs, wa / ws, ca / cs, 100 * exact);
    }
    free(a), free(b), free(dab), free(dba);
    MPI_Finalize();
    return bad;
}
