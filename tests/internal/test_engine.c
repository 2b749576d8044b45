/*
 * test_engine.c -- the `auto` engine gives the brute force's answer, bit for
 * bit, with the brute force's witness, at one thread and at three.
 *
 * Every case runs through the public calls (the engine choosing its path)
 * and through each of the engine's two paths, the grid pass and the bucket
 * trees, forced.  Thousands of seeded cases cover what makes the engine's
 * shortcuts
 * delicate: lattice ties (many points at exactly the maximum), duplicates,
 * nearly identical clouds and translated copies (every nearest distance
 * within a rounding of the maximum, so the quantised approximations cannot
 * decide and exact reads must), sizes 1:1000, far offsets (1e9) and tiny
 * scales (1e-9), float32 and strided views, and sets large enough for many
 * buckets, tree levels and tasks.  The grid pass also runs alone on
 * lattices whose points lie on its cells' faces and tie at the maximum,
 * where it must discard whole cells (and does, exactly, only with the
 * cells' margin and a strict proof).
 */
#include "brute.h"
#include "check.h"
#include "gen.h"
#include "engine/engine.h"
#include "engine/grid.h" /* white-box: the grid pass, the maximum, the tree kernels */
#include "engine/tree.h"

#include <math.h>
#include <stdlib.h>

/* The kinds of pairs (A, B) the random cases draw from. */
enum {
    K_OVERLAP, K_DISJOINT, K_PARTIAL, K_LATTICE, K_DUPLICATES, K_PERTURBED, K_TRANSLATED,
    K_FAR, K_TINY, K_PLANE_LINE, K_CUBE, K_COUNT
};
static const char *const kind_name[K_COUNT] = {
    "overlap", "disjoint", "partial", "lattice", "duplicates", "perturbed", "translated",
    "far-offset", "tiny-scale", "plane-line", "cube",
};

static void make_pair(gen_rng_t *g, int kind, double *a, size_t na, double *b, size_t nb) {
    double m0[3] = {0, 0, 0}, m1[3] = {0, 0, 0};
    switch (kind) {
    case K_OVERLAP:
        gen_gauss(g, a, na, m0, 1.0);
        gen_gauss(g, b, nb, m0, 1.0);
        break;
    case K_DISJOINT:
        m1[0] = 20;
        gen_gauss(g, a, na, m0, 1.0);
        gen_gauss(g, b, nb, m1, 1.0);
        break;
    case K_PARTIAL:
        m1[1] = 2;
        gen_gauss(g, a, na, m0, 1.0);
        gen_gauss(g, b, nb, m1, 1.0);
        break;
    case K_LATTICE: {
        int side = 2 + (int)(gen_u64(g) % 9);
        gen_lattice(g, a, na, side + (int)(gen_u64(g) % 3));
        gen_lattice(g, b, nb, side);
        break;
    }
    case K_DUPLICATES:
        /* Few distinct points, each repeated many times, in both sets. */
        gen_gauss(g, a, na < 7 ? na : 7, m0, 1.0);
        for (size_t k = 7; k < na; k++)
            for (int c = 0; c < 3; c++) a[3 * k + c] = a[3 * (gen_u64(g) % 7) + c];
        for (size_t k = 0; k < nb; k++)
            for (int c = 0; c < 3; c++) b[3 * k + c] = a[3 * (gen_u64(g) % (na < 7 ? na : 7)) + c];
        break;
    case K_PERTURBED:
    case K_TRANSLATED: {
        /* B is a copy of A's points (cycled to nb), moved slightly. */
        gen_gauss(g, a, na, m0, 1.0);
        double t[3] = {1e-3 * gen_normal(g), 1e-3 * gen_normal(g), 0};
        for (size_t k = 0; k < nb; k++)
            for (int c = 0; c < 3; c++)
                b[3 * k + c] = a[3 * (k % na) + c] +
                               (kind == K_PERTURBED ? 1e-3 * gen_normal(g) : t[c]);
        break;
    }
    case K_FAR:
        gen_gauss(g, a, na, m0, 1.0);
        gen_gauss(g, b, nb, m0, 1.0);
        gen_affine(a, na, 1.0, 1e9);
        gen_affine(b, nb, 1.0, 1e9);
        break;
    case K_TINY:
        gen_gauss(g, a, na, m0, 1.0);
        m1[2] = 0.5;
        gen_gauss(g, b, nb, m1, 1.0);
        gen_affine(a, na, 1e-9, 0.0);
        gen_affine(b, nb, 1e-9, 0.0);
        break;
    case K_PLANE_LINE:
        gen_plane(g, a, na);
        gen_line(g, b, nb);
        break;
    default:
        gen_cube(g, a, na, -1, 1);
        gen_cube(g, b, nb, 0, 2);
    }
}

/* Compare one directed result with the brute force. */
static void check_directed(const hd_result_t *r, const brute_t *want) {
    CHECK_BITS(r->distance2, want->d2);
    CHECK_BITS(r->distance, sqrt(want->d2));
    CHECK_EQ(r->i, want->i);
    CHECK_EQ(r->j, want->j);
    CHECK_EQ(r->algorithm, HD_ALG_AUTO);
}

/* H(A,B) of the views A and B through the public call, at `threads`
 * threads: both directions are the brute force's ab and ba, witnesses
 * included, and the distance is the larger. */
static void check_hausdorff(const hd_points_t *A, const hd_points_t *B, const brute_t *ab, const brute_t *ba,
                            int threads) {
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    hd_symmetric_t s;
    CHECK_RC(hd_hausdorff(A, B, &o, &s, NULL), HD_OK);
    check_directed(&s.ab, ab);
    check_directed(&s.ba, ba);
    CHECK_BITS(s.distance, sqrt(ab->d2 >= ba->d2 ? ab->d2 : ba->d2));
}

/* H(A,B) and h(A,B) with the engine against the brute force. */
static void check_case(double *a, size_t na, double *b, size_t nb, int threads) {
    brute_t ab = brute_directed(a, na, b, nb), ba = brute_directed(b, nb, a, na);
    hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
    check_hausdorff(&A, &B, &ab, &ba, threads);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    hd_result_t r;
    CHECK_RC(hd_directed(&A, &B, &o, &r, NULL), HD_OK);
    check_directed(&r, &ab);
    /* Whatever the engine's choice, both of its paths are exact. */
    static const hd__engine_force_t paths[] = {HD__ENGINE_FORCE_GRID, HD__ENGINE_FORCE_TREES};
    for (int k = 0; k < 2; k++) {
        hd_symmetric_t s;
        CHECK_RC(hd__engine_forced(&A, &B, &o, paths[k], &s, NULL), HD_OK);
        check_directed(&s.ab, &ab);
        check_directed(&s.ba, &ba);
    }
}

/* A and B rounded to float, given to the engine as float32 views, against
 * the brute force on the rounded values (a and b are overwritten with them). */
static void check_float32(double *a, size_t na, double *b, size_t nb, int threads) {
    float *fa = malloc(12 * na), *fb = malloc(12 * nb);
    for (size_t k = 0; k < 3 * na; k++) a[k] = (double)(fa[k] = (float)a[k]);
    for (size_t k = 0; k < 3 * nb; k++) b[k] = (double)(fb[k] = (float)b[k]);
    brute_t ab = brute_directed(a, na, b, nb), ba = brute_directed(b, nb, a, na);
    hd_points_t A = hd_points_f32(fa, na), B = hd_points_f32(fb, nb);
    check_hausdorff(&A, &B, &ab, &ba, threads);
    free(fa);
    free(fb);
}

/* Seeds g with `seed`, named with the sizes in failure messages from here
 * on, and returns an array for na points (to fill from g) with one for nb
 * in *b; the caller frees both. */
