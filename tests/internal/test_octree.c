/*
 * test_octree.c -- the octree (src/classic/octree.c) and the box bounds every
 * pruning rule relies on: a computed lower bound never exceeds, and a
 * computed upper bound is never below, the computed squared distance to any
 * point the box holds, at ordinary, huge (1e150) and tiny (1e-150) scales;
 * and the tree's structure: a partition of the points by the stored split
 * values, exact node boxes, leaves where the limits say, and every point
 * finding its own leaf.
 */
#include "brute.h"
#include "check.h"
#include "gen.h"
#include "classic/classic_int.h" /* white-box: the octree */

#include <math.h>
#include <stdlib.h>

/* A seeded point set of one of several shapes and scales. */
static double *make_points(gen_rng_t *g, size_t n, int shape, double scale) {
    double *p = malloc(3 * n * sizeof *p);
    double m[3] = {0, 0, 0};
    switch (shape) {
    case 0: gen_gauss(g, p, n, m, 1.0); break;
    case 1: gen_cube(g, p, n, -1.0, 1.0); break;
    case 2: gen_lattice(g, p, n, 4); break;
    case 3: gen_plane(g, p, n); break;
    default: gen_line(g, p, n); break;
    }
    gen_affine(p, n, scale, 0.0);
    return p;
}

static const double scales[] = {1.0, 1e150, 1e-150, 1e-9};

TEST(point_to_box_bounds_bracket_every_distance) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 400; seed++) {
        gen_seed(&g, seed);
        double scale = scales[seed % 4];
        size_t n = 1 + gen_u64(&g) % 20;
        CONTEXT("seed=%llu scale=%g n=%zu", (unsigned long long)seed, scale, n);
        double *p = make_points(&g, n, (int)(seed % 5), scale);
        hd__box_t box;
        hd__box_of(p, n, &box);
        for (int q = 0; q < 20 && !hdt_failed(); q++) {
            double x[3];
            if (q < 5) {
                for (int k = 0; k < 3; k++) x[k] = p[3 * (gen_u64(&g) % n) + k];
            } else {
                for (int k = 0; k < 3; k++) x[k] = (4.0 * gen_unit(&g) - 2.0) * scale;
            }
            double lb = hd__box_lb2(&box, x), ub = hd__box_ub2(&box, x);
            for (size_t k = 0; k < n; k++) {
                double d = brute_d2(x, p + 3 * k);
                CHECK(lb <= d);
                CHECK(d <= ub);
            }
        }
        free(p);
        if (hdt_failed()) return;
    }
}

TEST(box_to_box_bounds_bracket_every_pair) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 400; seed++) {
        gen_seed(&g, seed);
        double scale = scales[seed % 4];
        size_t na = 1 + gen_u64(&g) % 15, nb = 1 + gen_u64(&g) % 15;
        CONTEXT("seed=%llu scale=%g", (unsigned long long)seed, scale);
        double *a = make_points(&g, na, (int)(seed % 5), scale);
        double *b = make_points(&g, nb, (int)((seed / 5) % 5), scale);
        double shift = (double)(gen_u64(&g) % 4) * scale; /* apart, touching or overlapping */
        for (size_t k = 0; k < nb; k++) b[3 * k] += shift;
        hd__box_t ba, bb;
        hd__box_of(a, na, &ba);
        hd__box_of(b, nb, &bb);
        double lb = hd__box_box_lb2(&ba, &bb), ub = hd__box_box_ub2(&ba, &bb);
        CHECK_BITS(lb, hd__box_box_lb2(&bb, &ba));
        CHECK_BITS(ub, hd__box_box_ub2(&bb, &ba));
        for (size_t i = 0; i < na; i++)
            for (size_t j = 0; j < nb; j++) {
                double d = brute_d2(a + 3 * i, b + 3 * j);
                CHECK(lb <= d);
                CHECK(d <= ub);
            }
        free(a);
        free(b);
        if (hdt_failed()) return;
    }
}

