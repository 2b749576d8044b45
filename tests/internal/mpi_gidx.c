/*
 * mpi_gidx.c -- the local sets' global indices of the MPI library
 * (src/mpi/gidx.c, ranges.h's hd__mpi_gidx_t): a set of indices of a side,
 * encoded in increasing order over the side's index runs, gives back every
 * index by position (hd__mpi_gidx), through a cursor (hd__mpi_gcur_at)
 * walked in order, with jumps, and backwards, with the rank whose run holds
 * it, and in bulk from any position (hd__mpi_gidx_decode); two sides'
 * shared indices are found by one walk over both codes (hd__mpi_gidx_common,
 * the pairs of a copy); in less than
 * 4 + log2(U / n) bits a point and a few words, charged to the call while
 * held.  No MPI call is made (the context only counts
 * bytes), so this runs without mpirun; built with the MPI library
 * (tests/mpi.cmake).
 */
#include "check.h"
#include "gen.h"
#include "mpi/ranges.h"

#include <stdlib.h>

/* A scene: both sides' runs of K ranks and, for each side, a local set. */
typedef struct {
    hd__mpi_ctx_t c;
    hd__mpi_ranges_t rg;
    uint64_t *g[2];           /* the local sets' indices, increasing */
    int *owner[2];            /* the rank of each one's run */
    size_t n[2];
} scene_t;

static void scene_free(scene_t *sc) {
    hd__mpi_ranges_free(&sc->c, &sc->rg);
    for (int s = 0; s < 2; s++) {
        free(sc->g[s]);
        free(sc->owner[s]);
    }
    CHECK_EQ(sc->c.cur, 0); /* every byte given back */
}

/* The runs (lo, hi, side, rank) as hd__mpi_ranges_t, and each side's local set:
 * every index of a run with probability keep (1: all of them). */
static void scene_make(scene_t *sc, int K, const hd__mpi_range_t *runs, size_t nruns, double keep, gen_rng_t *rng) {
    memset(sc, 0, sizeof *sc);
    sc->rg.K = K;
    sc->rg.total = nruns;
    sc->rg.all = hd__mpi_alloc(&sc->c, nruns, sizeof(hd__mpi_range_t));
    memcpy(sc->rg.all, runs, nruns * sizeof(hd__mpi_range_t));
    CHECK_RC(hd__mpi_ranges_index(&sc->c, &sc->rg), HD_OK);
    for (int s = 0; s < 2; s++) {
        size_t a = sc->rg.seg[(size_t)s * ((size_t)K + 1)], b = sc->rg.seg[(size_t)s * ((size_t)K + 1) + (size_t)K],
               cap = 0;
        for (size_t i = a; i < b; i++) cap += (size_t)(sc->rg.bylo[i].hi - sc->rg.bylo[i].lo + 1);
        sc->g[s] = malloc((cap ? cap : 1) * sizeof(uint64_t));
        sc->owner[s] = malloc((cap ? cap : 1) * sizeof(int));
        for (size_t i = a; i < b; i++) /* by first index: the set comes out increasing */
            for (uint64_t g = sc->rg.bylo[i].lo;; g++) {
                if (keep >= 1 || gen_unit(rng) < keep) {
                    sc->g[s][sc->n[s]] = g;
                    sc->owner[s][sc->n[s]++] = sc->rg.bylo[i].rank;
                }
                if (g == sc->rg.bylo[i].hi) break;
            }
    }
}

