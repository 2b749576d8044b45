/*
 * test_c2m.c -- the distance from points to a triangle mesh
 * (hd_mesh_distances) equals a brute force over every triangle with the
 * same kernel, bit for bit: each point's distance and nearest triangle
 * (ties: the smallest index), its closest point and weights, and the
 * witness of the largest distance, at 1 and 3 threads.  The meshes: random
 * triangle soups, bundled models (their faces read from data/orig/),
 * degenerate and duplicated triangles, integer lattices with points on
 * corners, edges and faces, and points far away.  The tree's lower bounds
 * are checked directly against the kernel, and bad meshes get their error.
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

/* The brute force: every triangle, smallest distance, smallest index. */
static void brute(const gen_soup_t *s, const double *p, hd__tri_near_t *best, size_t *index) {
    *index = SIZE_MAX;
    for (size_t k = 0; k < s->nt; k++) {
        hd__tri_near_t r;
        const uint64_t *f = s->t + 3 * k;
        CHECK_RC(hd__tri_nearest(p, s->v + 3 * f[0], s->v + 3 * f[1], s->v + 3 * f[2], &r), HD_OK);
        if (*index == SIZE_MAX || r.d < best->d) *best = r, *index = k;
    }
}

/* hd_mesh_distances at 1 and 3 threads equals the brute force on every
 * point; returns the number of points whose nearest triangle was exact. */
static void same_as_brute(const gen_soup_t *s, const double *pts, size_t n, const char *what) {
    hd_points_t P = hd_points_f64(pts, n);
    hd_mesh_t M = gen_soup_view(s);
    double *d = malloc(n * sizeof *d), *cp = malloc(3 * n * sizeof *cp), *bc = malloc(3 * n * sizeof *bc);
    size_t *tri = malloc(n * sizeof *tri);
    double far = -1;
    size_t far_i = 0, far_t = 0;
    hd__tri_near_t *want = malloc(n * sizeof *want);
    size_t *want_t = malloc(n * sizeof *want_t);
    for (size_t i = 0; i < n; i++) {
        brute(s, pts + 3 * i, &want[i], &want_t[i]);
        if (want[i].d > far) far = want[i].d, far_i = i, far_t = want_t[i];
    }
    for (int threads = 1; threads <= 3; threads += 2) {
        CONTEXT("%s, %d threads", what, threads);
        hd_options_t opt;
        hd_options_init(&opt);
        opt.threads = threads;
        hd_surface_result_t r;
        hd_error_t err;
        int rc = hd_mesh_distances(&P, &M, &opt, d, tri, cp, bc, &r, &err);
        CHECK_RC(rc, HD_OK);
        if (rc) {
            printf("%s\n", err.message);
            break;
        }
        size_t bad = 0;
        for (size_t i = 0; i < n && bad < 5; i++) {
            int ok = memcmp(&d[i], &want[i].d, sizeof d[i]) == 0 && tri[i] == want_t[i] &&
                     memcmp(cp + 3 * i, want[i].point, sizeof want[i].point) == 0 &&
                     memcmp(bc + 3 * i, want[i].bary, sizeof want[i].bary) == 0;
            if (!ok) {
                bad++;
                CONTEXT("%s, %d threads, point %zu (%.17g %.17g %.17g): %.17g tri %zu, brute %.17g tri %zu", what,
                        threads, i, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], d[i], tri[i], want[i].d, want_t[i]);
                CHECK(ok);
            }
        }
        CHECK_BITS(r.distance, far);
        CHECK_EQ(r.i, far_i);
        CHECK_EQ(r.triangle, far_t);
        CHECK(r.kernel_calls >= n);
    }
    free(d), free(cp), free(bc), free(tri), free(want), free(want_t);
}

static void soup_random(gen_rng_t *g, gen_soup_t *s, size_t nt, double size) {
    s->nv = 3 * nt, s->nt = nt;
    s->v = malloc(3 * s->nv * sizeof *s->v);
    s->t = malloc(3 * nt * sizeof *s->t);
    for (size_t k = 0; k < nt; k++) {
        double c[3] = {gen_unit(g), gen_unit(g), gen_unit(g)};
        for (int j = 0; j < 3; j++) {
            for (int i = 0; i < 3; i++) s->v[9 * k + 3 * j + i] = c[i] + size * (gen_unit(g) - 0.5);
            s->t[3 * k + j] = 3 * k + j;
        }
    }
}

/* n points: a third uniform in the cube [-1, 2]^3, a third near corners
 * and edges of the mesh, a third far (1e3 away). */
static double *points_around(gen_rng_t *g, const gen_soup_t *s, size_t n) {
    double *p = malloc(3 * n * sizeof *p);
    for (size_t i = 0; i < n; i++) {
        double *q = p + 3 * i;
        const uint64_t *f = s->t + 3 * (gen_u64(g) % s->nt);
        double w = gen_unit(g);
        switch (i % 3) {
        case 0:
            for (int c = 0; c < 3; c++) q[c] = 3 * gen_unit(g) - 1;
            break;
        case 1:
            for (int c = 0; c < 3; c++)
                q[c] = w * s->v[3 * f[0] + c] + (1 - w) * s->v[3 * f[1] + c] + 1e-9 * (gen_unit(g) - 0.5);
            break;
        default:
            for (int c = 0; c < 3; c++) q[c] = 1e3 * (gen_unit(g) - 0.5) + s->v[3 * f[0] + c];
        }
    }
    return p;
}

TEST(random_soups_equal_the_brute_force_at_1_and_3_threads) {
    for (uint64_t seed = 1; seed <= 6; seed++) {
        gen_rng_t g;
        gen_seed(&g, seed);
        gen_soup_t s;
        soup_random(&g, &s, seed < 4 ? 50 : 400 / SCALE, seed % 2 ? 0.2 : 0.02);
        size_t n = 1500 / SCALE;
        double *p = points_around(&g, &s, n);
        char what[64];
        snprintf(what, sizeof what, "random soup, seed %llu", (unsigned long long)seed);
        same_as_brute(&s, p, n, what);
        free(p);
        gen_soup_free(&s);
    }
}