static double *seeded_arrays(gen_rng_t *g, uint64_t seed, size_t na, size_t nb, double **b) {
    gen_seed(g, seed);
    CONTEXT("seed=%llu na=%zu nb=%zu", (unsigned long long)seed, na, nb);
    *b = malloc(24 * nb);
    return malloc(24 * na);
}

/* A check of one pair at a thread count (check_case, check_float32). */
typedef void (*check_fn)(double *a, size_t na, double *b, size_t nb, int threads);

/* One seeded case: the pair of `kind`, na and nb points, drawn from g
 * (seeded with `seed`, the sizes already drawn from it), checked at
 * `threads` threads, or at one and at three when `threads` is 0; a failure
 * prints the seed, the kind, the sizes and the thread count. */
static void check_seeded_pair(gen_rng_t *g, uint64_t seed, int kind, size_t na, size_t nb, int threads,
                              check_fn check) {
    double *a = malloc(24 * na), *b = malloc(24 * nb);
    make_pair(g, kind, a, na, b, nb);
    for (int t = threads ? threads : 1; t <= (threads ? threads : 3); t += 2) {
        CONTEXT("seed=%llu kind=%s na=%zu nb=%zu threads=%d", (unsigned long long)seed, kind_name[kind], na, nb, t);
        check(a, na, b, nb, t);
    }
    free(a);
    free(b);
}

TEST(engine_matches_brute_force_on_thousands_of_seeded_cases) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 2200 && !hdt_failed(); seed++) {
        gen_seed(&g, seed);
        int kind = (int)(seed % K_COUNT);
        /* Mostly small sets (one to a few buckets), some up to ~40 buckets. */
        size_t cap = seed % 10 == 0 ? 1300 : 160;
        size_t na = 1 + gen_u64(&g) % cap, nb = 1 + gen_u64(&g) % cap;
        check_seeded_pair(&g, seed, kind, na, nb, seed % 2 ? 1 : 3, check_case);
    }
}

/* A filter like the MPI library's (a point counts only when the plane
 * x = cut is farther than its own nearest distance), or one that refuses
 * every third index above a threshold, or everything. */
typedef struct {
    const double *p;
    double cut, t2;
    int rule; /* 0: the plane, 1: every third index above t2, 2: none kept */
    const double *q; /* the other set, for offered */
    size_t nq;
    int wrong;       /* offers whose distance or nearest index was not the brute force's */
} keep_rule_t;

static int keep_by_rule(void *ctx, size_t i, double d2) {
    const keep_rule_t *r = ctx;
    if (r->rule == 2) return 0;
    if (r->rule == 1) return i % 3 != 0 || d2 <= r->t2;
    double g = r->p[3 * i] - r->cut;
    return g * g > d2;
}

/* The filter as the engine calls it: each offer is also checked against
 * the brute force (the point's exact nearest distance, and the smallest
 * index at it, which the MPI library takes as the point's answer). */
static int offered(void *ctx, size_t i, double d2, size_t j) {
    keep_rule_t *r = ctx;
    size_t want;
    double w2 = brute_nearest(r->p + 3 * i, r->q, r->nq, &want);
    r->wrong += !(w2 == d2 && want == j);
    return keep_by_rule(ctx, i, d2);
}

/* The brute force's maximum over the points of a the rule keeps (d2 = -1
 * and no witness when none is). */
static brute_t brute_kept(const double *a, size_t na, const double *b, size_t nb, keep_rule_t *r) {
    brute_t best = {-1.0, HD__NONE, HD__NONE};
    for (size_t i = 0; i < na; i++) {
        size_t j;
        double d2 = brute_nearest(a + 3 * i, b, nb, &j);
        if (keep_by_rule(r, i, d2) && d2 > best.d2) best = (brute_t){d2, i, j};
    }
    return best;
}

TEST(a_filtered_maximum_is_the_maximum_over_the_points_kept) {
    /* hd__engine_hausdorff_kept, as the MPI library runs it on a rank's
     * local sets: each direction's answer is the brute force's over the
     * points its filter keeps (every path of the engine offers each point
     * that may beat the maximum; the refused ones raise no bound), ties
     * to the smallest index, at one thread and at three; copies in one
     * order (whose correspondence path must not run) included.  Every
     * offer carries the point's exact nearest distance and the smallest
     * index at it. */
    gen_rng_t g;
    for (uint64_t seed = 7000; seed < 7000 + 40 * K_COUNT && !hdt_failed(); seed++) {
        gen_seed(&g, seed);
        int kind = (int)(seed % K_COUNT), threads = seed % 2 ? 1 : 3, rule = (int)(seed / K_COUNT % 5);
        rule = rule < 3 ? 0 : rule == 3 ? 1 : 2;
        size_t cap = seed % 7 == 0 ? 3000 : 300;
        size_t na = 1 + gen_u64(&g) % cap, nb = seed % 5 == 0 ? na : 1 + gen_u64(&g) % cap;
        CONTEXT("seed=%llu kind=%s na=%zu nb=%zu threads=%d rule=%d", (unsigned long long)seed, kind_name[kind],
                na, nb, threads, rule);
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        make_pair(&g, kind, a, na, b, nb);
        if (nb == na && seed % 10 == 0) /* a copy in one order */
            for (size_t k = 0; k < 3 * na; k++) b[k] = a[k] + (k % 3 == 0 ? 1e-3 : 0);
        keep_rule_t ra = {a, a[3 * (na / 2)], 0, rule, b, nb, 0}, rb = {b, b[3 * (nb / 2)], 0, rule, a, na, 0};
        ra.t2 = rb.t2 = brute_directed(a, na, b, nb).d2 / 4;
        brute_t want_ab = brute_kept(a, na, b, nb, &ra), want_ba = brute_kept(b, nb, a, na, &rb);
        hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
        hd__box_t ba, bb;
        hd__box_of(a, na, &ba);
        hd__box_of(b, nb, &bb);
        hd_options_t o;
        hd_options_init(&o);
        o.threads = threads;
        hd__keep_t keep[2] = {{offered, &ra}, {offered, &rb}};
        hd_symmetric_t s;
        CHECK_RC(hd__engine_hausdorff_kept(&A, &B, &ba, &bb, &o, keep, &s, NULL), HD_OK);
        CHECK_BITS(s.ab.distance2, want_ab.d2);
        CHECK_EQ(s.ab.i, want_ab.i);
        CHECK_BITS(s.ba.distance2, want_ba.d2);
        CHECK_EQ(s.ba.i, want_ba.i);
        if (want_ab.i != HD__NONE) CHECK_EQ(s.ab.j, want_ab.j);
        if (want_ba.i != HD__NONE) CHECK_EQ(s.ba.j, want_ba.j);
        CHECK_EQ(ra.wrong, 0);
        CHECK_EQ(rb.wrong, 0);
        free(a);
        free(b);
    }
}

/* hd__box_checked (the validation's and the local boxes' loop, four
 * points a step) against one coordinate at a time: the same bounds, bit
 * for bit but for the sign of a zero bound (which no use of a box sees,
 * and which depends on the order the points are read in), and a refusal
 * wherever one coordinate is NaN, infinite or beyond HD_MAX_COORD, at
 * every position of every size up to 41 (the step's remainder 0 to 3). */
