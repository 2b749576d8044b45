/*
 * test_labels.c -- surfel areas (masks/surfels.c), connected components
 * (masks/components.c), the area-weighted percentile and label maps
 * (hd_label_map), each against values worked out by hand from the
 * definitions or against a direct computation.
 *
 * Hand values of the areas: one corner cut off is the triangle of the
 * three edge midpoints next to it, area sqrt(3)/8; two corners of an edge
 * give the rectangle 1 x sqrt(2)/2; four corners of a face the unit
 * square; a corner with its three neighbours the regular hexagon of side
 * sqrt(2)/2, area 3 sqrt(3)/4.  With spacing (s0, s1, s2) the corner's
 * triangle has edge vectors (-s0/2, s1/2, 0) and (-s0/2, 0, s2/2), area
 * |(s1 s2, s0 s2, s0 s1)| / 8.  Seeds are printed by CONTEXT.
 */
#include "check.h"
#include "gen.h"

#include "masks/masks.h"

#include <math.h>
#include <stdlib.h>

static const double ident[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

static int close_to(double a, double b) { return fabs(a - b) <= 1e-12 * (1 + fabs(b)); }

TEST(surfel_areas_of_the_planar_configurations_are_their_polygons) {
    double area[256];
    hd__surfel_areas(3, ident, area);
    CHECK(area[0] == 0 && area[255] == 0);
    CHECK(close_to(area[1], sqrt(3) / 8));
    CHECK(close_to(area[0x80], sqrt(3) / 8));
    CHECK(close_to(area[0x03], sqrt(2) / 2)); /* corners 0, 1: the edge along i */
    CHECK(close_to(area[0x0f], 1.0));         /* the face k = 0 */
    CHECK(close_to(area[0x55], 1.0));         /* the face i = 0 */
    CHECK(close_to(area[0x17], 3 * sqrt(3) / 4)); /* corner 0 and its neighbours 1, 2, 4 */
    CHECK(close_to(area[0x09], 2 * sqrt(3) / 8)); /* corners 0, 3: a face diagonal, two triangles */
}

/* Non-planar loops: the largest fan from a crossing.  Three corners of the
 * face k = 0 (0, 1, 2): the pentagon's largest fan is the triangle of the
 * three k-edge midpoints, in the plane k = 1/2 (area 1/2), and two
 * triangles of area vectors (1, 1, 1)/4 and (1, 1, 1)/8 (as DeepMind's
 * table has it for this configuration).  Four corners in a chain (1, 0, 2,
 * 6 as i, j, k steps): the hexagon's largest fan has triangles sqrt(3)/8,
 * 3 sqrt(3)/8 and two of sqrt(2)/4 (DeepMind's: the same four). */
TEST(surfel_areas_of_non_planar_loops_are_their_largest_fans) {
    double area[256];
    hd__surfel_areas(3, ident, area);
    CHECK(close_to(area[0x07], 0.5 + sqrt(3) / 4 + sqrt(3) / 8));
    CHECK(close_to(area[0x47], sqrt(3) / 2 + sqrt(2) / 2));
}

TEST(surfel_areas_follow_the_spacing) {
    const double s[3] = {3, 2, 1}, lin[3][3] = {{3, 0, 0}, {0, 2, 0}, {0, 0, 1}};
    double area[256];
    hd__surfel_areas(3, lin, area);
    double corner = sqrt(s[1] * s[1] * s[2] * s[2] + s[0] * s[0] * s[2] * s[2] + s[0] * s[0] * s[1] * s[1]) / 8;
    CHECK(close_to(area[1], corner));
    CHECK(close_to(area[0x0f], s[0] * s[1]));
    CHECK(close_to(area[0x55], s[1] * s[2]));
    CHECK(close_to(area[0x03], s[0] * sqrt(s[1] * s[1] + s[2] * s[2]) / 2));
    double sq[256];
    hd__surfel_areas(2, lin, sq);
    CHECK(close_to(sq[1], 0.5 * sqrt(s[0] * s[0] + s[1] * s[1])));
    CHECK(close_to(sq[3], s[0])); /* corners 0, 1: the boundary runs along i */
    CHECK(close_to(sq[5], s[1]));
    CHECK(close_to(sq[6], sqrt(s[0] * s[0] + s[1] * s[1]))); /* two diagonal corners: two segments */
    CHECK(sq[0] == 0 && sq[15] == 0);
}

/* The code of a configuration after permuting and reflecting the axes. */
static int transformed(int code, const int perm[3], int flip) {
    int out = 0;
    for (int v = 0; v < 8; v++) {
        if (!(code >> v & 1)) continue;
        int w = 0;
        for (int a = 0; a < 3; a++) w |= ((v >> perm[a] & 1) ^ (flip >> a & 1)) << a;
        out |= 1 << w;
    }
    return out;
}

TEST(surfel_areas_do_not_depend_on_how_the_cube_is_turned_or_complemented) {
    double area[256];
    hd__surfel_areas(3, ident, area);
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int code = 1; code < 255; code++) {
        CONTEXT("code %d", code);
        CHECK(area[code] > 0);
        CHECK(close_to(area[code ^ 0xff], area[code]));
        for (int p = 0; p < 6; p++)
            for (int flip = 0; flip < 8; flip++) CHECK(close_to(area[transformed(code, perms[p], flip)], area[code]));
    }
}

