/*
 * mpi_api.c -- hd_mpi_hausdorff (hausdorff_mpi.h) equals hd_hausdorff on
 * the union of every rank's points, bit for bit, witnesses, alpha and
 * disjoint included, however the points are spread over the ranks; and a
 * failure on one rank is the same failure, with the same message, on every
 * rank.  Run under mpirun with 1, 2, 3, 4 and 7 ranks (tests/mpi.cmake).
 *
 * Every rank generates the same sets from the same seed; each layout
 * (below) gives each rank some runs of them as parts; the reference is
 * hd_hausdorff on the whole sets, one thread, on every rank.  The cases are
 * the adversarial ones of issue 14: ties across region boundaries (integer
 * lattices, a half-step shifted copy), all points in one region (every
 * point equal; all on one plane), ranks with no points, one side on one
 * rank, a nearest neighbour two regions away (B far from most of A, and
 * absent from most regions), duplicates, 1e-9 and 1e9 scales.
 *
 * The harness is this file's own (tests/support/check.c has a main of its
 * own and knows nothing of ranks): a failure prints the rank, the case, the
 * layout and the seed; the ranks agree on the verdict, and rank 0 prints
 * "N passed, M failed".
 */
#include <hausdorff_mpi.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gen.h"
#include "mpicheck.h"

/* ---- layouts: which runs of each set a rank holds ------------------------ */

enum { LAY_BLOCKS, LAY_CHUNKS, LAY_ALL_ON_0, LAY_A_ON_LAST, LAY_HOLES, LAY_COUNT };
static const char *const lay_name[LAY_COUNT] = {"blocks", "chunks-of-7 round robin, parts reversed",
                                                "all on rank 0", "A on the last rank, B in blocks",
                                                "rank 1 empty, random runs"};

/* The parts of a set of n points (packed xyz) that this rank holds. */
static size_t layout(int how, int side, const double *xyz, size_t n, uint64_t seed, hd_mpi_part_t *parts,
                     size_t cap) {
    size_t np = 0;
    int K = K_, r = rank_;
    switch (how) {
    case LAY_BLOCKS: {
        size_t lo = n * (size_t)r / (size_t)K, hi = n * (size_t)(r + 1) / (size_t)K;
        parts[np++] = (hd_mpi_part_t){hd_points_f64(xyz + 3 * lo, hi - lo), lo};
        break;
    }
    case LAY_CHUNKS: {
        size_t w = n / 7 < cap - 1 ? 7 : n / (cap - 1) + 1; /* chunks of 7, fewer for large sets */
        for (size_t lo = 0, c = 0; lo < n; lo += w, c++)
            if ((int)(c % (size_t)K) == r) {
                size_t m = n - lo < w ? n - lo : w;
                parts[np++] = (hd_mpi_part_t){hd_points_f64(xyz + 3 * lo, m), lo};
            }
        for (size_t k = 0; k < np / 2; k++) { /* any order: the library sorts */
            hd_mpi_part_t t = parts[k];
            parts[k] = parts[np - 1 - k];
            parts[np - 1 - k] = t;
        }
        break;
    }
    case LAY_ALL_ON_0:
        if (r == 0) parts[np++] = (hd_mpi_part_t){hd_points_f64(xyz, n), 0};
        break;
    case LAY_A_ON_LAST:
        if (side == 0) {
            if (r == K - 1) parts[np++] = (hd_mpi_part_t){hd_points_f64(xyz, n), 0};
        } else {
            return layout(LAY_BLOCKS, side, xyz, n, seed, parts, cap);
        }
        break;
    case LAY_HOLES: { /* runs of random length to random ranks other than 1 */
        gen_rng_t g;
        gen_seed(&g, seed * 31 + (uint64_t)side);
        for (size_t lo = 0; lo < n;) {
            size_t m = 1 + (size_t)(gen_u64(&g) % 400);
            if (m > n - lo) m = n - lo;
            int to = (int)(gen_u64(&g) % (uint64_t)K);
            if (K > 1 && to == 1) to = 0;
            if (to == r && np < cap) parts[np++] = (hd_mpi_part_t){hd_points_f64(xyz + 3 * lo, m), lo};
            lo += m;
        }
        break;
    }
    }
    /* an empty part is allowed anywhere */
    if (np < cap) parts[np++] = (hd_mpi_part_t){hd_points_f64(xyz, 0), 12345};
    return np;
}

/* ---- data sets ---------------------------------------------------------- */

typedef struct {
    const char *name;
    double *a, *b;
    size_t na, nb;
} set_t;

enum {
    DS_UNIFORM, DS_LATTICE, DS_LATTICE_HALF, DS_ONE_POINT, DS_PLANE, DS_FAR_B, DS_CORNER_B, DS_DUPLICATES,
    DS_TINY, DS_HUGE, DS_NOISE, DS_DISJOINT, DS_CHECKER, DS_STRAY, DS_DEEP, DS_SMALL_LATTICE, DS_BIG_LATTICE,
    DS_BIG_UNIFORM, DS_BIG_SHIFTED, DS_COUNT
};

#define BIG 40000 /* points a side of the sets large enough for the partition's second samples */