/* A triangulated grid of side x side unit squares in z = 0 (integer
 * corners), each square split along its diagonal into two triangles. */
static void soup_grid(gen_soup_t *s, int side) {
    s->nv = (size_t)(side + 1) * (side + 1), s->nt = 2 * (size_t)side * side;
    s->v = malloc(3 * s->nv * sizeof *s->v);
    s->t = malloc(3 * s->nt * sizeof *s->t);
    for (int y = 0; y <= side; y++)
        for (int x = 0; x <= side; x++) {
            double *v = s->v + 3 * ((size_t)y * (side + 1) + x);
            v[0] = x, v[1] = y, v[2] = 0;
        }
    size_t k = 0;
    for (int y = 0; y < side; y++)
        for (int x = 0; x < side; x++) {
            uint64_t a = (uint64_t)y * (side + 1) + x, b = a + 1, c = a + side + 1, d = c + 1;
            uint64_t *t = s->t + 3 * k;
            t[0] = a, t[1] = b, t[2] = d, t[3] = a, t[4] = d, t[5] = c;
            k += 2;
        }
}

TEST(points_on_corners_edges_and_faces_are_at_zero_from_the_smallest_triangle) {
    gen_soup_t s;
    soup_grid(&s, 8);
    /* corners (up to 6 triangles), edge midpoints (2), face points, and the
     * same raised by 1/4 (the same ties at distance 0.25) */
    size_t n = 0;
    double p[3 * 400];
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++)
            for (int k = 0; k < 3 && n < 400; k++) {
                double q[3][3] = {{x, y, 0}, {x + 0.5, y, 0}, {x + 0.75, y + 0.25, 0}};
                memcpy(p + 3 * n++, q[k], sizeof q[k]);
            }
    size_t flat = n;
    for (size_t i = 0; i < flat && n < 400; i++, n++) {
        memcpy(p + 3 * n, p + 3 * i, 3 * sizeof *p);
        p[3 * n + 2] = 0.25;
    }
    same_as_brute(&s, p, n, "grid, points on features");
    hd_points_t P = hd_points_f64(p, 1);
    hd_mesh_t M = gen_soup_view(&s);
    double d;
    size_t t;
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, &d, &t, NULL, NULL, NULL, NULL), HD_OK);
    CHECK_BITS(d, 0.0); /* the corner (0,0,0): triangles 0 and 1 touch it */
    CHECK_EQ(t, 0);
    gen_soup_free(&s);
}

TEST(duplicated_triangles_tie_to_the_smallest_index) {
    gen_soup_t s;
    soup_grid(&s, 4);
    /* append every triangle again, corners rotated, in reverse order */
    size_t nt = s.nt;
    s.t = realloc(s.t, 6 * nt * sizeof *s.t);
    for (size_t k = 0; k < nt; k++) {
        const uint64_t *f = s.t + 3 * (nt - 1 - k);
        uint64_t *o = s.t + 3 * (nt + k);
        o[0] = f[1], o[1] = f[2], o[2] = f[0];
    }
    s.nt = 2 * nt;
    gen_rng_t g;
    gen_seed(&g, 11);
    double p[3 * 300];
    for (int i = 0; i < 300; i++) {
        p[3 * i] = 5 * gen_unit(&g) - 0.5, p[3 * i + 1] = 5 * gen_unit(&g) - 0.5;
        p[3 * i + 2] = i % 2 ? 0 : gen_unit(&g) - 0.5;
    }
    same_as_brute(&s, p, 300, "grid with every triangle twice");
    hd_points_t P = hd_points_f64(p, 300);
    hd_mesh_t M = gen_soup_view(&s);
    size_t tri[300];
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, tri, NULL, NULL, NULL, NULL), HD_OK);
    for (int i = 0; i < 300; i++) CHECK(tri[i] < nt);
    gen_soup_free(&s);
}

/* Two triangles whose true distances differ but round to the same double:
 * the smaller index wins even when its true distance is the larger, as
 * in the brute force, wherever the nearer one sits in the tree. */
TEST(equal_rounded_distances_tie_to_the_smallest_index_whatever_the_true_order) {
    double o[3] = {0, 0, 0}, v1[3] = {1, 1, 0}, v0[3] = {1, 1, 0};
    hd__tri_near_t r0, r1;
    double e1[3] = {11, 1, 0}, e2[3] = {1, 11, 0};
    CHECK_RC(hd__tri_nearest(o, v1, e1, e2, &r1), HD_OK);
    int found = 0;
    for (int k = 1; k < 64 && !found; k++) { /* |v0| > sqrt(2), rounded alike */
        v0[1] = 1 + k * 0x1p-52;
        double f1[3] = {11, v0[1], 0}, f2[3] = {1, v0[1] + 10, 0};
        CHECK_RC(hd__tri_nearest(o, v0, f1, f2, &r0), HD_OK);
        found = r0.d == r1.d;
    }
    CHECK(found);
    if (!found) return;
    gen_rng_t g;
    gen_seed(&g, 41);
    gen_soup_t s;
    soup_random(&g, &s, 300, 0.3); /* in [-0.15, 1.15]^3, then 4 higher: never nearest */
    for (size_t k = 0; k < 3 * s.nv; k += 3) s.v[k + 2] += 4;
    double tri0[9] = {v0[0], v0[1], 0, 11, v0[1], 0, 1, v0[1] + 10, 0};
    double tri1[9] = {1, 1, 0, 11, 1, 0, 1, 11, 0};
    for (int place = 0; place < 2; place++) {
        /* the farther-but-equal triangle first (index 0) or last; the other
         * at the other end */
        size_t a = place ? s.nt - 1 : 0, b = place ? 0 : s.nt - 1;
        memcpy(s.v + 9 * a, tri0, sizeof tri0);
        memcpy(s.v + 9 * b, tri1, sizeof tri1);
        double p[3 * 64];
        for (int i = 0; i < 64; i++) /* the origin, between other points */
            for (int c = 0; c < 3; c++) p[3 * i + c] = i % 2 ? 0 : 0.01 * (gen_unit(&g) - 0.5);
        same_as_brute(&s, p, 64, place ? "equal rounded distances, farther last" : "equal rounded distances, farther first");
        hd_points_t P = hd_points_f64(o, 1);
        hd_mesh_t M = gen_soup_view(&s);
        double d;
        size_t t;
        CHECK_RC(hd_mesh_distances(&P, &M, NULL, &d, &t, NULL, NULL, NULL, NULL), HD_OK);
        CHECK_BITS(d, r1.d);
        CHECK_EQ(t, a < b ? a : b);
    }
    gen_soup_free(&s);
}

