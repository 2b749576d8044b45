/*
 * mpi_tiny.c -- a tiny side replicated on every rank (src/mpi/tiny.c):
 * hd_mpi_hausdorff and hd_mpi_directed on a large set against one of a few
 * hundred points, both ways (the tiny side as B and as A), at the K of
 * tests/mpi.cmake:
 *  - the result equals hd_hausdorff's (and hd_directed's) on the whole sets
 *    bit for bit, witnesses included, where the ties cross ranks: a
 *    lattice whose every tiny point is at the same distance from eight
 *    lattice points (consecutive indices, so on different ranks in the
 *    round-robin layout) and a large set held twice (every point's copy
 *    half the set away, so on another rank in blocks), whose nearest
 *    points and farthest points tie across ranks: the smallest global
 *    index must win each;
 *  - the replicated course ran: the only bytes moved are the tiny side's
 *    (24 a point to each other rank) and its answers' reduction (32 a
 *    point and rank less a K-th, counted as a ring's), no point is
 *    searched one by one or forwarded;
 *  - hd_mpi_options_t.replicate = 0 gives the same result;
 *  - hd_mpi_distances gives every rank's points what hd_distances gives
 *    them (the per-point files of hausdorff-mpi --distances), both
 *    directions and each alone, by the replicated course too.
 * Seeds are fixed and printed with every failure.
 */
#include <hausdorff_mpi.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gen.h"
#include "mpicheck.h"

enum { UNIFORM, LATTICE, TWICE, SETS };
static const char *const set_name[SETS] = {"uniform, 300 points against 40000",
                                           "half-step centres against a lattice (eight-way ties)",
                                           "300 points against a set held twice (ties half the set apart)"};

/* The large side L and the tiny side T (malloc'd, packed xyz). */
static void make(int set, uint64_t seed, double **L, size_t *nl, double **T, size_t *nt) {
    gen_rng_t g;
    gen_seed(&g, seed);
    if (set == LATTICE) {
        size_t s = 34, c = 7;
        *nl = s * s * s, *nt = c * c * c;
        *L = malloc(3 * *nl * sizeof(double)), *T = malloc(3 * *nt * sizeof(double));
        for (size_t k = 0; k < *nl; k++)
            (*L)[3 * k] = (double)(k % s), (*L)[3 * k + 1] = (double)(k / s % s), (*L)[3 * k + 2] = (double)(k / s / s);
        for (size_t k = 0; k < *nt; k++)
            (*T)[3 * k] = 5.0 * (double)(k % c) + 0.5, (*T)[3 * k + 1] = 5.0 * (double)(k / c % c) + 0.5,
            (*T)[3 * k + 2] = 5.0 * (double)(k / c / c) + 0.5;
        return;
    }
    size_t half = 21952;
    *nl = set == TWICE ? 2 * half : 40000, *nt = 300;
    *L = malloc(3 * *nl * sizeof(double)), *T = malloc(3 * *nt * sizeof(double));
    if (set == TWICE) { /* a lattice of 28^3, then the same points again */
        for (size_t k = 0; k < half; k++)
            for (int a = 0; a < 3; a++) {
                double v = (double)(a == 0 ? k % 28 : a == 1 ? k / 28 % 28 : k / 784);
                (*L)[3 * k + a] = (*L)[3 * (k + half) + a] = v;
            }
        gen_cube(&g, *T, *nt, 0, 27);
        return;
    }
    gen_cube(&g, *L, *nl, 0, 100);
    gen_cube(&g, *T, *nt, 0, 100);
}

enum { LAY_BLOCKS, LAY_CHUNKS, LAY_TINY_ON_LAST, LAY_COUNT };
static const char *const lay_name[LAY_COUNT] = {"blocks (B rotated by K/2)", "chunks of 7 round robin",
                                                "the tiny side on the last rank, the other in blocks"};