TEST(a_single_point_box_gives_the_exact_distance) {
    double p[3] = {1.5, -2.25, 1e-3}, q[3] = {-7.0, 0.125, 3.0};
    hd__box_t box;
    hd__box_of(p, 1, &box);
    CHECK_BITS(hd__box_lb2(&box, q), brute_d2(p, q));
    CHECK_BITS(hd__box_ub2(&box, q), brute_d2(p, q));
}

/* Walk the tree checking its structural invariants. */
static void check_node(const hd__octree_t *t, const hd__onode_t *nd, size_t leaf_size,
                       size_t *leaves) {
    CHECK(t->node[nd->id] == nd);
    hd__box_t box;
    hd__box_of(t->pts + 3 * nd->begin, nd->count, &box);
    for (int k = 0; k < 3; k++) {
        CHECK_BITS(nd->box.lo[k], box.lo[k]);
        CHECK_BITS(nd->box.hi[k], box.hi[k]);
    }
    int equal = box.lo[0] == box.hi[0] && box.lo[1] == box.hi[1] && box.lo[2] == box.hi[2];
    if (!nd->kids) {
        for (size_t p = nd->begin + 1; p < nd->begin + nd->count; p++)
            CHECK(t->idx[p - 1] < t->idx[p]); /* the partition is stable */
        (*leaves)++;
        CHECK(nd->depth >= t->max_depth || nd->count <= leaf_size || equal);
        return;
    }
    CHECK(nd->depth < t->max_depth && nd->count > leaf_size && !equal);
    size_t next = nd->begin;
    for (int k = 0; k < nd->nkids; k++) {
        const hd__onode_t *c = &nd->kids[k];
        CHECK(c->count > 0);
        CHECK_EQ(c->begin, next);
        CHECK_EQ(c->depth, nd->depth + 1);
        if (k) CHECK(nd->kids[k - 1].octant < c->octant);
        for (size_t p = c->begin; p < c->begin + c->count; p++)
            CHECK_EQ(hd__octant(nd->mid, t->pts + 3 * p), c->octant);
        next += c->count;
        check_node(t, c, leaf_size, leaves);
    }
    CHECK_EQ(next, nd->begin + nd->count);
}

TEST(tree_partitions_the_points_by_its_split_values) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 120; seed++) {
        gen_seed(&g, seed);
        double scale = scales[seed % 4];
        size_t n = 1 + gen_u64(&g) % 400;
        int depth = (int)(gen_u64(&g) % 11);
        size_t leaf = 1 + gen_u64(&g) % 10;
        CONTEXT("seed=%llu n=%zu depth=%d leaf=%zu scale=%g", (unsigned long long)seed, n, depth,
                leaf, scale);
        double *p = make_points(&g, n, (int)(seed % 5), scale);
        hd__octree_t t;
        CHECK_RC(hd__octree_build(&t, p, n, depth, leaf, NULL), HD_OK);
        CHECK(t.depth <= depth);
        int *seen = calloc(n, sizeof *seen);
        for (size_t k = 0; k < n; k++) {
            CHECK(t.idx[k] < n);
            if (t.idx[k] < n) seen[t.idx[k]]++;
            for (int c = 0; c < 3; c++) CHECK_BITS(t.pts[3 * k + c], p[3 * t.idx[k] + c]);
        }
        for (size_t k = 0; k < n; k++) CHECK_EQ(seen[k], 1);
        size_t leaves = 0;
        check_node(&t, t.root, leaf, &leaves);
        CHECK_EQ(leaves, t.leaves);
        free(seen);
        hd__octree_free(&t);
        free(p);
        if (hdt_failed()) return;
    }
}

