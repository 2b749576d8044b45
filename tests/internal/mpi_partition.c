/*
 * mpi_partition.c -- the partition (src/mpi/rcb.c) gives every rank its
 * share of the points however few first samples rank 0 cuts its tree from,
 * down to the fewest a rank that hd__mpi_first_samples allows at many
 * ranks; and that count keeps rank 0's samples bounded as ranks are added.
 * Run under mpirun with 1, 2, 3, 4 and 7 ranks (tests/mpi.cmake; 3 in the
 * sanitizer build).
 *
 * White-box: the body runs inside hd__mpi_call's context, sets the first
 * samples a rank (hd__mpi_ctx_t.first) itself, calls hd__mpi_partition and routes
 * every local point with hd__mpi_rank_of, as the exchange does.  The
 * imbalance is the largest rank's count over the mean.  The partition is a
 * deterministic function of the points and their spread, so each check
 * gives the same figure on every run; the bound (1.05) is what issue 14's
 * 1.15 leaves after a margin, and the counts 1024 and 64 are measured at
 * 16 and 64 ranks in docs/scale-out.md ("Fewer first samples at many
 * ranks").
 */
#include "mpi/course.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gen.h"
#include "mpicheck.h"

/* ---- the count ----------------------------------------------------------- */

/* 1024 a rank up to 64 ranks; beyond, at most 65536 at rank 0 until 64 a
 * rank is reached; never fewer than 64 a rank. */
static void first_samples_keep_rank_0s_share_bounded(void) {
    snprintf(context_, sizeof context_, "hd__mpi_first_samples");
    for (int K = 1; K <= 1 << 20; K += K / 3 + 1) {
        int per = hd__mpi_first_samples(K);
        uint64_t total = (uint64_t)per * (uint64_t)K;
        int ok[4] = {per >= 64 && per <= 1024, K > 64 || per == 1024, total <= 65536 || per == 64,
                     total + (uint64_t)K > 65536 || per == 1024};
        for (int q = 0; q < 4; q++) CHECK(ok[q]);
        if (!(ok[0] && ok[1] && ok[2] && ok[3])) fprintf(stderr, "K = %d: %d first samples a rank\n", K, per);
    }
}

/* ---- the balance ------------------------------------------------------- */

enum { SET_UNIFORM, SET_CLUSTERS, SET_COPY, SET_COUNT };
static const char *const set_name[SET_COUNT] = {"uniform", "clusters", "perturbed copy"};

#define N_SIDE 60000 /* points a side: the second samples are then a quarter of them */

typedef struct {
    int first;        /* first samples a rank */
    double imbalance; /* out: the largest rank's points over the mean */
} probe_t;

static int partition_body(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, void *arg, hd_mpi_stats_t *st) {
    (void)st;
    probe_t *pr = arg;
    hd__mpi_course_t cs;
    hd__mpi_course_init(c, &cs);
    int rc = hd__mpi_begin(c, opt, in, pr, &cs.rg, cs.N, NULL);
    hd__mpi_node_t *tree = hd__mpi_alloc(c, (size_t)c->K, sizeof(hd__mpi_node_t));
    uint64_t *count = hd__mpi_alloc(c, 2 * (size_t)c->K, sizeof(uint64_t));
    if (rc == HD_OK && (!tree || !count)) rc = hd__mpi_nomem(c, "the test's counts", (size_t)c->K);
    if ((rc = hd__mpi_agree(c, rc)) == HD_OK) {
        c->first = pr->first;
        rc = hd__mpi_partition(c, in, NULL, cs.N[0] + cs.N[1], tree);
    }
    if (rc == HD_OK) {
        memset(count, 0, (size_t)c->K * sizeof *count);
        for (int s = 0; s < 2; s++)
            for (size_t p = 0; p < in->nparts[s]; p++) {
                const hd_mpi_part_t *part = &in->parts[s][p];
                for (size_t k = 0; k < part->points.count; k++) {
                    double x[3];
                    hd__mpi_get_point(&part->points, k, x);
                    count[hd__mpi_rank_of(tree, c->K, x, (uint64_t)s, part->offset + k)]++;
                }
            }
        MPI_Allreduce(count, count + c->K, c->K, MPI_UINT64_T, MPI_SUM, c->comm);
        uint64_t most = 0, all = 0;
        for (int r = 0; r < c->K; r++) {
            all += count[c->K + r];
            most = count[c->K + r] > most ? count[c->K + r] : most;
        }
        pr->imbalance = (double)most * c->K / (double)all;
    }
    hd__mpi_free(c, tree, (size_t)c->K, sizeof(hd__mpi_node_t));
    hd__mpi_free(c, count, 2 * (size_t)c->K, sizeof(uint64_t));
    hd__mpi_course_free(c, &cs);
    return rc;
}

