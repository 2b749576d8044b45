/*
 * test_metrics.c -- scores at tolerances (hd_tolerance_scores), DTU's
 * capped means (hd_capped_means) and mask surfaces (hd_mask_points),
 * each against a direct computation from its definition.
 *
 * References here are loops that apply the definition to each value or
 * voxel: a count of d <= tau (or d < tau) per tolerance, a weight summed in
 * long double over values whose sum is exact in it (small integers times
 * powers of two), and the erosion written as "some neighbour in the
 * structure is background or outside".  Seeds are printed by CONTEXT.
 */
#include "check.h"
#include "gen.h"

#include <math.h>
#include <stdlib.h>

/* ---- scores at tolerances ---------------------------------------------------- */

static size_t count_within(const double *d, size_t n, double tau, hd_tolerance_rule_t rule) {
    size_t c = 0;
    for (size_t k = 0; k < n; k++) c += rule == HD_AT_MOST ? d[k] <= tau : d[k] < tau;
    return c;
}

/* Distances on a grid of 1/8 so that many equal a tolerance exactly. */
static double *grid_distances(gen_rng_t *r, size_t n) {
    double *d = malloc((n ? n : 1) * sizeof *d);
    for (size_t k = 0; k < n; k++) d[k] = (double)(gen_u64(r) % 40) / 8.0;
    return d;
}

TEST(each_tolerance_counts_the_points_within_it_by_its_rule) {
    for (uint64_t seed = 1; seed <= 60; seed++) {
        gen_rng_t r;
        gen_seed(&r, seed);
        size_t n_a = 1 + gen_u64(&r) % 300, n_b = 1 + gen_u64(&r) % 300, m = 1 + gen_u64(&r) % 9;
        double *da = grid_distances(&r, n_a), *db = grid_distances(&r, n_b), taus[9];
        for (size_t k = 0; k < m; k++) taus[k] = (double)(gen_u64(&r) % 44) / 8.0; /* unsorted, repeated */
        if (seed % 7 == 0) da[0] = INFINITY;
        for (int rule = 0; rule < 2; rule++) {
            CONTEXT("seed %llu, n_a %zu, n_b %zu, %zu taus, rule %d", (unsigned long long)seed, n_a, n_b, m, rule);
            hd_tolerance_t out[9];
            hd_error_t err;
            CHECK_RC(hd_tolerance_scores(da, NULL, n_a, db, NULL, n_b, taus, m, (hd_tolerance_rule_t)rule, out, &err),
                     HD_OK);
            for (size_t k = 0; k < m; k++) {
                size_t ca = count_within(da, n_a, taus[k], (hd_tolerance_rule_t)rule);
                size_t cb = count_within(db, n_b, taus[k], (hd_tolerance_rule_t)rule);
                CHECK_BITS(out[k].tau, taus[k]);
                CHECK_EQ(out[k].count_ab, ca);
                CHECK_EQ(out[k].count_ba, cb);
                double p = (double)ca / (double)n_a, q = (double)cb / (double)n_b;
                CHECK_BITS(out[k].precision, p);
                CHECK_BITS(out[k].recall, q);
                CHECK_BITS(out[k].fscore, p + q > 0 ? 2 * p * q / (p + q) : 0.0);
                CHECK_BITS(out[k].nsd, (double)(ca + cb) / (double)(n_a + n_b));
            }
        }
        free(da), free(db);
    }
}