TEST(every_loop_is_closed_and_each_crossing_edge_is_in_one_loop) {
    for (int code = 1; code < 255; code++) {
        int e[48], n = hd__surfel_loops(code, 3, e), seen[12] = {0}, crossings = 0;
        int c = __builtin_popcount((unsigned)code) > 4 ? code ^ 0xff : code;
        for (int t = 0; t < n; t++)
            if (e[t] >= 0) seen[e[t]]++;
        for (int edge = 0; edge < 12; edge++) {
            int axis = edge / 4, q = edge % 4, lo = axis == 0 ? 1 : 0, hi = axis == 2 ? 1 : 2;
            int v = (q & 1) << lo | (q >> 1 & 1) << hi, w = v | 1 << axis;
            int crosses = (c >> v & 1) != (c >> w & 1);
            CONTEXT("code %d edge %d", code, edge);
            CHECK_EQ(seen[edge], crosses);
            crossings += crosses;
        }
        CHECK(n >= crossings + 1 && e[n - 1] == -1);
    }
}

/* ---- the area-weighted percentile ---------------------------------------------- */

TEST(weighted_percentile_is_the_first_distance_holding_the_share) {
    const double d[] = {3, 1, 2, 2, 5}, w[] = {1, 1, 2, 0, 1}; /* sorted: 1(1) 2(2) 2(0) 3(1) 5(1); total 5 */
    double out;
    hd_error_t err;
    CHECK_RC(hd_weighted_percentile(d, w, 5, 20, &out, &err), HD_OK);
    CHECK_BITS(out, 1.0);
    CHECK_RC(hd_weighted_percentile(d, w, 5, 21, &out, &err), HD_OK);
    CHECK_BITS(out, 2.0);
    CHECK_RC(hd_weighted_percentile(d, w, 5, 60, &out, &err), HD_OK);
    CHECK_BITS(out, 2.0);
    CHECK_RC(hd_weighted_percentile(d, w, 5, 80, &out, &err), HD_OK);
    CHECK_BITS(out, 3.0);
    CHECK_RC(hd_weighted_percentile(d, w, 5, 100, &out, &err), HD_OK);
    CHECK_BITS(out, 5.0);
    CHECK_RC(hd_weighted_percentile(d, w, 5, 0, &out, &err), HD_OK);
    CHECK_BITS(out, 1.0);
    CHECK_RC(hd_weighted_percentile(d, w, 0, 50, &out, &err), HD_EEMPTY);
    CHECK_RC(hd_weighted_percentile(d, w, 5, 101, &out, &err), HD_EINVAL);
    const double zero[] = {0, 0}, neg[] = {1, -1};
    CHECK_RC(hd_weighted_percentile(d, zero, 2, 50, &out, &err), HD_EINVAL);
    CHECK_RC(hd_weighted_percentile(d, neg, 2, 50, &out, &err), HD_EINVAL);
}

/* ---- components ------------------------------------------------------------------ */