TEST(the_box_and_its_check_agree_with_a_point_at_a_time) {
    const double bad[4] = {NAN, INFINITY, -INFINITY, 2 * HD_MAX_COORD};
    gen_rng_t g;
    for (size_t n = 1; n <= 41; n++) {
        uint64_t seed = 7100 + n;
        gen_seed(&g, seed);
        CONTEXT("seed=%llu n=%zu", (unsigned long long)seed, n);
        double *p = malloc(24 * n);
        for (size_t i = 0; i < 3 * n; i++) {
            uint64_t r = gen_u64(&g);
            p[i] = r % 7 == 0 ? 0.0 : r % 7 == 1 ? -0.0 : (gen_unit(&g) - 0.5) * 1e6;
        }
        hd__box_t want, got;
        for (int c = 0; c < 3; c++) want.lo[c] = want.hi[c] = p[c];
        for (size_t i = 1; i < n; i++)
            for (int c = 0; c < 3; c++) {
                double v = p[3 * i + (size_t)c];
                want.lo[c] = v < want.lo[c] ? v : want.lo[c];
                want.hi[c] = v > want.hi[c] ? v : want.hi[c];
            }
        CHECK_EQ(hd__box_checked(p, n, &got), 1);
        for (int c = 0; c < 3; c++) {
            CHECK_EQ(got.lo[c] == want.lo[c], 1);
            CHECK_EQ(got.hi[c] == want.hi[c], 1);
        }
        hd__box_of(p, n, &got);
        for (int c = 0; c < 3; c++) CHECK_EQ(got.lo[c] == want.lo[c] && got.hi[c] == want.hi[c], 1);
        for (size_t i = 0; i < 3 * n; i++) {
            double keep = p[i];
            p[i] = bad[i % 4];
            CHECK_EQ(hd__box_checked(p, n, &got), 0);
            hd_points_t v = hd_points_f64(p, n);
            CHECK_EQ(hd__points_scan(&v, "set", 1, &got, NULL) != HD_OK, 1);
            p[i] = keep;
        }
        free(p);
    }
}

TEST(engine_matches_brute_force_on_large_sets) {
    gen_rng_t g;
    for (int kind = 0; kind < K_COUNT; kind++) {
        uint64_t seed = 5000 + (uint64_t)kind;
        gen_seed(&g, seed);
        size_t na = 4000 + gen_u64(&g) % 2000, nb = 4000 + gen_u64(&g) % 2000;
        check_seeded_pair(&g, seed, kind, na, nb, 0, check_case);
    }
}

TEST(sizes_one_to_a_thousand) {
    gen_rng_t g;
    for (int kind = 0; kind < K_COUNT; kind++) {
        uint64_t seed = 6000 + (uint64_t)kind;
        gen_seed(&g, seed);
        size_t small = 3 + gen_u64(&g) % 5;
        check_seeded_pair(&g, seed, kind, small, 1000 * small, kind % 2 ? 1 : 3, check_case);
    }
}

TEST(same_answer_at_every_thread_count) {
    gen_rng_t g;
    size_t n = 20000;
    double *b, *a = seeded_arrays(&g, 7000, n, n, &b);
    make_pair(&g, K_LATTICE, a, n, b, n);
    hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
    hd_options_t o;
    hd_options_init(&o);
    hd_symmetric_t first, s;
    memset(&first, 0, sizeof first);
    for (int t = 1; t <= 4; t++) {
        o.threads = t;
        CHECK_RC(hd_hausdorff(&A, &B, &o, &s, NULL), HD_OK);
        if (t == 1) {
            first = s;
            continue;
        }
        CHECK_BITS(s.distance, first.distance);
        CHECK_EQ(s.ab.i, first.ab.i);
        CHECK_EQ(s.ab.j, first.ab.j);
        CHECK_EQ(s.ba.i, first.ba.i);
        CHECK_EQ(s.ba.j, first.ba.j);
    }
    /* And it is the brute force's. */
    brute_t ab = brute_directed(a, 3000, b, n);
    hd_points_t A3 = hd_points_f64(a, 3000);
    hd_result_t r;
    o.threads = 3;
    CHECK_RC(hd_directed(&A3, &B, &o, &r, NULL), HD_OK);
    check_directed(&r, &ab);
    free(a);
    free(b);
}

TEST(float32_views_are_exact_for_the_float_values) {
    gen_rng_t g;
    for (uint64_t seed = 8000; seed < 8060; seed++) {
        gen_seed(&g, seed);
        int kind = (int)(seed % K_COUNT);
        size_t na = 1 + gen_u64(&g) % 900, nb = 1 + gen_u64(&g) % 900;
        check_seeded_pair(&g, seed, kind, na, nb, seed % 2 ? 1 : 3, check_float32);
    }
}

TEST(strided_and_reversed_views_are_read_correctly) {
    gen_rng_t g;
    size_t na = 2345, nb = 3456;
    double *b, *a = seeded_arrays(&g, 9000, na, nb, &b);
    make_pair(&g, K_PERTURBED, a, na, b, nb);
    /* A as a column-major (Fortran) array; B reversed, inside records of
     * four doubles, through a negative stride. */
    double *col = malloc(24 * na), *rec = malloc(32 * nb), *brev = malloc(24 * nb);
    for (size_t k = 0; k < na; k++)
        for (int c = 0; c < 3; c++) col[c * na + k] = a[3 * k + c];
    for (size_t k = 0; k < nb; k++) {
        for (int c = 0; c < 3; c++) rec[4 * k + c] = b[3 * k + c];
        rec[4 * k + 3] = NAN;
        memcpy(brev + 3 * k, b + 3 * (nb - 1 - k), 24);
    }
    hd_points_t A = hd_points_f64(col, na);
    A.stride = sizeof(double);
    A.cstride = (ptrdiff_t)(na * sizeof(double));
    hd_points_t B = hd_points_f64(rec + 4 * (nb - 1), nb);
    B.stride = -4 * (ptrdiff_t)sizeof(double);
    brute_t ab = brute_directed(a, na, brev, nb), ba = brute_directed(brev, nb, a, na);
    hd_options_t o;
    hd_options_init(&o);
    for (int t = 1; t <= 3; t += 2) {
        o.threads = t;
        hd_symmetric_t s;
        CHECK_RC(hd_hausdorff(&A, &B, &o, &s, NULL), HD_OK);
        check_directed(&s.ab, &ab);
        check_directed(&s.ba, &ba);
    }
    free(a);
    free(b);
    free(col);
    free(rec);
    free(brev);
}

TEST(identical_sets_are_at_distance_zero_with_witness_zero) {
    gen_rng_t g;
    gen_seed(&g, 9100);
    CONTEXT("seed=9100");
    size_t n = 5000;
    double *a = malloc(24 * n);
    make_pair(&g, K_OVERLAP, a, n, a, 0);
    hd_points_t A = hd_points_f64(a, n);
    hd_symmetric_t s;
    CHECK_RC(hd_hausdorff(&A, &A, NULL, &s, NULL), HD_OK);
    CHECK_BITS(s.distance, 0.0);
    /* Every point is at distance 0 from itself: the witness is A[0], B[0]. */
    CHECK_EQ(s.ab.i, 0);
    CHECK_EQ(s.ab.j, 0);
    free(a);
}

TEST(statistics_explain_the_work) {
    gen_rng_t g;
    size_t n = 30000;
    double *b, *a = seeded_arrays(&g, 9200, n, n, &b);
    make_pair(&g, K_DISJOINT, a, n, b, n);
    hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
    hd_result_t r;
    CHECK_RC(hd_directed(&A, &B, NULL, &r, NULL), HD_OK);
    CHECK_EQ(r.algorithm, HD_ALG_AUTO);
    CHECK(r.stats.distance_evals > 0);
    /* Far apart sets: nearly every point is discarded without a search. */
    CHECK(r.stats.points_culled > n / 2);
    CHECK(r.stats.points_culled <= n);
    free(a);
    free(b);
}

/* ---- the correspondence path: B a copy of A in the same order ---------------- */

/* The engine's plan for H(A,B) as values (hd__engine_explain's
 * hd__engine_plan_t): which path answers, whether the correspondence path
 * listed pairs, and which directions it resolved.  Every field is checked
 * to be in its range, so a plan the engine failed to fill fails the test. */