TEST(weights_are_summed_exactly_whatever_their_order) {
    for (uint64_t seed = 1; seed <= 30; seed++) {
        gen_rng_t r;
        gen_seed(&r, seed);
        size_t n = 50 + gen_u64(&r) % 200;
        double *da = grid_distances(&r, n), *db = grid_distances(&r, n), *wa = malloc(n * sizeof *wa),
               *wb = malloc(n * sizeof *wb);
        for (size_t k = 0; k < n; k++) {
            /* 1e16 and 1: a plain double loop loses the ones */
            wa[k] = k % 3 ? 1.0 : 1e16;
            wb[k] = (double)(gen_u64(&r) % 1000) * 0.25;
        }
        double tau = 2.5;
        CONTEXT("seed %llu, n %zu", (unsigned long long)seed, n);
        hd_tolerance_t t;
        CHECK_RC(hd_tolerance_scores(da, wa, n, db, wb, n, &tau, 1, HD_AT_MOST, &t, NULL), HD_OK);
        long double in_a = 0, in_b = 0, all_a = 0, all_b = 0; /* exact: integers below 2^64 */
        for (size_t k = 0; k < n; k++) {
            all_a += wa[k], all_b += wb[k];
            if (da[k] <= tau) in_a += wa[k];
            if (db[k] <= tau) in_b += wb[k];
        }
        CHECK_BITS(t.within_ab, (double)in_a);
        CHECK_BITS(t.within_ba, (double)in_b);
        CHECK_BITS(t.total_a, (double)all_a);
        CHECK_BITS(t.precision, (double)in_a / (double)all_a);
        CHECK_BITS(t.nsd, (double)(in_a + in_b) / (double)(all_a + all_b));
        free(da), free(db), free(wa), free(wb);
    }
}

TEST(a_distance_equal_to_tau_is_within_at_most_and_not_below) {
    double d[] = {1.0, 0.5, 2.0}, tau = 1.0;
    hd_tolerance_t le, lt;
    CHECK_RC(hd_tolerance_scores(d, NULL, 3, d, NULL, 3, &tau, 1, HD_AT_MOST, &le, NULL), HD_OK);
    CHECK_RC(hd_tolerance_scores(d, NULL, 3, d, NULL, 3, &tau, 1, HD_BELOW, &lt, NULL), HD_OK);
    CHECK_EQ(le.count_ab, 2);
    CHECK_EQ(lt.count_ab, 1);
}

TEST(an_empty_side_gives_nan_shares_and_an_nsd_of_the_other_side) {
    double inf[] = {INFINITY, INFINITY}, tau = 3;
    hd_tolerance_t t;
    /* B empty: A's points have nothing to be near (MONAI: NSD 0) */
    CHECK_RC(hd_tolerance_scores(inf, NULL, 2, NULL, NULL, 0, &tau, 1, HD_AT_MOST, &t, NULL), HD_OK);
    CHECK_BITS(t.precision, 0.0);
    CHECK(isnan(t.recall) && isnan(t.fscore));
    CHECK_BITS(t.nsd, 0.0);
    CHECK_RC(hd_tolerance_scores(NULL, NULL, 0, NULL, NULL, 0, &tau, 1, HD_AT_MOST, &t, NULL), HD_OK);
    CHECK(isnan(t.nsd) && isnan(t.precision));
}

TEST(bad_tolerance_input_is_refused_with_its_place) {
    double d[] = {1, NAN}, tau = 1, neg = -1, w[] = {1, -2};
    hd_tolerance_t t;
    hd_error_t err;
    CHECK_RC(hd_tolerance_scores(d, NULL, 2, d, NULL, 1, &tau, 1, HD_AT_MOST, &t, &err), HD_ENONFINITE);
    CHECK(strstr(err.message, "distance 1 of A to B") != NULL);
    CHECK_RC(hd_tolerance_scores(d, NULL, 1, d, NULL, 1, &neg, 1, HD_AT_MOST, &t, &err), HD_EINVAL);
    CHECK_RC(hd_tolerance_scores(d, w, 1, d, w, 2, &tau, 1, HD_AT_MOST, &t, &err), HD_ENONFINITE);
    CHECK_RC(hd_tolerance_scores(d, w, 1, d + 1, NULL, 0, &tau, 1, HD_AT_MOST, &t, &err), HD_OK);
    double w2[] = {-2};
    CHECK_RC(hd_tolerance_scores(d, w2, 1, NULL, NULL, 0, &tau, 1, HD_AT_MOST, &t, &err), HD_EINVAL);
    CHECK_RC(hd_tolerance_scores(d, NULL, 1, NULL, NULL, 0, &tau, 1, (hd_tolerance_rule_t)7, &t, &err), HD_EINVAL);
    CHECK_RC(hd_tolerance_scores(NULL, NULL, 1, NULL, NULL, 0, &tau, 1, HD_AT_MOST, &t, &err), HD_EINVAL);
}

