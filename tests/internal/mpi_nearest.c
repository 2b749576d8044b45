/*
 * mpi_nearest.c -- the per-point searches of a rank's local set Q
 * (src/mpi/slab.c, hd__mpi_nearest_in_q): each asker gets the exact
 * nearest point of Q with the smallest index on ties, as the brute force
 * gives it, whether a few askers are answered by one pass over Q (the
 * scan, which starts from a strided sample of Q and passes over points it
 * proves farther) or more ask the slab's structures.  No MPI call is made,
 * so this runs without mpirun; built with the MPI library
 * (tests/mpi.cmake).
 */
#include "brute.h"
#include "check.h"
#include "gen.h"
#include "mpi/search.h"

#include <math.h>
#include <stdlib.h>

/* The brute force (tests/support/brute.c): the smallest index at the
 * smallest squared distance. */
static size_t brute(const double *x, const double *Q, size_t nQ) {
    size_t at = 0;
    brute_nearest(x, Q, nQ, &at);
    return at;
}

/* hd__mpi_nearest_in_q for n askers against Q in the region r, its
 * answers checked against the brute force; unproven NULL, so every answer
 * must be exact. */
static void check_against_brute_peak(const hd__box_t *r, double *P, const uint32_t *pos, size_t n, double *Q, size_t nQ,
                                     size_t *peak) {
    hd__mpi_ctx_t c;
    memset(&c, 0, sizeof c);
    c.threads = 1;
    hd__mpi_qtree_t q;
    memset(&q, 0, sizeof q);
    q.M0 = 0.5;
    size_t nP = 0;
    for (size_t k = 0; k < n; k++) nP = pos && pos[k] + 1 > nP ? pos[k] + 1 : nP;
    hd__mpi_dir_t d = {P, NULL, pos ? nP : n, Q, NULL, nQ, 1, NULL};
    size_t *near = malloc(n * sizeof *near);
    CHECK(near != NULL);
    CHECK_EQ(hd__mpi_nearest_in_q(&c, &d, r, &q, P, pos, n, near, NULL), HD_OK);
    for (size_t k = 0; k < n; k++) {
        const double *x = P + 3 * (pos ? pos[k] : k);
        CHECK_EQ(near[k], brute(x, Q, nQ));
    }
    hd__mpi_qtree_free(&c, &q);
    CHECK_EQ(c.cur, 0);
    if (peak) *peak = c.peak;
    free(near);
}

static void check_against_brute(const hd__box_t *r, double *P, const uint32_t *pos, size_t n, double *Q, size_t nQ) {
    check_against_brute_peak(r, P, pos, n, Q, nQ, NULL);
}

static const hd__box_t everything = {{-INFINITY, -INFINITY, -INFINITY}, {INFINITY, INFINITY, INFINITY}};

TEST(a_few_askers_get_the_smallest_index_at_a_tie_the_sample_met_first) {
    /* 5000 points far away, but for two at distance 1 from the asker: index
     * 10, in the scan's sample (every 5th point), and index 3, not in it */
    size_t nQ = 5000;
    double *Q = malloc(nQ * 3 * sizeof *Q);
    CHECK(Q != NULL);
    for (size_t j = 0; j < nQ; j++) Q[3 * j] = 100.0 + (double)j, Q[3 * j + 1] = Q[3 * j + 2] = 0;
    Q[30] = 0, Q[31] = 1, Q[32] = 0;
    Q[9] = 1, Q[10] = 0, Q[11] = 0;
    double P[3] = {0, 0, 0};
    check_against_brute(&everything, P, NULL, 1, Q, nQ);
    free(Q);
}

