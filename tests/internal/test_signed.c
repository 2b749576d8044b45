/*
 * test_signed.c -- the signed distance to a closed mesh
 * (hd_mesh_signed_distances): the sign is -1 inside, +1 outside, 0 where
 * the distance is 0; the winding number is exact on points whose rays run
 * through edges and vertices; meshes that are not closed or consistently
 * oriented are refused naming an edge; the other outputs equal
 * hd_mesh_distances' bit for bit.  References: the analytic solids (cube,
 * sphere, torus), a ray-parity count in doubles along a random direction,
 * and the sum of the triangles' solid angles (Van Oosterom and Strackee
 * 1983) rounded, both on points away from the surface.
 */
#include "check.h"
#include "gen.h"
#include "mesh/mesh.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>

#ifdef __SANITIZE_ADDRESS__
#define SCALE 4 /* the sanitizer build runs fewer cases */
#else
#define SCALE 1
#endif

static size_t add_vertex(gen_soup_t *s, double x, double y, double z) {
    s->v = realloc(s->v, 3 * (s->nv + 1) * sizeof *s->v);
    s->v[3 * s->nv] = x, s->v[3 * s->nv + 1] = y, s->v[3 * s->nv + 2] = z;
    return s->nv++;
}

static void add_tri(gen_soup_t *s, uint64_t a, uint64_t b, uint64_t c) {
    s->t = realloc(s->t, 3 * (s->nt + 1) * sizeof *s->t);
    s->t[3 * s->nt] = a, s->t[3 * s->nt + 1] = b, s->t[3 * s->nt + 2] = c;
    s->nt++;
}

/* The box [lo, hi]^3 with 8 shared vertices and 12 outward triangles;
 * flip != 0 orients it inward. */
static void add_cube(gen_soup_t *s, const double lo[3], const double hi[3], int flip) {
    size_t base = s->nv;
    for (int k = 0; k < 8; k++) add_vertex(s, k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]);
    static const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int f = 0; f < 6; f++) {
        const int *c = q[f];
        if (flip) {
            add_tri(s, base + c[0], base + c[2], base + c[1]);
            add_tri(s, base + c[0], base + c[3], base + c[2]);
        } else {
            add_tri(s, base + c[0], base + c[1], base + c[2]);
            add_tri(s, base + c[0], base + c[2], base + c[3]);
        }
    }
}

static void unit_cube(gen_soup_t *s) {
    memset(s, 0, sizeof *s);
    add_cube(s, (double[3]){0, 0, 0}, (double[3]){1, 1, 1}, 0);
}

/* A radius in [0.8, 1.2] that depends only on a direction's bits, so that
 * copies of a vertex stay bit-equal. */
static double bumpy(const double *u) {
    uint64_t h = 1469598103934665603ull, b;
    for (int k = 0; k < 3; k++) {
        memcpy(&b, &u[k], 8);
        h = (h ^ b) * 1099511628211ull;
        h ^= h >> 29;
    }
    return 0.8 + 0.4 * (double)(h >> 11) * 0x1p-53;
}

/* An icosphere of radius r around c, subdivided `levels` times, as a soup
 * of separately stored corners (shared by equal coordinates only); bump
 * moves each vertex radially by bumpy(); flip orients it inward. */