/* ---- DTU's capped means ---------------------------------------------------------- */

TEST(capped_means_drop_the_distances_at_or_above_the_cap) {
    double a[] = {0.5, 1.5, 20.0, 30.0, INFINITY}, b[] = {2.0, 4.0};
    hd_capped_mean_t c;
    CHECK_RC(hd_capped_means(a, 5, b, 2, 20.0, &c, NULL), HD_OK);
    CHECK_EQ(c.kept_ab, 2);
    CHECK_BITS(c.accuracy, 1.0);
    CHECK_BITS(c.completeness, 3.0);
    CHECK_BITS(c.overall, 2.0);
    CHECK_RC(hd_capped_means(a, 5, b, 2, INFINITY, &c, NULL), HD_OK);
    CHECK_EQ(c.kept_ab, 4);
    CHECK_BITS(c.accuracy, 52.0 / 4);
    CHECK_RC(hd_capped_means(a, 5, b, 2, 0.1, &c, NULL), HD_OK);
    CHECK(isnan(c.accuracy) && isnan(c.overall));
    CHECK_RC(hd_capped_means(a, 5, b, 2, 0.0, &c, NULL), HD_EINVAL);
    CHECK_RC(hd_capped_means(a, 5, b, 2, NAN, &c, NULL), HD_EINVAL);
}

/* ---- mask surfaces ------------------------------------------------------------------ */

/* The definition: foreground, and some offset of the structure (at most
 * `conn` nonzero entries, only along the used axes) leads to background or
 * outside the image. */
static int brute_surface(const uint8_t *v, const size_t n[3], const int used[3], int conn, size_t i, size_t j,
                         size_t k) {
    int rank = used[0] + used[1] + used[2];
    if (rank == 0) return 1;
    long at[3] = {(long)i, (long)j, (long)k};
    for (int o = 0; o < 27; o++) {
        int d[3] = {o % 3 - 1, o / 3 % 3 - 1, o / 9 - 1}, nz = 0, ok = 1;
        for (int a = 0; a < 3; a++) {
            nz += d[a] != 0;
            if (d[a] && !used[a]) ok = 0;
        }
        if (!ok || nz == 0 || nz > conn) continue;
        long q[3];
        for (int a = 0; a < 3; a++) q[a] = at[a] + d[a];
        for (int a = 0; a < 3; a++)
            if (q[a] < 0 || q[a] >= (long)n[a]) return 1;
        if (!v[((size_t)q[2] * n[1] + (size_t)q[1]) * n[0] + (size_t)q[0]]) return 1;
    }
    return 0;
}

TEST(mask_surfaces_are_the_voxels_erosion_removes) {
    for (uint64_t seed = 1; seed <= 40; seed++) {
        gen_rng_t r;
        gen_seed(&r, seed);
        size_t n[3] = {1 + gen_u64(&r) % 12, 1 + gen_u64(&r) % 12, 1 + gen_u64(&r) % 9};
        if (seed % 5 == 0) n[2] = 1; /* a 2-D mask */
        size_t nv = n[0] * n[1] * n[2];
        uint8_t *v = malloc(nv);
        unsigned density = 40 + (unsigned)(gen_u64(&r) % 60);
        for (size_t q = 0; q < nv; q++) v[q] = (uint8_t)(gen_u64(&r) % 100 < density ? 1 + gen_u64(&r) % 200 : 0);
        double spacing[3] = {0.75, 1.25, 2.5};
        hd_mask_t mk;
        hd_mask_init(&mk, v, n[0], n[1], n[2], spacing);
        for (int conn = 1; conn <= 3; conn++)
            for (int dims = 0; dims <= 3; dims += dims == 0 ? 2 : 1) {
                CONTEXT("seed %llu, %zux%zux%zu, connectivity %d, dims %d", (unsigned long long)seed, n[0], n[1],
                        n[2], conn, dims);
                hd_mask_options_t o;
                hd_mask_options_init(&o);
                o.connectivity = conn;
                o.dims = dims;
                hd_cloud_t *c = NULL;
                hd_mask_info_t info;
                CHECK_RC(hd_mask_points(&mk, &o, &c, &info, NULL), HD_OK);
                if (!c) return;
                int used[3];
                for (int a = 0; a < 3; a++) used[a] = dims == 3 ? 1 : dims == 2 ? a < 2 : n[a] > 1;
                size_t p = 0, fg = 0;
                const double *xyz = c->data;
                for (size_t k = 0; k < n[2]; k++)
                    for (size_t j = 0; j < n[1]; j++)
                        for (size_t i = 0; i < n[0]; i++) {
                            if (!v[(k * n[1] + j) * n[0] + i]) continue;
                            fg++;
                            if (!brute_surface(v, n, used, conn, i, j, k)) continue;
                            CHECK(p < c->count);
                            if (p >= c->count) break;
                            CHECK_BITS(xyz[3 * p], 0.75 * (double)i);
                            CHECK_BITS(xyz[3 * p + 1], 1.25 * (double)j);
                            CHECK_BITS(xyz[3 * p + 2], 2.5 * (double)k);
                            p++;
                        }
                CHECK_EQ(p, c->count);
                CHECK_EQ(info.points, c->count);
                CHECK_EQ(info.foreground, fg);
                hd_cloud_free(c);
            }
        free(v);
    }
}