typedef enum { PLAN_UNREAD = 0, PLAN_PAIRS = HD__PLAN_PAIRS, PLAN_GRID = HD__PLAN_GRID,
               PLAN_TREES = HD__PLAN_TREES } plan_path_t;
typedef struct {
    plan_path_t path;
    int listed;      /* 1: pairs listed, 0: not tried */
    int resolved[2]; /* per direction, 0 or 1 */
} plan_t;

static plan_t plan_of(const double *a, size_t na, const double *b, size_t nb) {
    plan_t p = {PLAN_UNREAD, -1, {-1, -1}};
    hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
    hd_options_t o;
    hd_options_init(&o);
    hd__engine_plan_t e;
    memset(&e, 0xff, sizeof e); /* out of range until the engine writes it */
    int rc = hd__engine_explain(&A, &B, &o, &e, NULL, 0, NULL);
    CHECK_RC(rc, HD_OK);
    if (rc != HD_OK) return p;
    if ((e.path != HD__PLAN_PAIRS && e.path != HD__PLAN_GRID && e.path != HD__PLAN_TREES) ||
        (e.pairs_listed != 0 && e.pairs_listed != 1) || (e.resolved[0] != 0 && e.resolved[0] != 1) ||
        (e.resolved[1] != 0 && e.resolved[1] != 1)) {
        hdt_fail(__FILE__, __LINE__, "the engine's plan has a field out of range: path %d, listed %d, "
                 "resolved %d / %d", (int)e.path, e.pairs_listed, e.resolved[0], e.resolved[1]);
        return p;
    }
    /* The path is "pairs" exactly when both directions were resolved. */
    CHECK_EQ(e.path == HD__PLAN_PAIRS, e.resolved[0] && e.resolved[1]);
    p.path = (plan_path_t)e.path;
    p.listed = e.pairs_listed;
    p.resolved[0] = e.resolved[0];
    p.resolved[1] = e.resolved[1];
    return p;
}

/* Whether the plan is (path, listed, resolved r0 / r1); -1 matches any. */
static int plan_is(plan_t p, int path, int listed, int r0, int r1) {
    return p.path != PLAN_UNREAD && (path < 0 || (int)p.path == path) && (listed < 0 || p.listed == listed) &&
           (r0 < 0 || p.resolved[0] == r0) && (r1 < 0 || p.resolved[1] == r1);
}

/* One seeded copy: B a copy of A's n points made by gen_copy's `how`
 * from g (seeded with `seed`, n already drawn from it), listed in a random
 * order when `shuffled`, then checked at `threads` threads, or at one and
 * at three when `threads` is 0; a failure prints the seed, the copy, the
 * size and the thread count.  When `settled` is given, it counts the
 * copies whose plan the correspondence path settles. */
static void check_seeded_copy(gen_rng_t *g, uint64_t seed, int how, size_t n, int shuffled, int threads,
                              check_fn check, int *settled) {
    double *a = malloc(24 * n), *b = malloc(24 * n);
    gen_copy(g, how, a, b, n);
    if (shuffled)
        for (size_t k = n; k > 1; k--) gen_swap(b, k - 1, gen_u64(g) % k);
    for (int t = threads ? threads : 1; t <= (threads ? threads : 3); t += 2) {
        CONTEXT("seed=%llu copy=%s n=%zu threads=%d", (unsigned long long)seed, gen_copy_name[how], n, t);
        check(a, n, b, n, t);
    }
    if (settled) *settled += plan_is(plan_of(a, n, b, n), PLAN_PAIRS, 1, 1, 1);
    free(a);
    free(b);
}

/* Copies listed in another order cannot use the correspondence path: the
 * trees must find every partner, and the partners across a jump of the
 * Morton curve are looked up by their cells' keys (engine.c, try_cells)
 * before any search.  Every kind of copy gen_copy makes (ties at the
 * maximum, duplicates, 1e9 offsets, 1e-150 scales), shuffled, through the
 * public call and both paths forced, at one thread and three. */
TEST(shuffled_copies_are_exact_in_every_variation) {
    gen_rng_t g;
    for (int how = 0; how < GEN_COPY_KINDS && !hdt_failed(); how++) {
        uint64_t seed = 7500 + (uint64_t)how;
        gen_seed(&g, seed);
        size_t n = 3000 + gen_u64(&g) % 3000;
        check_seeded_copy(&g, seed, how, n, 1, 0, check_case, NULL);
    }
}

TEST(same_order_copies_are_exact_in_every_variation) {
    gen_rng_t g;
    int settled = 0, cases = 0;
    for (uint64_t seed = 10000; seed < 10440 && !hdt_failed(); seed++) {
        gen_seed(&g, seed);
        int how = (int)(seed % GEN_COPY_KINDS);
        size_t n = 1 + gen_u64(&g) % (seed % 8 == 0 ? 6000 : 700);
        check_seeded_copy(&g, seed, how, n, 0, seed % 2 ? 1 : 3, check_case, &settled);
        cases++;
    }
    /* The path itself was under test in most cases (not only the fallback). */
    CONTEXT("settled by the correspondence path: %d of %d", settled, cases);
    CHECK(settled >= cases / 2);
}

TEST(same_order_copies_in_float32_are_exact_for_the_float_values) {
    gen_rng_t g;
    for (uint64_t seed = 11000; seed < 11044 && !hdt_failed(); seed++) {
        gen_seed(&g, seed);
        int how = (int)(seed % GEN_COPY_KINDS);
        if (how == GEN_COPY_SUBNORMAL_SCALE) continue; /* not representable in float */
        size_t n = 1 + gen_u64(&g) % 3000;
        check_seeded_copy(&g, seed, how, n, 0, seed % 2 ? 1 : 3, check_float32, NULL);
    }
}

TEST(a_noisy_copy_is_settled_by_the_correspondence_path) {
    gen_rng_t g;
    size_t n = 50000;
    double *b, *a = seeded_arrays(&g, 12000, n, n, &b);
    gen_copy(&g, GEN_COPY_NOISE, a, b, n);
    CHECK(plan_is(plan_of(a, n, b, n), PLAN_PAIRS, 1, 1, 1));
    check_case(a, n, b, n, 3);
    free(a);
    free(b);
}

TEST(independent_clouds_and_shuffled_copies_do_not_take_the_correspondence_path) {
    gen_rng_t g;
    size_t n = 20000;
    double *b, *a = seeded_arrays(&g, 12100, n, n, &b);
    make_pair(&g, K_OVERLAP, a, n, b, n);
    CHECK(plan_is(plan_of(a, n, b, n), -1, 0, -1, -1));
    /* A noisy copy listed backwards: the partners are unrelated points. */
    gen_copy(&g, GEN_COPY_NOISE, a, b, n);
    for (size_t k = 0; k < n / 2; k++) gen_swap(b, k, n - 1 - k);
    CHECK(plan_is(plan_of(a, n, b, n), -1, 0, -1, -1));
    check_case(a, n, b, n, 1);
    free(a);
    free(b);
}

/* The plan's early decision (engine.c, EARLY_COST): two independent
 * uniform cubes of 300K points cost more than EARLY_COST in h(A,B)'s trial
 * on B's grid alone, so the trees are taken before A's grid is built, and
 * h(B,A)'s trial is never run (cost 0).  The answer is the one both paths
 * forced give, bit for bit, witnesses included; each path is checked
 * against the brute force on the smaller cases above. */
/* Two independent uniform cubes of n points (seed printed on failure). */
static void two_cubes(uint64_t seed, size_t n, double **a, double **b, hd_points_t *A, hd_points_t *B) {
    gen_rng_t g;
    gen_seed(&g, seed);
    CONTEXT("seed=%llu n=%zu", (unsigned long long)seed, n);
    gen_cube_pair(&g, n, n, a, b, A, B);
}