/* This rank's parts of a side of n points; tiny: the side is the tiny one. */
static size_t layout(int how, int side, int tiny, const double *xyz, size_t n, hd_mpi_part_t *parts, size_t cap) {
    size_t np = 0;
    if (how == LAY_CHUNKS) {
        size_t w = n / 7 < cap - 1 ? 7 : n / (cap - 1) + 1;
        for (size_t lo = 0, c = 0; lo < n; lo += w, c++)
            if ((int)(c % (size_t)K_) == rank_)
                parts[np++] = (hd_mpi_part_t){hd_points_f64(xyz + 3 * lo, n - lo < w ? n - lo : w), lo};
        return np;
    }
    if (how == LAY_TINY_ON_LAST && tiny) {
        if (rank_ == K_ - 1) parts[np++] = (hd_mpi_part_t){hd_points_f64(xyz, n), 0};
        return np;
    }
    int blk = side ? (rank_ + K_ / 2) % K_ : rank_;
    size_t lo = n * (size_t)blk / (size_t)K_, hi = n * (size_t)(blk + 1) / (size_t)K_;
    parts[np++] = (hd_mpi_part_t){hd_points_f64(xyz + 3 * lo, hi - lo), lo};
    return np;
}

static int same_result(const hd_result_t *x, const hd_result_t *y) {
    return SAME_BITS(x->distance2, y->distance2) && x->i == y->i && x->j == y->j;
}

/* The replicated course's figures: nothing but the tiny side moved. */
static void replicated(const hd_mpi_stats_t *st, size_t nt) {
    if (K_ == 1) return;
    CHECK(st->bytes_partition <= 56 * (uint64_t)(K_ - 1) * nt);
    CHECK(st->forwarded_points == 0 && st->shell_points == 0 && st->bytes_forwarding == 0);
}

/* Each rank's per-point answers of a side against the reference's. */
static void same_distances(const hd_mpi_part_t *parts, size_t np, const double *d, const size_t *n, const double *rd,
                           const size_t *rn, const char *what) {
    size_t t = 0, bad = 0;
    for (size_t p = 0; p < np; p++)
        for (size_t k = 0; k < parts[p].points.count; k++, t++) {
            size_t g = parts[p].offset + k;
            if (!SAME_BITS(d[t], rd[g]) || n[t] != rn[g]) bad++;
        }
    CHECK(bad == 0);
    if (bad) fprintf(stderr, "rank %d: %s: %zu points differ\n", rank_, what, bad);
}

static void distances(const hd_points_t *A, const hd_points_t *B, const hd_mpi_part_t *pa, size_t na,
                      const hd_mpi_part_t *pb, size_t nb, const hd_mpi_options_t *mo) {
    size_t NA = A->count, NB = B->count;
    double *rd[2] = {malloc(NA * sizeof(double)), malloc(NB * sizeof(double))};
    double *d[2] = {malloc(NA * sizeof(double)), malloc(NB * sizeof(double))};
    size_t *rn[2] = {malloc(NA * sizeof(size_t)), malloc(NB * sizeof(size_t))};
    size_t *n[2] = {malloc(NA * sizeof(size_t)), malloc(NB * sizeof(size_t))};
    hd_error_t err;
    hd_mpi_stats_t st;
    CHECK(hd_distances(A, B, &mo->engine, rd[0], rn[0], rd[1], rn[1], &err) == HD_OK);
    CHECK(hd_mpi_distances(MPI_COMM_WORLD, pa, na, pb, nb, mo, d[0], n[0], d[1], n[1], &st, &err) == HD_OK);
    same_distances(pa, na, d[0], n[0], rd[0], rn[0], "A to B");
    same_distances(pb, nb, d[1], n[1], rd[1], rn[1], "B to A");
    replicated(&st, NA < NB ? NA : NB);
    CHECK(st.bytes_returned == 0);
    /* each direction alone: the other's outputs NULL on every rank */
    memset(d[0], 0, NA * sizeof(double));
    CHECK(hd_mpi_distances(MPI_COMM_WORLD, pa, na, pb, nb, mo, d[0], n[0], NULL, NULL, &st, &err) == HD_OK);
    same_distances(pa, na, d[0], n[0], rd[0], rn[0], "A to B alone");
    memset(n[1], 0, NB * sizeof(size_t));
    CHECK(hd_mpi_distances(MPI_COMM_WORLD, pa, na, pb, nb, mo, NULL, NULL, d[1], n[1], &st, &err) == HD_OK);
    same_distances(pb, nb, d[1], n[1], rd[1], rn[1], "B to A alone");
    for (int s = 0; s < 2; s++) free(rd[s]), free(d[s]), free(rn[s]), free(n[s]);
}