TEST(node_bounds_bracket_the_distance_to_each_of_its_points) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 60; seed++) {
        gen_seed(&g, seed);
        double scale = scales[seed % 4];
        size_t n = 1 + gen_u64(&g) % 300;
        CONTEXT("seed=%llu n=%zu scale=%g", (unsigned long long)seed, n, scale);
        double *p = make_points(&g, n, (int)(seed % 5), scale);
        hd__octree_t t;
        CHECK_RC(hd__octree_build(&t, p, n, 1 + (int)(seed % 10), 1, NULL), HD_OK);
        for (int q = 0; q < 10 && !hdt_failed(); q++) {
            double x[3];
            for (int k = 0; k < 3; k++) x[k] = (6.0 * gen_unit(&g) - 3.0) * scale;
            for (size_t id = 0; id < t.nodes; id++) {
                const hd__onode_t *nd = t.node[id];
                double lb = hd__box_lb2(&nd->box, x), ub = hd__box_ub2(&nd->box, x);
                for (size_t k = nd->begin; k < nd->begin + nd->count; k++) {
                    double d = brute_d2(x, t.pts + 3 * k);
                    CHECK(lb <= d);
                    CHECK(d <= ub);
                }
            }
        }
        hd__octree_free(&t);
        free(p);
        if (hdt_failed()) return;
    }
}

TEST(every_point_of_the_tree_locates_its_own_leaf) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 60; seed++) {
        gen_seed(&g, seed);
        size_t n = 1 + gen_u64(&g) % 500;
        CONTEXT("seed=%llu n=%zu", (unsigned long long)seed, n);
        double *p = make_points(&g, n, (int)(seed % 5), scales[seed % 4]);
        hd__octree_t t;
        CHECK_RC(hd__octree_build(&t, p, n, 8, 1 + seed % 4, NULL), HD_OK);
        for (size_t id = 0; id < t.nodes; id++) {
            const hd__onode_t *nd = t.node[id];
            if (nd->kids) continue;
            for (size_t k = nd->begin; k < nd->begin + nd->count; k++)
                CHECK(hd__octree_locate(&t, t.pts + 3 * k) == nd);
        }
        hd__octree_free(&t);
        free(p);
        if (hdt_failed()) return;
    }
}

TEST(a_point_in_an_empty_octant_has_no_leaf) {
    /* Two points in opposite corners: six of the root's octants are empty. */
    double p[] = {0, 0, 0, 1, 1, 1};
    hd__octree_t t;
    CHECK_RC(hd__octree_build(&t, p, 2, 4, 1, NULL), HD_OK);
    CHECK_EQ(t.root->nkids, 2);
    double q[3] = {0.9, 0.1, 0.1};
    CHECK(hd__octree_locate(&t, q) == NULL);
    double r[3] = {0.1, 0.2, 0.3};
    CHECK(hd__octree_locate(&t, r) == &t.root->kids[0]);
    hd__octree_free(&t);
}

TEST(coincident_points_stay_in_one_leaf_at_any_depth) {
    double p[3 * 50];
    for (int k = 0; k < 50; k++) {
        p[3 * k] = 1e-300;
        p[3 * k + 1] = -2.0;
        p[3 * k + 2] = 7.0;
    }
    hd__octree_t t;
    CHECK_RC(hd__octree_build(&t, p, 50, 60, 1, NULL), HD_OK);
    CHECK_EQ(t.nodes, 1);
    CHECK(t.root->kids == NULL);
    CHECK_EQ(t.root->count, 50);
    hd__octree_free(&t);
}

TEST(depth_zero_is_one_leaf_and_bad_parameters_are_refused) {
    double p[] = {0, 0, 0, 1, 2, 3, 4, 5, 6};
    hd__octree_t t;
    CHECK_RC(hd__octree_build(&t, p, 3, 0, 1, NULL), HD_OK);
    CHECK_EQ(t.nodes, 1);
    CHECK_EQ(t.leaves, 1);
    hd__octree_free(&t);
    hd_error_t e;
    CHECK_RC(hd__octree_build(&t, p, 0, 3, 1, &e), HD_EINVAL);
    CHECK_RC(hd__octree_build(&t, p, 3, 3, 0, &e), HD_EINVAL);
    CHECK_RC(hd__octree_build(&t, p, 3, 61, 1, &e), HD_EINVAL);
}