TEST(a_few_askers_match_the_brute_force_on_lattices_with_ties_and_duplicates) {
    for (uint64_t seed = 1; seed <= 60; seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t nQ = 1 + gen_u64(&g) % 9000, n = 1 + gen_u64(&g) % 16;
        CONTEXT("seed=%llu nQ=%zu askers=%zu", (unsigned long long)seed, nQ, n);
        double *Q = malloc(nQ * 3 * sizeof *Q), P[16 * 3];
        CHECK(Q != NULL);
        gen_lattice(&g, Q, nQ, 2 + (int)(gen_u64(&g) % 12));
        /* askers on the lattice, halfway between its planes (ties between
         * two or more nearest points), or far outside it */
        for (size_t k = 0; k < n; k++)
            for (int a = 0; a < 3; a++) {
                double v = (double)(gen_u64(&g) % 16) * 0.5;
                P[3 * k + a] = gen_u64(&g) % 8 == 0 ? v * 1000.0 - 20.0 : v;
            }
        check_against_brute(&everything, P, NULL, n, Q, nQ);
        free(Q);
    }
}

TEST(a_few_askers_named_by_position_match_the_brute_force) {
    gen_rng_t g;
    gen_seed(&g, 7);
    CONTEXT("seed=7");
    size_t nQ = 20000, nP = 400;
    double *Q = malloc(nQ * 3 * sizeof *Q), *P = malloc(nP * 3 * sizeof *P);
    CHECK(Q != NULL && P != NULL);
    gen_cube(&g, Q, nQ, 0, 1);
    gen_cube(&g, P, nP, 0, 1);
    uint32_t pos[16];
    for (size_t k = 0; k < 16; k++) pos[k] = (uint32_t)(k * 25 + 3); /* increasing, as the shell's */
    check_against_brute(&everything, P, pos, 16, Q, nQ);
    free(Q);
    free(P);
}

TEST(more_askers_than_the_scan_takes_ask_the_slab_and_get_the_same_answers) {
    for (uint64_t seed = 1; seed <= 10; seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        CONTEXT("seed=%llu", (unsigned long long)seed);
        /* the region x <= 4 of a lattice in [0, 8)^3 (Q holds its own part),
         * askers near the face x = 4, on both sides */
        size_t nQ = 0, n = 17 + gen_u64(&g) % 40, cap = 6000;
        double *Q = malloc(cap * 3 * sizeof *Q), *P = malloc(n * 3 * sizeof *P), pt[3];
        CHECK(Q != NULL && P != NULL);
        while (nQ < cap) {
            gen_lattice(&g, pt, 1, 8);
            if (pt[0] <= 4) memcpy(Q + 3 * nQ++, pt, sizeof pt);
        }
        for (size_t k = 0; k < n; k++) {
            gen_lattice(&g, P + 3 * k, 1, 8);
            P[3 * k] = 3.5 + 0.5 * (double)(gen_u64(&g) % 3);
        }
        hd__box_t r = {{-INFINITY, -INFINITY, -INFINITY}, {4, INFINITY, INFINITY}};
        check_against_brute(&r, P, NULL, n, Q, nQ);
        free(Q);
        free(P);
    }
}

TEST(askers_of_all_of_a_large_q_search_it_a_chunk_at_a_time_with_the_same_answers) {
    /* A rank holding Q alone answers other ranks' queries from all of Q
     * (no face to cut a slab at): a structure over a chunk of Q at a
     * time, never over all of it (about 38 bytes a point of it while
     * built), and every answer the brute force's, ties across chunks to
     * the smallest index (a lattice with each point repeated in every
     * chunk, askers halfway between its planes). */
    gen_rng_t g;
    gen_seed(&g, 11);
    CONTEXT("seed=11");
    size_t nQ = 300000, n = 64;
    double *Q = malloc(nQ * 3 * sizeof *Q), *P = malloc(n * 3 * sizeof *P);
    CHECK(Q != NULL && P != NULL);
    gen_lattice(&g, Q, nQ, 12);
    for (size_t k = 0; k < n; k++)
        for (int a = 0; a < 3; a++) P[3 * k + a] = (double)(gen_u64(&g) % 26) * 0.5 - 0.5;
    size_t peak = 0;
    check_against_brute_peak(&everything, P, NULL, n, Q, nQ, &peak);
    CHECK(peak < 16 * nQ); /* a structure over all of Q alone takes more */
    free(Q);
    free(P);
}
