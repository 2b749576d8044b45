/*
 * test_bvh.c -- the triangle tree's build (src/mesh/bvh_build.c): the same
 * tree on 1 and on several threads, a valid tree (every triangle in
 * exactly one leaf, the first child over the first half, each box the
 * exact box of what it holds, so it contains its children and their
 * corners), the same answers from every tree, and triangles prepared
 * only when a search reaches them, with hd__tri_prep's bits whoever
 * prepared them, on every thread.
 */
#include "check.h"
#include "gen.h"
#include "mesh/mesh.h"

#include <math.h>
#include <stdlib.h>

#ifdef __SANITIZE_ADDRESS__
#define SCALE 4 /* the sanitizer build runs fewer cases */
#else
#define SCALE 1
#endif

/* n triangles: random small ones in the unit cube, or (ties) every third
 * one a copy of the one before, or a torus's. */
static hd__tri_t *tris_make(uint64_t seed, size_t n, int kind) {
    gen_rng_t g;
    gen_seed(&g, seed);
    hd__tri_t *t = malloc(n * sizeof *t);
    double *v = NULL;
    uint64_t *f = NULL;
    if (kind == 2) gen_torus_mesh(3, 1, (int)(n / 2 / 50), 50, &v, &f);
    for (size_t k = 0; k < n; k++) {
        t[k].index = k;
        if (kind == 2) {
            for (int j = 0; j < 3; j++) memcpy(t[k].v[j], v + 3 * f[3 * k + j], sizeof t[k].v[j]);
            continue;
        }
        if (kind == 1 && k % 3 == 2) {
            memcpy(t[k].v, t[k - 1].v, sizeof t[k].v);
            continue;
        }
        double c[3] = {gen_unit(&g), gen_unit(&g), gen_unit(&g)};
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 3; i++) t[k].v[j][i] = c[i] + 0.01 * (gen_unit(&g) - 0.5);
    }
    free(v), free(f);
    return t;
}

static int box_equal(const hd__box_t *a, const hd__box_t *b) { return memcmp(a, b, sizeof *a) == 0; }

/* Node me over [first, first + n) (positions in t->tris): checks its
 * children recursively; returns the position after its subtree, or 0
 * after a failed check.  seen[k] counts the leaves holding k. */
static size_t check_node(const hd__bvh_t *t, size_t me, size_t first, size_t n, int depth, unsigned char *seen) {
    if (me >= t->n_nodes || depth > 100) {
        CHECK(me < t->n_nodes && depth <= 100);
        return 0;
    }
    const hd__bvh_node_t *node = &t->nodes[me];
    hd__box_t box;
    if (node->count) {
        CHECK_EQ(node->first_or_second, first);
        CHECK_EQ(node->count, n);
        CHECK(n <= 4);
        box = t->boxes[first];
        for (size_t k = first; k < first + n; k++) {
            hd__box_t b;
            for (int c = 0; c < 3; c++) { /* the triangle's own box, exact */
                b.lo[c] = b.hi[c] = t->tris[k].v[0][c];
                for (int j = 1; j < 3; j++) {
                    b.lo[c] = t->tris[k].v[j][c] < b.lo[c] ? t->tris[k].v[j][c] : b.lo[c];
                    b.hi[c] = t->tris[k].v[j][c] > b.hi[c] ? t->tris[k].v[j][c] : b.hi[c];
                }
            }
            CHECK(box_equal(&b, &t->boxes[k]));
            hd__box_merge(&box, &b);
            seen[k]++;
        }
        CHECK(box_equal(&box, &node->box));
        return hdt_failed() ? 0 : me + 1;
    }
    CHECK(n > 4);
    size_t second = check_node(t, me + 1, first, n / 2, depth + 1, seen);
    if (!second) return 0;
    CHECK_EQ(node->first_or_second, second);
    size_t end = check_node(t, second, first + n / 2, n - n / 2, depth + 1, seen);
    if (!end) return 0;
    box = t->nodes[me + 1].box;
    hd__box_merge(&box, &t->nodes[second].box);
    CHECK(box_equal(&box, &node->box)); /* exactly its children's: it contains them */
    return hdt_failed() ? 0 : end;
}