TEST(degenerate_triangles_are_their_hulls_and_counted) {
    /* a segment (collinear corners), a repeated index, a point (coincident
     * distinct vertices), a needle, and one proper triangle */
    double v[] = {0, 0, 0, 1, 0, 0, 3, 0, 0,    /* 0-2 collinear */
                  0, 2, 0, 0, 2, 0, 0, 2, 0,    /* 3-5 one point thrice */
                  5, 5, 5, 6, 5, 5, 5.5, 5 + 0x1p-50, 5, /* 6-8 nearly collinear: a triangle */
                  0, 0, 4, 1, 0, 4, 0, 1, 4};   /* 9-11 proper */
    uint64_t t[] = {0, 1, 2, 1, 1, 9, 3, 4, 5, 6, 7, 8, 9, 10, 11, 2, 2, 2};
    gen_soup_t s = {v, 12, t, 6};
    gen_rng_t g;
    gen_seed(&g, 5);
    double p[3 * 600];
    for (int i = 0; i < 600; i++)
        for (int c = 0; c < 3; c++) p[3 * i + c] = 8 * gen_unit(&g) - 1.5;
    same_as_brute(&s, p, 600, "degenerate triangles");
    hd_points_t P = hd_points_f64(p, 600);
    hd_mesh_t M = gen_soup_view(&s);
    hd_surface_result_t r;
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, &r, NULL), HD_OK);
    CHECK_EQ(r.n_degenerate, 4); /* 0-1-2, 1-1-9, 3-4-5, 2-2-2 */
    double q[3] = {2, 1, 0};
    P = hd_points_f64(q, 1);
    double d;
    size_t tr;
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, &d, &tr, NULL, NULL, NULL, NULL), HD_OK);
    CHECK_BITS(d, 1.0); /* to the segment (0,0,0)-(3,0,0) */
    CHECK_EQ(tr, 0);
}

/* A mesh file's vertices and faces as a soup. */
static int soup_read(const char *path, gen_soup_t *s) {
    hd_mesh_file_t *m;
    hd_error_t err;
    int rc = hd_read_mesh(path, NULL, &m, &err);
    CHECK_RC(rc, HD_OK);
    if (rc) {
        printf("%s\n", err.message);
        return rc;
    }
    s->nv = m->n_vertices, s->nt = m->n_triangles;
    s->v = malloc(3 * s->nv * sizeof *s->v);
    s->t = malloc(3 * s->nt * sizeof *s->t);
    memcpy(s->v, m->vertices, 3 * s->nv * sizeof *s->v);
    memcpy(s->t, m->triangles, 3 * s->nt * sizeof *s->t);
    hd_mesh_file_free(m);
    return HD_OK;
}

TEST(bundled_models_equal_the_brute_force) {
    const char *files[] = {"data/orig/pinion.off", "data/orig/cow.off", "data/orig/Wuson.stl",
                           "data/orig/WusonOBJ.obj", "data/orig/stanford_bunny_reduced.ply"};
    for (size_t f = 0; f < sizeof files / sizeof *files; f++) {
        gen_soup_t s;
        if (soup_read(files[f], &s)) continue;
        gen_rng_t g;
        gen_seed(&g, 100 + f);
        /* the box's scale: points around it, near its surface, far away */
        double lo[3], hi[3];
        for (int c = 0; c < 3; c++) lo[c] = hi[c] = s.v[c];
        for (size_t k = 0; k < s.nv; k++)
            for (int c = 0; c < 3; c++) {
                lo[c] = s.v[3 * k + c] < lo[c] ? s.v[3 * k + c] : lo[c];
                hi[c] = s.v[3 * k + c] > hi[c] ? s.v[3 * k + c] : hi[c];
            }
        size_t n = 240 / SCALE;
        double *p = malloc(3 * n * sizeof *p);
        for (size_t i = 0; i < n; i++) {
            const uint64_t *t = s.t + 3 * (gen_u64(&g) % s.nt);
            double u = gen_unit(&g), w = gen_unit(&g) * (1 - u);
            for (int c = 0; c < 3; c++) {
                double ext = hi[c] - lo[c];
                double on = u * s.v[3 * t[0] + c] + w * s.v[3 * t[1] + c] + (1 - u - w) * s.v[3 * t[2] + c];
                p[3 * i + c] = i % 4 == 0   ? s.v[3 * t[0] + c]                                  /* a vertex */
                               : i % 4 == 1 ? on + 1e-3 * ext * (gen_unit(&g) - 0.5)          /* near */
                               : i % 4 == 2 ? lo[c] - ext + 3 * ext * gen_unit(&g)            /* box x3 */
                                            : lo[c] + 50 * ext * (gen_unit(&g) - 0.5);        /* far */
            }
        }
        same_as_brute(&s, p, n, files[f]);
        free(p);
        gen_soup_free(&s);
    }
}