/* Set `which` from the seed, A and B of N_SIDE points each. */
static void make_set(int which, uint64_t seed, double *a, double *b) {
    gen_rng_t g;
    gen_seed(&g, seed);
    switch (which) {
    case SET_UNIFORM:
        gen_cube(&g, a, N_SIDE, 0, 1000);
        gen_cube(&g, b, N_SIDE, 0, 1000);
        break;
    case SET_CLUSTERS: /* a dense quarter, like a city in open land */
        for (int s = 0; s < 2; s++) {
            double *x = s ? b : a;
            const double at[3] = {200, 700, 20};
            gen_cube(&g, x, N_SIDE / 4, 0, 1000);
            for (size_t k = 0; k < N_SIDE / 4; k++) x[3 * k + 2] *= 0.05;
            gen_gauss(&g, x + 3 * (N_SIDE / 4), N_SIDE - N_SIDE / 4, at, 30);
        }
        break;
    default: /* B = A and 1 cm of noise, in the same order */
        gen_cube(&g, a, N_SIDE, 0, 1000);
        for (size_t k = 0; k < 3 * (size_t)N_SIDE; k++) b[k] = a[k] + 0.01 * gen_normal(&g);
        break;
    }
}

/* Each rank holds a block of A and a block of B (the one after its A's,
 * so no rank's share of the space is its own). */
static double imbalance_with(int which, int first, uint64_t seed) {
    double *a = malloc(3 * sizeof(double) * N_SIDE), *b = malloc(3 * sizeof(double) * N_SIDE);
    if (!a || !b) {
        fprintf(stderr, "out of memory\n");
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    make_set(which, seed, a, b);
    size_t lo = (size_t)N_SIDE * (size_t)rank_ / (size_t)K_, hi = (size_t)N_SIDE * (size_t)(rank_ + 1) / (size_t)K_;
    int rb = (rank_ + 1) % K_;
    size_t blo = (size_t)N_SIDE * (size_t)rb / (size_t)K_, bhi = (size_t)N_SIDE * (size_t)(rb + 1) / (size_t)K_;
    hd_mpi_part_t pa = {hd_points_f64(a + 3 * lo, hi - lo), lo}, pb = {hd_points_f64(b + 3 * blo, bhi - blo), blo};
    probe_t pr = {first, 0};
    hd_error_t err;
    int rc = hd__mpi_call(MPI_COMM_WORLD, &pa, 1, &pb, 1, NULL, partition_body, &pr, NULL, &err);
    CHECK(rc == HD_OK);
    if (rc != HD_OK) fprintf(stderr, "rank %d: %s\n", rank_, err.message);
    free(a);
    free(b);
    return pr.imbalance;
}

/* With 1024 first samples a rank (every K up to 64) and with the fewest,
 * 64 (from 1024 ranks on), the largest rank holds at most 5 % above its
 * share on uniform points, a dense cluster in open land, and a perturbed
 * copy. */
static void fewest_first_samples_still_balance(void) {
    if (K_ < 2) return;
    const int firsts[2] = {1024, 64};
    for (int which = 0; which < SET_COUNT; which++)
        for (int f = 0; f < 2; f++) {
            uint64_t seed = 7000 + (uint64_t)which;
            snprintf(context_, sizeof context_, "%s, %d first samples a rank, seed %llu", set_name[which],
                     firsts[f], (unsigned long long)seed);
            double imb = imbalance_with(which, firsts[f], seed);
            CHECK(imb >= 1.0 && imb <= 1.05);
            if (rank_ == 0 && (imb < 1.0 || imb > 1.05)) fprintf(stderr, "%s: imbalance %.4f\n", context_, imb);
        }
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &K_);
    first_samples_keep_rank_0s_share_bounded();
    fewest_first_samples_still_balance();
    return mpicheck_finish("mpi_partition");
}