/* Side s's set encoded, then read back every way. */
static void check_side(scene_t *sc, int s, gen_rng_t *rng) {
    size_t n = sc->n[s];
    const uint64_t *g = sc->g[s];
    size_t before = sc->c.cur;
    hd__mpi_gidx_t x;
    CHECK_RC(hd__mpi_gidx_init(&sc->c, &x, &sc->rg, s, n), HD_OK);
    for (size_t k = 0, m; k < n; k += m) /* in pieces of any length, as the exchange's runs */
        hd__mpi_gidx_put_indices(&x, k, g + k, m = 1 + (size_t)(gen_u64(rng) % (n - k)));
    /* charged while held, and small: n l low bits, n ones and U >> l < 2n
     * zeros, a sample word per 64 points (l = floor(log2(U / n)), U the
     * side's indices), and at most a word of rounding in each part */
    CHECK_EQ(sc->c.cur - before, x.words * sizeof(uint64_t));
    uint64_t U = 0;
    for (size_t i = 0; i < x.nrun; i++) U += x.run[i].hi - x.run[i].lo + 1;
    int l = 0;
    while (n && (U >> (l + 1)) >= n) l++;
    CHECK_EQ(x.l, l);
    CHECK((uint64_t)x.words * 64 <= (uint64_t)n * (uint64_t)(l + 4) + 3 * 64);
    /* every position at random access */
    for (size_t k = 0; k < n && !hdt_failed(); k++) CHECK_EQ(hd__mpi_gidx(&x, k), g[k]);
    /* the cursor in order, each position twice (the second from the
     * cursor's memory), with its run's rank */
    hd__mpi_gcur_t cu;
    hd__mpi_gcur_init(&cu, &x);
    for (size_t k = 0; k < n && !hdt_failed(); k++) {
        CHECK_EQ(hd__mpi_gcur_at(&cu, k), g[k]);
        CHECK_EQ(hd__mpi_gcur_at(&cu, k), g[k]);
        CHECK_EQ(hd__mpi_gcur_rank(&cu), sc->owner[s][k]);
    }
    /* forward jumps, short (stepped) and long (selected) */
    hd__mpi_gcur_init(&cu, &x);
    for (size_t k = n ? gen_u64(rng) % n : 0; k < n && !hdt_failed();) {
        CHECK_EQ(hd__mpi_gcur_at(&cu, k), g[k]);
        CHECK_EQ(hd__mpi_gcur_rank(&cu), sc->owner[s][k]);
        uint64_t r = gen_u64(rng) % 4;
        k += r == 0 ? 1 : r == 1 ? gen_u64(rng) % 70 : r == 2 ? 250 + gen_u64(rng) % 10 : gen_u64(rng) % 5000;
    }
    /* decoded in bulk: the whole set, and stretches of any length from
     * anywhere (a word's middle, a run's end, the last position) */
    uint64_t *d = malloc((n + 1) * sizeof *d);
    hd__mpi_gidx_decode(&x, 0, n, d);
    for (size_t k = 0; k < n && !hdt_failed(); k++) CHECK_EQ(d[k], g[k]);
    for (int t = 0; t < 200 && n && !hdt_failed(); t++) {
        size_t k = (size_t)(gen_u64(rng) % n), m = (size_t)(gen_u64(rng) % (n - k + 1));
        hd__mpi_gidx_decode(&x, k, m, d);
        for (size_t i = 0; i < m && !hdt_failed(); i++) CHECK_EQ(d[i], g[k + i]);
    }
    free(d);
    /* anywhere, backwards included */
    hd__mpi_gcur_init(&cu, &x);
    for (int t = 0; t < 2000 && n && !hdt_failed(); t++) {
        size_t k = (size_t)(gen_u64(rng) % n);
        CHECK_EQ(hd__mpi_gcur_at(&cu, k), g[k]);
        CHECK_EQ(hd__mpi_gcur_rank(&cu), sc->owner[s][k]);
    }
    hd__mpi_gidx_free(&sc->c, &x);
    CHECK_EQ(sc->c.cur, before);
}

/* Both sides encoded: hd__mpi_gidx_common marks exactly the positions
 * whose indices the other side holds too (a merge of the plain indices
 * says which), counts them, and, without masks, counts the same. */
static void check_common(scene_t *sc) {
    hd__mpi_gidx_t x[2];
    for (int s = 0; s < 2; s++) {
        CHECK_RC(hd__mpi_gidx_init(&sc->c, &x[s], &sc->rg, s, sc->n[s]), HD_OK);
        hd__mpi_gidx_put_indices(&x[s], 0, sc->g[s], sc->n[s]);
    }
    unsigned char *m[2], *want[2];
    size_t nc = 0;
    for (int s = 0; s < 2; s++) {
        m[s] = calloc(sc->n[s] + 1, 1);
        want[s] = calloc(sc->n[s] + 1, 1);
    }
    for (size_t i = 0, j = 0; i < sc->n[0] && j < sc->n[1];) {
        if (sc->g[0][i] == sc->g[1][j]) want[0][i++] = want[1][j++] = 1, nc++;
        else if (sc->g[0][i] < sc->g[1][j]) i++;
        else j++;
    }
    CHECK_EQ(hd__mpi_gidx_common(&x[0], &x[1], m[0], m[1]), nc);
    CHECK_EQ(hd__mpi_gidx_common(&x[0], &x[1], NULL, NULL), nc);
    for (int s = 0; s < 2; s++) {
        CHECK(memcmp(m[s], want[s], sc->n[s]) == 0);
        free(m[s]);
        free(want[s]);
        hd__mpi_gidx_free(&sc->c, &x[s]);
    }
}

static void check_scene(int K, const hd__mpi_range_t *runs, size_t nruns, double keep, uint64_t seed) {
    gen_rng_t rng;
    gen_seed(&rng, seed);
    scene_t sc;
    scene_make(&sc, K, runs, nruns, keep, &rng);
    for (int s = 0; s < 2 && !hdt_failed(); s++) {
        CONTEXT("seed=%llu K=%d runs=%zu keep=%g side=%d n=%zu", (unsigned long long)seed, K, nruns, keep, s,
                sc.n[s]);
        check_side(&sc, s, &rng);
    }
    if (!hdt_failed()) {
        CONTEXT("seed=%llu K=%d runs=%zu keep=%g: the indices both sides hold", (unsigned long long)seed, K, nruns,
                keep);
        check_common(&sc);
    }
    scene_free(&sc);
}

/* A copy's two sides: the same runs (each side's index runs the other's),
 * each rank's set a random part, as after a partition. */