static void add_sphere(gen_soup_t *s, const double c[3], double r, int levels, int bump, int flip) {
    const double t = (1 + sqrt(5.0)) / 2;
    double ico[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    static const int f[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                 {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    size_t n = 20;
    double(*tri)[3][3] = malloc(n * sizeof *tri);
    for (size_t k = 0; k < n; k++)
        for (int j = 0; j < 3; j++)
            for (int d = 0; d < 3; d++) tri[k][j][d] = ico[f[k][j]][d] / sqrt(1 + t * t);
    for (int l = 0; l < levels; l++) {
        double(*next)[3][3] = malloc(4 * n * sizeof *next);
        for (size_t k = 0; k < n; k++) {
            double m[3][3];
            for (int j = 0; j < 3; j++) {
                const double *a = tri[k][j], *b = tri[k][(j + 1) % 3];
                double len = 0;
                for (int d = 0; d < 3; d++) m[j][d] = a[d] + b[d], len += m[j][d] * m[j][d];
                len = sqrt(len);
                for (int d = 0; d < 3; d++) m[j][d] /= len;
            }
            double *out[4][3] = {{tri[k][0], m[0], m[2]}, {m[0], tri[k][1], m[1]}, {m[2], m[1], tri[k][2]},
                                 {m[0], m[1], m[2]}};
            for (int q = 0; q < 4; q++)
                for (int j = 0; j < 3; j++) memcpy(next[4 * k + q][j], out[q][j], sizeof next[0][0]);
        }
        free(tri);
        tri = next;
        n *= 4;
    }
    for (size_t k = 0; k < n; k++) {
        size_t id[3];
        for (int j = 0; j < 3; j++) {
            double rr = r * (bump ? bumpy(tri[k][j]) : 1.0);
            id[j] = add_vertex(s, c[0] + rr * tri[k][j][0], c[1] + rr * tri[k][j][1], c[2] + rr * tri[k][j][2]);
        }
        if (flip) add_tri(s, id[0], id[2], id[1]);
        else add_tri(s, id[0], id[1], id[2]);
    }
    free(tri);
}

/* The torus mesh of gen.h. */
static void torus(gen_soup_t *s, double R, double r, int nu, int nv) {
    gen_torus_mesh(R, r, nu, nv, &s->v, &s->t);
    s->nv = (size_t)nu * (size_t)nv;
    s->nt = 2 * s->nv;
}

/* The signs of n points (1 and 3 threads must agree, and the distances
 * must be hd_mesh_distances'); returns HD_OK or the error. */
static int signs(const gen_soup_t *s, const double *pts, size_t n, int8_t *sg, double *dist, hd_error_t *err) {
    hd_points_t P = hd_points_f64(pts, n);
    hd_mesh_t M = gen_soup_view(s);
    hd_options_t opt;
    hd_options_init(&opt);
    opt.threads = 1;
    double *d1 = malloc(n * sizeof *d1), *d3 = malloc(n * sizeof *d3), *cp = malloc(3 * n * sizeof *cp),
           *cq = malloc(3 * n * sizeof *cq);
    size_t *t1 = malloc(n * sizeof *t1), *t3 = malloc(n * sizeof *t3);
    int8_t *s3 = malloc(n);
    int rc = hd_mesh_signed_distances(&P, &M, &opt, dist, t1, cp, NULL, sg, NULL, err);
    if (rc == HD_OK) {
        opt.threads = 3;
        CHECK_RC(hd_mesh_signed_distances(&P, &M, &opt, NULL, NULL, NULL, NULL, s3, NULL, err), HD_OK);
        CHECK(memcmp(sg, s3, n) == 0);
        CHECK_RC(hd_mesh_distances(&P, &M, &opt, d3, t3, cq, NULL, NULL, err), HD_OK);
        CHECK(memcmp(dist, d3, n * sizeof *d3) == 0);
        CHECK(memcmp(t1, t3, n * sizeof *t3) == 0);
        CHECK(memcmp(cp, cq, 3 * n * sizeof *cp) == 0);
    }
    free(d1), free(d3), free(cp), free(cq), free(t1), free(t3), free(s3);
    return rc;
}

/* ---- references on generic points ---------------------------------------- */

/* Hits of the ray p + t dir, t > 0, with the triangles (Moller-Trumbore in
 * doubles): its parity is inside/outside for points and directions in
 * general position. */
static int ray_parity(const gen_soup_t *s, const double *p, const double *dir) {
    int hits = 0;
    for (size_t k = 0; k < s->nt; k++) {
        const double *a = s->v + 3 * s->t[3 * k], *b = s->v + 3 * s->t[3 * k + 1], *c = s->v + 3 * s->t[3 * k + 2];
        double e1[3], e2[3], pv[3], tv[3], qv[3];
        for (int d = 0; d < 3; d++) e1[d] = b[d] - a[d], e2[d] = c[d] - a[d], tv[d] = p[d] - a[d];
        pv[0] = dir[1] * e2[2] - dir[2] * e2[1], pv[1] = dir[2] * e2[0] - dir[0] * e2[2],
        pv[2] = dir[0] * e2[1] - dir[1] * e2[0];
        double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
        if (det == 0) continue;
        double u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) / det;
        qv[0] = tv[1] * e1[2] - tv[2] * e1[1], qv[1] = tv[2] * e1[0] - tv[0] * e1[2],
        qv[2] = tv[0] * e1[1] - tv[1] * e1[0];
        double v = (dir[0] * qv[0] + dir[1] * qv[1] + dir[2] * qv[2]) / det;
        double t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
        hits += u >= 0 && v >= 0 && u + v <= 1 && t > 0;
    }
    return hits & 1;
}

/* The solid angles' sum over 4 pi (Van Oosterom-Strackee), in doubles. */
static double solid_winding(const gen_soup_t *s, const double *p) {
    double sum = 0;
    for (size_t k = 0; k < s->nt; k++) {
        double a[3], b[3], c[3];
        for (int d = 0; d < 3; d++) {
            a[d] = s->v[3 * s->t[3 * k] + d] - p[d];
            b[d] = s->v[3 * s->t[3 * k + 1] + d] - p[d];
            c[d] = s->v[3 * s->t[3 * k + 2] + d] - p[d];
        }
        double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]),
               lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        double det = a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
                     a[2] * (b[0] * c[1] - b[1] * c[0]);
        double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2], bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2],
               ca = c[0] * a[0] + c[1] * a[1] + c[2] * a[2];
        sum += 2 * atan2(det, la * lb * lc + ab * lc + bc * la + ca * lb);
    }
    return sum / (4 * M_PI);
}