/* Every triangle of the input in exactly one leaf, the tree's shape and
 * boxes as mesh.h states, nothing prepared yet. */
static void check_tree(const hd__bvh_t *t, size_t n) {
    unsigned char *seen = calloc(n, 1), *index_seen = calloc(n, 1);
    CHECK_EQ(t->n_tris, n);
    CHECK_EQ(check_node(t, 0, 0, n, 0, seen), t->n_nodes);
    for (size_t k = 0; k < n && !hdt_failed(); k++) {
        CHECK_EQ(seen[k], 1);
        CHECK(t->tris[k].index < n && !index_seen[t->tris[k].index]);
        if (t->tris[k].index < n) index_seen[t->tris[k].index] = 1;
        CHECK_EQ(atomic_load(&t->slot[k]), 0);
    }
    free(seen), free(index_seen);
}

static void same_tree(const hd__bvh_t *a, const hd__bvh_t *b) {
    CHECK_EQ(a->n_nodes, b->n_nodes);
    CHECK_EQ(a->n_tris, b->n_tris);
    if (hdt_failed()) return;
    CHECK(memcmp(a->nodes, b->nodes, a->n_nodes * sizeof *a->nodes) == 0);
    CHECK(memcmp(a->tris, b->tris, a->n_tris * sizeof *a->tris) == 0);
    CHECK(memcmp(a->boxes, b->boxes, a->n_tris * sizeof *a->boxes) == 0);
}

/* The brute force: the nearest of n triangles to p (ties: the smallest
 * index), its index and its answer in *want. */
static size_t brute_nearest(const double p[3], const hd__tri_t *orig, size_t n, hd__tri_near_t *want) {
    size_t at = SIZE_MAX;
    for (size_t k = 0; k < n; k++) {
        hd__tri_near_t r;
        CHECK_RC(hd__tri_nearest(p, orig[k].v[0], orig[k].v[1], orig[k].v[2], &r), HD_OK);
        if (at == SIZE_MAX || r.d < want->d) *want = r, at = k;
    }
    return at;
}

/* The search's box test (bvh.c's box_lb2s, through hd__box_lower) has
 * the bits of the scalar hd__box_lb2s: points inside, on a face, beyond
 * one, two or three slabs, signed zeros and flat boxes. */
TEST(the_box_bound_has_the_scalar_bounds_bits) {
    gen_rng_t g;
    uint64_t seed = 77;
    gen_seed(&g, seed);
    const double pick[4] = {0.0, -0.0, 0.25, -0.25};
    for (long i = 0; i < 200000 && !hdt_failed(); i++) {
        hd__box_t b;
        double p[3];
        for (int k = 0; k < 3; k++) {
            double x = gen_unit(&g) * 2 - 1, y = gen_unit(&g) * 2 - 1;
            if (i % 7 == 0) y = x;                      /* flat */
            b.lo[k] = x < y ? x : y, b.hi[k] = x < y ? y : x;
            uint64_t r = gen_u64(&g) % 6;
            p[k] = r < 4 ? pick[r] : r == 4 ? b.lo[k] : gen_unit(&g) * 4 - 2;
        }
        double s = hd__box_lb2s(&b, p[0], p[1], p[2]);
        double want = s >= 0x1p-1000 ? sqrt(s) * (1.0 - 0x1p-48) : 0.0;
        CONTEXT("seed %llu, case %ld", (unsigned long long)seed, i);
        CHECK_BITS(hd__box_lower(&b, p), want);
    }
}