TEST(the_indices_both_sides_hold_are_found_in_one_walk) {
    for (uint64_t seed = 200; seed < 230 && !hdt_failed(); seed++) {
        gen_rng_t rng;
        gen_seed(&rng, seed);
        int K = 1 + (int)(gen_u64(&rng) % 7);
        size_t nruns = 1 + gen_u64(&rng) % 6;
        hd__mpi_range_t runs[12];
        uint64_t at = gen_u64(&rng) % 2 ? 0 : gen_u64(&rng) >> 4;
        for (size_t i = 0; i < nruns; i++) {
            uint64_t len = 1 + gen_u64(&rng) % 5000, gap = gen_u64(&rng) % 2 ? 0 : gen_u64(&rng) % 100000;
            int r = (int)(gen_u64(&rng) % (uint64_t)K);
            runs[2 * i] = (hd__mpi_range_t){at, at + len - 1, 0, r};
            runs[2 * i + 1] = (hd__mpi_range_t){at, at + len - 1, 1, (r + K / 2) % K};
            at += len + gap;
        }
        double keep = seed % 3 == 0 ? 1.0 : 0.3 + 0.7 * gen_unit(&rng);
        check_scene(K, runs, 2 * nruns, keep, seed);
    }
}

TEST(an_empty_set_holds_nothing_and_frees_cleanly) {
    hd__mpi_range_t runs[] = {{0, 999, 0, 0}, {5, 5, 1, 1}};
    check_scene(2, runs, 2, 0.0, 1);
}

TEST(one_point_among_many_is_found) {
    gen_rng_t rng;
    gen_seed(&rng, 2);
    hd__mpi_range_t runs[] = {{100, 100099, 0, 0}, {0, 0, 1, 0}};
    scene_t sc;
    scene_make(&sc, 1, runs, 2, 0.0, &rng);
    sc.g[0][0] = 77777, sc.owner[0][0] = 0, sc.n[0] = 1; /* one point of A */
    CONTEXT("one point of A at 77777 of 100 .. 100099");
    check_side(&sc, 0, &rng);
    sc.g[0][0] = 100099; /* the last index of all */
    check_side(&sc, 0, &rng);
    sc.g[1][0] = 0, sc.owner[1][0] = 0, sc.n[1] = 1; /* B's only index */
    check_side(&sc, 1, &rng);
    scene_free(&sc);
}

TEST(all_points_of_a_side_on_one_rank_take_no_low_bits) {
    hd__mpi_range_t runs[] = {{0, 9999, 0, 0}, {10000, 20000, 0, 1}, {30000, 30000, 0, 0}, {0, 4095, 1, 1}};
    check_scene(2, runs, 4, 1.0, 3); /* every index of both sides: l = 0 */
}

TEST(sparse_huge_offsets_near_two_to_the_63_and_the_top) {
    uint64_t top = UINT64_MAX - 1; /* the largest index a part may hold */
    hd__mpi_range_t runs[] = {
        {(UINT64_C(1) << 63) - 1000, (UINT64_C(1) << 63) + 1000, 0, 2}, /* across 2^63 */
        {(UINT64_C(1) << 63) + 5000, (UINT64_C(1) << 63) + 5000, 0, 0}, /* a gap, one index */
        {UINT64_C(1) << 40, (UINT64_C(1) << 40) + 3000, 0, 1},
        {top - 2000, top, 0, 1},
        {0, 63, 0, 0},
        {(UINT64_C(1) << 62), (UINT64_C(1) << 62) + 9000, 1, 0},
        {top - 10, top, 1, 2},
    };
    for (uint64_t seed = 10; seed < 16; seed++) {
        double keep = seed == 10 ? 1.0 : 1.0 / (double)(1u << (seed - 10) * 2);
        check_scene(3, runs, sizeof runs / sizeof *runs, keep, seed);
    }
}

/* Random runs: K ranks, runs of random lengths and gaps (gaps up to 2^50),
 * owned by random ranks, kept at a random density. */
TEST(random_runs_and_densities_read_back_exactly) {
    for (uint64_t seed = 100; seed < 160 && !hdt_failed(); seed++) {
        gen_rng_t rng;
        gen_seed(&rng, seed);
        int K = 1 + (int)(gen_u64(&rng) % 9);
        size_t nruns = 1 + gen_u64(&rng) % 40, maxlen = 1 + gen_u64(&rng) % 3000;
        hd__mpi_range_t *runs = malloc(nruns * sizeof *runs);
        uint64_t at[2] = {gen_u64(&rng) % 2 ? 0 : gen_u64(&rng) >> 2, gen_u64(&rng) >> 3};
        for (size_t i = 0; i < nruns; i++) {
            int s = (int)(gen_u64(&rng) % 2);
            uint64_t len = 1 + gen_u64(&rng) % maxlen, gap = gen_u64(&rng) % 3 ? gen_u64(&rng) % 5 : gen_u64(&rng) >> 14;
            runs[i] = (hd__mpi_range_t){at[s], at[s] + len - 1, s, (int)(gen_u64(&rng) % (uint64_t)K)};
            at[s] += len + gap;
        }
        double keep = gen_u64(&rng) % 4 == 0 ? 1.0 : gen_unit(&rng) * gen_unit(&rng);
        check_scene(K, runs, nruns, keep, seed);
        free(runs);
    }
}
