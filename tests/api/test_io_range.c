/*
 * test_io_range.c -- reading part of a file (hd_read_options_t.range_first
 * and range_count) and its count from the header (hd_read_count), which
 * let processes split one big file between them (hausdorff-mpi).
 *
 * The specification: a range read gives exactly the slice of the whole
 * read, bit for bit, in every format (the binary ones skip the rest, the
 * others read whole and cut); a range past the end is HD_ERANGE naming
 * both numbers; hd_read_count equals the whole read's count where it
 * answers, and refuses (HD_EUNSUPPORTED) where only a whole read can know.
 */
#include "check.h"
#include "files.h"

#include <stdlib.h>
#include <string.h>

/* not collinear, so that triangles of them have area */
static double coord(size_t k, int c) { return (double)((k * k * (size_t)(c + 1) + k) % 13) * 0.25 - 1.5 + c; }

/* n points as binary little-endian PLY of floats, with an extra property
 * between y and z so the record is not 12 bytes. */
static const char *ply_binary(const char *name, size_t n) {
    tf_buf_t b = {0};
    tf_putf(&b, "ply\nformat binary_little_endian 1.0\nelement vertex %zu\nproperty float x\nproperty float y\n"
                "property uchar q\nproperty float z\nend_header\n", n);
    for (size_t k = 0; k < n; k++) {
        tf_f32(&b, (float)coord(k, 0), 0);
        tf_f32(&b, (float)coord(k, 1), 0);
        tf_u8(&b, 7);
        tf_f32(&b, (float)coord(k, 2), 0);
    }
    return tf_finish(&b, name);
}

static const char *npy_f8(const char *name, size_t n) {
    tf_buf_t b = {0};
    char dict[128];
    int len = snprintf(dict, sizeof dict, "{'descr': '<f8', 'fortran_order': False, 'shape': (%zu, 3), }", n);
    size_t total = 10 + (size_t)len + 1, pad = (64 - total % 64) % 64;
    tf_put(&b, "\x93NUMPY\x01\x00", 8);
    tf_u16(&b, (unsigned)(len + 1 + pad), 0);
    tf_put(&b, dict, (size_t)len);
    for (size_t k = 0; k < pad; k++) tf_u8(&b, ' ');
    tf_u8(&b, '\n');
    for (size_t k = 0; k < n; k++)
        for (int c = 0; c < 3; c++) tf_f64(&b, coord(k, c), 0);
    return tf_finish(&b, name);
}

/* Binary STL of t triangles: 3t points, three to a 50-byte record. */
static const char *stl_binary(const char *name, size_t t) {
    tf_buf_t b = {0};
    char h[80];
    memset(h, ' ', sizeof h);
    tf_put(&b, h, 80);
    tf_u32(&b, (uint32_t)t, 0);
    for (size_t k = 0; k < t; k++) {
        for (int c = 0; c < 3; c++) tf_f32(&b, 0, 0);
        for (size_t v = 0; v < 3; v++)
            for (int c = 0; c < 3; c++) tf_f32(&b, (float)coord(3 * k + v, c), 0);
        tf_u16(&b, 0, 0);
    }
    return tf_finish(&b, name);
}

static const char *xyz_text(const char *name, size_t n) {
    tf_buf_t b = {0};
    for (size_t k = 0; k < n; k++) tf_putf(&b, "%.17g %.17g %.17g\n", coord(k, 0), coord(k, 1), coord(k, 2));
    return tf_finish(&b, name);
}

static hd_cloud_t *read_range(const char *path, uint64_t first, uint64_t count, int *rc, hd_error_t *e) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.range_first = first;
    o.range_count = count;
    hd_cloud_t *c = NULL;
    *rc = hd_read_file(path, &o, &c, e);
    return c;
}

/* Every range [f, f + m) of a file of n points, m > 0, read alone, is the
 * slice of the whole read, bit for bit. */