TEST(float32_strided_vertices_and_uint32_indices_give_the_same_answers) {
    gen_rng_t g;
    gen_seed(&g, 21);
    gen_soup_t s;
    soup_random(&g, &s, 100, 0.3);
    float *vf = malloc(4 * s.nv * sizeof *vf); /* x y z and a pad, as float */
    uint32_t *t32 = malloc(3 * s.nt * sizeof *t32);
    for (size_t k = 0; k < s.nv; k++)
        for (int c = 0; c < 3; c++) {
            vf[4 * k + c] = (float)s.v[3 * k + c];
            s.v[3 * k + c] = vf[4 * k + c]; /* the soup holds the widened floats */
        }
    for (size_t k = 0; k < 3 * s.nt; k++) t32[k] = (uint32_t)s.t[k];
    size_t n = 300;
    double *p = points_around(&g, &s, n);
    hd_points_t P = hd_points_f64(p, n);
    hd_mesh_t M64 = gen_soup_view(&s);
    hd_mesh_t M32 = {{vf, s.nv, HD_FLOAT32, 4 * sizeof(float), 0}, t32, s.nt, HD_INDEX_U32};
    double d64[300], d32[300];
    size_t t64[300], tt32[300];
    CHECK_RC(hd_mesh_distances(&P, &M64, NULL, d64, t64, NULL, NULL, NULL, NULL), HD_OK);
    CHECK_RC(hd_mesh_distances(&P, &M32, NULL, d32, tt32, NULL, NULL, NULL, NULL), HD_OK);
    CHECK(memcmp(d64, d32, sizeof d64) == 0);
    CHECK(memcmp(t64, tt32, sizeof t64) == 0);
    free(vf), free(t32), free(p);
    gen_soup_free(&s);
}

/* The bounds the search discards with (a box's, the support bound in the
 * direction of the box's centre) never exceed the
 * kernel's distance
 * (which is within half an ulp of the true one): on random, degenerate and
 * tiny or huge triangles, with points near and far. */
TEST(the_lower_bounds_never_exceed_the_distance) {
    gen_rng_t g;
    gen_seed(&g, 77);
    const double scales[] = {1e-300, 1e-150, 1e-20, 1, 1e20, 1e150};
    int far_cases = 0, tight = 0;
    for (int k = 0; k < 60000 / SCALE; k++) {
        double sc = scales[k % 6];
        hd__tri_t t;
        double p[3];
        for (int j = 0; j < 3; j++)
            for (int c = 0; c < 3; c++) t.v[j][c] = sc * (gen_unit(&g) - 0.5);
        if (k % 5 == 1) memcpy(t.v[2], t.v[1], sizeof t.v[1]);                  /* a segment */
        if (k % 5 == 2) for (int c = 0; c < 3; c++) t.v[2][c] = 2 * t.v[1][c] - t.v[0][c]; /* collinear */
        double far = k % 3 == 0 ? 1e-6 : k % 3 == 1 || sc > 1e100 ? 1 : 1e6;
        for (int c = 0; c < 3; c++) p[c] = t.v[0][c] + sc * far * (gen_unit(&g) - 0.5);
        hd__tri_near_t r;
        CHECK_RC(hd__tri_nearest(p, t.v[0], t.v[1], t.v[2], &r), HD_OK);
        /* the true distance is at least r.d minus half its ulp */
        double floor_d = r.d - (nextafter(r.d, INFINITY) - r.d);
        hd__box_t b;
        for (int c = 0; c < 3; c++) {
            b.lo[c] = fmin(fmin(t.v[0][c], t.v[1][c]), t.v[2][c]);
            b.hi[c] = fmax(fmax(t.v[0][c], t.v[1][c]), t.v[2][c]);
        }
        double w[3];
        for (int c = 0; c < 3; c++) w[c] = p[c] - (b.lo[c] / 2 + b.hi[c] / 2);
        double lb = hd__support_lower(&t, 1, p, w), bl = hd__box_lower(&b, p);
        if (far > 1) far_cases++, tight += lb >= r.d * (1 - 1e-5);
        if (lb > r.d || bl > r.d) {
            CONTEXT("seed 77, case %d: d %.17g, support bound %.17g, box bound %.17g (floor %.17g)", k, r.d, lb, bl,
                    floor_d);
            CHECK(lb <= r.d && bl <= r.d);
            break;
        }
    }
    /* the bound of a group of triangles stays below each one's distance */
    for (int k = 0; k < 20000 / SCALE; k++) {
        hd__tri_t t[8];
        hd__box_t b;
        double p[3], sc = scales[k % 6], least = INFINITY;
        for (int j = 0; j < 8; j++)
            for (int v = 0; v < 3; v++)
                for (int c = 0; c < 3; c++) t[j].v[v][c] = sc * (gen_unit(&g) - 0.5) * (j + 1) / 8;
        for (int c = 0; c < 3; c++) {
            b.lo[c] = b.hi[c] = t[0].v[0][c];
            p[c] = sc * (k % 2 ? 2 : 1e-3) * (gen_unit(&g) - 0.5) + (k % 3 ? 0 : sc);
        }
        for (int j = 0; j < 8; j++) {
            hd__tri_near_t r;
            CHECK_RC(hd__tri_nearest(p, t[j].v[0], t[j].v[1], t[j].v[2], &r), HD_OK);
            least = r.d < least ? r.d : least;
            for (int v = 0; v < 3; v++)
                for (int c = 0; c < 3; c++) {
                    b.lo[c] = fmin(b.lo[c], t[j].v[v][c]);
                    b.hi[c] = fmax(b.hi[c], t[j].v[v][c]);
                }
        }
        double w[3];
        for (int c = 0; c < 3; c++) w[c] = p[c] - (b.lo[c] / 2 + b.hi[c] / 2);
        double gl = hd__support_lower(t, 8, p, w);
        if (gl > least) {
            CONTEXT("seed 77, group case %d: nearest %.17g, group bound %.17g", k, least, gl);
            CHECK(gl <= least);
            break;
        }
    }
    /* and the support bound is nearly the distance far away, as pruning needs */
    CONTEXT("seed 77: %d of %d far cases tight", tight, far_cases);
    CHECK(tight >= far_cases * 9 / 10);
}