static void run(int set, int tiny_b, int how, uint64_t seed) {
    snprintf(context_, sizeof context_, "%s, tiny side %s, layout %s, seed %llu", set_name[set], tiny_b ? "B" : "A",
             lay_name[how], (unsigned long long)seed);
    double *L, *T;
    size_t nl, nt;
    make(set, seed, &L, &nl, &T, &nt);
    double *a = tiny_b ? L : T, *b = tiny_b ? T : L;
    size_t NA = tiny_b ? nl : nt, NB = tiny_b ? nt : nl;
    hd_points_t A = hd_points_f64(a, NA), B = hd_points_f64(b, NB);
    hd_mpi_options_t mo;
    hd_mpi_options_init(&mo);
    mo.engine.threads = 1;
    hd_symmetric_t ref, got;
    hd_result_t dref, dgot;
    hd_error_t err;
    CHECK(hd_hausdorff(&A, &B, &mo.engine, &ref, &err) == HD_OK);
    CHECK(hd_directed(&A, &B, &mo.engine, &dref, &err) == HD_OK);
    hd_mpi_part_t pa[8000], pb[8000];
    size_t na = layout(how, 0, !tiny_b, a, NA, pa, 8000), nb = layout(how, 1, tiny_b, b, NB, pb, 8000);
    hd_mpi_stats_t st;
    int rc = hd_mpi_hausdorff(MPI_COMM_WORLD, pa, na, pb, nb, &mo, &got, &st, &err);
    CHECK(rc == HD_OK);
    if (rc != HD_OK) fprintf(stderr, "rank %d: %s\n", rank_, err.message);
    CHECK(SAME_BITS(got.distance, ref.distance) && same_result(&got.ab, &ref.ab) && same_result(&got.ba, &ref.ba));
    if (!same_result(&got.ab, &ref.ab) || !same_result(&got.ba, &ref.ba))
        fprintf(stderr, "rank %d: witnesses (%zu, %zu) (%zu, %zu), expected (%zu, %zu) (%zu, %zu)\n", rank_, got.ab.i,
                got.ab.j, got.ba.i, got.ba.j, ref.ab.i, ref.ab.j, ref.ba.i, ref.ba.j);
    replicated(&st, nt);
    CHECK(hd_mpi_directed(MPI_COMM_WORLD, pa, na, pb, nb, &mo, &dgot, &st, &err) == HD_OK);
    CHECK(same_result(&dgot, &dref));
    replicated(&st, nt);
    if (how == LAY_BLOCKS) {
        mo.replicate = 0; /* the partition's course: the same answer */
        CHECK(hd_mpi_hausdorff(MPI_COMM_WORLD, pa, na, pb, nb, &mo, &got, &st, &err) == HD_OK);
        CHECK(same_result(&got.ab, &ref.ab) && same_result(&got.ba, &ref.ba));
        CHECK(K_ == 1 || st.bytes_partition > 56 * (uint64_t)(K_ - 1) * nt);
        mo.replicate = 1;
    }
    if (how != LAY_BLOCKS) distances(&A, &B, pa, na, pb, nb, &mo);
    free(L);
    free(T);
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &K_);
    for (int set = 0; set < SETS; set++)
        for (int tiny_b = 0; tiny_b < 2; tiny_b++)
            for (int how = 0; how < LAY_COUNT; how++) run(set, tiny_b, how, 4200 + (uint64_t)set);
    return mpicheck_finish("mpi_tiny");
}