TEST(the_tree_is_valid_and_the_same_on_1_and_several_threads) {
    const size_t sizes[] = {1, 2, 3, 4, 5, 7, 8, 9, 17, 100, 1000, 4097, 9001, 40000 / SCALE};
    const int threads[] = {2, 3, 8};
    for (int kind = 0; kind < 3; kind++)
        for (size_t s = 0; s < sizeof sizes / sizeof *sizes && !hdt_failed(); s++) {
            size_t n = kind == 2 ? (sizes[s] / 100) * 100 : sizes[s];
            if (n == 0) continue;
            hd__bvh_t one;
            CONTEXT("seed 5, kind %d (0 random, 1 copies, 2 torus), %zu triangles, 1 thread", kind, n);
            CHECK_RC(hd__bvh_build_threads(&one, tris_make(5, n, kind), n, 1), HD_OK);
            check_tree(&one, n);
            for (int k = 0; k < 3 && !hdt_failed(); k++) {
                hd__bvh_t many;
                CONTEXT("seed 5, kind %d, %zu triangles, %d threads", kind, n, threads[k]);
                CHECK_RC(hd__bvh_build_threads(&many, tris_make(5, n, kind), n, threads[k]), HD_OK);
                check_tree(&many, n);
                same_tree(&one, &many);
                hd__bvh_free(&many);
            }
            hd__bvh_free(&one);
        }
}

/* Points near the triangles and far from them: every tree gives the
 * brute force's answer (smallest rounded distance, then smallest index). */
TEST(trees_built_on_1_and_3_threads_give_the_brute_force_answers) {
    size_t n = 12000 / SCALE, queries = 300 / SCALE;
    hd__tri_t *orig = tris_make(9, n, 1);
    hd__bvh_t tree[2];
    for (int k = 0; k < 2; k++) {
        hd__tri_t *copy = malloc(n * sizeof *copy);
        memcpy(copy, orig, n * sizeof *copy);
        CHECK_RC(hd__bvh_build_threads(&tree[k], copy, n, k ? 3 : 1), HD_OK);
    }
    gen_rng_t g;
    gen_seed(&g, 9);
    for (size_t q = 0; q < queries && !hdt_failed(); q++) {
        double p[3];
        for (int c = 0; c < 3; c++) p[c] = q % 2 ? 3 * gen_unit(&g) - 1 : orig[q * 7 % n].v[0][c] + 1e-4 * gen_unit(&g);
        hd__tri_near_t want;
        size_t want_index = SIZE_MAX;
        want_index = brute_nearest(p, orig, n, &want);
        for (int k = 0; k < 2; k++) {
            hd__tri_near_t got;
            size_t index;
            hd__bvh_stats_t st = {0, 0, 0, 0, 0, 0};
            hd__bvh_nearest(&tree[k], p, SIZE_MAX, 0, &got, &index, &st);
            CONTEXT("seed 9, query %zu, tree built on %d threads", q, k ? 3 : 1);
            CHECK_BITS(got.d, want.d);
            CHECK_EQ(index, want_index);
        }
    }
    hd__bvh_free(&tree[0]);
    hd__bvh_free(&tree[1]);
    free(orig);
}

/* A search prepares the triangles it bounds and no others. */
TEST(a_query_prepares_only_the_triangles_it_reaches) {
    size_t n = 20000;
    hd__bvh_t t;
    CHECK_RC(hd__bvh_build_threads(&t, tris_make(3, n, 0), n, 2), HD_OK);
    double p[3] = {0.5, 0.5, 0.5};
    hd__tri_near_t best;
    size_t index, ready = 0;
    hd__bvh_stats_t st = {0, 0, 0, 0, 0, 0};
    hd__bvh_nearest(&t, p, SIZE_MAX, 0, &best, &index, &st);
    for (size_t k = 0; k < n; k++) ready += atomic_load(&t.slot[k]) != 0;
    CONTEXT("seed 3: %zu of %zu triangles prepared, %llu bounded", ready, n, (unsigned long long)st.bounded);
    CHECK(ready >= 1 && ready < n / 100);
    hd__bvh_free(&t);
}

typedef struct {
    const hd__bvh_t *t;
    const hd__tri_prep_t *want;
    atomic_int differ;
} prep_job_t;

