/*
 * test_m2m_shared.c -- the shared-face table (hd__m2m_shared,
 * src/mesh/m2m_shared.c): a face of either side is dropped exactly when a
 * face of the other side has the same three corners as a multiset, bit
 * for bit (corners in any order; 0 and -0 differ; a repeated corner counts
 * twice), as a comparison of every pair of faces says.
 */
#include "check.h"
#include "gen.h"
#include "mesh/mesh.h"

#include <stdlib.h>
#include <string.h>

/* Corners drawn from a pool of few vertices (some with -0 where others
 * have 0), so that faces repeat, in other corner orders, and some repeat
 * a corner. */
static void random_faces(gen_rng_t *r, const double (*pool)[3], int n_pool, hd__tri_t *t, size_t n) {
    for (size_t k = 0; k < n; k++) {
        for (int j = 0; j < 3; j++) memcpy(t[k].v[j], pool[gen_u64(r) % (uint64_t)n_pool], sizeof t[k].v[j]);
        t[k].index = k;
    }
}

static int same_multiset(const hd__tri_t *s, const hd__tri_t *t) {
    int used[3] = {0, 0, 0};
    for (int i = 0; i < 3; i++) {
        int j = 0;
        while (j < 3 && (used[j] || memcmp(s->v[i], t->v[j], sizeof s->v[i]))) j++;
        if (j == 3) return 0;
        used[j] = 1;
    }
    return 1;
}

static int in_other(const hd__tri_t *f, const hd__tri_t *other, size_t n) {
    for (size_t k = 0; k < n; k++)
        if (same_multiset(f, &other[k])) return 1;
    return 0;
}

TEST(a_face_is_dropped_exactly_when_the_other_side_has_its_corners) {
    gen_rng_t r;
    double pool[6][3] = {{0, 0, 0}, {-0.0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0x1p-52}};
    for (uint64_t seed = 1; seed <= 200; seed++) {
        CONTEXT("seed %llu", (unsigned long long)seed);
        gen_seed(&r, seed);
        size_t nx = 1 + gen_u64(&r) % 60, ny = 1 + gen_u64(&r) % 60, cx = 0, cy = 0, ex = 0, ey = 0;
        hd__tri_t x[60], y[60];
        unsigned char dx[60], dy[60];
        int n_pool = 3 + (int)(seed % 4);
        random_faces(&r, (const double (*)[3])pool, n_pool, x, nx);
        random_faces(&r, (const double (*)[3])pool, n_pool, y, ny);
        CHECK_RC(hd__m2m_shared(x, nx, y, ny, dx, dy, &cx, &cy), HD_OK);
        for (size_t k = 0; k < nx; k++) {
            CHECK_EQ(dx[k], in_other(&x[k], y, ny));
            ex += dx[k];
        }
        for (size_t k = 0; k < ny; k++) {
            CHECK_EQ(dy[k], in_other(&y[k], x, nx));
            ey += dy[k];
        }
        CHECK_EQ(cx, ex);
        CHECK_EQ(cy, ey);
    }
}