/* Random points in [lo, hi]^3 kept when at least `gap` from the surface;
 * the sign agrees with the ray parity and the rounded solid-angle sum
 * (whose distance to its integer is checked below 0.01), and the exact
 * winding number equals that integer.  Returns the points inside. */
static size_t against_box(const gen_soup_t *s, uint64_t seed, size_t n, const double lo[3], const double hi[3],
                          double gap) {
    gen_rng_t r;
    gen_seed(&r, seed);
    double *p = malloc(3 * n * sizeof *p), *d = malloc(n * sizeof *d);
    int8_t *sg = malloc(n);
    gen_cube(&r, p, n, 0, 1);
    for (size_t k = 0; k < 3 * n; k++) p[k] = lo[k % 3] + (hi[k % 3] - lo[k % 3]) * p[k];
    hd_error_t err;
    size_t inside = 0, compared = 0;
    CHECK_RC(signs(s, p, n, sg, d, &err), HD_OK);
    hd__wtri_t *w = malloc(s->nt * sizeof *w);
    for (size_t k = 0; k < s->nt; k++)
        for (int j = 0; j < 3; j++) {
            w[k].vi[j] = s->t[3 * k + j];
            memcpy(w[k].v[j], s->v + 3 * s->t[3 * k + j], sizeof w[k].v[j]);
        }
    hd__solid_t *solid;
    CHECK_RC(hd__solid_build(&solid, w, s->nt, &err), HD_OK);
    for (size_t i = 0; i < n && !hdt_failed(); i++) {
        CONTEXT("seed %llu, point %zu (%.17g %.17g %.17g)", (unsigned long long)seed, i, p[3 * i], p[3 * i + 1],
                p[3 * i + 2]);
        CHECK(sg[i] == 1 || sg[i] == -1);
        inside += sg[i] < 0;
        if (d[i] < gap) continue;
        double dir[3] = {gen_normal(&r), gen_normal(&r), gen_normal(&r)};
        double ws = solid_winding(s, p + 3 * i);
        long wi = lround(ws);
        int on;
        CHECK(fabs(ws - (double)wi) < 0.01);
        CHECK_EQ(hd__solid_winding(solid, p + 3 * i, &on), wi);
        CHECK_EQ(on, 0);
        CHECK_EQ(sg[i], wi != 0 ? -1 : 1);
        if (labs(wi) <= 1) CHECK_EQ(ray_parity(s, p + 3 * i, dir), wi != 0);
        compared++;
    }
    CHECK(compared > n / 2);
    hd__solid_free(solid);
    free(w), free(p), free(d), free(sg);
    return inside;
}

static size_t against_references(const gen_soup_t *s, uint64_t seed, size_t n, double lo, double hi, double gap) {
    return against_box(s, seed, n, (double[3]){lo, lo, lo}, (double[3]){hi, hi, hi}, gap);
}

/* ---- behaviours -------------------------------------------------------- */

TEST(cube_points_inside_outside_and_on_it) {
    gen_soup_t s;
    unit_cube(&s);
    const double tiny = 0x1p-1000;
    double p[][3] = {
        {0.5, 0.5, 0.5},     {0.25, 0.5, 0.5},   {2, 0.5, 0.5},   {-1, 0.5, 0.5},  /* rays through diagonals */
        {-1, 0, 0},          {-1, 1, 1},         {-1, 0, 0.5},    {2, 1, 0},       /* rays along edges */
        {0.5, 0, 0},         {0, 0, 0},          {1, 1, 1},       {0.5, 0.5, 0},   /* on an edge, a vertex, a face */
        {0.3, 0.7, 1},       {2, 0.5, 0},        {0.5, 3, 1},     {-5, -5, 0},     /* on a face; on a face's plane */
        {tiny, tiny, tiny},  {-tiny, 0.5, 0.5},  {0.5, 0.5, 1 - 0x1p-53}, {0.5, 1 + 0x1p-52, 0.5},
        {0.1, 0.5, 0.5},     {0.9, 0.5, 0.5},    {1e150, 0.5, 0.5}, {-1e150, 0, 0},
    };
    int8_t want[] = {-1, -1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 1, 1, 1, -1, 1, -1, 1, -1, -1, 1, 1};
    size_t n = sizeof p / sizeof p[0];
    int8_t sg[sizeof want];
    double d[sizeof want];
    hd_error_t err;
    CHECK_RC(signs(&s, &p[0][0], n, sg, d, &err), HD_OK);
    for (size_t i = 0; i < n; i++) {
        CONTEXT("point %zu (%g %g %g)", i, p[i][0], p[i][1], p[i][2]);
        CHECK_EQ(sg[i], want[i]);
        CHECK_EQ(d[i] == 0, want[i] == 0);
    }
    gen_soup_free(&s);
}

