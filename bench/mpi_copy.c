/*
 * mpi_copy.c -- what MPI itself costs a point of the exchange
 * (docs/scale-out.md, "Cost model"): the CPU time of one MPI_Alltoallv
 * of 28-byte records (a point's coordinates and its 4-byte number, as
 * src/mpi/exchange.c sends them), each rank sending (K-1)/K of its n
 * records, all ranks entering together (a barrier first), per record
 * sent:
 *     mpirun -n K build/bench/mpi_copy [--points n] [--repeat R]
 * Rank 0 prints the smallest over R calls of the largest rank's CPU time
 * and wall time per record sent.  On one machine this is the shared-memory
 * transport's copies (sender to a shared segment, segment to receiver);
 * a network adds its own time on top (the model prices it from the link).
 */
#include <mpi.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu_now(void) {
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    int K, rank;
    MPI_Comm_size(MPI_COMM_WORLD, &K);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    long n = 1000000, R = 7;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--points")) n = atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--repeat")) R = atol(argv[i + 1]);
    }
    MPI_Datatype rec;
    MPI_Type_contiguous(28, MPI_BYTE, &rec);
    MPI_Type_commit(&rec);
    int *cnt = malloc(4 * (size_t)K * sizeof(int));
    long share = n / K;
    for (int r = 0; r < K; r++) {
        cnt[r] = r == rank ? 0 : (int)share;               /* send counts */
        cnt[K + r] = (int)((long)r * share);               /* send displacements */
        cnt[2 * K + r] = r == rank ? 0 : (int)share;       /* receive counts */
        cnt[3 * K + r] = (int)((long)r * share);           /* receive displacements */
    }
    char *s = malloc((size_t)n * 28), *d = malloc((size_t)n * 28);
    memset(s, 1, (size_t)n * 28);
    memset(d, 0, (size_t)n * 28);
    double best_cpu = 1e30, best_wall = 1e30;
    for (long t = 0; t < R; t++) {
        MPI_Barrier(MPI_COMM_WORLD);
        double w0 = MPI_Wtime(), c0 = cpu_now();
        MPI_Alltoallv(s, cnt, cnt + K, rec, d, cnt + 2 * K, cnt + 3 * K, rec, MPI_COMM_WORLD);
        double m[2] = {cpu_now() - c0, MPI_Wtime() - w0}, most[2];
        MPI_Reduce(m, most, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
        if (most[0] < best_cpu) best_cpu = most[0];
        if (most[1] < best_wall) best_wall = most[1];
    }
    double sent = (double)share * (K - 1);
    if (rank == 0)
        printf("mpi_copy K=%d records/rank=%ld sent/rank=%.0f cpu ns/record %.2f wall ns/record %.2f\n", K, n, sent,
               1e9 * best_cpu / sent, 1e9 * best_wall / sent);
    free(s), free(d), free(cnt);
    MPI_Type_free(&rec);
    MPI_Finalize();
    return 0;
}