/* Task k asks for every triangle, from a different start, twice. */
static void ask_all(void *ctx, size_t task, int worker) {
    (void)worker;
    prep_job_t *J = ctx;
    size_t n = J->t->n_tris;
    for (size_t i = 0; i < 2 * n; i++) {
        size_t k = (i + task * 7919) % n;
        const hd__tri_prep_t *q = hd__bvh_prep(J->t, k);
        if (memcmp(q, &J->want[k], sizeof *q) != 0) atomic_fetch_add(&J->differ, 1);
    }
}

TEST(prepared_triangles_have_the_same_bits_whichever_thread_prepares_them) {
    size_t n = 5000 / SCALE;
    hd__bvh_t t;
    CHECK_RC(hd__bvh_build_threads(&t, tris_make(4, n, 1), n, 1), HD_OK);
    hd__tri_prep_t *want = calloc(n, sizeof *want); /* calloc: padding compares equal */
    for (size_t k = 0; k < n; k++) hd__tri_prep(t.tris[k].v[0], t.tris[k].v[1], t.tris[k].v[2], &want[k]);
    prep_job_t J = {&t, want, 0};
    hd__parallel_for(4, 8, ask_all, &J);
    CONTEXT("seed 4: %d prepared records differ from hd__tri_prep's", atomic_load(&J.differ));
    CHECK_EQ(atomic_load(&J.differ), 0);
    for (size_t k = 0; k < n; k++) CHECK(atomic_load(&t.slot[k]) - 1 < n); /* prepared, in a record */
    CHECK_EQ(atomic_load(t.used), n);
    hd__bvh_free(&t);
    free(want);
}

/* A near point searched from a seed on the far side of a torus: a leaf's
 * triangles are bounded as soon as it is screened, so the threshold drops
 * to about the point's distance at the first leaf reached and the descent
 * opens few nodes more than from the best seed (not the seed's loose
 * bound all the way down); the answers stay the brute force's. */
TEST(a_near_point_from_a_far_seed_opens_few_nodes) {
    size_t n = 20000, queries = 200 / SCALE;
    hd__tri_t *orig = tris_make(11, n, 2);
    hd__tri_t *copy = malloc(n * sizeof *copy);
    memcpy(copy, orig, n * sizeof *copy);
    hd__bvh_t t;
    CHECK_RC(hd__bvh_build_threads(&t, copy, n, 1), HD_OK);
    gen_rng_t g;
    gen_seed(&g, 11);
    hd__bvh_stats_t st = {0, 0, 0, 0, 0, 0};
    for (size_t q = 0; q < queries && !hdt_failed(); q++) {
        const hd__tri_t *on = &orig[gen_u64(&g) % n];
        double p[3], lo = INFINITY;
        size_t seed = 0;
        for (int c = 0; c < 3; c++) p[c] = (on->v[0][c] + on->v[1][c] + on->v[2][c]) / 3 + 1e-3 * (gen_unit(&g) - 0.5);
        for (size_t k = 0; k < n; k++) { /* the seed: a triangle about opposite p */
            double s = t.tris[k].v[0][0] * p[0] + t.tris[k].v[0][1] * p[1];
            if (s < lo) lo = s, seed = k;
        }
        hd__tri_near_t want, got;
        size_t want_index = SIZE_MAX, index;
        want_index = brute_nearest(p, orig, n, &want);
        hd__bvh_nearest(&t, p, seed, 0, &got, &index, &st);
        CONTEXT("seed 11, query %zu", q);
        CHECK_BITS(got.d, want.d);
        CHECK_EQ(index, want_index);
    }
    double nodes = (double)st.nodes / (double)queries;
    CONTEXT("seed 11: %.1f nodes opened a query", nodes);
    CHECK(nodes < 40);
    hd__bvh_free(&t);
    free(orig);
}