TEST(cube_lattice_points_agree_with_the_box) {
    /* Points on a lattice of quarter steps: many lie on the planes, edges
     * and vertices of the cube, and their rays run along edges. */
    gen_soup_t s;
    unit_cube(&s);
    double p[9 * 9 * 9 * 3];
    size_t n = 0;
    for (int i = 0; i < 9; i++)
        for (int j = 0; j < 9; j++)
            for (int k = 0; k < 9; k++, n++) p[3 * n] = i / 4.0 - 0.5, p[3 * n + 1] = j / 4.0 - 0.5, p[3 * n + 2] = k / 4.0 - 0.5;
    int8_t sg[9 * 9 * 9];
    double d[9 * 9 * 9];
    hd_error_t err;
    CHECK_RC(signs(&s, p, n, sg, d, &err), HD_OK);
    for (size_t i = 0; i < n; i++) {
        const double *q = p + 3 * i;
        int in = 1, on = 0;
        for (int c = 0; c < 3; c++) in &= q[c] > 0 && q[c] < 1;
        int closed = q[0] >= 0 && q[0] <= 1 && q[1] >= 0 && q[1] <= 1 && q[2] >= 0 && q[2] <= 1;
        on = closed && !in;
        CONTEXT("point (%g %g %g)", q[0], q[1], q[2]);
        CHECK_EQ(sg[i], on ? 0 : in ? -1 : 1);
    }
    gen_soup_free(&s);
}

TEST(icospheres_match_the_references) {
    for (int bump = 0; bump <= 1; bump++) {
        gen_soup_t s = {0};
        add_sphere(&s, (double[3]){0.1, -0.2, 0.3}, 1.0, 3, bump, 0);
        size_t inside = against_references(&s, 11 + (uint64_t)bump, 4000 / SCALE, -1.5, 1.5, 1e-6);
        CHECK(inside > 0);
        gen_soup_free(&s);
    }
}

TEST(inward_sphere_is_inside_too) {
    /* Consistently oriented inward: the winding number is -1 inside, and
     * the sign is still -1 there. */
    gen_soup_t s = {0};
    add_sphere(&s, (double[3]){0, 0, 0}, 1.0, 2, 0, 1);
    double p[] = {0, 0, 0, 0.3, 0.2, 0.1, 2, 0, 0};
    int8_t sg[3];
    double d[3];
    hd_error_t err;
    CHECK_RC(signs(&s, p, 3, sg, d, &err), HD_OK);
    CHECK_EQ(sg[0], -1);
    CHECK_EQ(sg[1], -1);
    CHECK_EQ(sg[2], 1);
    gen_soup_free(&s);
}

TEST(torus_matches_its_tube) {
    gen_soup_t s;
    torus(&s, 1.0, 0.4, 48, 24);
    gen_rng_t r;
    gen_seed(&r, 5);
    size_t n = 3000 / SCALE;
    double *p = malloc(3 * n * sizeof *p), *d = malloc(n * sizeof *d);
    int8_t *sg = malloc(n);
    gen_cube(&r, p, n, -1.6, 1.6);
    hd_error_t err;
    CHECK_RC(signs(&s, p, n, sg, d, &err), HD_OK);
    size_t inside = 0;
    for (size_t i = 0; i < n; i++) {
        const double *q = p + 3 * i;
        double rho = hypot(q[0], q[1]) - 1.0, tube = hypot(rho, q[2]);
        CONTEXT("seed 5, point %zu (%.17g %.17g %.17g)", i, q[0], q[1], q[2]);
        /* The polygonal tube lies within 0.4 (1 - cos(pi / 24)) < 0.002 of the smooth one, its
         * ring within 1.4 (1 - cos(pi / 48)) < 0.003: compare outside that band. */
        if (tube < 0.38) {
            CHECK_EQ(sg[i], -1);
            inside++;
        }
        if (tube > 0.41) CHECK_EQ(sg[i], 1);
    }
    CHECK(inside > 100 / SCALE);
    free(p), free(d), free(sg);
    against_references(&s, 6, 2000 / SCALE, -1.6, 1.6, 1e-6);
    gen_soup_free(&s);
}

TEST(nested_shells) {
    /* A hollow ball (the inner shell inward: a cavity) and two outward
     * shells (the inner region has winding number 2: inside). */
    for (int cavity = 0; cavity <= 1; cavity++) {
        gen_soup_t s = {0};
        add_sphere(&s, (double[3]){0, 0, 0}, 2.0, 2, 0, 0);
        add_sphere(&s, (double[3]){0.1, 0, 0}, 1.0, 2, 1, cavity);
        double p[] = {0, 0, 0, 0.2, 0.1, -0.3, 1.6, 0, 0, 0, -1.5, 0.2, 3, 0, 0};
        int8_t want[] = {cavity ? 1 : -1, cavity ? 1 : -1, -1, -1, 1};
        int8_t sg[5];
        double d[5];
        hd_error_t err;
        CONTEXT("cavity %d", cavity);
        CHECK_RC(signs(&s, p, 5, sg, d, &err), HD_OK);
        for (int i = 0; i < 5; i++) CHECK_EQ(sg[i], want[i]);
        against_references(&s, 21 + (uint64_t)cavity, 2000 / SCALE, -2.5, 2.5, 1e-6);
        gen_soup_free(&s);
    }
}