TEST(uniform_cubes_take_the_trees_before_a_grid_of_a_is_built) {
    size_t n = 300000;
    double *a, *b;
    hd_points_t A, B;
    two_cubes(12150, n, &a, &b, &A, &B);
    hd_options_t o;
    hd_options_init(&o);
    hd__engine_plan_t e;
    CHECK_RC(hd__engine_explain(&A, &B, &o, &e, NULL, 0, NULL), HD_OK);
    CHECK_EQ(e.path, HD__PLAN_TREES);
    CHECK(e.grid_cost[0] > 8.0);
    CHECK_BITS(e.grid_cost[1], 0.0);
    hd_symmetric_t s[3];
    for (int f = 0; f < 3; f++) CHECK_RC(hd__engine_forced(&A, &B, &o, (hd__engine_force_t)f, &s[f], NULL), HD_OK);
    for (int f = 1; f < 3; f++) {
        CHECK_BITS(s[0].ab.distance2, s[f].ab.distance2);
        CHECK_BITS(s[0].ba.distance2, s[f].ba.distance2);
        CHECK_EQ(s[0].ab.i, s[f].ab.i);
        CHECK_EQ(s[0].ab.j, s[f].ab.j);
        CHECK_EQ(s[0].ba.i, s[f].ba.i);
        CHECK_EQ(s[0].ba.j, s[f].ba.j);
    }
    free(a);
    free(b);
}

/* The early decision under filters, as the MPI library runs the engine:
 * in each direction only the points with x < 0.003 are kept (about 900 of
 * 300K), each answer is the brute force's over them, and every point
 * offered (the sampled prime's, the trial's, the seeds of h(B,A) chosen
 * without A's grid, the walk's) comes with its exact nearest distance and
 * smallest nearest index. */
typedef struct {
    const double *a, *b;
    size_t nb, wrong;
} slab_rule_t;

static int keep_thin_slab(void *ctx, size_t i, double d2, size_t j) {
    slab_rule_t *r = ctx;
    size_t want;
    r->wrong += !(brute_nearest(r->a + 3 * i, r->b, r->nb, &want) == d2 && want == j);
    return r->a[3 * i] < 0.003;
}

static brute_t brute_thin_slab(const double *a, size_t na, const double *b, size_t nb) {
    brute_t want = {-1.0, HD__NONE, HD__NONE};
    for (size_t i = 0; i < na; i++) {
        if (!(a[3 * i] < 0.003)) continue;
        size_t j;
        double d2 = brute_nearest(a + 3 * i, b, nb, &j);
        if (d2 > want.d2) want = (brute_t){d2, i, j};
    }
    return want;
}

TEST(the_early_decision_keeps_filtered_maxima_exact) {
    size_t n = 300000;
    double *a, *b;
    hd_points_t A, B;
    two_cubes(12160, n, &a, &b, &A, &B);
    brute_t want_ab = brute_thin_slab(a, n, b, n), want_ba = brute_thin_slab(b, n, a, n);
    hd__box_t ba, bb;
    hd__box_of(a, n, &ba);
    hd__box_of(b, n, &bb);
    hd_options_t o;
    hd_options_init(&o);
    slab_rule_t ra = {a, b, n, 0}, rb = {b, a, n, 0};
    hd__keep_t keep[2] = {{keep_thin_slab, &ra}, {keep_thin_slab, &rb}};
    hd_symmetric_t s;
    CHECK_RC(hd__engine_hausdorff_kept(&A, &B, &ba, &bb, &o, keep, &s, NULL), HD_OK);
    CHECK_EQ(ra.wrong, 0);
    CHECK_EQ(rb.wrong, 0);
    CHECK_BITS(s.ab.distance2, want_ab.d2);
    CHECK_EQ(s.ab.i, want_ab.i);
    CHECK_EQ(s.ab.j, want_ab.j);
    CHECK_BITS(s.ba.distance2, want_ba.d2);
    CHECK_EQ(s.ba.i, want_ba.i);
    CHECK_EQ(s.ba.j, want_ba.j);
    free(a);
    free(b);
}

TEST(a_copy_with_more_exchanged_partners_than_the_list_falls_back_exactly) {
    gen_rng_t g;
    /* 5% of 60000 partners exchanged: some 3000 pairs far larger than the
     * answer, more than the path lists, so it must hand over to the grid or
     * the trees with what it found. */
    size_t n = 60000;
    double *b, *a = seeded_arrays(&g, 12200, n, n, &b);
    gen_copy(&g, GEN_COPY_NOISE, a, b, n);
    for (size_t r = 0; r < n / 40; r++) {
        size_t x = gen_u64(&g) % n;
        gen_swap(b, x, gen_u64(&g) % n);
    }
    CHECK(plan_is(plan_of(a, n, b, n), -1, 1, 0, 0));
    check_case(a, n, b, n, 3);
    free(a);
    free(b);
}

/* ---- the grid pass: whole cells discarded ------------------------------------ */

/* The lattice {0, step, 2 step, ..., side - 1 steps}^3 (side^3 points), scaled by
 * `scale` and moved by `offset`, in an order shuffled by g (so that ties
 * go to indices other than the first). */
static double *shuffled_lattice(gen_rng_t *g, int side, int step, double scale, double offset,
                                size_t *n) {
    *n = (size_t)side * (size_t)side * (size_t)side;
    double *p = malloc(24 * *n);
    size_t k = 0;
    for (int x = 0; x < side; x++)
        for (int y = 0; y < side; y++)
            for (int z = 0; z < side; z++, k++) {
                p[3 * k] = (double)(x * step) * scale + offset;
                p[3 * k + 1] = (double)(y * step) * scale + offset;
                p[3 * k + 2] = (double)(z * step) * scale + offset;
            }
    for (size_t i = *n - 1; i > 0; i--) gen_swap(p, i, gen_u64(g) % (i + 1));
    return p;
}

/* H(A,B) through the grid path forced, and h(A,B) through the grid pass
 * alone, unprimed (cmax starts at 0, and the pass reads A in input order)
 * and primed as the engine primes it (the pass walks A's cells), at
 * `threads` threads: the brute force's answers; returns whether the primed
 * pass computed fewer distances than A has points (so it discarded some
 * cells whole, unread). */
static int grid_discards_whole_cells(const hd_points_t *A, const hd_points_t *B,
                                     const brute_t *ab, const brute_t *ba, int threads) {
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    hd_symmetric_t s;
    CHECK_RC(hd__engine_forced(A, B, &o, HD__ENGINE_FORCE_GRID, &s, NULL), HD_OK);
    check_directed(&s.ab, ab);
    check_directed(&s.ba, ba);
    hd__src_t src[2];
    hd__box_t box[2];
    hd__grid_t grid[2];
    const hd_points_t *P[2] = {A, B};
    for (int k = 0; k < 2; k++) {
        hd__src_init(&src[k], P[k], NULL);
        CHECK_RC(hd__points_scan(P[k], "set", threads, &box[k], NULL), HD_OK);
        CHECK_RC(hd__grid_build(&grid[k], &src[k], P[k]->count, &box[k], threads, NULL, NULL), HD_OK);
    }
    hd__counts_t n = {0, 0, 0};
    for (int primed = 0; primed <= 1; primed++) {
        hd__max_t m;
        CHECK_RC(hd__max_init(&m), HD_OK);
        hd__counts_t before = {0, 0, 0};
        if (primed) hd__grid_prime(&grid[0], &grid[1], &m, &before);
        uint64_t culled = 0;
        n = before;
        CHECK_RC(hd__grid_directed(&grid[0], &grid[1], &m, threads, &n, &culled, NULL), HD_OK);
        CHECK_BITS(m.best.d2, ab->d2);
        CHECK_EQ(m.best.i, ab->i);
        CHECK_EQ(m.best.j, ab->j);
        CHECK_EQ(culled <= A->count, 1);
        n.evals -= before.evals, n.exact -= before.exact;
        hd__max_destroy(&m);
    }
    for (int k = 0; k < 2; k++) hd__grid_free(&grid[k]);
    return n.evals + n.exact < A->count;
}