static void every_range_is_the_slice(const char *path, size_t n) {
    CONTEXT("%s", path);
    hd_cloud_t *whole = NULL;
    hd_error_t e;
    CHECK_RC(hd_read_file(path, NULL, &whole, &e), HD_OK);
    if (!whole) return;
    CHECK_EQ(whole->count, n);
    const double *w = whole->data;
    for (size_t f = 0; f < n; f++)
        for (size_t m = 1; f + m <= n; m++) {
            int rc;
            hd_cloud_t *part = read_range(path, f, m, &rc, &e);
            CHECK_RC(rc, HD_OK);
            if (!part) continue;
            CHECK_EQ(part->count, m);
            if (part->count == m) CHECK(memcmp(part->data, w + 3 * f, m * 3 * sizeof(double)) == 0);
            hd_cloud_free(part);
        }
    hd_cloud_free(whole);
}

TEST(a_range_of_ply_npy_stl_and_text_is_the_slice_of_the_whole_read) {
    every_range_is_the_slice(ply_binary("r.ply", 9), 9);
    every_range_is_the_slice(npy_f8("r.npy", 9), 9);
    every_range_is_the_slice(stl_binary("r.stl", 3), 9);
    every_range_is_the_slice(xyz_text("r.xyz", 9), 9);
}

TEST(a_range_of_las_and_of_laz_across_chunks_is_the_slice_of_the_whole_read) {
    /* the LAZ files have chunks of a few points: ranges start and end
     * inside chunks, cover whole ones, and skip some */
    static const char *const files[] = {"tests/corpus/las/v14_fmt6.las", "tests/corpus/laz/fmt0_chunks16.laz",
                                        "tests/corpus/laz/fmt1_variable.laz", "tests/corpus/laz/fmt6_channels.laz"};
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        uint64_t n = 0;
        hd_error_t e;
        CONTEXT("%s", files[k]);
        CHECK_RC(hd_read_count(files[k], NULL, &n, &e), HD_OK);
        CHECK(n > 0);
        if (n > 80) n = 80; /* the quadratic sweep over a prefix: the count itself is checked below */
        hd_cloud_t *whole = NULL;
        CHECK_RC(hd_read_file(files[k], NULL, &whole, &e), HD_OK);
        if (!whole) continue;
        const double *w = whole->data;
        for (uint64_t f = 0; f < n; f += 3)
            for (uint64_t m = 1; f + m <= whole->count; m += 1 + m / 2) {
                int rc;
                hd_cloud_t *part = read_range(files[k], f, m, &rc, &e);
                CHECK_RC(rc, HD_OK);
                if (!part) continue;
                CHECK_EQ(part->count, (size_t)m);
                if (part->count == m) CHECK(memcmp(part->data, w + 3 * f, (size_t)m * 3 * sizeof(double)) == 0);
                hd_cloud_free(part);
            }
        hd_cloud_free(whole);
    }
}

TEST(a_range_of_a_sampled_mesh_is_the_slice_of_the_samples) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.mesh = HD_MESH_SAMPLE;
    o.sample = 50;
    o.seed = 11;
    const char *path = stl_binary("s.stl", 4);
    hd_cloud_t *whole = NULL, *part = NULL;
    hd_error_t e;
    CHECK_RC(hd_read_file(path, &o, &whole, &e), HD_OK);
    o.range_first = 20;
    o.range_count = 25;
    CHECK_RC(hd_read_file(path, &o, &part, &e), HD_OK);
    if (whole && part) {
        CHECK_EQ(part->count, (size_t)25);
        CHECK(memcmp(part->data, (const double *)whole->data + 60, 25 * 3 * sizeof(double)) == 0);
    }
    hd_cloud_free(whole);
    hd_cloud_free(part);
}