TEST(cube_soup_and_signed_zeros_are_one_vertex) {
    /* Every triangle with corners of its own, some zeros negative: the
     * corners merge by value and the mesh is closed. */
    gen_soup_t c, s = {0};
    unit_cube(&c);
    for (size_t k = 0; k < c.nt; k++) {
        uint64_t id[3];
        for (int j = 0; j < 3; j++) {
            const double *v = c.v + 3 * c.t[3 * k + j];
            double x = v[0], y = v[1], z = v[2];
            if (k % 2) x = x == 0 ? -0.0 : x, y = y == 0 ? -0.0 : y;
            id[j] = add_vertex(&s, x, y, z);
        }
        add_tri(&s, id[0], id[1], id[2]);
    }
    double p[] = {0.5, 0.5, 0.5, 1.5, 0.5, 0.5};
    int8_t sg[2];
    double d[2];
    hd_error_t err;
    CHECK_RC(signs(&s, p, 2, sg, d, &err), HD_OK);
    CHECK_EQ(sg[0], -1);
    CHECK_EQ(sg[1], 1);
    gen_soup_free(&c), gen_soup_free(&s);
}

TEST(non_manifold_edge_shared_both_ways_is_closed) {
    /* Two cubes touching along an edge: that edge has four triangles, two
     * each way.  A degenerate triangle with a repeated corner is skipped. */
    gen_soup_t s = {0};
    add_cube(&s, (double[3]){0, 0, 0}, (double[3]){1, 1, 1}, 0);
    add_cube(&s, (double[3]){1, 1, 0}, (double[3]){2, 2, 1}, 0);
    add_tri(&s, 0, 0, 5);
    double p[] = {0.5, 0.5, 0.5, 1.5, 1.5, 0.5, 1.5, 0.5, 0.5, 1, 1, 0.5, 0.5, 1.5, 0.5};
    int8_t want[] = {-1, -1, 1, 0, 1}, sg[5];
    double d[5];
    hd_error_t err;
    CHECK_RC(signs(&s, p, 5, sg, d, &err), HD_OK);
    for (int i = 0; i < 5; i++) CHECK_EQ(sg[i], want[i]);
    gen_soup_free(&s);
}

TEST(open_mesh_is_refused_naming_an_edge) {
    gen_soup_t s;
    unit_cube(&s);
    s.nt--; /* the last triangle (1, 7, 5) gone: edges 1-7, 7-5, 5-1 are boundaries */
    double p[] = {0.5, 0.5, 0.5}, d[1];
    int8_t sg[1] = {42};
    hd_error_t err;
    CHECK_RC(signs(&s, p, 1, sg, d, &err), HD_EINVAL);
    CHECK(strstr(err.message, "not closed") != NULL);
    CHECK(strstr(err.message, "edge between vertices 1 and 7 is used by triangle 10 alone") ||
          strstr(err.message, "edge between vertices 5 and 7 is used by triangle 2 alone") ||
          strstr(err.message, "edge between vertices 1 and 5 is used by triangle 4 alone"));
    CHECK_EQ(sg[0], 42);
    /* The distances alone still work on an open mesh. */
    hd_points_t P = hd_points_f64(p, 1);
    hd_mesh_t M = gen_soup_view(&s);
    CHECK_RC(hd_mesh_distances(&P, &M, NULL, d, NULL, NULL, NULL, NULL, &err), HD_OK);
    gen_soup_free(&s);
}

TEST(flipped_face_is_refused) {
    gen_soup_t s;
    unit_cube(&s);
    uint64_t x = s.t[3 * 4 + 1]; /* triangle 4 reversed */
    s.t[3 * 4 + 1] = s.t[3 * 4 + 2], s.t[3 * 4 + 2] = x;
    double p[] = {0.5, 0.5, 0.5}, d[1];
    int8_t sg[1];
    hd_error_t err;
    CHECK_RC(signs(&s, p, 1, sg, d, &err), HD_EINVAL);
    CHECK(strstr(err.message, "not consistently oriented") != NULL);
    CHECK(strstr(err.message, "triangles 4 and") || strstr(err.message, "and 4 both"));
    gen_soup_free(&s);
}