TEST(whole_cells_are_discarded_exactly_on_lattices_with_ties) {
    /* A: the integer lattice {0..20}^3; B: a coarser lattice of the same
     * box.  Lattice points lie on (or within a rounding of) the grid's cell
     * faces, cells of A lie wholly within the maximum of one point of B,
     * others straddle it, and many points of A tie at the maximum with
     * several nearest points of B each.  Each variation moves the whole
     * picture to where rounding is hardest: tiny scales (squared distances
     * near and below the smallest normal double), a huge offset with a
     * small spacing, float32 values and strided views. */
    static const struct {
        int coarse;   /* B's spacing in lattice steps */
        double scale, offset;
    } v[] = {
        {10, 1.0, 0.0},   {2, 1.0, 0.0},      {5, 1.0, 0.0},      {10, 1e-150, 0.0},
        {2, 1e-155, 0.0}, {10, 1e-3, 1e9},    {5, 1e-3, 1e9},     {10, 0.1, -3.0},
    };
    gen_rng_t g;
    int whole = 0;
    for (size_t k = 0; k < sizeof v / sizeof v[0] && !hdt_failed(); k++) {
        gen_seed(&g, 13000 + k);
        CONTEXT("variation %zu: B spacing %d, scale %g, offset %g", k, v[k].coarse, v[k].scale,
                v[k].offset);
        size_t na, nb;
        double *a = shuffled_lattice(&g, 21, 1, v[k].scale, v[k].offset, &na);
        double *b = shuffled_lattice(&g, 20 / v[k].coarse + 1, v[k].coarse, v[k].scale,
                                     v[k].offset, &nb);
        brute_t ab = brute_directed(a, na, b, nb), ba = brute_directed(b, nb, a, na);
        hd_points_t A = hd_points_f64(a, na), B = hd_points_f64(b, nb);
        for (int t = 1; t <= 3; t += 2) whole += grid_discards_whole_cells(&A, &B, &ab, &ba, t);
        check_case(a, na, b, nb, 3);
        /* The same values as float32 where they are floats, and A as a
         * column-major array (a strided view). */
        float *fa = malloc(12 * na), *fb = malloc(12 * nb);
        for (size_t i = 0; i < 3 * na; i++) a[i] = (double)(fa[i] = (float)a[i]);
        for (size_t i = 0; i < 3 * nb; i++) b[i] = (double)(fb[i] = (float)b[i]);
        brute_t fab = brute_directed(a, na, b, nb), fba = brute_directed(b, nb, a, na);
        hd_points_t FA = hd_points_f32(fa, na), FB = hd_points_f32(fb, nb);
        whole += grid_discards_whole_cells(&FA, &FB, &fab, &fba, 3);
        double *col = malloc(24 * na);
        for (size_t i = 0; i < na; i++)
            for (int c = 0; c < 3; c++) col[c * na + i] = a[3 * i + c];
        hd_points_t CA = hd_points_f64(col, na);
        CA.stride = sizeof(double);
        CA.cstride = (ptrdiff_t)(na * sizeof(double));
        hd_points_t DB = hd_points_f64(b, nb);
        whole += grid_discards_whole_cells(&CA, &DB, &fab, &fba, 1);
        free(a);
        free(b);
        free(fa);
        free(fb);
        free(col);
    }
    /* Whole cells were discarded (not only points) in most variations. */
    CONTEXT("runs that discarded whole cells: %d", whole);
    CHECK(whole >= 8);
}

TEST(whole_cells_at_the_maximum_keep_the_canonical_witness) {
    /* Clusters of A whose whole cells sit at the maximum distance from B
     * (B is a copy of A's cluster centres moved by exactly the same vector
     * for every cluster, so every cluster holds points at the maximum), in
     * sets large enough for several tasks per pass; and the same far apart
     * (every cell of A discarded by the last useful point of B). */
    gen_rng_t g;
    for (int far = 0; far <= 1 && !hdt_failed(); far++) {
        gen_seed(&g, 13100 + (uint64_t)far);
        size_t clusters = 400, per = 64, na = clusters * per, nb = clusters;
        double *a = malloc(24 * na), *b = malloc(24 * nb);
        for (size_t c = 0; c < clusters; c++) {
            double ctr[3];
            for (int k = 0; k < 3; k++) ctr[k] = (double)(gen_u64(&g) % 64);
            for (int k = 0; k < 3; k++) b[3 * c + k] = ctr[k] + (far ? 500.0 : 0.5);
            /* The cluster: points of a small lattice around the centre. */
            for (size_t p = 0; p < per; p++)
                for (int k = 0; k < 3; k++)
                    a[3 * (p * clusters + c) + k] =
                        ctr[k] + 0.125 * (double)((p >> (2 * k)) & 3);
        }
        CONTEXT("far=%d na=%zu nb=%zu", far, na, nb);
        check_case(a, na, b, nb, 1);
        check_case(a, na, b, nb, 3);
        free(a);
        free(b);
    }
}

/* ---- ordered subsets: the smaller set's points, in order, copied from the larger -- */

/* B: every point of A kept with probability 1 / step (at least one), in A's
 * order; returns its size. */
static size_t make_subset(gen_rng_t *g, const double *a, size_t na, size_t step, double *b) {
    size_t nb = 0;
    for (size_t k = 0; k < na; k++)
        if (gen_u64(g) % step == 0) memcpy(b + 3 * nb++, a + 3 * k, 24);
    if (nb == 0) memcpy(b + 3 * nb++, a + 3 * (na / 2), 24);
    return nb;
}

TEST(ordered_subsets_are_exact_in_both_directions) {
    gen_rng_t g;
    int settled = 0, cases = 0;
    for (uint64_t seed = 13000; seed < 13240 && !hdt_failed(); seed++) {
        gen_seed(&g, seed);
        int kind = (int)(seed % 4); /* gauss, lattice (ties), duplicates, 1e-150 scale */
        size_t na = 2 + gen_u64(&g) % (seed % 8 == 0 ? 8000 : 900), step = 2 + gen_u64(&g) % 12;
        CONTEXT("seed=%llu kind=%d na=%zu step=%zu", (unsigned long long)seed, kind, na, step);
        double *a = malloc(24 * na), *b = malloc(24 * na), m0[3] = {0, 0, 0};
        if (kind == 1) gen_lattice(&g, a, na, 2 + (int)(gen_u64(&g) % 12));
        else gen_gauss(&g, a, na, m0, 1.0);
        if (kind == 2)
            for (size_t k = 0; k < na; k++)
                if (gen_u64(&g) % 2) memcpy(a + 3 * k, a + 3 * (gen_u64(&g) % na), 24);
        if (kind == 3) gen_affine(a, na, 1e-150, 0.0);
        size_t nb = make_subset(&g, a, na, step, b);
        if (nb == na) nb--; /* a proper subset */
        check_case(a, na, b, nb, seed % 2 ? 1 : 3);
        check_case(b, nb, a, na, seed % 2 ? 3 : 1);
        settled += plan_is(plan_of(a, na, b, nb), -1, -1, 0, 1);
        cases++;
        free(a);
        free(b);
    }
    CONTEXT("settled by the subset walk: %d of %d", settled, cases);
    CHECK(settled >= cases * 9 / 10);
}

