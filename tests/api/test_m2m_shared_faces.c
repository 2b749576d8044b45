/*
 * test_m2m_shared_faces.c -- faces of A that are faces of B change
 * nothing in h(A, B) but the count of dropped faces: the enclosure, its
 * witness and the work done are those of h(A', B), A' being A without
 * them (same faces, same order), bit for bit, at 1 and 2 threads; and
 * h(B, A) is 0 when every face of B is a face of A.
 */
#include "check.h"
#include "gen.h"

#include <stdlib.h>

/* Corner k of soup s as the library sees it. */
static const double *corner(const gen_soup_t *s, size_t face, int j) { return s->v + 3 * s->t[3 * face + j]; }

/* A soup of faces copied from src (face list `which`, n of them), each
 * with corners of its own. */
static gen_soup_t soup_from(const gen_soup_t *src, const size_t *which, size_t n) {
    gen_soup_t s = {malloc(9 * n * sizeof(double) + 1), 3 * n, malloc(3 * n * sizeof(uint64_t) + 1), n};
    for (size_t k = 0; k < n; k++)
        for (int j = 0; j < 3; j++) {
            memcpy(s.v + 9 * k + 3 * j, corner(src, which[k], j), 3 * sizeof(double));
            s.t[3 * k + j] = 3 * k + j;
        }
    return s;
}

/* nt random triangles with corners on a lattice of 2 side + 1 per axis. */
static gen_soup_t random_soup(gen_rng_t *r, size_t nt, int side) {
    gen_soup_t s = {malloc(9 * nt * sizeof(double) + 1), 3 * nt, malloc(3 * nt * sizeof(uint64_t) + 1), nt};
    for (size_t k = 0; k < 9 * nt; k++) s.v[k] = (double)((int)(gen_u64(r) % (uint64_t)(2 * side + 1)) - side);
    for (size_t k = 0; k < 3 * nt; k++) s.t[k] = k;
    return s;
}

TEST(shared_faces_change_nothing_but_the_dropped_count) {
    gen_rng_t r;
    for (uint64_t seed = 1; seed <= 6; seed++) {
        CONTEXT("seed %llu", (unsigned long long)seed);
        gen_seed(&r, 3800 + seed);
        /* U: a pool of faces; B: every other one; A: all of U in U's
         * order (B's faces interleaved with its own); A': A's own only */
        size_t nu = 1200;
        gen_soup_t U = random_soup(&r, nu, 40);
        size_t *in_b = malloc(nu * sizeof *in_b), *own = malloc(nu * sizeof *own), *all = malloc(nu * sizeof *all);
        size_t nb = 0, no = 0;
        for (size_t k = 0; k < nu; k++) {
            all[k] = k;
            if (gen_u64(&r) % 3) in_b[nb++] = k;
            else own[no++] = k;
        }
        gen_soup_t A = soup_from(&U, all, nu), B = soup_from(&U, in_b, nb), A1 = soup_from(&U, own, no);
        hd_mesh_t a = gen_soup_view(&A), b = gen_soup_view(&B), a1 = gen_soup_view(&A1);
        for (int threads = 1; threads <= 2; threads++) {
            hd_surface_options_t o;
            hd_surface_options_init(&o);
            o.tolerance = seed % 2 ? 1e-3 : 1e-9;
            o.threads = threads;
            hd_enclosure_t ab, ba, a1b;
            CHECK_RC(hd_surface_hausdorff(&a, &b, &o, &ab, &ba, NULL), HD_OK);
            /* the same absolute tolerance: A' has A's box only if U's corners span it */
            o.tolerance = ab.tolerance, o.relative = 0;
            CHECK_RC(hd_surface_hausdorff(&a1, &b, &o, &a1b, NULL, NULL), HD_OK);
            CHECK_EQ(ab.faces_dropped, nb);
            CHECK_EQ(a1b.faces_dropped, 0);
            CHECK_BITS(ab.lower, a1b.lower);
            CHECK_BITS(ab.upper, a1b.upper);
            CHECK(ab.face_a != SIZE_MAX && a1b.face_a < no);
            if (a1b.face_a < no) CHECK_EQ(ab.face_a, own[a1b.face_a]);
            for (int d = 0; d < 3; d++) CHECK_BITS(ab.point_a[d], a1b.point_a[d]);
            CHECK_BITS(ab.witness_distance, a1b.witness_distance);
            CHECK_EQ(ab.faces_split, a1b.faces_split);
            CHECK_EQ(ab.kernel_calls, a1b.kernel_calls);
            CHECK(ba.lower == 0 && ba.upper == 0);
            CHECK_EQ(ba.faces_dropped, nb);
        }
        free(in_b), free(own), free(all);
        gen_soup_free(&U), gen_soup_free(&A), gen_soup_free(&B), gen_soup_free(&A1);
    }
}