static void make_set(int which, uint64_t seed, set_t *s) {
    gen_rng_t g;
    gen_seed(&g, seed);
    size_t n = 2000;
    s->na = n;
    s->nb = n;
    s->a = malloc(3 * BIG * sizeof(double)); /* the largest sets (DS_BIG_*) */
    s->b = malloc(3 * BIG * sizeof(double));
    switch (which) {
    case DS_UNIFORM:
        s->name = "uniform A and B";
        s->nb = 1500;
        gen_cube(&g, s->a, n, -1, 1);
        gen_cube(&g, s->b, s->nb, -1, 1);
        break;
    case DS_LATTICE:
        s->name = "integer lattice (ties across regions)";
        gen_lattice(&g, s->a, n, 12);
        gen_lattice(&g, s->b, n, 12);
        break;
    case DS_LATTICE_HALF:
        s->name = "lattice copy shifted half a step (ties with neighbours)";
        gen_copy(&g, GEN_COPY_LATTICE_HALF, s->a, s->b, n);
        break;
    case DS_ONE_POINT:
        s->name = "every point equal (all in one region)";
        for (size_t k = 0; k < 3 * n; k++) s->a[k] = 0.25, s->b[k] = 0.25;
        s->b[0] = 0.5; /* one B point elsewhere: h(B,A) > 0 */
        break;
    case DS_PLANE:
        s->name = "all points on the plane x = 1 (split keys tie on x)";
        gen_cube(&g, s->a, n, 0, 1);
        gen_cube(&g, s->b, n, 0, 1);
        for (size_t k = 0; k < n; k++) s->a[3 * k] = 1, s->b[3 * k] = 1;
        break;
    case DS_FAR_B:
        s->name = "B a small cluster far from A (nearest neighbours regions away)";
        s->nb = 40;
        gen_cube(&g, s->a, n, 0, 1);
        gen_cube(&g, s->b, s->nb, 5, 5.01);
        break;
    case DS_CORNER_B:
        s->name = "B in one corner of A's cube (most regions have no B)";
        gen_cube(&g, s->a, n, 0, 1);
        gen_cube(&g, s->b, n, 0, 0.1);
        break;
    case DS_DUPLICATES:
        s->name = "copy with repeated points";
        gen_copy(&g, GEN_COPY_DUPLICATES, s->a, s->b, n);
        break;
    case DS_TINY:
        s->name = "scale 1e-9";
        gen_copy(&g, GEN_COPY_NOISE, s->a, s->b, n);
        gen_affine(s->a, n, 1e-9, 0);
        gen_affine(s->b, n, 1e-9, 0);
        break;
    case DS_HUGE:
        s->name = "at 1e9 (copy moved far away)";
        gen_copy(&g, GEN_COPY_FAR, s->a, s->b, n);
        break;
    case DS_NOISE:
        s->name = "perturbed copy";
        gen_copy(&g, GEN_COPY_NOISE, s->a, s->b, n);
        break;
    case DS_CHECKER: {
        /* Every A point's nearest B points are its lattice neighbours at
         * distance 1, so h(A,B) = 1 is tied by every A point; the witness
         * is A[0] = (7, 8, 7) (mid-cube, where the first split falls) and
         * B[0] = (8, 8, 7), its neighbour across the middle plane: beyond
         * a region face exactly 1 away: a face at the distance does not
         * confirm a point. */
        s->name = "checkerboard lattice (every A point ties, across faces)";
        size_t na = 0, nb = 0;
        for (int x = 0; x < 16; x++)
            for (int y = 0; y < 16; y++)
                for (int z = 0; z < 16; z++) {
                    double *to = (x + y + z) % 2 ? s->b + 3 * nb++ : s->a + 3 * na++;
                    to[0] = x, to[1] = y, to[2] = z;
                }
        s->na = na;
        s->nb = nb;
        for (size_t k = na - 1; k > 0; k--) gen_swap(s->a, k, (size_t)(gen_u64(&g) % (k + 1)));
        for (size_t k = nb - 1; k > 0; k--) gen_swap(s->b, k, (size_t)(gen_u64(&g) % (k + 1)));
        for (size_t k = 0; k < na; k++)
            if (s->a[3 * k] == 7 && s->a[3 * k + 1] == 8 && s->a[3 * k + 2] == 7) gen_swap(s->a, 0, k);
        for (size_t k = 0; k < nb; k++) /* its neighbour across the middle, B[0] */
            if (s->b[3 * k] == 8 && s->b[3 * k + 1] == 8 && s->b[3 * k + 2] == 7) gen_swap(s->b, 0, k);
        break;
    }
    case DS_STRAY: {
        /* A copy (|A| = |B|, B[g] = A[g] + 1e-3 noise) of a 20^3 lattice
         * whose every point is in A twice (g and g + 8000), so that the
         * ranks' correspondence pass runs; but B[c] and B[c + 8000] are
         * moved 0.3 off A[c] = (2, 2, 2), which makes A[c] the pairs'
         * farthest point, and B[s], the partner of the far A[s] =
         * (17, 17, 17), sits 0.1 from A[c]: a point of B whose partner is on
         * another rank, nearer to the pairs' witness than its pairs.  So
         * h(A,B) = 0.1 at A[c], not the pairs' 0.3. */
        s->name = "copy whose farthest pair has a nearer point paired elsewhere";
        size_t N = 8000, c = 0, f = 0, k = 0;
        for (int x = 0; x < 20; x++)
            for (int y = 0; y < 20; y++)
                for (int z = 0; z < 20; z++, k++) {
                    s->a[3 * k] = x, s->a[3 * k + 1] = y, s->a[3 * k + 2] = z;
                    if (x == 2 && y == 2 && z == 2) c = k;
                    if (x == 17 && y == 17 && z == 17) f = k;
                }
        memcpy(s->a + 3 * N, s->a, 3 * N * sizeof(double));
        s->na = s->nb = 2 * N;
        for (size_t q = 0; q < 3 * s->na; q++) s->b[q] = s->a[q] + 1e-3 * gen_normal(&g);
        s->b[3 * c + 1] = 2.3, s->b[3 * c] = 2, s->b[3 * c + 2] = 2;
        s->b[3 * (c + N) + 1] = 1.7, s->b[3 * (c + N)] = 2, s->b[3 * (c + N) + 2] = 2;
        s->b[3 * f] = 2.1, s->b[3 * f + 1] = 2, s->b[3 * f + 2] = 2;
        break;
    }
    case DS_DEEP: {
        /* A and B sampled on the strip [0, 4] x [0, 1] of the plane z = 0
         * (the first cut falls near x = 2), with A[0] = (1.5, 0.5, 5) above
         * it and B[0] = (5.5, 0.5, 5) beside that, 4 away: nearer than the
         * plane (5), in another region and deep inside it.  A[0] is
         * forwarded, and the answering rank's slab (the strip's points near
         * its face) gives the plane; only the comparison with every point
         * of its B finds B[0] (and likewise B[0]'s query finds A[0]). */
        s->name = "forwarded query whose nearest lies deep in another region";
        for (size_t k = 0; k < n; k++) {
            s->a[3 * k] = 4 * gen_unit(&g), s->a[3 * k + 1] = gen_unit(&g), s->a[3 * k + 2] = 0;
            s->b[3 * k] = 4 * gen_unit(&g), s->b[3 * k + 1] = gen_unit(&g), s->b[3 * k + 2] = 0;
        }
        s->a[0] = 1.5, s->a[1] = 0.5, s->a[2] = 5;
        s->b[0] = 5.5, s->b[1] = 0.5, s->b[2] = 5;
        break;
    }
    case DS_SMALL_LATTICE:
        /* Run over many seeds: every distance is the root of a small
         * integer, so most points tie with many others, across faces, in
         * the interior and in the shell, in both directions. */
        s->name = "small lattice, ties everywhere";
        s->na = s->nb = 400;
        gen_lattice(&g, s->a, s->na, 7);
        gen_lattice(&g, s->b, s->nb, 7);
        break;
    case DS_BIG_LATTICE:
        /* Enough points (at 7 ranks too) that the partition refines its
         * splits by its second samples (src/mpi/rcb.c, refine), whose
         * planes fall between or on the lattice's: ties across them. */
        s->name = "large integer lattice (refined splits, ties across them)";
        s->na = s->nb = BIG;
        gen_lattice(&g, s->a, s->na, 24);
        gen_lattice(&g, s->b, s->nb, 24);
        break;
    case DS_BIG_UNIFORM:
        s->name = "large uniform A and B (refined splits)";
        s->na = s->nb = BIG;
        gen_cube(&g, s->a, s->na, -1, 1);
        gen_cube(&g, s->b, s->nb, -1, 1);
        break;
    case DS_BIG_SHIFTED:
        /* h is a third of the cube, larger than a region at K >= 2, so most
         * points are in the shells: each rank searches them in several
         * batches (src/mpi/slab.c, slab_search: at least 4096 a batch). */
        s->name = "large uniform B moved by a third of the cube (shells of most points, in batches)";
        s->na = s->nb = BIG;
        gen_cube(&g, s->a, s->na, -1, 1);
        gen_cube(&g, s->b, s->nb, -1 + 2.0 / 3, 1 + 2.0 / 3);
        break;
    case DS_DISJOINT:
        s->name = "disjoint boxes";
        gen_cube(&g, s->a, n, 0, 1);
        gen_cube(&g, s->b, n, 2, 3);
        break;
    }
}