TEST(bad_meshes_get_the_distance_errors) {
    gen_soup_t s;
    unit_cube(&s);
    s.t[5] = 99;
    double p[] = {0.5, 0.5, 0.5}, d[1];
    int8_t sg[1];
    hd_error_t err;
    CHECK_RC(signs(&s, p, 1, sg, d, &err), HD_EINVAL);
    CHECK(strstr(err.message, "refers to vertex 99") != NULL);
    s.t[5] = 1;
    s.v[4] = NAN;
    CHECK_RC(signs(&s, p, 1, sg, d, &err), HD_ENONFINITE);
    hd_mesh_t M = gen_soup_view(&s);
    CHECK_RC(hd_mesh_signed_distances(NULL, &M, NULL, NULL, NULL, NULL, NULL, sg, NULL, &err), HD_EINVAL);
    gen_soup_free(&s);
}

TEST(float32_vertices_and_u32_indices) {
    gen_soup_t s = {0};
    add_sphere(&s, (double[3]){0, 0, 0}, 1.0, 2, 1, 0);
    float *v = malloc(3 * s.nv * sizeof *v);
    uint32_t *t = malloc(3 * s.nt * sizeof *t);
    for (size_t k = 0; k < 3 * s.nv; k++) v[k] = (float)s.v[k];
    for (size_t k = 0; k < 3 * s.nt; k++) t[k] = (uint32_t)s.t[k];
    hd_mesh_t M = {hd_points_f32(v, s.nv), t, s.nt, HD_INDEX_U32};
    double p[] = {0, 0, 0, 0.5, 0.1, 0, 1.5, 0, 0};
    hd_points_t P = hd_points_f64(p, 3);
    int8_t sg[3];
    hd_error_t err;
    CHECK_RC(hd_mesh_signed_distances(&P, &M, NULL, NULL, NULL, NULL, NULL, sg, NULL, &err), HD_OK);
    CHECK_EQ(sg[0], -1);
    CHECK_EQ(sg[1], -1);
    CHECK_EQ(sg[2], 1);
    free(v), free(t);
    gen_soup_free(&s);
}

TEST(points_on_the_icosphere_vertices_and_edges) {
    /* Every vertex and edge midpoint of a bumpy sphere is on the surface
     * (sign 0); the same points scaled by 1 -/+ 2^-40 are inside/outside. */
    gen_soup_t s = {0};
    add_sphere(&s, (double[3]){0, 0, 0}, 1.0, 1, 1, 0);
    size_t n = 3 * s.nt;
    double *p = malloc(3 * 3 * n * sizeof *p), *d = malloc(3 * n * sizeof *d);
    int8_t *sg = malloc(3 * n);
    for (size_t k = 0; k < n; k++) {
        const double *a = s.v + 3 * s.t[k], *b = s.v + 3 * s.t[k / 3 * 3 + (k + 1) % 3];
        double *q = p + 9 * k;
        for (int c = 0; c < 3; c++) {
            q[c] = k % 2 ? a[c] : (a[c] + b[c]) / 2;
            q[3 + c] = q[c] * (1 - 0x1p-40);
            q[6 + c] = q[c] * (1 + 0x1p-40);
        }
    }
    hd_error_t err;
    CHECK_RC(signs(&s, p, 3 * n, sg, d, &err), HD_OK);
    for (size_t k = 0; k < n; k++) {
        CONTEXT("corner %zu", k);
        if (k % 2) CHECK_EQ(sg[3 * k], 0); /* a vertex: exactly on; a midpoint may round off the edge */
        CHECK_EQ(sg[3 * k + 1], -1);
        CHECK_EQ(sg[3 * k + 2], 1);
    }
    free(p), free(d), free(sg);
    gen_soup_free(&s);
}

/* A bundled model as a soup (copies of its arrays). */
static int read_model(const char *path, gen_soup_t *s) {
    hd_mesh_file_t *m;
    hd_error_t err;
    int rc = hd_read_mesh(path, NULL, &m, &err);
    CHECK_RC(rc, HD_OK);
    if (rc) return rc;
    s->nv = m->n_vertices, s->nt = m->n_triangles;
    s->v = malloc(3 * s->nv * sizeof *s->v);
    s->t = malloc(3 * s->nt * sizeof *s->t);
    memcpy(s->v, m->vertices, 3 * s->nv * sizeof *s->v);
    memcpy(s->t, m->triangles, 3 * s->nt * sizeof *s->t);
    hd_mesh_file_free(m);
    return HD_OK;
}

TEST(bundled_closed_models_match_the_references) {
    const char *files[] = {"data/orig/pinion.off", "data/orig/cow.off", "data/orig/fandisk_large.off"};
    for (int f = 0; f < 3; f++) {
        gen_soup_t s;
        CONTEXT("%s", files[f]);
        if (read_model(files[f], &s)) continue;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t k = 0; k < 3 * s.nv; k++) lo[k % 3] = fmin(lo[k % 3], s.v[k]), hi[k % 3] = fmax(hi[k % 3], s.v[k]);
        size_t inside = against_box(&s, 31 + (uint64_t)f, 600 / SCALE, lo, hi, 1e-9 * (hi[0] - lo[0]));
        CHECK(inside > 0);
        gen_soup_free(&s);
    }
}