TEST(a_range_past_the_end_is_erange_naming_both_numbers) {
    const char *files[] = {npy_f8("e.npy", 5), xyz_text("e.xyz", 5), "tests/corpus/laz/fmt0_chunks16.laz"};
    uint64_t n[] = {5, 5, 0};
    hd_error_t e;
    CHECK_RC(hd_read_count(files[2], NULL, &n[2], &e), HD_OK);
    for (int k = 0; k < 3; k++) {
        CONTEXT("%s", files[k]);
        int rc;
        hd_cloud_t *c = read_range(files[k], n[k] - 1, 2, &rc, &e);
        CHECK_RC(rc, HD_ERANGE);
        CHECK(c == NULL);
        char want[96];
        snprintf(want, sizeof want, "points [%llu, %llu) asked of a file of %llu points", (unsigned long long)(n[k] - 1),
                 (unsigned long long)(n[k] + 1), (unsigned long long)n[k]);
        if (!strstr(e.message, want)) hdt_fail(__FILE__, __LINE__, "message '%s' lacks '%s'", e.message, want);
        if (strncmp(e.message, files[k], strlen(files[k])) != 0)
            hdt_fail(__FILE__, __LINE__, "message '%s' does not start with the file name", e.message);
        c = read_range(files[k], n[k], 1, &rc, &e);
        CHECK_RC(rc, HD_ERANGE);
    }
}

TEST(a_range_start_without_a_count_or_that_overflows_is_einval) {
    const char *path = npy_f8("i.npy", 5);
    int rc;
    hd_error_t e;
    CHECK(read_range(path, 2, 0, &rc, &e) == NULL);
    CHECK_RC(rc, HD_EINVAL);
    CHECK(read_range(path, UINT64_MAX, 2, &rc, &e) == NULL);
    CHECK_RC(rc, HD_EINVAL);
}

TEST(a_bad_point_inside_the_range_is_reported_with_its_file_index_and_offset) {
    tf_buf_t b = {0};
    tf_puts(&b, "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
                "property double z\nend_header\n");
    size_t head = b.size;
    for (int k = 0; k < 12; k++) tf_f64(&b, k == 7 ? 0.0 / 0.0 : k, 0);
    const char *path = tf_write("nan.ply", b.data, b.size);
    tf_free(&b);
    int rc;
    hd_error_t e;
    hd_cloud_t *c = read_range(path, 0, 2, &rc, &e); /* points 0 and 1: clean */
    CHECK_RC(rc, HD_OK);
    hd_cloud_free(c);
    CHECK(read_range(path, 1, 2, &rc, &e) == NULL); /* point 2 holds the NaN (its y) */
    CHECK_RC(rc, HD_ENONFINITE);
    CHECK_EQ(e.offset, (long long)(head + 7 * 8));
    if (!strstr(e.message, "point 2:")) hdt_fail(__FILE__, __LINE__, "message '%s' lacks 'point 2:'", e.message);
}

TEST(count_from_the_header_equals_the_whole_read) {
    const char *files[] = {ply_binary("c.ply", 7), npy_f8("c.npy", 7), stl_binary("c.stl", 3),
                           "tests/corpus/las/v12_fmt0.las", "tests/corpus/laz/fmt3_extra2.laz"};
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        CONTEXT("%s", files[k]);
        uint64_t n = 12345;
        hd_cloud_t *c = NULL;
        hd_error_t e;
        CHECK_RC(hd_read_count(files[k], NULL, &n, &e), HD_OK);
        CHECK_RC(hd_read_file(files[k], NULL, &c, &e), HD_OK);
        if (c) CHECK_EQ(n, (uint64_t)c->count);
        hd_cloud_free(c);
    }
}

TEST(count_is_refused_where_only_a_whole_read_knows_it) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    const char *files[] = {xyz_text("u.xyz", 3), tf_printf("u.obj", "v 0 0 0\nv 1 0 0\n"),
                           tf_printf("u.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                              "property float y\nproperty float z\nend_header\n1 2 3\n"),
                           "-"};
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        CONTEXT("%s", files[k]);
        uint64_t n = 5;
        hd_error_t e;
        CHECK_RC(hd_read_count(files[k], &o, &n, &e), HD_EUNSUPPORTED);
        CHECK_EQ(n, (uint64_t)0);
        if (!strstr(e.message, "needs reading")) hdt_fail(__FILE__, __LINE__, "message '%s'", e.message);
    }
    o.mesh = HD_MESH_SAMPLE;
    o.sample = 10;
    uint64_t n;
    hd_error_t e;
    CHECK_RC(hd_read_count(stl_binary("m.stl", 2), &o, &n, &e), HD_EUNSUPPORTED);
}