TEST(bad_meshes_get_an_error_naming_the_triangle) {
    double v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, NAN, 0, 0};
    uint64_t t[] = {0, 1, 2, 0, 1, 4};
    double q[3] = {0, 0, 1};
    hd_points_t P = hd_points_f64(q, 1);
    hd_error_t err;
    hd_mesh_t M = {hd_points_f64(v, 4), t, 2, HD_INDEX_U64};
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, NULL, &err), HD_EINVAL);
    CHECK(strstr(err.message, "triangle 1 refers to vertex 4, but there are 4 vertices") != NULL);
    t[5] = 3;
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, NULL, &err), HD_ENONFINITE);
    CHECK(strstr(err.message, "triangle 1, corner 2 (vertex 3)") != NULL);
    M.n_triangles = 1; /* vertex 3 unused: never read */
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, NULL, &err), HD_OK);
    M.n_triangles = 0;
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, NULL, &err), HD_EEMPTY);
    M.n_triangles = 1;
    M.vertices.count = 0;
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, NULL, &err), HD_EEMPTY);
    CHECK(strstr(err.message, "no vertices") != NULL);
    M.vertices.count = 4;
    M.index_type = (hd_index_type_t)7;
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, NULL, &err), HD_EINVAL);
    M.index_type = HD_INDEX_U64;
    q[2] = NAN;
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, NULL, &err), HD_ENONFINITE);
}

/* Every vertex in range: the triangles are copied without a check per
 * corner, and an index out of range is still reported by its triangle;
 * the two index types and float32 vertices read the same corners. */
TEST(a_mesh_of_vertices_in_range_reads_every_index_type_alike) {
    double v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    float vf[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    uint32_t t32[] = {0, 1, 2, 1, 2, 3};
    uint64_t t64[] = {0, 1, 2, 1, 2, 3};
    double q[6] = {0.2, 0.2, 1, 1, 1, 1}, d[3][2];
    size_t f[3][2];
    hd_points_t P = hd_points_f64(q, 2);
    hd_error_t err;
    hd_mesh_t M[3] = {{hd_points_f64(v, 4), t32, 2, HD_INDEX_U32},
                      {hd_points_f64(v, 4), t64, 2, HD_INDEX_U64},
                      {hd_points_f32(vf, 4), t64, 2, HD_INDEX_U64}};
    for (int m = 0; m < 3; m++) {
        CONTEXT("mesh %d", m);
        CHECK_RC(hd_mesh_distances(&P, &M[m], NULL, d[m], f[m], NULL, NULL, NULL, &err), HD_OK);
        CHECK_BITS(d[m][0], d[0][0]);
        CHECK_BITS(d[m][1], d[0][1]);
        CHECK_EQ(f[m][1], (size_t)1);
    }
    t32[4] = 9;
    CHECK_RC(hd_mesh_distances(&P, &M[0], NULL, NULL, NULL, NULL, NULL, NULL, &err), HD_EINVAL);
    CHECK(strstr(err.message, "triangle 1 refers to vertex 9, but there are 4 vertices") != NULL);
}

/* ---- the discards of the search: far, clustered, tied, scaled ---------- */

/* The corners' box of a soup. */
static void soup_box(const gen_soup_t *s, double lo[3], double hi[3]) {
    for (int c = 0; c < 3; c++) lo[c] = hi[c] = s->v[c];
    for (size_t k = 0; k < s->nv; k++)
        for (int c = 0; c < 3; c++) {
            lo[c] = s->v[3 * k + c] < lo[c] ? s->v[3 * k + c] : lo[c];
            hi[c] = s->v[3 * k + c] > hi[c] ? s->v[3 * k + c] : hi[c];
        }
}

/* Dense clouds far from a model (the box grown 3 and 100 times: the
 * neighbouring points share one list of triangles) and clusters of points
 * a millionth of the model apart (tiny groups, many equal seeds). */
TEST(far_and_clustered_clouds_equal_the_brute_force) {
    const char *files[] = {"data/orig/pinion.off", "data/orig/cow.off"};
    for (size_t f = 0; f < 2; f++) {
        gen_soup_t s;
        if (soup_read(files[f], &s)) continue;
        double lo[3], hi[3];
        soup_box(&s, lo, hi);
        gen_rng_t g;
        gen_seed(&g, 300 + f);
        size_t n = 3000 / SCALE;
        double *p = malloc(3 * n * sizeof *p);
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                double ext = hi[c] - lo[c], mid = lo[c] / 2 + hi[c] / 2;
                p[3 * i + c] = i < n / 3 ? mid + 1.5 * ext * (2 * gen_unit(&g) - 1)
                               : i < 2 * n / 3 ? mid + 50 * ext * (2 * gen_unit(&g) - 1)
                                               : 0; /* clusters: below */
            }
        for (size_t i = 2 * n / 3; i < n; i++) { /* 20 clusters around vertices and beyond the box */
            size_t k = i % 20;
            const double *v = s.v + 3 * ((k * 7919) % s.nv);
            for (int c = 0; c < 3; c++)
                p[3 * i + c] = v[c] * (k % 2 ? 1 : 1.5) + 1e-6 * (hi[c] - lo[c]) * (gen_unit(&g) - 0.5);
        }
        char what[96];
        snprintf(what, sizeof what, "%s, far and clustered clouds (seed %zu)", files[f], 300 + f);
        same_as_brute(&s, p, n, what);
        free(p);
        gen_soup_free(&s);
    }
}

