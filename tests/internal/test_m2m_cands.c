/*
 * test_m2m_cands.c -- the candidate lists of surface-to-surface refinement
 * (hd__m2m_candidates, src/mesh/m2m.c): for a sub-triangle with a bound U
 * on the distance over the hull of its corners and a slack e, every point
 * within 2e of the hull has its distance to the mesh attained on the list
 * (the list's nearest equals the tree's), whether the list is collected
 * from the tree or filtered from a parent's list; on a grid, where U is
 * tight and points 2e off the hull reach triangles beside the corners'
 * box, and on random soups at scales from tiny to huge.
 */
#include "check.h"
#include "gen.h"
#include "mesh/mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef __SANITIZE_ADDRESS__
#define SCALE 4
#else
#define SCALE 1
#endif

#define CAP 100000

/* A flat grid of side x side squares (two triangles each) of width w in
 * z = 0, or with random corners (a soup of n triangles of size w in the
 * unit cube, scaled) when soup is set. */
static size_t make_tris(hd__tri_t **out, int side, double w, int soup, gen_rng_t *r, double scale) {
    size_t n = soup ? (size_t)side * side : 2 * (size_t)side * side, k = 0;
    hd__tri_t *t = malloc(n * sizeof *t);
    for (int i = 0; i < side; i++)
        for (int j = 0; j < side; j++) {
            if (soup) {
                double c[3] = {gen_unit(r), gen_unit(r), gen_unit(r)};
                for (int v = 0; v < 3; v++)
                    for (int d = 0; d < 3; d++) t[k].v[v][d] = scale * (c[d] + w * (gen_unit(r) - 0.5));
                t[k].index = k, k++;
                continue;
            }
            double x0 = i * w, y0 = j * w, x1 = x0 + w, y1 = y0 + w;
            double q[4][3] = {{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}};
            memcpy(t[k].v[0], q[0], sizeof q[0]), memcpy(t[k].v[1], q[1], sizeof q[0]);
            memcpy(t[k].v[2], q[2], sizeof q[0]), t[k].index = k, k++;
            memcpy(t[k].v[0], q[0], sizeof q[0]), memcpy(t[k].v[1], q[2], sizeof q[0]);
            memcpy(t[k].v[2], q[3], sizeof q[0]), t[k].index = k, k++;
        }
    *out = t;
    return n;
}

/* The distance of p to the whole tree, and to the listed triangles only. */
static double d_all(const hd__bvh_t *T, const double p[3]) {
    hd__tri_near_t nb;
    size_t index;
    hd__bvh_stats_t st = {0};
    hd__bvh_nearest(T, p, SIZE_MAX, 0, &nb, &index, &st);
    return nb.d;
}
static double d_list(const hd__bvh_t *T, const double p[3], const uint32_t *list, size_t n) {
    hd__tri_near_t nb;
    size_t index;
    hd__bvh_stats_t st = {0};
    if (n == 0) return INFINITY;
    hd__bvh_nearest_in(T, p, list, n, list[0], 0, &nb, &index, &st);
    return nb.d;
}

/* A point of the hull of c (random weights) moved by a random vector of
 * length below 2e. */
static void near_hull(const double c[3][3], double e, gen_rng_t *r, double q[3]) {
    double a = gen_unit(r), b = gen_unit(r);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    double v[3] = {gen_normal(r), gen_normal(r), gen_normal(r)};
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), s = 2 * e * (1 - 0x1p-20) * gen_unit(r) / len;
    if (gen_u64(r) % 4 == 0) s = 2 * e * (1 - 0x1p-20) / len; /* often the full 2e */
    for (int d = 0; d < 3; d++) q[d] = c[0][d] + a * (c[1][d] - c[0][d]) + b * (c[2][d] - c[0][d]) + s * v[d];
}

/* U >= d(y, Y) over the hull of c: the largest corner distance plus the
 * longest edge (each point of the hull is within it of a corner), up. */
static double hull_bound(const hd__bvh_t *T, const double c[3][3]) {
    double m = 0, l = 0;
    for (int i = 0; i < 3; i++) {
        m = fmax(m, d_all(T, c[i]));
        double dx = c[i][0] - c[(i + 1) % 3][0], dy = c[i][1] - c[(i + 1) % 3][1], dz = c[i][2] - c[(i + 1) % 3][2];
        l = fmax(l, sqrt(dx * dx + dy * dy + dz * dz));
    }
    return nextafter(nextafter(m + l, INFINITY), INFINITY);
}

/* Points near the hull of c whose distance the list does not attain: 0
 * expected.  With a parent (pc, pU) the list is the parent's filtered. */
