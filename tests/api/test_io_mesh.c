/*
 * test_io_mesh.c -- meshes read as vertices or as points sampled on their
 * faces: reproducible for a seed, on the surface, proportional to area, the
 * same from every mesh format, and refused with a reason when impossible.
 */
#include "check.h"
#include "files.h"
#include "gen.h"

#include <math.h>
#include <stdlib.h>

static hd_read_options_t sampling(size_t n, uint64_t seed) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.mesh = HD_MESH_SAMPLE;
    o.sample = n;
    o.seed = seed;
    return o;
}

static hd_cloud_t *read_with(const char *path, const hd_read_options_t *o) {
    hd_cloud_t *c = NULL;
    hd_error_t e;
    int rc = hd_read_file(path, o, &c, &e);
    if (rc != HD_OK) hdt_fail(__FILE__, __LINE__, "reading %s: %s: %s", path, hd_err_name(rc), e.message);
    return c;
}

static int same(const hd_cloud_t *a, const hd_cloud_t *b) {
    return a && b && a->count == b->count && memcmp(a->data, b->data, a->count * 24) == 0;
}

/* A unit square in z = 0 as two triangles (0,1,2) and (0,2,3), and a
 * triangle of area 3/2 at x in [2, 5]. */
static const double square[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}};

static const char *square_obj(void) {
    return tf_printf("square.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
}

TEST(sampling_is_reproducible_for_a_seed_and_differs_across_seeds) {
    const char *p = square_obj();
    hd_read_options_t o1 = sampling(500, 42), o2 = sampling(500, 42), o3 = sampling(500, 43);
    CONTEXT("seeds 42, 42, 43");
    hd_cloud_t *a = read_with(p, &o1), *b = read_with(p, &o2), *c = read_with(p, &o3);
    CHECK(a && a->count == 500);
    CHECK(same(a, b));
    CHECK(!same(a, c));
    hd_cloud_free(a);
    hd_cloud_free(b);
    hd_cloud_free(c);
}

TEST(sampled_points_lie_on_the_faces_and_cover_them) {
    hd_read_options_t o = sampling(4000, 7);
    CONTEXT("seed 7");
    hd_cloud_t *c = read_with(square_obj(), &o);
    if (!c) return;
    const double *p = c->data;
    int quadrant[4] = {0, 0, 0, 0};
    for (size_t k = 0; k < c->count; k++) {
        CHECK(p[3 * k + 2] == 0.0);
        CHECK(p[3 * k] >= 0 && p[3 * k] <= 1 + 1e-15 && p[3 * k + 1] >= 0 && p[3 * k + 1] <= 1 + 1e-15);
        quadrant[(p[3 * k] >= 0.5) + 2 * (p[3 * k + 1] >= 0.5)]++;
    }
    for (int q = 0; q < 4; q++) CHECK(quadrant[q] > 800 && quadrant[q] < 1200); /* about 1000 each */
    hd_cloud_free(c);
}

TEST(sampling_chooses_faces_in_proportion_to_their_area) {
    /* triangle A area 1/2, triangle B area 3/2 (and a zero-area one) */
    const char *p = tf_printf("areas.off", "OFF\n6 3 0\n0 0 0\n1 0 0\n0 1 0\n2 0 0\n5 0 0\n2 1 0\n"
                                           "3 0 1 2\n3 3 4 5\n3 0 1 1\n");
    hd_read_options_t o = sampling(40000, 5);
    CONTEXT("seed 5");
    hd_cloud_t *c = read_with(p, &o);
    if (!c) return;
    size_t in_b = 0;
    for (size_t k = 0; k < c->count; k++) in_b += ((const double *)c->data)[3 * k] >= 2;
    /* expected 30000; the binomial standard deviation is about 87 */
    CHECK(in_b > 29500 && in_b < 30500);
    hd_cloud_free(c);
}

TEST(the_same_mesh_in_obj_off_ply_and_stl_gives_the_same_samples) {
    const char *obj = tf_printf("m.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 # first\nf 1 3 4\nf 2 5 3\n");
    const char *off = tf_printf("m.off", "OFF\n5 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n3 0 1 2\n3 0 2 3\n3 1 4 2\n");
    const char *ply = tf_printf("m.ply", "ply\nformat ascii 1.0\nelement vertex 5\nproperty double x\nproperty double y\n"
                                         "property double z\nelement face 3\nproperty list uchar uint vertex_indices\nend_header\n"
                                         "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n3 0 1 2\n3 0 2 3\n3 1 4 2\n");
    tf_buf_t b = {0}, s = {0};
    char h[80] = "binary";
    tf_put(&b, h, 80);
    tf_u32(&b, 3, 0);
    static const int tri[3][3] = {{0, 1, 2}, {0, 2, 3}, {1, 4, 2}};
    tf_puts(&s, "solid m\n");
    for (int t = 0; t < 3; t++) {
        for (int d = 0; d < 3; d++) tf_f32(&b, 0, 0);
        tf_puts(&s, "facet normal 0 0 1\nouter loop\n");
        for (int v = 0; v < 3; v++) {
            for (int d = 0; d < 3; d++) tf_f32(&b, (float)square[tri[t][v]][d], 0);
            tf_putf(&s, "vertex %g %g %g\n", square[tri[t][v]][0], square[tri[t][v]][1], square[tri[t][v]][2]);
        }
        tf_u16(&b, 0, 0);
        tf_puts(&s, "endloop\nendfacet\n");
    }
    tf_puts(&s, "endsolid m\n");
    const char *stl = tf_write("m.stl", b.data, b.size);
    const char *astl = tf_write("ascii.stl", s.data, s.size);
    tf_free(&b);
    tf_free(&s);
    hd_read_options_t o = sampling(300, 11);
    CONTEXT("seed 11");
    hd_cloud_t *c[5] = {read_with(obj, &o), read_with(off, &o), read_with(ply, &o), read_with(stl, &o), read_with(astl, &o)};
    for (int k = 1; k < 5; k++) CHECK(same(c[0], c[k]));
    for (int k = 0; k < 5; k++) hd_cloud_free(c[k]);
}

TEST(binary_ply_faces_are_sampled_like_ascii_ply_faces) {
    const char *ascii = tf_printf("a.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                           "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                           "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
    tf_buf_t b = {0};
    tf_puts(&b, "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n");
    for (int v = 0; v < 4; v++)
        for (int d = 0; d < 3; d++) tf_f32(&b, (float)square[v][d], 1);
    tf_u8(&b, 4);
    for (int v = 0; v < 4; v++) tf_u32(&b, (uint32_t)v, 1);
    const char *bin = tf_write("b.ply", b.data, b.size);
    tf_free(&b);
    hd_read_options_t o = sampling(100, 3);
    CONTEXT("seed 3");
    hd_cloud_t *x = read_with(ascii, &o), *y = read_with(bin, &o), *z = read_with(square_obj(), &o);
    CHECK(same(x, y));
    CHECK(same(x, z));
    hd_cloud_free(x);
    hd_cloud_free(y);
    hd_cloud_free(z);
}

TEST(obj_relative_face_references_resolve_across_parallel_chunks) {
    /* about 3 MB of a triangle strip, once with absolute and once with
     * relative (negative) references: identical samples */
    size_t n = 60000;
    gen_rng_t r;
    gen_seed(&r, 21);
    CONTEXT("seed 21");
    tf_buf_t a = {0}, b = {0};
    for (size_t k = 0; k < n; k++) {
        double x = (double)k, y = (double)(k % 2), z = gen_unit(&r);
        tf_putf(&a, "v %.17g %.17g %.17g\n", x, y, z);
        tf_putf(&b, "v %.17g %.17g %.17g\n", x, y, z);
        if (k >= 2) {
            tf_putf(&a, "f %zu %zu %zu\n", k - 1, k, k + 1);
            tf_puts(&b, "f -3 -2 -1\n");
        }
    }
    const char *pa = tf_write("abs.obj", a.data, a.size), *pb = tf_write("rel.obj", b.data, b.size);
    tf_free(&a);
    tf_free(&b);
    hd_read_options_t o = sampling(5000, 9);
    for (int threads = 1; threads <= 4; threads *= 2) {
        o.threads = threads;
        hd_cloud_t *x = read_with(pa, &o), *y = read_with(pb, &o);
        CHECK(same(x, y));
        if (x) CHECK_EQ(x->n_faces, n - 2);
        hd_cloud_free(x);
        hd_cloud_free(y);
    }
}

TEST(float32_storage_of_samples_rounds_the_double_samples) {
    hd_read_options_t o = sampling(200, 1), of = sampling(200, 1);
    of.dtype = HD_FLOAT32;
    hd_cloud_t *d = read_with(square_obj(), &o), *f = read_with(square_obj(), &of);
    if (d && f) {
        CHECK_EQ(f->dtype, HD_FLOAT32);
        for (size_t k = 0; k < 600; k++) CHECK(((float *)f->data)[k] == (float)((double *)d->data)[k]);
    }
    hd_cloud_free(d);
    hd_cloud_free(f);
}

static void check_refused(const char *path, const hd_read_options_t *o, int code, const char *needle, long long line) {
    hd_cloud_t *c = NULL;
    hd_error_t e;
    CHECK_RC(hd_read_file(path, o, &c, &e), code);
    CHECK(c == NULL);
    if (!strstr(e.message, needle)) hdt_fail(__FILE__, __LINE__, "message '%s' lacks '%s'", e.message, needle);
    if (line) CHECK_EQ(e.line, line);
}

TEST(a_format_without_faces_is_read_as_its_points_under_sampling) {
    /* a mesh compared with a scan under one --sample: the scan keeps its points */
    hd_read_options_t o = sampling(10, 1), v;
    hd_read_options_init(&v);
    const char *files[] = {tf_printf("p.xyz", "1 2 3\n4 5 6\n"), "data/derived/pinion_gear_c_f8.npy",
                           "data/derived/pinion_gear_binary.pcd"};
    for (int k = 0; k < 3; k++) {
        CONTEXT("%s", files[k]);
        hd_cloud_t *sampled = read_with(files[k], &o), *points = read_with(files[k], &v);
        CHECK(same(sampled, points));
        CHECK_EQ(sampled->n_faces, 0);
        hd_cloud_free(sampled);
        hd_cloud_free(points);
    }
    uint64_t n = 0; /* and its count is still its header's, for a process's range */
    hd_error_t e;
    CHECK_RC(hd_read_count("data/derived/pinion_gear_c_f8.npy", &o, &n, &e), HD_OK);
    CHECK_EQ(n, 650);
}

TEST(sampling_is_refused_without_faces_or_points_or_with_bad_indices) {
    hd_read_options_t o = sampling(10, 1);
    check_refused(tf_printf("noface.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                                          "property float z\nend_header\n1 2 3\n"),
                  &o, HD_EFORMAT, "no faces to sample", 0);
    check_refused(tf_printf("nofaces.obj", "v 1 2 3\nv 4 5 6\n"), &o, HD_EFORMAT, "no faces to sample", 0);
    check_refused(tf_printf("flat.obj", "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n"), &o, HD_EFORMAT, "no area", 0);
    check_refused(tf_printf("range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), &o, HD_EFORMAT, "refers to vertex 3", 6);
    check_refused(tf_printf("range.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                         "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                         "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
                  &o, HD_EFORMAT, "refers to vertex 7", 13);
    check_refused(tf_printf("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 -4\n"), &o, HD_EFORMAT, "refers to vertex -4", 5);
    check_refused(tf_printf("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), &o, HD_EFORMAT, "not a vertex reference", 4);
    o.sample = 0;
    check_refused(square_obj(), &o, HD_EINVAL, "positive number", 0);
}