/* A node of 1024 triangles or more chooses its axis from every
 * (n / 64)-th centroid of its range, a smaller one from every (n / 8)-th
 * (bvh_build.c): here every `every`-th triangle of n lies along y over
 * [0, 1], the others along x over [0, 4], so the sample's longest axis is
 * y and the whole set's x.  The root splits along y: its first child holds
 * the n / 2 lowest centroids in y, and both children span x.  With 2048
 * triangles every fourth is along y (the sample: every 32nd); with 512
 * every 64th (the sample: every 64th; a sample of 64, every 8th, would be
 * mostly along x). */
static void root_splits_along_y(size_t n, size_t every) {
    hd__tri_t *t = malloc(n * sizeof *t);
    for (size_t k = 0; k < n; k++) {
        double x = k % every ? 4.0 * (double)k / (double)n : 0.5, y = k % every ? 0.5 : (double)k / (double)n;
        double c[3][3] = {{x, y, 0}, {x + 1e-3, y, 0}, {x, y + 1e-3, 1e-3}};
        memcpy(t[k].v, c, sizeof c);
        t[k].index = k;
    }
    hd__bvh_t tree;
    CHECK_RC(hd__bvh_build_threads(&tree, t, n, 1), HD_OK);
    const hd__box_t *a = &tree.nodes[1].box, *b = &tree.nodes[tree.nodes[0].first_or_second].box;
    CONTEXT("%zu triangles: first child y [%g, %g] x [%g, %g]; second y [%g, %g]", n, a->lo[1], a->hi[1], a->lo[0],
            a->hi[0], b->lo[1], b->hi[1]);
    CHECK(a->hi[1] <= 0.5 + 1e-3 && b->hi[1] > 0.8); /* split along y: x spans the whole range in both */
    CHECK(a->hi[0] - a->lo[0] > 3);
    hd__bvh_free(&tree);
}

TEST(a_large_node_splits_along_the_longest_axis_of_its_sampled_centroids) { root_splits_along_y(2048, 4); }

TEST(a_small_node_splits_along_the_longest_axis_of_eight_sampled_centroids) { root_splits_along_y(512, 64); }

/* Every inner node's first child holds the n / 2 lowest centroids along
 * some axis: the selection's postcondition (bvh_build.c's select_rank,
 * with its band steps on ranges of more than 1024 keys), on centroids
 * along x in increasing, decreasing and organ-pipe order, with three
 * values only (ties), and random; 3,000 to 100,000 triangles (the sample
 * of the largest is itself narrowed by a band). */
static int halves_separated(const hd__bvh_t *t, size_t me, size_t first, size_t n) {
    const hd__bvh_node_t *node = &t->nodes[me];
    if (node->count) return 1;
    size_t half = n / 2;
    int ok = 0;
    for (int a = 0; a < 3 && !ok; a++) {
        double hi = -INFINITY, lo = INFINITY;
        for (size_t k = first; k < first + n; k++) {
            const double(*v)[3] = t->tris[k].v;
            double c = v[0][a] + v[1][a] + v[2][a];
            if (k < first + half) hi = c > hi ? c : hi;
            else lo = c < lo ? c : lo;
        }
        ok = hi <= lo;
    }
    return ok && halves_separated(t, me + 1, first, half) &&
           halves_separated(t, node->first_or_second, first + half, n - half);
}

TEST(every_split_puts_the_lower_half_of_its_axis_first) {
    size_t sizes[] = {3000, 20000, 100000 / SCALE};
    for (int kind = 0; kind < 5; kind++)
        for (int z = 0; z < 3; z++) {
            size_t n = sizes[z];
            gen_rng_t g;
            gen_seed(&g, 13);
            hd__tri_t *t = malloc(n * sizeof *t);
            for (size_t k = 0; k < n; k++) {
                double f = (double)k / (double)n;
                double x = kind == 0 ? f : kind == 1 ? 1 - f : kind == 2 ? (f < 0.5 ? 2 * f : 2 - 2 * f)
                         : kind == 3 ? (double)(k % 3) : gen_unit(&g);
                double y = 0.01 * gen_unit(&g), z = 0.01 * gen_unit(&g);
                double c[3][3] = {{x, y, z}, {x + 1e-4, y, z}, {x, y + 1e-4, z + 1e-4}};
                memcpy(t[k].v, c, sizeof c);
                t[k].index = k;
            }
            hd__bvh_t tree;
            CHECK_RC(hd__bvh_build_threads(&tree, t, n, 1), HD_OK);
            CONTEXT("seed 13, order %d, %zu triangles", kind, n);
            CHECK(halves_separated(&tree, 0, 0, n));
            hd__bvh_free(&tree);
        }
}