TEST(bundled_open_models_are_refused) {
    const char *files[] = {"data/orig/Wuson.stl", "data/orig/stanford_bunny_reduced.ply", "data/orig/lion.off"};
    for (int f = 0; f < 3; f++) {
        gen_soup_t s;
        CONTEXT("%s", files[f]);
        if (read_model(files[f], &s)) continue;
        double p[3] = {0, 0, 0}, d[1];
        int8_t sg[1];
        hd_error_t err;
        CHECK_RC(signs(&s, p, 1, sg, d, &err), HD_EINVAL);
        CHECK(strstr(err.message, "alone (a boundary)") != NULL);
        gen_soup_free(&s);
    }
}

/* The boundary of a random set of unit voxels in a 5^3 grid, outward:
 * voxels touching along an edge only give non-manifold edges (four faces,
 * two each way) and vertices; rays from lattice points run along grid lines
 * through edges and vertices everywhere. */
#define G 5
static void voxels(gen_soup_t *s, const uint8_t *fill) {
    memset(s, 0, sizeof *s);
    for (int z = 0; z <= G; z++)
        for (int y = 0; y <= G; y++)
            for (int x = 0; x <= G; x++) add_vertex(s, x, y, z);
    for (int i = 0; i < G * G * G; i++) {
        if (!fill[i]) continue;
        int c[3] = {i % G, i / G % G, i / (G * G)};
        for (int axis = 0; axis < 3; axis++)
            for (int side = 0; side <= 1; side++) {
                int nb[3] = {c[0], c[1], c[2]};
                nb[axis] += side ? 1 : -1;
                if (nb[axis] >= 0 && nb[axis] < G && fill[nb[0] + G * nb[1] + G * G * nb[2]]) continue;
                int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
                uint64_t q[4];
                for (int k = 0; k < 4; k++) {
                    int v[3] = {c[0], c[1], c[2]};
                    v[axis] += side;
                    v[a1] += k == 1 || k == 2;
                    v[a2] += k >= 2;
                    q[k] = (uint64_t)(v[0] + (G + 1) * v[1] + (G + 1) * (G + 1) * v[2]);
                }
                /* (e_a1) x (e_a2) = e_axis: outward when side = 1. */
                if (side) add_tri(s, q[0], q[1], q[2]), add_tri(s, q[0], q[2], q[3]);
                else add_tri(s, q[0], q[2], q[1]), add_tri(s, q[0], q[3], q[2]);
            }
    }
}

TEST(voxel_solids_on_their_lattice) {
    for (uint64_t seed = 1; seed <= 6; seed++) {
        gen_rng_t r;
        gen_seed(&r, seed);
        uint8_t fill[G * G * G];
        for (int i = 0; i < G * G * G; i++) fill[i] = gen_unit(&r) < 0.45;
        gen_soup_t s;
        voxels(&s, fill);
        if (!s.nt) continue;
        enum { STEPS = 2 * G + 3 };
        double *p = malloc(3 * STEPS * STEPS * STEPS * sizeof *p), *d = malloc(STEPS * STEPS * STEPS * sizeof *d);
        int8_t *sg = malloc(STEPS * STEPS * STEPS);
        size_t n = 0;
        for (int i = 0; i < STEPS; i++)
            for (int j = 0; j < STEPS; j++)
                for (int k = 0; k < STEPS; k++, n++)
                    p[3 * n] = i / 2.0 - 0.5, p[3 * n + 1] = j / 2.0 - 0.5, p[3 * n + 2] = k / 2.0 - 0.5;
        hd_error_t err;
        CONTEXT("seed %llu", (unsigned long long)seed);
        int rc = signs(&s, p, n, sg, d, &err);
        CHECK_RC(rc, HD_OK);
        for (size_t i = 0; i < n && rc == HD_OK; i++) {
            const double *q = p + 3 * i;
            int c[3], in = 1;
            for (int a = 0; a < 3; a++) {
                c[a] = (int)floor(q[a]);
                in &= c[a] >= 0 && c[a] < G;
            }
            int want = d[i] == 0 ? 0 : in && fill[c[0] + G * c[1] + G * G * c[2]] ? -1 : 1;
            CONTEXT("seed %llu, point (%g %g %g)", (unsigned long long)seed, q[0], q[1], q[2]);
            CHECK_EQ(sg[i], want);
        }
        free(p), free(d), free(sg);
        gen_soup_free(&s);
    }
}