TEST(mask_all_gives_every_foreground_voxel_through_the_affine_and_scale) {
    uint8_t v[8] = {0, 1, 0, 1, 1, 0, 0, 1};
    hd_mask_t mk;
    hd_mask_init(&mk, v, 2, 2, 2, NULL);
    double m[3][4] = {{0, 2, 0, 1}, {3, 0, 0, -1}, {0, 0.5, 4, 0}};
    memcpy(mk.m, m, sizeof m);
    mk.scale = 1000;
    hd_mask_options_t o;
    hd_mask_options_init(&o);
    o.points = HD_MASK_ALL;
    o.dtype = HD_FLOAT32;
    hd_cloud_t *c = NULL;
    CHECK_RC(hd_mask_points(&mk, &o, &c, NULL, NULL), HD_OK);
    CHECK_EQ(c->count, 4);
    CHECK_EQ(c->dtype, HD_FLOAT32);
    const float *f = c->data; /* voxel 1 = (1, 0, 0): x = 1 * 1000, y = (3 + -1) * 1000, z = 0 */
    CHECK_BITS((double)f[0], 1000.0);
    CHECK_BITS((double)f[1], 2000.0);
    CHECK_BITS((double)f[2], 0.0);
    hd_cloud_free(c);
}

TEST(bad_masks_are_refused) {
    uint8_t v[4] = {1, 1, 1, 1};
    hd_mask_t mk;
    hd_mask_options_t o;
    hd_mask_options_init(&o);
    hd_cloud_t *c = (hd_cloud_t *)&mk;
    hd_error_t err;
    hd_mask_init(&mk, v, 2, 2, 0, NULL);
    CHECK_RC(hd_mask_points(&mk, &o, &c, NULL, &err), HD_EINVAL);
    CHECK(c == NULL);
    hd_mask_init(&mk, v, 2, 2, 1, NULL);
    o.connectivity = 4;
    CHECK_RC(hd_mask_points(&mk, &o, &c, NULL, &err), HD_EINVAL);
    o.connectivity = 1;
    o.dims = 1;
    CHECK_RC(hd_mask_points(&mk, &o, &c, NULL, &err), HD_EINVAL);
    o.dims = 0;
    mk.m[0][0] = 1e200;
    CHECK_RC(hd_mask_points(&mk, &o, &c, NULL, &err), HD_ERANGE);
    mk.m[0][0] = NAN;
    CHECK_RC(hd_mask_points(&mk, &o, &c, NULL, &err), HD_ENONFINITE);
    hd_mask_init(&mk, v, (size_t)1 << 62, 4, 4, NULL);
    CHECK_RC(hd_mask_points(&mk, &o, &c, NULL, &err), HD_EOVERFLOW);
}