TEST(ordered_subsets_in_float32_are_exact_for_the_float_values) {
    gen_rng_t g;
    for (uint64_t seed = 13500; seed < 13530 && !hdt_failed(); seed++) {
        gen_seed(&g, seed);
        size_t na = 2 + gen_u64(&g) % 3000;
        CONTEXT("seed=%llu na=%zu", (unsigned long long)seed, na);
        double *a = malloc(24 * na), *b = malloc(24 * na), m0[3] = {0, 0, 0};
        gen_gauss(&g, a, na, m0, 1.0);
        size_t nb = make_subset(&g, a, na, 3, b);
        if (nb == na) nb--;
        check_float32(a, na, b, nb, seed % 2 ? 1 : 3);
        free(a);
        free(b);
    }
}

TEST(subsets_out_of_order_or_with_a_stranger_are_left_to_the_other_paths) {
    gen_rng_t g;
    size_t na = 40000;
    double *b, *a = seeded_arrays(&g, 13600, na, na, &b), m0[3] = {0, 0, 0};
    gen_gauss(&g, a, na, m0, 1.0);
    size_t nb = make_subset(&g, a, na, 10, b);
    CHECK(plan_is(plan_of(a, na, b, nb), -1, -1, 0, 1));
    /* The last point no longer a copy: the walk fails at its very end. */
    b[3 * (nb - 1)] += 1e-3;
    CHECK(plan_is(plan_of(a, na, b, nb), -1, -1, 0, 0));
    check_case(a, na, b, nb, 3);
    b[3 * (nb - 1)] -= 1e-3;
    /* Out of order: the walk gives up within its first window. */
    for (size_t k = 0; k < nb / 2; k++) gen_swap(b, k, nb - 1 - k);
    CHECK(plan_is(plan_of(a, na, b, nb), -1, -1, 0, 0));
    check_case(a, na, b, nb, 1);
    free(a);
    free(b);
}

/* The engine's memory on the tree path: its pool holds at most 16 bytes a
 * point of both sets (docs/engine.md, "Threads and memory": the larger
 * set's sort alone, the smaller's sort beside the larger's permutation and
 * boxes, or the two finished trees at 13.4), plus at most two 2 MiB chunks
 * that arrays under about 1.9 MB are cut from; for sets of one size, the
 * finished trees' 13.4 bytes a point with their blocks' last 2 MiB pages
 * kept whole: at most 14 bytes a point and a chunk (before the sorts were
 * set apart from the trees, 22).  The results' stats.peak_bytes report it, the same in both directions.  Uniform clouds,
 * equal and 10:1 either way. */
TEST(the_tree_path_holds_at_most_16_bytes_a_point_and_reports_it) {
    /* Equal and 10:1 either way; then sizes around the reuse set's
     * thresholds, and random ones (the build hands blocks between the two
     * sets' sorts, permutations and quantised copies: at 265928 + 232739
     * points a kept block cut from a chunk once lost its chunk under it, a
     * crash), at one thread and two.  The trees' answer equals the grids'
     * (both exact, computed independently). */
    static const size_t fixed[][2] = {{300000, 300000}, {300000, 30000}, {30000, 300000}, {265928, 232739},
                                      {232739, 265928}, {65536, 65537},   {2731, 87381},   {131072, 4096},
                                      {174763, 174762}, {1, 300000},      {300000, 1}};
    enum { N_FIXED = sizeof fixed / sizeof fixed[0], N_RANDOM = 8 };
    for (int c = 0; c < N_FIXED + N_RANDOM; c++) {
        uint64_t seed = 8100 + (uint64_t)c;
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t na = c < N_FIXED ? fixed[c][0] : 1 + gen_u64(&g) % 400000;
        size_t nb = c < N_FIXED ? fixed[c][1] : 1 + gen_u64(&g) % 400000;
        CONTEXT("seed=%llu na=%zu nb=%zu", (unsigned long long)seed, na, nb);
        double *a, *b;
        hd_points_t A, B;
        gen_cube_pair(&g, na, nb, &a, &b, &A, &B);
        hd_options_t o;
        hd_options_init(&o);
        o.threads = c < 3 ? 2 : 1 + c % 2;
        hd_symmetric_t s, r;
        CHECK_RC(hd__engine_forced(&A, &B, &o, HD__ENGINE_FORCE_TREES, &s, NULL), HD_OK);
        size_t peak = (size_t)s.ab.stats.peak_bytes;
        CHECK_EQ(s.ba.stats.peak_bytes, s.ab.stats.peak_bytes);
        /* At least both trees' permutations and quantised copies. */
        CHECK(peak >= 10 * (na + nb));
        size_t chunk = ((size_t)2 << 20) + 4096;
        CHECK(peak <= 16 * (na + nb) + 2 * chunk);
        if (na == nb) CHECK(peak <= 14 * (na + nb) + chunk);
        if (peak > 16 * (na + nb) + 2 * chunk || (na == nb && peak > 14 * (na + nb) + chunk))
            fprintf(stderr, "peak %.2f bytes a point\n", (double)peak / (double)(na + nb));
        CHECK_RC(hd__engine_forced(&A, &B, &o, HD__ENGINE_FORCE_GRID, &r, NULL), HD_OK);
        CHECK(s.ab.distance == r.ab.distance && s.ab.i == r.ab.i && s.ab.j == r.ab.j);
        CHECK(s.ba.distance == r.ba.distance && s.ba.i == r.ba.i && s.ba.j == r.ba.j);
        free(a);
        free(b);
    }
}

/* The two trees of a pair keep their quantised copies in one block, the
 * larger set's copy first (64-byte aligned) and the smaller's after it,
 * borrowed: on small sets each copy in a block of its own kept a whole last
 * 2 MiB page (16.8 bytes a point of 250K + 250K uniform points, against
 * 14.4 in one block).  The pool's peak is checked against that, with room
 * for the blocks' rounding and their header pages; without huge pages it
 * is lower still. */
/* Two runs of 64 equal Morton keys next to each other in key order (two
 * clusters in neighbouring cells of the 1024^3 grid, each two blobs of 32
 * points listed alternately) are both refined: each of the four buckets
 * they fill holds one blob, so its box is a blob's (1e-5 wide), not the
 * cluster's (8e-4).  The second run starts right where the first ends. */
TEST(adjacent_crowded_cells_are_each_refined) {
    size_t n = 32 + 128 + 1;
    double *p = malloc(24 * n);
    gen_rng_t g;
    gen_seed(&g, 8400);
    CONTEXT("seed=8400");
    size_t k = 0;
    for (int i = 0; i < 32; i++, k++) p[3 * k] = p[3 * k + 1] = p[3 * k + 2] = 0.0;
    for (int c = 0; c < 2; c++)
        for (int i = 0; i < 64; i++, k++) {
            p[3 * k] = (512 + c) / 1024.0 + (i % 2 ? 8e-4 : 0.0) + 1e-5 * gen_unit(&g);
            p[3 * k + 1] = 0.5 + 1e-5 * gen_unit(&g);
            p[3 * k + 2] = 0.5 + 1e-5 * gen_unit(&g);
        }
    p[3 * k] = p[3 * k + 1] = p[3 * k + 2] = 1.0;
    hd_points_t P = hd_points_f64(p, n);
    hd__src_t src[2];
    hd__box_t box[2];
    size_t nn[2] = {n, n};
    for (int s = 0; s < 2; s++) {
        hd__src_init(&src[s], &P, NULL);
        CHECK_RC(hd__points_scan(&P, "set", 1, &box[s], NULL), HD_OK);
    }
    hd__reuse_t pool;
    hd__reuse_init(&pool);
    hd__tree_t t[2];
    CHECK_RC(hd__tree_build_pair(t, src, nn, box, 1, &pool, NULL), HD_OK);
    for (size_t b = 1; b <= 4; b++) {
        const hd__box_t *x = &t[0].bucket[b].box;
        CHECK(x->hi[0] - x->lo[0] < 1e-4);
    }
    hd__tree_free(&t[0]);
    hd__tree_free(&t[1]);
    hd__reuse_free(&pool);
    free(p);
}