TEST(scaled_cubes_far_from_one) {
    /* The filters give up (orient3 overflows near 1e150, products underflow
     * near 1e-300) and the exact path decides; rays run through diagonals
     * and along edges. */
    const double scales[] = {1e150, 0x1p-1000, 3e-300, 1e-170};
    for (int k = 0; k < 4; k++) {
        double x = scales[k];
        gen_soup_t s = {0};
        add_cube(&s, (double[3]){0, 0, 0}, (double[3]){x, x, x}, 0);
        double p[] = {x / 2, x / 2, x / 2, x / 4, x / 2, x / 2, -x, x / 2, x / 2, -x, 0, 0, 2 * x, x / 2, 0,
                      x / 4, x / 4, x / 4, x / 2, x / 2, x, -x, x, x};
        int8_t want[] = {-1, -1, 1, 1, 1, -1, 0, 1}, sg[8];
        double d[8];
        hd_error_t err;
        CONTEXT("scale %g", x);
        CHECK_RC(signs(&s, p, 8, sg, d, &err), HD_OK);
        for (int i = 0; i < 8; i++) CHECK_EQ(sg[i], want[i]);
        gen_soup_free(&s);
    }
}

/* The winding number of the mesh and point with coordinates rotated
 * (x, y, z) -> (y, z, x) `rot` times, or mirrored in x (w changes sign):
 * the same solid, seen along another ray through other degeneracies. */
static long winding_moved(const gen_soup_t *s, const double *p, int rot, int mirror, int *on) {
    hd__wtri_t *w = malloc(s->nt * sizeof *w);
    double q[3];
    for (int c = 0; c < 3; c++) q[c] = p[(c + rot) % 3];
    if (mirror) q[0] = -q[0];
    for (size_t k = 0; k < s->nt; k++)
        for (int j = 0; j < 3; j++) {
            const double *v = s->v + 3 * s->t[3 * k + j];
            w[k].vi[j] = s->t[3 * k + j];
            for (int c = 0; c < 3; c++) w[k].v[j][c] = v[(c + rot) % 3];
            if (mirror) w[k].v[j][0] = -w[k].v[j][0];
        }
    hd__solid_t *S;
    hd_error_t err;
    long r = LONG_MIN;
    if (hd__solid_build(&S, w, s->nt, &err) == HD_OK) {
        r = hd__solid_winding(S, q, on);
        hd__solid_free(S);
    }
    free(w);
    return mirror ? -r : r;
}

TEST(points_a_hair_from_the_surface_agree_along_every_axis) {
    /* Points within a few ulps of faces, edges and vertices, where the
     * solid-angle sum cannot be trusted: the exact count along x, along y
     * and z (rotated) and along -x (mirrored) agree. */
    gen_soup_t meshes[3] = {{0}};
    add_sphere(&meshes[0], (double[3]){0.1, 0.2, 0.3}, 1.0, 1, 1, 0);
    torus(&meshes[1], 1.0, 0.4, 12, 8);
    uint8_t fill[G * G * G];
    gen_rng_t r;
    gen_seed(&r, 77);
    for (int i = 0; i < G * G * G; i++) fill[i] = gen_unit(&r) < 0.45;
    voxels(&meshes[2], fill);
    for (int m = 0; m < 3; m++) {
        const gen_soup_t *s = &meshes[m];
        for (int i = 0; i < 60 / SCALE; i++) {
            size_t t = gen_u64(&r) % s->nt;
            const double *a = s->v + 3 * s->t[3 * t], *b = s->v + 3 * s->t[3 * t + 1], *c = s->v + 3 * s->t[3 * t + 2];
            double u = gen_unit(&r), v = gen_unit(&r), p[3];
            int where = i % 3; /* face, edge, vertex */
            if (where == 1) v = 0;
            if (where == 2) u = v = 0;
            if (u + v > 1) u = 1 - u, v = 1 - v;
            for (int k = 0; k < 3; k++) {
                p[k] = a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]);
                int ulps = (int)(gen_u64(&r) % 5) - 2;
                for (; ulps > 0; ulps--) p[k] = nextafter(p[k], INFINITY);
                for (; ulps < 0; ulps++) p[k] = nextafter(p[k], -INFINITY);
            }
            double d[1];
            int8_t sg[1];
            hd_error_t err;
            CONTEXT("mesh %d, triangle %zu, point (%.17g %.17g %.17g)", m, t, p[0], p[1], p[2]);
            CHECK_RC(signs(s, p, 1, sg, d, &err), HD_OK);
            if (d[0] == 0) {
                CHECK_EQ(sg[0], 0);
                continue;
            }
            int on;
            long w0 = winding_moved(s, p, 0, 0, &on);
            CHECK_EQ(on, 0);
            CHECK_EQ(sg[0], w0 != 0 ? -1 : 1);
            for (int rot = 1; rot < 3; rot++) CHECK_EQ(winding_moved(s, p, rot, 0, &on), w0);
            CHECK_EQ(winding_moved(s, p, 0, 1, &on), w0);
            CHECK(w0 == 0 || w0 == 1);
        }
    }
    for (int m = 0; m < 3; m++) gen_soup_free(&meshes[m]);
}