/* The regular octahedron: its centre is at the same distance from all 8
 * faces, a point on an axis from the 4 faces of a corner, a point on a
 * diagonal plane from 2 faces: every such point ties, in groups of equal
 * and of nearby points. */
TEST(equidistant_points_of_a_symmetric_mesh_tie_to_the_smallest_index) {
    double v[] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
    uint64_t t[] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    gen_soup_t s = {v, 6, t, 8};
    double p[3 * 400];
    size_t n = 0;
    for (int i = 0; i < 40; i++) p[n++] = 0, p[n++] = 0, p[n++] = 0; /* the centre, 40 times */
    for (int i = 0; i < 120; i++) { /* on the axes, near and far, both sides */
        double r = ldexp(1.0 + i % 7, i / 7 - 8) * (i % 2 ? 1 : -1);
        p[n++] = i % 3 == 0 ? r : 0, p[n++] = i % 3 == 1 ? r : 0, p[n++] = i % 3 == 2 ? r : 0;
    }
    for (int i = 0; i < 240; i++) { /* on the planes x = y, y = z, z = x, and x = y = z */
        double a = ldexp(1.0 + i % 5, i / 20 - 6), b = i % 4 ? a / 3 : a;
        double q[3] = {a, a, b};
        int rot = i % 3;
        p[n++] = q[rot], p[n++] = q[(rot + 1) % 3], p[n++] = q[(rot + 2) % 3];
    }
    same_as_brute(&s, p, n / 3, "octahedron, equidistant points");
    /* far beyond a corner: the 4 triangles around it tie there, and only
     * the first needs the kernel (the others are decided at the corner) */
    gen_rng_t g;
    gen_seed(&g, 400);
    for (int i = 0; i < 400; i++) {
        p[3 * i] = 50 + gen_unit(&g), p[3 * i + 1] = gen_unit(&g) - 0.5, p[3 * i + 2] = gen_unit(&g) - 0.5;
    }
    same_as_brute(&s, p, 400, "octahedron, beyond the corner (1, 0, 0) (seed 400)");
    hd_points_t P = hd_points_f64(p, 400);
    hd_mesh_t M = gen_soup_view(&s);
    hd_surface_result_t r;
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, &r, NULL), HD_OK);
    CONTEXT("octahedron, 400 points beyond a corner: %llu kernel calls", (unsigned long long)r.kernel_calls);
    CHECK(r.kernel_calls <= 440);
}

/* The same soups and clouds with every coordinate scaled by a power of
 * two from 2^-990 to 2^480 (rounding unchanged, underflow and huge bounds
 * not), and by 1e-300 and 1e150 (rounded). */
TEST(huge_and_tiny_coordinates_equal_the_brute_force) {
    const double scales[] = {0x1p-990, 1e-300, 0x1p-500, 1e-20, 1e20, 1e150, 0x1p480};
    for (size_t k = 0; k < sizeof scales / sizeof *scales; k++) {
        gen_rng_t g;
        gen_seed(&g, 500 + k);
        gen_soup_t s;
        soup_random(&g, &s, 200 / SCALE, k % 2 ? 0.2 : 0.02);
        size_t n = 900 / SCALE;
        double *p = points_around(&g, &s, n);
        for (size_t i = 0; i < 3 * s.nv; i++) s.v[i] *= scales[k];
        for (size_t i = 0; i < 3 * n; i++) p[i] *= scales[k];
        char what[64];
        snprintf(what, sizeof what, "random soup scaled by %g (seed %zu)", scales[k], 500 + k);
        same_as_brute(&s, p, n, what);
        free(p);
        gen_soup_free(&s);
    }
}

/* Degenerate triangles (segments, points, needles) among proper ones,
 * with clouds clustered on them and far from them. */
TEST(clusters_on_degenerate_triangles_equal_the_brute_force) {
    gen_rng_t g;
    gen_seed(&g, 600);
    gen_soup_t s;
    soup_random(&g, &s, 300 / SCALE, 0.1);
    for (size_t k = 0; k < s.nt; k += 3) { /* every third: a segment, a point or a needle */
        double *a = s.v + 9 * k, *b = a + 3, *c = a + 6;
        for (int i = 0; i < 3; i++)
            c[i] = k % 9 == 0 ? 2 * b[i] - a[i] : k % 9 == 3 ? a[i] : b[i] + 0x1p-40 * (a[i] - b[i]);
        if (k % 9 == 3) memcpy(b, a, 3 * sizeof *a);
    }
    size_t n = 1500 / SCALE;
    double *p = malloc(3 * n * sizeof *p);
    for (size_t i = 0; i < n; i++) {
        const double *v = s.v + 9 * (3 * (i % (s.nt / 3)));
        double sc = i % 3 == 0 ? 1e-9 : i % 3 == 1 ? 1e-3 : 30;
        for (int c = 0; c < 3; c++) p[3 * i + c] = v[c] + sc * (gen_unit(&g) - 0.5);
    }
    same_as_brute(&s, p, n, "clusters on degenerate triangles (seed 600)");
    free(p);
    gen_soup_free(&s);
}

/* The prepared bounds decide before the kernel: on a cloud near a smooth
 * model the kernel runs for about one triangle a point (the nearest),
 * and on a cloud far from it for its ties only. */