TEST(components_follow_the_connectivity) {
    /* 3 x 3 x 1: two voxels touching at a corner, one apart */
    const uint8_t fg[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const size_t w[3] = {3, 3, 1};
    uint32_t comp[9];
    hd__neighbourhood_t nb;
    hd__neighbourhood(&nb, w, 0, 1);
    CHECK_EQ(hd__components(fg, w, &nb, comp), 3);
    CHECK_EQ(comp[0], 1);
    CHECK_EQ(comp[4], 2);
    CHECK_EQ(comp[8], 3);
    hd__neighbourhood(&nb, w, 0, 2);
    CHECK_EQ(hd__components(fg, w, &nb, comp), 1);
    CHECK_EQ(comp[8], 1);
    /* in 3-D, voxels touching at a vertex only: 26-connected alone */
    const uint8_t cube[8] = {1, 0, 0, 0, 0, 0, 0, 1};
    const size_t w3[3] = {2, 2, 2};
    uint32_t c3[8];
    for (int conn = 1; conn <= 3; conn++) {
        hd__neighbourhood(&nb, w3, 0, conn);
        CHECK_EQ(hd__components(cube, w3, &nb, c3), conn == 3 ? 1 : 2);
    }
}

/* ---- label maps -------------------------------------------------------------------- */

static hd_label_row_t *row_of(hd_label_table_t *t, int64_t label) {
    for (size_t k = 0; k < t->n_rows; k++)
        if (t->rows[k].label == label) return &t->rows[k];
    return NULL;
}

TEST(a_label_map_row_equals_the_masks_measured_whole) {
    for (uint64_t seed = 1; seed <= 12; seed++) {
        gen_rng_t r;
        gen_seed(&r, seed);
        size_t n[3] = {6 + gen_u64(&r) % 7, 5 + gen_u64(&r) % 7, seed % 3 == 0 ? 1 : 4 + gen_u64(&r) % 5};
        size_t nv = n[0] * n[1] * n[2];
        int16_t *la = malloc(nv * sizeof *la), *lb = malloc(nv * sizeof *lb);
        uint8_t *ma = malloc(nv), *mb = malloc(nv);
        for (size_t v = 0; v < nv; v++) la[v] = (int16_t)(gen_u64(&r) % 4), lb[v] = (int16_t)(gen_u64(&r) % 4);
        const double sp[3] = {0.5, 1.25, 2};
        hd_label_image_t ia, ib;
        hd_label_image_init(&ia, la, HD_LABEL_I16, n[0], n[1], n[2], sp);
        hd_label_image_init(&ib, lb, HD_LABEL_I16, n[0], n[1], n[2], sp);
        hd_label_options_t o;
        hd_label_options_init(&o);
        hd_label_table_t *t = NULL;
        hd_error_t err;
        CONTEXT("seed %llu, %zu x %zu x %zu", (unsigned long long)seed, n[0], n[1], n[2]);
        CHECK_RC(hd_label_map(&ia, &ib, &o, &t, &err), HD_OK);
        for (int64_t label = 1; label <= 3 && t; label++) {
            hd_label_row_t *row = row_of(t, label);
            CHECK(row != NULL);
            if (!row) continue;
            for (size_t v = 0; v < nv; v++) ma[v] = la[v] == label, mb[v] = lb[v] == label;
            hd_mask_t mka, mkb;
            hd_mask_init(&mka, ma, n[0], n[1], n[2], sp);
            hd_mask_init(&mkb, mb, n[0], n[1], n[2], sp);
            hd_mask_options_t mo;
            hd_mask_options_init(&mo);
            hd_cloud_t *ca = NULL, *cb = NULL;
            CHECK_RC(hd_mask_points(&mka, &mo, &ca, NULL, &err), HD_OK);
            CHECK_RC(hd_mask_points(&mkb, &mo, &cb, NULL, &err), HD_OK);
            if (!ca || !cb || !ca->count || !cb->count) {
                hd_cloud_free(ca), hd_cloud_free(cb);
                continue;
            }
            double *da = malloc(ca->count * sizeof *da), *db = malloc(cb->count * sizeof *db);
            hd_points_t A = hd_cloud_points(ca), B = hd_cloud_points(cb);
            CHECK_RC(hd_distances(&A, &B, NULL, da, NULL, db, NULL, &err), HD_OK);
            hd_summary_t s;
            hd_percentile_t p;
            CHECK_RC(hd_summarize(da, ca->count, db, cb->count, &s, &err), HD_OK);
            CHECK_RC(hd_percentile_of(da, ca->count, db, cb->count, 95, &p, &err), HD_OK);
            CHECK_EQ(row->points_a, ca->count);
            CHECK_EQ(row->points_b, cb->count);
            CHECK_BITS(row->hd_ab, s.max_ab);
            CHECK_BITS(row->hd_ba, s.max_ba);
            CHECK_BITS(row->hd_p, p.symmetric);
            CHECK_BITS(row->hd_p_pooled, p.pooled);
            CHECK_BITS(row->assd, s.mean_pooled);
            /* the surfels of the windows are those of the whole masks */
            hd_cloud_t *sa = NULL, *sb = NULL;
            double *wa = NULL, *wb = NULL;
            CHECK_RC(hd_mask_surfels(&mka, 0, &sa, &wa, &err), HD_OK);
            CHECK_RC(hd_mask_surfels(&mkb, 0, &sb, &wb, &err), HD_OK);
            CHECK_EQ(row->surfels_a, sa->count);
            CHECK_EQ(row->surfels_b, sb->count);
            hd_cloud_free(sa), hd_cloud_free(sb), free(wa), free(wb);
            free(da), free(db);
            hd_cloud_free(ca), hd_cloud_free(cb);
        }
        hd_label_table_free(t);
        free(la), free(lb), free(ma), free(mb);
    }
}

TEST(absent_labels_follow_the_empty_policy) {
    const uint8_t a[8] = {0, 1, 1, 0, 0, 0, 0, 0}, b[8] = {0, 1, 2, 0, 0, 0, 0, 0};
    hd_label_image_t ia, ib;
    hd_label_image_init(&ia, a, HD_LABEL_U8, 2, 2, 2, NULL);
    hd_label_image_init(&ib, b, HD_LABEL_U8, 2, 2, 2, NULL);
    hd_label_options_t o;
    hd_label_options_init(&o);
    hd_label_table_t *t = (hd_label_table_t *)&o;
    hd_error_t err;
    CHECK_RC(hd_label_map(&ia, &ib, &o, &t, &err), HD_EEMPTY); /* label 2 is absent from A */
    CHECK(t == NULL);
    CHECK(strstr(err.message, "label 2") != NULL);
    o.empty = HD_EMPTY_MONAI;
    const int64_t want[3] = {2, 7, 1};
    o.labels = want, o.n_labels = 3;
    CHECK_RC(hd_label_map(&ia, &ib, &o, &t, &err), HD_OK);
    CHECK_EQ(t->n_rows, 3);
    CHECK_EQ(t->rows[0].label, 2);
    CHECK_EQ(t->rows[0].empty, 1);
    CHECK(isinf(t->rows[0].hausdorff) && isinf(t->rows[0].hd_surfel));
    CHECK_BITS(t->rows[0].nsd, 0.0);
    CHECK_BITS(t->rows[0].nsd_surfel, 0.0);
    CHECK_BITS(t->rows[0].dice, 0.0);
    CHECK_EQ(t->rows[1].empty, 3); /* 7: in neither */
    CHECK(isnan(t->rows[1].hausdorff) && isnan(t->rows[1].nsd) && isnan(t->rows[1].dice));
    CHECK_EQ(t->rows[2].empty, 0);
    CHECK_BITS(t->rows[2].dice, 2.0 / 3.0);
    hd_label_table_free(t);
    hd_label_table_free(NULL);
}

TEST(components_are_listed_per_label_and_side) {
    /* 7 x 1 x 1... as 7 x 3 x 1: A has two blobs of label 1, B one */
    uint8_t a[21] = {0}, b[21] = {0};
    a[7 + 1] = a[7 + 5] = 1;
    b[7 + 1] = b[7 + 2] = 1;
    hd_label_image_t ia, ib;
    hd_label_image_init(&ia, a, HD_LABEL_U8, 7, 3, 1, NULL);
    hd_label_image_init(&ib, b, HD_LABEL_U8, 7, 3, 1, NULL);
    hd_label_options_t o;
    hd_label_options_init(&o);
    o.components = 4;
    o.tau = 2;
    hd_label_table_t *t = NULL;
    hd_error_t err;
    CHECK_RC(hd_label_map(&ia, &ib, &o, &t, &err), HD_OK);
    CHECK_EQ(t->rows[0].components_a, 2);
    CHECK_EQ(t->rows[0].components_b, 1);
    CHECK_EQ(t->n_components, 3);
    const hd_label_component_t *c = t->components;
    CHECK(c[0].side == 0 && c[0].index == 1 && c[0].overlap == 1 && c[0].detected);
    CHECK_BITS(c[0].hausdorff, 0.0);
    CHECK(c[1].side == 0 && c[1].index == 2 && c[1].overlap == 0 && !c[1].detected); /* 3 from B's nearest */
    CHECK_BITS(c[1].hausdorff, 3.0);
    CHECK_BITS(c[1].nearest, 3.0);
    CHECK(c[2].side == 1 && c[2].voxels == 2 && c[2].detected);
    CHECK_BITS(c[2].hausdorff, 1.0);
    hd_label_table_free(t);
    /* B without the label: A's components are at +inf, not detected */
    memset(b, 0, sizeof b);
    o.empty = HD_EMPTY_MONAI;
    CHECK_RC(hd_label_map(&ia, &ib, &o, &t, &err), HD_OK);
    CHECK_EQ(t->n_components, 2);
    for (size_t k = 0; k < t->n_components; k++) {
        CHECK(isinf(t->components[k].hausdorff) && isinf(t->components[k].hd_p) && isinf(t->components[k].nearest));
        CHECK(!t->components[k].detected);
    }
    hd_label_table_free(t);
}

TEST(bad_label_maps_are_refused) {
    const uint8_t a[8] = {0};
    hd_label_image_t ia, ib;
    hd_label_image_init(&ia, a, HD_LABEL_U8, 2, 2, 2, NULL);
    hd_label_image_init(&ib, a, HD_LABEL_U8, 2, 4, 1, NULL);
    hd_label_options_t o;
    hd_label_options_init(&o);
    hd_label_table_t *t = NULL;
    hd_error_t err;
    CHECK_RC(hd_label_map(&ia, &ib, &o, &t, &err), HD_EINVAL);
    CHECK_RC(hd_label_map(&ia, &ia, &o, NULL, &err), HD_EINVAL);
    o.components = 5;
    CHECK_RC(hd_label_map(&ia, &ia, &o, &t, &err), HD_EINVAL);
    o.components = 0, o.percentile = 101;
    CHECK_RC(hd_label_map(&ia, &ia, &o, &t, &err), HD_EINVAL);
    o.percentile = 95, o.tau = NAN;
    CHECK_RC(hd_label_map(&ia, &ia, &o, &t, &err), HD_EINVAL);
    o.tau = 1;
    ib = ia;
    ib.type = (hd_label_type_t)99;
    CHECK_RC(hd_label_map(&ia, &ib, &o, &t, &err), HD_EINVAL);
    CHECK(t == NULL);
    CHECK_RC(hd_label_map(&ia, &ia, &o, &t, &err), HD_OK); /* all background: no row */
    CHECK_EQ(t->n_rows, 0);
    hd_label_table_free(t);
}

static int by_d(const void *x, const void *y) {
    const double *a = x, *b = y;
    return (a[0] > b[0]) - (a[0] < b[0]);
}

/* The reference: sort, then the running weight at the end of each run of
 * equal distances (weights are multiples of 1/8 below 2^20: every partial
 * sum is exact in a double). */
TEST(weighted_percentile_equals_a_sorted_pass) {
    for (uint64_t seed = 1; seed <= 200; seed++) {
        gen_rng_t r;
        gen_seed(&r, seed);
        size_t n = 1 + gen_u64(&r) % 200;
        double *d = malloc(n * sizeof *d), *w = malloc(n * sizeof *w), *pair = malloc(2 * n * sizeof *pair);
        double all = 0;
        for (size_t k = 0; k < n; k++) {
            d[k] = (double)(gen_u64(&r) % 30) / 4;
            w[k] = seed % 5 == 0 && k % 3 ? 0.0 : (double)(gen_u64(&r) % 64) / 8;
            if (k == n - 1 && all + w[k] == 0) w[k] = 1;
            all += w[k];
            pair[2 * k] = d[k], pair[2 * k + 1] = w[k];
        }
        qsort(pair, n, 2 * sizeof *pair, by_d);
        double p = seed % 7 == 0 ? 100.0 : seed % 11 == 0 ? 0.0 : (double)(gen_u64(&r) % 1001) / 10;
        double want = pair[2 * (n - 1)], run = 0;
        for (size_t k = 0; k < n; k++) {
            run += pair[2 * k + 1];
            if (k + 1 < n && pair[2 * k + 2] == pair[2 * k]) continue;
            if (run / all >= p / 100) {
                want = pair[2 * k];
                break;
            }
        }
        double got;
        hd_error_t err;
        CONTEXT("seed %llu, n %zu, p %g", (unsigned long long)seed, n, p);
        CHECK_RC(hd_weighted_percentile(d, w, n, p, &got, &err), HD_OK);
        CHECK_BITS(got, want);
        free(d), free(w), free(pair);
    }
}