/* Near points searched from a seed close by (hd__bvh_nearest's climb from
 * the seed's leaf): half of the points lie near a triangle B of the root's
 * second child and are seeded with the triangle A of its first child
 * nearest to B, so the answer is found only in the sibling next to the
 * root, the last subtree the climb reaches; the others are seeded with
 * the answer of a point 0.1 away.  The answers are the brute force's, and
 * the search opens few nodes (the climb starts at the seed's leaf, not at
 * the root). */
TEST(a_near_seed_climbs_from_its_leaf_through_every_sibling) {
    size_t n = 20000, queries = 400 / SCALE, across = 0;
    hd__tri_t *orig = tris_make(12, n, 2);
    hd__tri_t *copy = malloc(n * sizeof *copy);
    memcpy(copy, orig, n * sizeof *copy);
    hd__bvh_t t;
    CHECK_RC(hd__bvh_build_threads(&t, copy, n, 1), HD_OK);
    size_t *pos = malloc(n * sizeof *pos);
    for (size_t k = 0; k < n; k++) pos[t.tris[k].index] = k;
    gen_rng_t g;
    gen_seed(&g, 12);
    hd__bvh_stats_t st = {0, 0, 0, 0, 0, 0};
    for (size_t q = 0; q < queries && !hdt_failed(); q++) {
        double p[3], c[3], o[3];
        size_t a = gen_u64(&g) % (n / 2), seed = a, b = a;
        for (int i = 0; i < 3; i++) c[i] = (t.tris[a].v[0][i] + t.tris[a].v[1][i] + t.tris[a].v[2][i]) / 3;
        if (q % 2 == 0) { /* B: the triangle of the second child nearest to A */
            double lo = INFINITY;
            for (size_t k = n / 2; k < n; k++) {
                double d = 0;
                for (int i = 0; i < 3; i++) {
                    double x = (t.tris[k].v[0][i] + t.tris[k].v[1][i] + t.tris[k].v[2][i]) / 3 - c[i];
                    d += x * x;
                }
                if (d < lo) lo = d, b = k;
            }
        }
        for (int i = 0; i < 3; i++) {
            p[i] = (t.tris[b].v[0][i] + t.tris[b].v[1][i] + t.tris[b].v[2][i]) / 3 + 1e-3 * (gen_unit(&g) - 0.5);
            o[i] = p[i] + 0.1 * (gen_unit(&g) - 0.5);
        }
        hd__tri_near_t want, got;
        size_t want_index = SIZE_MAX, index;
        want_index = brute_nearest(p, orig, n, &want);
        if (q % 2) { /* the answer of a point 0.1 away */
            hd__bvh_stats_t other = {0, 0, 0, 0, 0, 0};
            seed = hd__bvh_nearest(&t, o, SIZE_MAX, 0, &got, &index, &other);
        }
        across += (seed < n / 2) != (pos[want_index] < n / 2);
        hd__bvh_nearest(&t, p, seed, 0, &got, &index, &st);
        CONTEXT("seed 12, query %zu", q);
        CHECK_BITS(got.d, want.d);
        CHECK_EQ(index, want_index);
    }
    double nodes = (double)st.nodes / (double)queries;
    CONTEXT("seed 12: %.1f nodes opened a query, %zu answers across the root's split", nodes, across);
    CHECK(across >= queries / 4);
    CHECK(nodes < 15);
    hd__bvh_free(&t);
    free(pos);
    free(orig);
}