TEST(the_kernel_runs_about_once_a_point) {
    gen_soup_t s;
    if (soup_read("data/orig/cow.off", &s)) return;
    double lo[3], hi[3];
    soup_box(&s, lo, hi);
    gen_rng_t g;
    gen_seed(&g, 700);
    size_t n = 4000 / SCALE;
    double *p = malloc(3 * n * sizeof *p);
    for (size_t i = 0; i < n; i++) {
        const uint64_t *t = s.t + 3 * (gen_u64(&g) % s.nt);
        double u = gen_unit(&g), w = gen_unit(&g) * (1 - u);
        for (int c = 0; c < 3; c++)
            p[3 * i + c] = u * s.v[3 * t[0] + c] + w * s.v[3 * t[1] + c] + (1 - u - w) * s.v[3 * t[2] + c] +
                           1e-3 * (hi[c] - lo[c]) * (gen_unit(&g) - 0.5);
    }
    hd_points_t P = hd_points_f64(p, n);
    hd_mesh_t M = gen_soup_view(&s);
    hd_surface_result_t r;
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, &r, NULL), HD_OK);
    CONTEXT("cow, %zu near points (seed 700): %llu kernel calls", n, (unsigned long long)r.kernel_calls);
    CHECK(r.kernel_calls <= n + n / 50);
    free(p);
    gen_soup_free(&s);
}

/* ---- the frames: an oriented bound for the nodes of a nearly flat patch -- */

/* The grid of soup_grid tilted into the plane z = x / 2 + y / 4 (exact
 * corners), optionally with every corner's z moved by up to `bump`. */
static void soup_tilted(gen_soup_t *s, int side, double bump, gen_rng_t *g) {
    soup_grid(s, side);
    for (size_t k = 0; k < s->nv; k++) {
        double *v = s->v + 3 * k;
        v[2] = v[0] / 2 + v[1] / 4 + (bump > 0 ? bump * (gen_unit(g) - 0.5) : 0);
    }
}

/* The tree of a soup, with frames. */
static void soup_tree(const gen_soup_t *s, hd__bvh_t *t) {
    hd__tri_t *tris = malloc(s->nt * sizeof *tris);
    for (size_t k = 0; k < s->nt; k++) {
        for (int j = 0; j < 3; j++) memcpy(tris[k].v[j], s->v + 3 * s->t[3 * k + j], sizeof tris[k].v[j]);
        tris[k].index = k;
    }
    CHECK_RC(hd__bvh_build(t, tris, s->nt), HD_OK);
    CHECK_RC(hd__bvh_frames(t), HD_OK);
}

/* Every node's frame bound stays below the squared distance of each of its
 * triangles (the kernel's, within half an ulp of the true one; the bound
 * is shrunk by far more), on tilted and bumpy grids and random soups,
 * tiny to huge, with points on, near and far from them; and over a flat
 * patch it is nearly the distance, as the search needs. */
TEST(the_frame_bound_never_exceeds_a_nodes_distance) {
    const double scales[] = {1, 0x1p-990, 1e-300, 1e150, 0x1p480};
    int framed = 0, tight = 0, far_flat = 0;
    for (int c = 0; c < 10; c++) {
        gen_rng_t g;
        gen_seed(&g, 800 + c);
        gen_soup_t s;
        if (c % 2 == 0) soup_tilted(&s, 12, c % 4 == 2 ? 0.05 : 0, &g);
        else soup_random(&g, &s, 200 / SCALE, 0.2);
        double sc = scales[c / 2];
        for (size_t i = 0; i < 3 * s.nv; i++) s.v[i] *= sc;
        hd__bvh_t t;
        soup_tree(&s, &t);
        double lo[3], hi[3];
        soup_box(&s, lo, hi);
        struct { size_t node, first, n; } stack[64];
        int top = 0;
        stack[top].node = 0, stack[top].first = 0, stack[top++].n = t.n_tris;
        while (top > 0) {
            size_t k = stack[--top].node, first = stack[top].first, n = stack[top].n;
            const hd__bvh_node_t *node = &t.nodes[k];
            if (!node->count) {
                stack[top].node = k + 1, stack[top].first = first, stack[top++].n = n / 2;
                stack[top].node = node->first_or_second, stack[top].first = first + n / 2, stack[top++].n = n - n / 2;
            }
            (void)hd__bvh_frame_lower2(&t, k, first, n, lo); /* makes the frame */
            if (atomic_load(&t.frames[k].state) != 2) continue;
            framed++;
            for (int i = 0; i < 40 / SCALE; i++) {
                double p[3], grow = i % 4 == 0 ? 0 : i % 4 == 1 ? 0.01 : i % 4 == 2 ? 3 : 100, least = INFINITY;
                const hd__tri_t *on = &t.tris[first + (size_t)i % n];
                double u = gen_unit(&g), w = (1 - u) * gen_unit(&g);
                for (int a = 0; a < 3; a++) { /* grow 0: on a triangle (rounded), or on its corner */
                    double mid = lo[a] / 2 + hi[a] / 2, ext = hi[a] - lo[a];
                    p[a] = grow == 0 ? (i % 8 == 0 ? on->v[0][a] : u * on->v[0][a] + w * on->v[1][a] +
                                                                       (1 - u - w) * on->v[2][a])
                                     : mid + grow * ext * (gen_unit(&g) - 0.5);
                }
                for (size_t j = first; j < first + n; j++) {
                    hd__tri_near_t r;
                    CHECK_RC(hd__tri_nearest(p, t.tris[j].v[0], t.tris[j].v[1], t.tris[j].v[2], &r), HD_OK);
                    least = r.d < least ? r.d : least;
                }
                double lo2 = hd__bvh_frame_lower2(&t, k, first, n, p);
                if (c % 4 == 0 && grow >= 3) far_flat++, tight += lo2 >= least * least * (1 - 1e-9);
                if (!(lo2 <= least * least)) {
                    CONTEXT("case %d (seed %d), node %zu, point %d: nearest %.17g, frame bound %.17g", c, 800 + c, k,
                            i, least, sqrt(lo2));
                    CHECK(lo2 <= least * least);
                    top = 0;
                    break;
                }
            }
        }
        hd__bvh_free(&t);
        gen_soup_free(&s);
    }
    CONTEXT("%d framed nodes; over the flat grids, %d of %d far points tight", framed, tight, far_flat);
    CHECK(framed > 0);
    CHECK(tight >= far_flat / 4);
}