/* Bucket b of t against its specification, one value at a time: the box
 * is the exact extremes of its points; each coordinate's code is
 * (v - lo) / step + 1/2 truncated (at most 65535), step = (hi - lo) /
 * 65535; err is sqrt(3) (with slack) times the largest |v - (lo + code
 * step)|, the dequantised value as hd__bucket_decode computes it; a short
 * bucket's padding repeats its point 0. */
static void check_bucket_spec(const hd__tree_t *t, const hd_points_t *P, size_t b) {
    int m = hd__bucket_size(t, b);
    const hd__bucket_t *bk = &t->bucket[b];
    const uint16_t *q = t->q + b * 3 * HD__BUCKET;
    double err = 0;
    for (int c = 0; c < 3; c++) {
        double v[HD__BUCKET];
        for (int k = 0; k < HD__BUCKET; k++) {
            double p[3];
            hd_points_get(P, t->perm[b * HD__BUCKET + (size_t)(k < m ? k : 0)], p);
            v[k] = p[c];
        }
        double lo = v[0], hi = v[0];
        for (int k = 1; k < HD__BUCKET; k++) {
            lo = v[k] < lo ? v[k] : lo;
            hi = v[k] > hi ? v[k] : hi;
        }
        CHECK_BITS(bk->box.lo[c], lo);
        CHECK_BITS(bk->box.hi[c], hi);
        double step = (hi - lo) * (1.0 / 65535.0), inv = step > 0 ? 1.0 / step : 0.0;
        for (int k = 0; k < HD__BUCKET; k++) {
            double u = (v[k] - lo) * inv + 0.5;
            int32_t code = (int32_t)(u < 65535.0 ? u : 65535.0);
            CHECK_EQ(q[c * HD__BUCKET + k], (uint16_t)code);
            double d = fabs(v[k] - (lo + (double)code * step));
            err = d > err ? d : err;
        }
    }
    CHECK_BITS(bk->err, err * 1.7320508075688776 * (1 + 1e-12));
}

TEST(every_bucket_is_quantised_as_specified) {
    enum { UNIFORM, FAR, TINY, LATTICE, FLAT, HUGE_RANGE, CASES };
    static const char *const name[CASES] = {"uniform", "far", "tiny", "lattice", "flat", "huge"};
    for (int c = 0; c < CASES; c++) {
        uint64_t seed = 8500 + (uint64_t)c;
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t n[2] = {3000 + 17 * (size_t)c, 2000 + 33 * (size_t)c}; /* short last buckets */
        CONTEXT("seed=%llu case=%s na=%zu nb=%zu", (unsigned long long)seed, name[c], n[0], n[1]);
        double *xyz[2];
        hd_points_t P[2];
        hd__src_t src[2];
        hd__box_t box[2];
        for (int s = 0; s < 2; s++) {
            xyz[s] = malloc(24 * n[s]);
            if (c == LATTICE) gen_lattice(&g, xyz[s], n[s], 6); /* duplicates in every bucket */
            else gen_cube(&g, xyz[s], n[s], 0.0, 1.0);
            if (c == FAR) gen_affine(xyz[s], n[s], 1e-3, 1e9);
            if (c == TINY) gen_affine(xyz[s], n[s], 1e-9, 0.0);
            if (c == HUGE_RANGE) gen_affine(xyz[s], n[s], 1.9e153, -0.95e153); /* near HD_MAX_COORD */
            if (c == FLAT)
                for (size_t k = 0; k < n[s]; k++) xyz[s][3 * k + 2] = 0.25; /* step 0 on z */
            P[s] = hd_points_f64(xyz[s], n[s]);
            hd__src_init(&src[s], &P[s], NULL);
            CHECK_RC(hd__points_scan(&P[s], "set", 1, &box[s], NULL), HD_OK);
        }
        hd__reuse_t pool;
        hd__reuse_init(&pool);
        hd__tree_t t[2];
        CHECK_RC(hd__tree_build_pair(t, src, n, box, 1 + c % 2, &pool, NULL), HD_OK);
        for (int s = 0; s < 2 && !hdt_failed(); s++)
            for (size_t b = 0; b < t[s].nb && !hdt_failed(); b++) check_bucket_spec(&t[s], &P[s], b);
        hd__tree_free(&t[0]);
        hd__tree_free(&t[1]);
        hd__reuse_free(&pool);
        free(xyz[0]);
        free(xyz[1]);
    }
}

TEST(a_pair_of_trees_keeps_both_quantised_copies_in_one_block) {
    static const size_t sizes[][2] = {{250000, 250000}, {300000, 30000}, {30000, 300000}, {5, 1}, {65536, 65537}};
    for (size_t c = 0; c < sizeof sizes / sizeof sizes[0]; c++) {
        uint64_t seed = 8300 + (uint64_t)c;
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t n[2] = {sizes[c][0], sizes[c][1]};
        CONTEXT("seed=%llu na=%zu nb=%zu", (unsigned long long)seed, n[0], n[1]);
        double *a, *b;
        hd_points_t P[2];
        gen_cube_pair(&g, n[0], n[1], &a, &b, &P[0], &P[1]);
        hd__src_t src[2];
        hd__box_t box[2];
        for (int k = 0; k < 2; k++) {
            hd__src_init(&src[k], &P[k], NULL);
            CHECK_RC(hd__points_scan(&P[k], "set", 1, &box[k], NULL), HD_OK);
        }
        hd__reuse_t pool;
        hd__reuse_init(&pool);
        hd__tree_t t[2];
        CHECK_RC(hd__tree_build_pair(t, src, n, box, 1 + (int)(c % 2), &pool, NULL), HD_OK);
        int big = n[1] > n[0];
        size_t q_big = (n[big] + HD__BUCKET - 1) / HD__BUCKET * 3 * HD__BUCKET * sizeof(uint16_t);
        CHECK_EQ(t[big].q_borrowed, 0);
        CHECK_EQ(t[!big].q_borrowed, 1);
        CHECK_EQ((size_t)((const unsigned char *)t[!big].q - (const unsigned char *)t[big].q), (q_big + 63) / 64 * 64);
        if (n[0] == 250000 && n[1] == 250000) {
            CHECK(pool.peak <= 29 * (n[0] + n[1]) / 2);
            if (pool.peak > 29 * (n[0] + n[1]) / 2)
                fprintf(stderr, "peak %.2f bytes a point\n", (double)pool.peak / (double)(n[0] + n[1]));
        }
        /* Each tree's first and last buckets decode to within err of their
         * points (the copies do not overlap: the first tree's last bucket
         * and the second's first are intact). */
        for (int k = 0; k < 2; k++) {
            const hd__tree_t *tr = &t[k];
            size_t ends[2] = {0, tr->nb - 1};
            for (int e = 0; e < 2; e++) {
                size_t bk = ends[e];
                double x[HD__BUCKET], y[HD__BUCKET], z[HD__BUCKET];
                hd__bucket_decode(tr, bk, x, y, z);
                for (int m = 0; m < hd__bucket_size(tr, bk); m++) {
                    double p[3];
                    hd_points_get(&P[k], tr->perm[bk * HD__BUCKET + (size_t)m], p);
                    CHECK(fabs(p[0] - x[m]) * 1.7320508075688776 <= tr->bucket[bk].err);
                    CHECK(fabs(p[1] - y[m]) * 1.7320508075688776 <= tr->bucket[bk].err);
                    CHECK(fabs(p[2] - z[m]) * 1.7320508075688776 <= tr->bucket[bk].err);
                }
            }
        }
        for (int k = 0; k < 2; k++) hd__tree_free(&t[k]);
        hd__reuse_free(&pool);
        free(a);
        free(b);
    }
}