static int misses(const hd__bvh_t *T, const double c[3][3], double U, double e, const double pc[3][3], double pU,
                  gen_rng_t *r, uint32_t *list, uint32_t *plist, int *seen) {
    size_t n;
    if (pc) {
        size_t pn = hd__m2m_candidates(T, pc, pU, e, NULL, 0, plist, CAP);
        CHECK(pn != SIZE_MAX);
        n = hd__m2m_candidates(T, c, U, e, plist, pn, list, CAP);
    } else {
        n = hd__m2m_candidates(T, c, U, e, NULL, 0, list, CAP);
    }
    CHECK(n != SIZE_MAX);
    int bad = 0;
    for (int s = 0; s < 40; s++) {
        double q[3];
        near_hull(c, e, r, q);
        double a = d_all(T, q), b = d_list(T, q, list, n);
        if (a != b) {
            if (!bad) CONTEXT("q %.17g %.17g %.17g: tree %.17g list %.17g (%zu listed)", q[0], q[1], q[2], a, b, n);
            bad++;
        }
    }
    *seen += n < T->n_tris; /* lists that leave triangles out */
    return bad;
}

/* Over a grid in z = 0, a small sub-triangle at height h (every point of
 * its hull at distance h: U tight) with e its own size: the points 2e off
 * the hull are nearest to triangles beside its box. */
TEST(lists_over_a_grid_hold_every_nearest_triangle_within_2e) {
    gen_rng_t r;
    gen_seed(&r, 3801);
    hd__tri_t *tris;
    size_t n = make_tris(&tris, 64, 1.0 / 64, 0, &r, 1);
    hd__bvh_t T;
    CHECK_RC(hd__bvh_build(&T, tris, n), HD_OK);
    uint32_t *list = malloc(CAP * sizeof *list), *plist = malloc(CAP * sizeof *plist);
    int bad = 0, seen = 0;
    for (int it = 0; it < 2000 / SCALE && !bad; it++) {
        double h = ldexp(1, -(int)(gen_u64(&r) % 12) - 4), w = h * ldexp(1, -(int)(gen_u64(&r) % 6) - 1);
        double x = 0.2 + 0.6 * gen_unit(&r), y = 0.2 + 0.6 * gen_unit(&r);
        double c[3][3] = {{x, y, h}, {x + w, y, h}, {x, y + w, h}};
        double e = w * (0.5 + gen_unit(&r)); /* 2e reaches beyond the corners' box */
        bad += misses(&T, c, nextafter(h, INFINITY), e, NULL, 0, &r, list, plist, &seen);
        double pc[3][3] = {{x - w, y - w, h}, {x + 3 * w, y - w, h}, {x - w, y + 3 * w, h}};
        if (!bad) bad += misses(&T, c, nextafter(h, INFINITY), e, pc, nextafter(h, INFINITY), &r, list, plist, &seen);
        if (bad) CONTEXT("seed 3801 case %d: h %.17g w %.17g e %.17g", it, h, w, e);
    }
    CHECK(bad == 0);
    CHECK(seen > 1000 / SCALE); /* the lists are short, not the whole mesh */
    free(list), free(plist);
    hd__bvh_free(&T);
}

/* Random soups from 2^-300 to 2^300, sub-triangles of many sizes with the
 * point bound as U and parents three times larger. */
TEST(lists_over_random_soups_hold_every_nearest_triangle) {
    gen_rng_t r;
    gen_seed(&r, 3802);
    uint32_t *list = malloc(CAP * sizeof *list), *plist = malloc(CAP * sizeof *plist);
    int bad = 0, seen = 0;
    for (int round = 0; round < 12 / SCALE + 1 && !bad; round++) {
        double scale = ldexp(1, (int)(gen_u64(&r) % 600) - 300);
        hd__tri_t *tris;
        size_t n = make_tris(&tris, 24, 0.05, 1, &r, scale);
        hd__bvh_t T;
        CHECK_RC(hd__bvh_build(&T, tris, n), HD_OK);
        for (int it = 0; it < 100 && !bad; it++) {
            double w = scale * ldexp(1, -(int)(gen_u64(&r) % 10) - 3), c[3][3], pc[3][3];
            for (int d = 0; d < 3; d++) {
                double o = scale * gen_unit(&r);
                for (int v = 0; v < 3; v++) pc[v][d] = o + w * (gen_unit(&r) - 0.5);
            }
            /* a child as refinement makes it: a corner and two midpoints */
            for (int d = 0; d < 3; d++) {
                c[0][d] = pc[0][d];
                c[1][d] = pc[0][d] + 0.5 * (pc[1][d] - pc[0][d]);
                c[2][d] = pc[0][d] + 0.5 * (pc[2][d] - pc[0][d]);
            }
            double e = w * ldexp(1, -(int)(gen_u64(&r) % 8)), U = hull_bound(&T, c), pU = hull_bound(&T, pc);
            bad += misses(&T, pc, pU, e, NULL, 0, &r, list, plist, &seen);
            if (!bad) bad += misses(&T, c, U, e, pc, pU, &r, list, plist, &seen);
            if (bad) CONTEXT("seed 3802 round %d case %d: scale %.17g w %.17g e %.17g", round, it, scale, w, e);
        }
        hd__bvh_free(&T);
    }
    CHECK(bad == 0);
    CHECK(seen > 100 / SCALE);
    free(list), free(plist);
}
