/*
 * rcb_bench.c -- what rank 0 pays for the partition's first step at many
 * ranks: its tree over every rank's first samples (hd__mpi_rcb_tree,
 * src/mpi/rcb.c), timed in one process, since this machine cannot run a
 * thousand ranks:
 *     build/bench/rcb_bench [--ranks LIST] [--runs R]
 * For each K it builds the tree over K x 1024 samples (every rank's count
 * before 2026-11-29's sixth session) and over K x hd__mpi_first_samples(K)
 * (now), uniform in a cube (a lidar-like scene changes the time by a few
 * percent: the work is quickselect's), and prints the median seconds of R
 * runs, the nanoseconds a sample and level, rank 0's sample buffer and the
 * ratio.  The gather of the samples and the broadcast of the tree are not
 * in it: docs/scale-out.md's model prices them from the link.
 */
#include "mpi/partition.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "benchutil.h"
#include "gen.h"

/* Median seconds of `runs` trees over S samples for K ranks (the samples
 * drawn afresh each run: the build reorders them). */
static double tree_seconds(size_t S, int K, int runs) {
    hd__mpi_sample_t *s = malloc(S * sizeof *s);
    hd__mpi_node_t *t = malloc((size_t)K * sizeof *t);
    double *br = malloc(2 * (size_t)K * sizeof *br), sec[15];
    if (!s || !t || !br) {
        fprintf(stderr, "rcb_bench: out of memory for %zu samples\n", S);
        exit(2);
    }
    gen_rng_t g;
    gen_seed(&g, 42);
    for (int r = 0; r < runs; r++) {
        for (size_t k = 0; k < S; k++) {
            for (int a = 0; a < 3; a++) s[k].x[a] = 1000 * gen_unit(&g);
            s[k].g = k / 2;
            s[k].side = k & 1;
        }
        double t0 = bench_now();
        hd__mpi_rcb_tree(s, S, K, t, br);
        sec[r] = bench_now() - t0;
    }
    free(s);
    free(t);
    free(br);
    return bench_median(sec, runs);
}

int main(int argc, char **argv) {
    const char *ranks = "64,256,1000,4096,16384";
    int runs = 5;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--ranks") && i + 1 < argc) ranks = argv[++i];
        else if (!strcmp(argv[i], "--runs") && i + 1 < argc) runs = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: rcb_bench [--ranks LIST] [--runs R]\n");
            return 2;
        }
    }
    if (runs < 1 || runs > 15) runs = 5;
    printf("# ranks  per-rank  samples     tree(s)  ns/sample/level  rank0 MB   | 1024 a rank: tree(s)  MB     ratio\n");
    size_t list[16];
    int nk = bench_parse_sizes(ranks, list, 16);
    for (int i = 0; i < nk; i++) {
        int K = list[i] <= (size_t)1 << 24 ? (int)list[i] : 0;
        if (K >= 2) {
            int per = hd__mpi_first_samples(K);
            size_t now = (size_t)per * (size_t)K, before = (size_t)1024 * (size_t)K;
            double tn = tree_seconds(now, K, runs), tb = tree_seconds(before, K, runs);
            printf("%7d %9d %9zu %11.4f %16.1f %9.1f   | %20.4f %6.1f %8.1f\n", K, per, now, tn,
                   tn / (double)now / log2((double)K) * 1e9, (double)(now * sizeof(hd__mpi_sample_t)) / 1e6, tb,
                   (double)(before * sizeof(hd__mpi_sample_t)) / 1e6, tb / tn);
        }
    }
    return 0;
}