/* Far points and ties over a tilted grid, where the frames decide: points
 * on the normals of corners (6 triangles tie), of edge midpoints (2 tie)
 * and of faces, from 1/8 to 500 away, and clouds in the box grown 3 and
 * 100 times, at 1 and 3 threads, equal the brute force; the search with
 * frames gives the answers of the search without them and opens fewer
 * nodes. */
TEST(far_points_and_ties_over_a_tilted_grid_equal_the_brute_force) {
    gen_rng_t g;
    gen_seed(&g, 900);
    gen_soup_t s;
    soup_tilted(&s, 24, 0, &g);
    size_t n = 2400 / SCALE, m = 0;
    double *p = malloc(3 * n * sizeof *p), lo[3], hi[3];
    soup_box(&s, lo, hi);
    const double up[3] = {-2, -1, 4}, away[] = {0.125, 1, 30, 500}; /* the normal, exact */
    for (; m < n / 2; m++) { /* exact points on the normals of corners, edge midpoints, faces */
        int x = (int)(gen_u64(&g) % 24), y = (int)(gen_u64(&g) % 24), kind = (int)(m % 3);
        double q[3] = {x + (kind ? 0.5 : 0), y + (kind == 2 ? 0.25 : 0), 0};
        q[2] = q[0] / 2 + q[1] / 4;
        double t = away[m / 3 % 4] * (m % 2 ? 1 : -1);
        for (int c = 0; c < 3; c++) p[3 * m + c] = q[c] + t * up[c];
    }
    for (; m < n; m++)
        for (int c = 0; c < 3; c++) {
            double mid = lo[c] / 2 + hi[c] / 2, ext = hi[c] - lo[c];
            p[3 * m + c] = mid + (m % 4 ? 1.5 : 50) * ext * (2 * gen_unit(&g) - 1);
        }
    same_as_brute(&s, p, n, "tilted grid, ties and far points (seed 900)");
    hd__bvh_t t;
    soup_tree(&s, &t);
    hd__bvh_frame_t *frames = t.frames;
    hd__bvh_stats_t with = {0, 0, 0, 0, 0, 0}, without = with;
    size_t seed_a = SIZE_MAX, seed_b = SIZE_MAX;
    for (size_t i = n / 2; i < n; i++) {
        hd__tri_near_t a, b;
        size_t ia, ib;
        t.frames = frames;
        seed_a = hd__bvh_nearest(&t, p + 3 * i, seed_a, 0, &a, &ia, &with);
        t.frames = NULL;
        seed_b = hd__bvh_nearest(&t, p + 3 * i, seed_b, 0, &b, &ib, &without);
        if (memcmp(&a.d, &b.d, sizeof a.d) != 0 || ia != ib) {
            CONTEXT("tilted grid (seed 900), point %zu: %.17g tri %zu with frames, %.17g tri %zu without", i, a.d, ia,
                    b.d, ib);
            CHECK(0);
            break;
        }
    }
    t.frames = frames;
    CONTEXT("tilted grid, far points: %llu nodes opened with frames, %llu without",
            (unsigned long long)with.nodes, (unsigned long long)without.nodes);
    CHECK(10 * with.nodes < 9 * without.nodes);
    hd__bvh_free(&t);
    free(p);
    gen_soup_free(&s);
}

/* The list a group of points shares (hd__bvh_collect with group_r2) must
 * keep every triangle that is nearest to some point of the group, however
 * far that point is from the group's first one.  Two parallel triangles,
 * in the planes x = 0 and x = X1, and points on the x axis: p0 = (1, 0, 0)
 * is nearest the plane x = 0 (at 1) and q = (4, 0, 0) the plane x = X1,
 * at X1 - 4 = 4 (1 - eps), just below its distance 4 to the first plane:
 * the group's radius (p0's distance plus the group's diagonal, 1 + 3) is
 * then tight, so a radius even slightly short of it drops q's triangle.
 * eps = 0 is a tie, which the first triangle (the far one, index 0)
 * wins.  The same mirrored (the other point first in the Morton order)
 * and scaled by 2^-600 and 2^400 (exact); 1 and 3 threads. */
TEST(a_group_keeps_the_triangle_nearest_to_its_far_point) {
    const double eps[] = {0x1p-3, 0x1p-20, 0x1p-52, 0}, scale[] = {1, 0x1p-600, 0x1p400};
    for (size_t e = 0; e < 4; e++)
        for (size_t k = 0; k < 3; k++)
            for (int mirror = 0; mirror < 2; mirror++) {
                double m = mirror ? -scale[k] : scale[k], x1 = 8 - 4 * eps[e];
                double v[] = {x1, -1, -1, x1, 1, -1, x1, 0, 1, 0, -1, -1, 0, 1, -1, 0, 0, 1};
                double p[] = {1, 0, 0, 4, 0, 0, 2.5, 0, 0};
                for (int i = 0; i < 18; i++) v[i] *= i % 3 == 0 ? m : scale[k];
                for (int i = 0; i < 9; i += 3) p[i] *= m;
                uint64_t t[] = {0, 1, 2, 3, 4, 5};
                gen_soup_t s = {v, 6, t, 2};
                char what[96];
                snprintf(what, sizeof what, "planes 0 and %.17g, scale %g%s", x1, scale[k], mirror ? ", mirrored" : "");
                same_as_brute(&s, p, 2, what);
                same_as_brute(&s, p, 3, what);
            }
}