/* ---- the checks --------------------------------------------------------- */

/* A case: the set, the context printed on failure, one thread. */
static void open_case(const char *call, int which, int how, uint64_t seed, set_t *s, hd_options_t *opt) {
    make_set(which, seed, s);
    snprintf(context_, sizeof context_, "%s: set \"%s\", layout \"%s\", seed %llu", call, s->name, lay_name[how],
             (unsigned long long)seed);
    hd_options_init(opt);
    opt->threads = 1;
}

/* The MPI calls' options around the engine's `opt` (the cells on).  A
 * tiny side is not replicated: these sets test the partition's course
 * (a small cluster far away would be replicated by default);
 * tests/api/mpi_tiny.c tests the replicated one. */
static hd_mpi_options_t mpi_opt(const hd_options_t *opt) {
    hd_mpi_options_t m;
    hd_mpi_options_init(&m);
    m.engine = *opt;
    m.replicate = 0;
    return m;
}

static void check_equal(int which, int how, uint64_t seed) {
    set_t s = {"", NULL, NULL, 0, 0};
    hd_options_t opt;
    open_case("hausdorff", which, how, seed, &s, &opt);
    hd_mpi_options_t mo = mpi_opt(&opt);
    hd_points_t A = hd_points_f64(s.a, s.na), B = hd_points_f64(s.b, s.nb);
    hd_symmetric_t ref, got;
    hd_error_t err;
    int rc = hd_hausdorff(&A, &B, &opt, &ref, &err);
    CHECK(rc == HD_OK);
    hd_mpi_part_t pa[400], pb[400];
    size_t na = layout(how, 0, s.a, s.na, seed, pa, 400), nb = layout(how, 1, s.b, s.nb, seed, pb, 400);
    unsigned long long held[2] = {0, 0}, all[2];
    for (size_t k = 0; k < na; k++) held[0] += pa[k].points.count;
    for (size_t k = 0; k < nb; k++) held[1] += pb[k].points.count;
    MPI_Allreduce(held, all, 2, MPI_UNSIGNED_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    CHECK(all[0] == s.na && all[1] == s.nb); /* the layout gave every point out once */
    hd_mpi_stats_t st;
    rc = hd_mpi_hausdorff(MPI_COMM_WORLD, pa, na, pb, nb, &mo, &got, &st, &err);
    CHECK(rc == HD_OK);
    if (rc != HD_OK) fprintf(stderr, "rank %d: %s\n", rank_, err.message);
    CHECK(SAME_BITS(got.distance, ref.distance));
    CHECK(SAME_BITS(got.ab.distance2, ref.ab.distance2));
    CHECK(SAME_BITS(got.ba.distance2, ref.ba.distance2));
    CHECK(SAME_BITS(got.ab.distance, ref.ab.distance));
    CHECK(got.ab.i == ref.ab.i && got.ab.j == ref.ab.j);
    CHECK(got.ba.i == ref.ba.i && got.ba.j == ref.ba.j);
    CHECK(SAME_BITS(got.alpha, ref.alpha));
    CHECK(got.disjoint == ref.disjoint);
    CHECK(st.points == s.na + s.nb && st.ranks == K_ && st.rounds == (K_ > 1 ? 4 : 0));
    if (got.ab.i != ref.ab.i || got.ab.j != ref.ab.j || got.ba.i != ref.ba.i || got.ba.j != ref.ba.j ||
        !SAME_BITS(got.distance, ref.distance))
        fprintf(stderr, "rank %d: got ab %.17g (%zu,%zu) ba %.17g (%zu,%zu); expected ab %.17g (%zu,%zu) ba "
                        "%.17g (%zu,%zu)\n",
                rank_, got.ab.distance, got.ab.i, got.ab.j, got.ba.distance, got.ba.i, got.ba.j,
                ref.ab.distance, ref.ab.i, ref.ab.j, ref.ba.distance, ref.ba.i, ref.ba.j);
    /* the directed call too (its engine pass is its own: shell.c), on
     * every layout; the overlap on one */
    hd_result_t dr;
    rc = hd_mpi_directed(MPI_COMM_WORLD, pa, na, pb, nb, &mo, &dr, NULL, &err);
    CHECK(rc == HD_OK);
    CHECK(SAME_BITS(dr.distance2, ref.ab.distance2) && dr.i == ref.ab.i && dr.j == ref.ab.j);
    if (how == LAY_HOLES) {
        double alpha = -1;
        int disjoint = -1;
        CHECK(hd_mpi_overlap(MPI_COMM_WORLD, pa, na, pb, nb, &alpha, &disjoint, &err) == HD_OK);
        CHECK(SAME_BITS(alpha, ref.alpha) && disjoint == ref.disjoint);
    }
    free(s.a);
    free(s.b);
}

/* hd_mpi_distances gives every rank, for its own points in the order of
 * its parts, what hd_distances gives on the whole sets: the distances to
 * the bit and the smallest nearest index, both directions; and each
 * direction alone (the other's outputs NULL on every rank). */
static size_t gather_expected(const hd_mpi_part_t *parts, size_t np, const double *ref_d, const size_t *ref_n,
                              double *d, size_t *n) {
    size_t t = 0;
    for (size_t p = 0; p < np; p++)
        for (size_t k = 0; k < parts[p].points.count; k++, t++) {
            d[t] = ref_d[parts[p].offset + k];
            n[t] = ref_n[parts[p].offset + k];
        }
    return t;
}

static int same_answers(const double *d, const size_t *n, const double *ed, const size_t *en, size_t m,
                        const char *what) {
    for (size_t k = 0; k < m; k++)
        if (memcmp(&d[k], &ed[k], sizeof(double)) != 0 || n[k] != en[k]) {
            fprintf(stderr, "rank %d: %s: point %zu of %zu: got %.17g [%zu], expected %.17g [%zu]\n", rank_, what, k,
                    m, d[k], n[k], ed[k], en[k]);
            return 0;
        }
    return 1;
}

static void check_distances(int which, int how, uint64_t seed) {
    set_t s = {"", NULL, NULL, 0, 0};
    hd_options_t opt;
    open_case("distances", which, how, seed, &s, &opt);
    hd_mpi_options_t mo = mpi_opt(&opt);
    hd_points_t A = hd_points_f64(s.a, s.na), B = hd_points_f64(s.b, s.nb);
    double *rd_ab = malloc(s.na * sizeof(double)), *rd_ba = malloc(s.nb * sizeof(double));
    size_t *rn_ab = malloc(s.na * sizeof(size_t)), *rn_ba = malloc(s.nb * sizeof(size_t));
    hd_error_t err;
    CHECK(hd_distances(&A, &B, &opt, rd_ab, rn_ab, rd_ba, rn_ba, &err) == HD_OK);
    hd_mpi_part_t pa[400], pb[400];
    size_t na = layout(how, 0, s.a, s.na, seed, pa, 400), nb = layout(how, 1, s.b, s.nb, seed, pb, 400);
    /* this rank's expected answers, and room for the call's */
    double *ed_ab = malloc((s.na + 1) * sizeof(double)), *ed_ba = malloc((s.nb + 1) * sizeof(double));
    size_t *en_ab = malloc((s.na + 1) * sizeof(size_t)), *en_ba = malloc((s.nb + 1) * sizeof(size_t));
    double *d_ab = malloc((s.na + 1) * sizeof(double)), *d_ba = malloc((s.nb + 1) * sizeof(double));
    size_t *n_ab = malloc((s.na + 1) * sizeof(size_t)), *n_ba = malloc((s.nb + 1) * sizeof(size_t));
    size_t ma = gather_expected(pa, na, rd_ab, rn_ab, ed_ab, en_ab), mb = gather_expected(pb, nb, rd_ba, rn_ba, ed_ba, en_ba);
    hd_mpi_stats_t st;
    int rc = hd_mpi_distances(MPI_COMM_WORLD, pa, na, pb, nb, &mo, d_ab, n_ab, d_ba, n_ba, &st, &err);
    CHECK(rc == HD_OK);
    if (rc != HD_OK) fprintf(stderr, "rank %d: %s\n", rank_, err.message);
    CHECK(same_answers(d_ab, n_ab, ed_ab, en_ab, ma, "A to B"));
    CHECK(same_answers(d_ba, n_ba, ed_ba, en_ba, mb, "B to A"));
    CHECK(st.points == s.na + s.nb && st.ranks == K_ && st.rounds == (K_ > 1 ? 2 : 0));
    /* one direction at a time, on two layouts: the other's outputs NULL */
    if (how == LAY_HOLES || how == LAY_CHUNKS) {
        memset(d_ab, 0, (s.na + 1) * sizeof(double));
        memset(n_ba, 0, (s.nb + 1) * sizeof(size_t));
        CHECK(hd_mpi_distances(MPI_COMM_WORLD, pa, na, pb, nb, &mo, d_ab, NULL, NULL, NULL, &st, &err) == HD_OK);
        CHECK(st.rounds == (K_ > 1 ? 1 : 0));
        for (size_t k = 0; k < ma; k++) n_ab[k] = en_ab[k];
        CHECK(same_answers(d_ab, n_ab, ed_ab, en_ab, ma, "A to B alone"));
        CHECK(hd_mpi_distances(MPI_COMM_WORLD, pa, na, pb, nb, &mo, NULL, NULL, NULL, n_ba, &st, &err) == HD_OK);
        for (size_t k = 0; k < mb; k++) d_ba[k] = ed_ba[k];
        CHECK(same_answers(d_ba, n_ba, ed_ba, en_ba, mb, "B to A alone"));
    }
    /* a direction runs when any rank asks for it: rank 0 does not ask for
     * B's answers, the others get theirs */
    if (how == LAY_BLOCKS) {
        memset(n_ba, 0, (s.nb + 1) * sizeof(size_t));
        int r0 = rank_ == 0;
        CHECK(hd_mpi_distances(MPI_COMM_WORLD, pa, na, pb, nb, &mo, d_ab, n_ab, r0 ? NULL : d_ba, r0 ? NULL : n_ba,
                               &st, &err) == HD_OK);
        CHECK(st.rounds == (K_ > 1 ? 2 : 0));
        CHECK(same_answers(d_ab, n_ab, ed_ab, en_ab, ma, "A to B, B to A asked by some ranks"));
        if (!r0) CHECK(same_answers(d_ba, n_ba, ed_ba, en_ba, mb, "B to A asked by some ranks"));
    }
    free(rd_ab), free(rd_ba), free(rn_ab), free(rn_ba);
    free(ed_ab), free(ed_ba), free(en_ab), free(en_ba);
    free(d_ab), free(d_ba), free(n_ab), free(n_ba);
    free(s.a);
    free(s.b);
}

static void check_errors(void) {
    double a[30], b[30];
    for (int k = 0; k < 30; k++) a[k] = k, b[k] = k + 0.5;
    int bad = K_ - 1; /* the rank with the bad input */
    hd_mpi_part_t pa = {hd_points_f64(a, 10), 10 * (size_t)rank_}, pb = {hd_points_f64(b, 10), 10 * (size_t)rank_};
    hd_error_t err;
    hd_symmetric_t r;

    snprintf(context_, sizeof context_, "a NaN on rank %d only", bad);
    double nan_a[30];
    memcpy(nan_a, a, sizeof a);
    if (rank_ == bad) nan_a[7] = NAN;
    hd_mpi_part_t pn = {hd_points_f64(nan_a, 10), 10 * (size_t)rank_};
    check_agreed(hd_mpi_hausdorff(MPI_COMM_WORLD, &pn, 1, &pb, 1, NULL, &r, NULL, &err), HD_ENONFINITE, &err,
                 "rank");

    snprintf(context_, sizeof context_, "a coordinate of 1e200 on rank %d only", bad);
    double big[30];
    memcpy(big, b, sizeof b);
    if (rank_ == bad) big[4] = 1e200;
    hd_mpi_part_t pbig = {hd_points_f64(big, 10), 10 * (size_t)rank_};
    check_agreed(hd_mpi_hausdorff(MPI_COMM_WORLD, &pa, 1, &pbig, 1, NULL, &r, NULL, &err), HD_ERANGE, &err,
                 "B (part 0");

    snprintf(context_, sizeof context_, "threads = -1 on rank %d only", bad);
    hd_options_t opt;
    hd_options_init(&opt);
    opt.threads = rank_ == bad ? -1 : 1;
    hd_mpi_options_t mo = mpi_opt(&opt);
    check_agreed(hd_mpi_hausdorff(MPI_COMM_WORLD, &pa, 1, &pb, 1, &mo, &r, NULL, &err), HD_EINVAL, &err,
                 "threads");

    snprintf(context_, sizeof context_, "B's parts share indices across ranks");
    hd_mpi_part_t same = {hd_points_f64(b, 10), rank_ == bad ? 5 : 10 * (size_t)rank_};
    if (K_ > 1)
        check_agreed(hd_mpi_hausdorff(MPI_COMM_WORLD, &pa, 1, &same, 1, NULL, &r, NULL, &err), HD_EINVAL, &err,
                     "share indices");
    hd_mpi_part_t twice[2] = {pb, pb};
    check_agreed(hd_mpi_hausdorff(MPI_COMM_WORLD, &pa, 1, twice, 2, NULL, &r, NULL, &err), HD_EINVAL, &err,
                 "share indices");

    snprintf(context_, sizeof context_, "B empty on every rank");
    check_agreed(hd_mpi_hausdorff(MPI_COMM_WORLD, &pa, 1, NULL, 0, NULL, &r, NULL, &err), HD_EEMPTY, &err,
                 "point set B is empty");

    snprintf(context_, sizeof context_, "result NULL on rank %d only", bad);
    check_agreed(hd_mpi_hausdorff(MPI_COMM_WORLD, &pa, 1, &pb, 1, NULL, rank_ == bad ? NULL : &r, NULL, &err),
                 HD_EINVAL, &err, "NULL");

    /* More than 2^32 - 1 points of a set on one rank (the exchange numbers
     * them in 4 bytes): refused before a point is read, so the view's
     * buffer need not hold them (the sanitizer build would see a read). */
    snprintf(context_, sizeof context_, "2^32 points of A on rank %d only", bad);
    hd_mpi_part_t huge[2] = {{hd_points_f64(a, (size_t)1 << 31), 1000}, {hd_points_f64(a, (size_t)1 << 31), 1000 + ((size_t)1 << 31)}};
    check_agreed(hd_mpi_hausdorff(MPI_COMM_WORLD, rank_ == bad ? huge : &pa, rank_ == bad ? 2 : 1, &pb, 1, NULL, &r,
                                  NULL, &err),
                 HD_ERANGE, &err, "more than 2^32 - 1 points");

    /* hd_mpi_distances agrees on failures the same way */
    double dd[10];
    size_t nn[10];
    snprintf(context_, sizeof context_, "distances: a NaN on rank %d only", bad);
    check_agreed(hd_mpi_distances(MPI_COMM_WORLD, &pn, 1, &pb, 1, NULL, dd, nn, NULL, NULL, NULL, &err),
                 HD_ENONFINITE, &err, "rank");
    snprintf(context_, sizeof context_, "distances: B empty on every rank");
    check_agreed(hd_mpi_distances(MPI_COMM_WORLD, &pa, 1, NULL, 0, NULL, dd, nn, NULL, NULL, NULL, &err), HD_EEMPTY,
                 &err, "point set B is empty");
    snprintf(context_, sizeof context_, "distances: threads = -1 on rank %d only", bad);
    check_agreed(hd_mpi_distances(MPI_COMM_WORLD, &pa, 1, &pb, 1, &mo, dd, nn, NULL, NULL, NULL, &err), HD_EINVAL,
                 &err, "threads");

    /* and after all that, a good call still works */
    snprintf(context_, sizeof context_, "a good call after the failures");
    CHECK(hd_mpi_hausdorff(MPI_COMM_WORLD, &pa, 1, &pb, 1, NULL, &r, NULL, &err) == HD_OK);
    CHECK(r.ab.distance2 == 0.75 && r.ab.i == 0 && r.ab.j == 0);
    /* every rank holds the same ten points of each set: A's point k is
     * nearest to B's point k of every rank, and rank 0's has the smallest
     * index */
    CHECK(hd_mpi_distances(MPI_COMM_WORLD, &pa, 1, &pb, 1, NULL, dd, nn, NULL, NULL, NULL, &err) == HD_OK);
    for (size_t k = 0; k < 10; k++) CHECK(dd[k] == sqrt(0.75) && nn[k] == k);
}

/* On one rank the call copies no point: a set given as one part, of any
 * layout (floats here), goes to the engine as it is, so the call's own
 * peak is the engine's (charged at its measured peak) and a few small
 * tables; a copy would be 24 bytes a point more, as it was before. */
static void check_single_rank_copies_nothing(void) {
    if (K_ != 1) return;
    uint64_t seed = 77;
    gen_rng_t g;
    gen_seed(&g, seed);
    size_t n = 3000;
    double *a = malloc(3 * n * sizeof(double)), *b = malloc(3 * n * sizeof(double));
    float *af = malloc(3 * n * sizeof(float)), *bf = malloc(3 * n * sizeof(float));
    gen_cube(&g, a, n, -1, 1);
    gen_cube(&g, b, n, -1, 1);
    for (size_t k = 0; k < 3 * n; k++) af[k] = (float)a[k], bf[k] = (float)b[k];
    snprintf(context_, sizeof context_, "one rank, float views, seed %llu", (unsigned long long)seed);
    hd_points_t A = hd_points_f32(af, n), B = hd_points_f32(bf, n);
    hd_symmetric_t ref, got;
    hd_error_t err;
    CHECK(hd_hausdorff(&A, &B, NULL, &ref, &err) == HD_OK);
    hd_mpi_part_t pa = {A, 500}, pb = {B, 9000};
    hd_mpi_stats_t st;
    CHECK(hd_mpi_hausdorff(MPI_COMM_WORLD, &pa, 1, &pb, 1, NULL, &got, &st, &err) == HD_OK);
    CHECK(SAME_BITS(got.distance, ref.distance) && SAME_BITS(got.ab.distance2, ref.ab.distance2) &&
          SAME_BITS(got.ba.distance2, ref.ba.distance2));
    CHECK(got.ab.i == ref.ab.i + 500 && got.ab.j == ref.ab.j + 9000);
    CHECK(got.ba.i == ref.ba.i + 9000 && got.ba.j == ref.ba.j + 500);
    CHECK(st.peak_bytes < 20 * 2 * n && st.bytes_partition == 0 && st.rounds == 0);
    if (st.peak_bytes >= 20 * 2 * n) fprintf(stderr, "peak %llu bytes\n", (unsigned long long)st.peak_bytes);
    free(a);
    free(b);
    free(af);
    free(bf);
}

/* Views of any layout travel as packed doubles do: here floats in records
 * of four (x, y, z and a weight: a stride of 16 bytes, read point by point
 * rather than in place), A's in blocks by rank and B's in reverse rank
 * order, large enough for several exchange rounds.  Coordinates are
 * integers, exact in floats, so the reference is hd_hausdorff on doubles. */
static void check_strided_views_over_ranks(void) {
    uint64_t seed = 91;
    gen_rng_t g;
    gen_seed(&g, seed);
    size_t n = 24000;
    double *a = malloc(3 * n * sizeof(double)), *b = malloc(3 * n * sizeof(double));
    float *af = malloc(4 * n * sizeof(float)), *bf = malloc(4 * n * sizeof(float));
    for (size_t k = 0; k < 3 * n; k++) {
        a[k] = (double)((int)(gen_u64(&g) % 101) - 50);
        b[k] = (double)((int)(gen_u64(&g) % 101) - 50);
    }
    for (size_t k = 0; k < n; k++)
        for (int c = 0; c < 4; c++) {
            af[4 * k + c] = c < 3 ? (float)a[3 * k + c] : 1.0f;
            bf[4 * k + c] = c < 3 ? (float)b[3 * k + c] : 1.0f;
        }
    snprintf(context_, sizeof context_, "strided float views over %d ranks, seed %llu", K_,
             (unsigned long long)seed);
    hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
    hd_symmetric_t ref, got;
    hd_error_t err;
    CHECK(hd_hausdorff(&A, &B, NULL, &ref, &err) == HD_OK);
    size_t a0 = n * (size_t)rank_ / (size_t)K_, a1 = n * ((size_t)rank_ + 1) / (size_t)K_;
    size_t rb = (size_t)(K_ - 1 - rank_), b0 = n * rb / (size_t)K_, b1 = n * (rb + 1) / (size_t)K_;
    hd_points_t va = {af + 4 * a0, a1 - a0, HD_FLOAT32, 4 * sizeof(float), sizeof(float)};
    hd_points_t vb = {bf + 4 * b0, b1 - b0, HD_FLOAT32, 4 * sizeof(float), sizeof(float)};
    hd_mpi_part_t pa = {va, a0}, pb = {vb, b0};
    CHECK(hd_mpi_hausdorff(MPI_COMM_WORLD, &pa, 1, &pb, 1, NULL, &got, NULL, &err) == HD_OK);
    CHECK(SAME_BITS(got.distance, ref.distance) && SAME_BITS(got.ab.distance2, ref.ab.distance2) &&
          SAME_BITS(got.ba.distance2, ref.ba.distance2));
    CHECK(got.ab.i == ref.ab.i && got.ab.j == ref.ab.j && got.ba.i == ref.ba.i && got.ba.j == ref.ba.j);
    free(a);
    free(b);
    free(af);
    free(bf);
}

/* Two independent sets, each rank holding the same index range of both,
 * and that range a strip of space, as ranks reading their tiles of two
 * epochs do: every point's partner by index is on its rank, yet the sets
 * are no copy.  The answer is the single process's, and only the points
 * the engine refused are searched one by one; taken for pairs (by their
 * indices alone, as before 2026-11-29), the engine ran unfiltered and the
 * points within h of a face were searched too, several percent of them. */
static void check_independent_tiles_are_not_pairs(void) {
    if (K_ < 2) return;
    size_t n = BIG;
    double *a = malloc(n * 3 * sizeof *a), *b = malloc(n * 3 * sizeof *b);
    if (!a || !b) abort();
    gen_rng_t g;
    gen_seed(&g, 77);
    for (int side = 0; side < 2; side++) {
        double *x = side ? b : a;
        for (size_t i = 0; i < n; i++) { /* x grows with the index, blurred by 0.1: block r is
                                            * about the strip r (exactly, and each rank's sets would
                                            * be whole sets in one order, which the engine judges) */
            x[3 * i] = 2.0 * K_ * (double)i / (double)n + 0.1 * gen_unit(&g);
            x[3 * i + 1] = gen_unit(&g);
            x[3 * i + 2] = gen_unit(&g);
        }
    }
    snprintf(context_, sizeof context_, "independent sets in strips over %d ranks, seed 77", K_);
    hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
    hd_symmetric_t ref, got;
    hd_error_t err;
    CHECK(hd_hausdorff(&A, &B, NULL, &ref, &err) == HD_OK);
    hd_mpi_part_t pa[2], pb[2];
    size_t na = layout(LAY_BLOCKS, 0, a, n, 77, pa, 2), nb = layout(LAY_BLOCKS, 1, b, n, 77, pb, 2);
    hd_mpi_stats_t st;
    CHECK(hd_mpi_hausdorff(MPI_COMM_WORLD, pa, na, pb, nb, NULL, &got, &st, &err) == HD_OK);
    CHECK(SAME_BITS(got.distance, ref.distance) && got.ab.i == ref.ab.i && got.ab.j == ref.ab.j &&
          got.ba.i == ref.ba.i && got.ba.j == ref.ba.j);
    CHECK(st.shell_points * 100 < 2 * n); /* under 1 % */
    if (st.shell_points * 100 >= 2 * n) fprintf(stderr, "shell %llu points\n", (unsigned long long)st.shell_points);
    free(a);
    free(b);
}

/* One call on the large uniform sets in layout `how`, its figures in *st. */
static void call_big_uniform(const char *what, int how, hd_mpi_stats_t *st) {
    uint64_t seed = 1000 + DS_BIG_UNIFORM;
    set_t s = {"", NULL, NULL, 0, 0};
    hd_options_t opt;
    open_case(what, DS_BIG_UNIFORM, how, seed, &s, &opt);
    hd_mpi_options_t mo = mpi_opt(&opt);
    hd_mpi_part_t pa[64], pb[64];
    size_t na = layout(how, 0, s.a, s.na, seed, pa, 64), nb = layout(how, 1, s.b, s.nb, seed, pb, 64);
    hd_symmetric_t got;
    hd_error_t err;
    CHECK(hd_mpi_hausdorff(MPI_COMM_WORLD, pa, na, pb, nb, &mo, &got, st, &err) == HD_OK);
    free(s.a);
    free(s.b);
}

/* The partition gives every rank its share of the points within 2 %:
 * the first samples (1024 a rank) alone leave the largest region a few
 * percent above its share, the second samples' exact counts move each
 * split to within a fraction of one.  Blocks of a uniform set over the
 * ranks, 80K points in all. */
static void check_partition_balances(void) {
    if (K_ < 2) return;
    hd_mpi_stats_t st;
    call_big_uniform("balance", LAY_BLOCKS, &st);
    CHECK(st.imbalance >= 1.0 && st.imbalance <= 1.02);
    if (st.imbalance > 1.02) fprintf(stderr, "rank %d: imbalance %.4f\n", rank_, st.imbalance);
}

/* Each rank's own figures (its points, peak, search and bookkeeping CPU)
 * are the ones whose maxima over the ranks the call reports. */
static void check_own_figures_make_the_maxima(void) {
    hd_mpi_stats_t st;
    call_big_uniform("own figures", LAY_CHUNKS, &st);
    double mine[3] = {st.search_cpu, st.other_cpu, st.search_seconds}, most[3];
    uint64_t own[2] = {st.local_points, st.peak_bytes}, omost[2];
    MPI_Allreduce(mine, most, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(own, omost, 2, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD);
    CHECK(st.search_cpu >= 0 && st.search_cpu <= st.search_cpu_max);
    CHECK(most[0] == st.search_cpu_max && most[1] == st.other_cpu_max && most[2] == st.search_seconds_max);
    CHECK(omost[0] == st.points_max && omost[1] == st.peak_bytes_max);
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &K_);
    const char *only = argc > 1 ? argv[1] : NULL; /* "errors" or a set number */
    if (!only || strcmp(only, "errors") == 0) check_errors();
    if (!only) check_single_rank_copies_nothing();
    if (!only) check_strided_views_over_ranks();
    if (!only) check_own_figures_make_the_maxima();
    if (!only) check_partition_balances();
    if (!only) check_independent_tiles_are_not_pairs();
    for (int which = 0; which < DS_COUNT; which++) {
        if (only && strcmp(only, "errors") != 0 && atoi(only) != which) continue;
        if (only && strcmp(only, "errors") == 0) break;
        for (int how = 0; how < LAY_COUNT; how++) check_equal(which, how, 1000 + (uint64_t)which);
        for (uint64_t seed = 1; which == DS_SMALL_LATTICE && seed < 60; seed++)
            check_equal(which, (int)(seed % LAY_COUNT), 5000 + seed);
        for (int how = 0; how < LAY_COUNT; how++) check_distances(which, how, 1000 + (uint64_t)which);
    }
    return mpicheck_finish("mpi_api");
}
