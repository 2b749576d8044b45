/*
 * test_readers.c -- every reader gives back exactly the coordinates that
 * were written, for every format variant, and the bundled models read from
 * their original formats are bit-identical to their PLY copies.
 *
 * Generated files come from seeded point sets (CONTEXT shows the seed)
 * written with 17 significant digits (text) or raw bytes (binary), so the
 * expected coordinates are known exactly; distances are compared with the
 * independent brute force of tests/support/brute.c bit for bit.
 */
#include "brute.h"
#include "check.h"
#include "files.h"
#include "gen.h"

#include <math.h>
#include <stdlib.h>

/* ---- helpers ------------------------------------------------------------ */

static hd_cloud_t *read_with(const char *path, const hd_read_options_t *o) {
    hd_cloud_t *c = NULL;
    hd_error_t e;
    int rc = hd_read_file(path, o, &c, &e);
    if (rc != HD_OK) {
        hdt_fail(__FILE__, __LINE__, "reading %s: %s: %s", path, hd_err_name(rc), e.message);
        return NULL;
    }
    return c;
}

static hd_cloud_t *read_ok(const char *path) { return read_with(path, NULL); }

/* The cloud holds exactly n points equal bit for bit to xyz (widened). */
static void check_points(const hd_cloud_t *c, const double *xyz, size_t n) {
    if (!c) return;
    CHECK_EQ(c->count, n);
    if (c->count != n) return;
    hd_points_t p = hd_cloud_points(c);
    for (size_t k = 0; k < n && !hdt_failed(); k++) {
        double q[3];
        hd_points_get(&p, k, q);
        for (int d = 0; d < 3; d++) CHECK_BITS(q[d], xyz[3 * k + d]);
    }
}

/* Two clouds hold the same points in the same order, bit for bit. */
static void check_same(const hd_cloud_t *a, const hd_cloud_t *b) {
    if (!a || !b) return;
    CHECK_EQ(a->count, b->count);
    CHECK_EQ(a->dtype, b->dtype);
    if (a->count == b->count && a->dtype == b->dtype)
        CHECK(memcmp(a->data, b->data, a->count * (a->dtype == HD_FLOAT32 ? 12 : 24)) == 0);
}

static void check_files_same(const char *a, const char *b) {
    CONTEXT("%s vs %s", a, b);
    hd_cloud_t *ca = read_ok(a), *cb = read_ok(b);
    check_same(ca, cb);
    hd_cloud_free(ca);
    hd_cloud_free(cb);
}

static double *points(uint64_t seed, size_t n, double lo, double hi) {
    double *xyz = malloc(3 * n * sizeof *xyz);
    gen_rng_t r;
    gen_seed(&r, seed);
    gen_cube(&r, xyz, n, lo, hi);
    return xyz;
}

/* Round each coordinate to float (what a float32 field holds). */
static void to_float(double *xyz, size_t n) {
    for (size_t k = 0; k < 3 * n; k++) xyz[k] = (double)(float)xyz[k];
}

/* ---- bundled models ------------------------------------------------------ */

TEST(bundled_off_models_equal_their_ply_copies) {
    static const char *const pairs[][2] = {
        {"data/orig/lion.off", "data/cgal_lion.ply"},       {"data/orig/lion-head.off", "data/cgal_lion_head.ply"},
        {"data/orig/armadillo.off", "data/armadillo.ply"},  {"data/orig/cow.off", "data/cow.ply"},
        {"data/orig/pinion.off", "data/pinion_gear.ply"},   {"data/orig/fandisk_large.off", "data/fandisk_large.ply"}};
    for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; k++) check_files_same(pairs[k][0], pairs[k][1]);
}

TEST(bundled_obj_stl_binary_ply_and_las_equal_their_ply_copies) {
    check_files_same("data/orig/WusonOBJ.obj", "data/wuson_obj.ply");
    check_files_same("data/orig/Wuson.stl", "data/wuson_stl.ply");
    check_files_same("data/orig/stanford_bunny_reduced.ply", "data/bunny_3511.ply");
    check_files_same("data/orig/Haystack_Rock.las", "data/haystack_rock.ply");
}

TEST(bundled_mesh_face_counts_are_reported) {
    hd_cloud_t *c = read_ok("data/orig/lion.off");
    if (c) CHECK_EQ(c->n_faces, 14859);
    hd_cloud_free(c);
    c = read_ok("data/orig/WusonOBJ.obj");
    if (c) CHECK_EQ(c->n_faces, 3732);
    hd_cloud_free(c);
    c = read_ok("data/orig/Wuson.stl");
    if (c) CHECK_EQ(c->n_faces, 3732);
    hd_cloud_free(c);
    c = read_ok("data/orig/stanford_bunny_reduced.ply");
    if (c) CHECK_EQ(c->n_faces, 6945);
    hd_cloud_free(c);
}

static double directed_files(const char *a, const char *b) {
    hd_cloud_t *ca = read_ok(a), *cb = read_ok(b);
    double d = -1;
    if (ca && cb) {
        brute_t br = brute_directed(ca->data, ca->count, cb->data, cb->count);
        hd_points_t A = hd_cloud_points(ca), B = hd_cloud_points(cb);
        hd_result_t r;
        CHECK_RC(hd_directed(&A, &B, NULL, &r, NULL), HD_OK);
        CHECK_BITS(r.distance2, br.d2);
        d = sqrt(br.d2);
    }
    hd_cloud_free(ca);
    hd_cloud_free(cb);
    return d;
}

TEST(readme_reference_distances_hold_to_the_bit_from_every_format) {
    CHECK_BITS(directed_files("data/cgal_lion.ply", "data/cgal_lion_head.ply"), 0.0);
    CHECK_BITS(directed_files("data/cgal_lion_head.ply", "data/cgal_lion.ply"), 0.14468150162771326);
    CHECK_BITS(directed_files("data/orig/lion-head.off", "data/orig/lion.off"), 0.14468150162771326);
    CHECK_BITS(directed_files("data/orig/lion.off", "data/cgal_lion.ply"), 0.0);
    CHECK_BITS(directed_files("data/cgal_lion.ply", "data/orig/lion.off"), 0.0);
    double ab = directed_files("data/orig/WusonOBJ.obj", "data/orig/Wuson.stl");
    double ba = directed_files("data/orig/Wuson.stl", "data/orig/WusonOBJ.obj");
    CHECK_BITS(ab > ba ? ab : ba, 7.8208679782962498e-08);
}

TEST(pcl_written_pcd_in_three_encodings_equals_the_ply) {
    check_files_same("data/derived/pinion_gear_ascii.pcd", "data/pinion_gear.ply");
    check_files_same("data/derived/pinion_gear_binary.pcd", "data/pinion_gear.ply");
    check_files_same("data/derived/pinion_gear_compressed.pcd", "data/pinion_gear.ply");
}

TEST(numpy_written_npy_in_c_and_big_endian_fortran_order_equals_the_ply) {
    check_files_same("data/derived/pinion_gear_c_f8.npy", "data/pinion_gear.ply");
    check_files_same("data/derived/pinion_gear_fortran_be_f8.npy", "data/pinion_gear.ply");
}

TEST(float32_npy_equals_the_ply_stored_as_float32) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.dtype = HD_FLOAT32;
    hd_cloud_t *a = read_with("data/derived/pinion_gear_f4.npy", &o), *b = read_with("data/pinion_gear.ply", &o);
    check_same(a, b);
    hd_cloud_free(a);
    hd_cloud_free(b);
}

/* ---- PLY ------------------------------------------------------------------- */

static const char *const ply_types[] = {"char", "uchar", "short", "ushort", "int", "uint", "float", "double",
                                        "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};

/* Value v as PLY type t (integers are written exactly; v must fit). */
static void ply_put(tf_buf_t *b, const char *t, double v, int fmt) {
    int big = fmt == 2;
    if (fmt == 0) {
        tf_putf(b, "%.17g ", v);
        return;
    }
    if (!strcmp(t, "char") || !strcmp(t, "int8") || !strcmp(t, "uchar") || !strcmp(t, "uint8")) tf_u8(b, (unsigned)(int)v & 255);
    else if (strstr(t, "short") || strstr(t, "16")) tf_u16(b, (unsigned)(int)v & 0xffff, big);
    else if (!strcmp(t, "int") || !strcmp(t, "uint") || strstr(t, "int32")) tf_u32(b, (uint32_t)(int64_t)v, big);
    else if (!strcmp(t, "float") || !strcmp(t, "float32")) tf_f32(b, (float)v, big);
    else tf_f64(b, v, big);
}

/* Values representable in type t: integers within its range, floats
 * rounded to float for float fields. */
static double ply_value(const char *t, gen_rng_t *r) {
    double u = gen_unit(r);
    int is_unsigned = t[0] == 'u';
    if (strstr(t, "char") || (strstr(t, "8") && !strstr(t, "float"))) return floor(u * 255) - (is_unsigned ? 0 : 128);
    if (strstr(t, "short") || strstr(t, "16")) return floor(u * 65535) - (is_unsigned ? 0 : 32768);
    if (!strcmp(t, "int") || !strcmp(t, "uint") || strstr(t, "int32")) return floor(u * 4294967295.0) - (is_unsigned ? 0 : 2147483648.0);
    if (!strcmp(t, "float") || !strcmp(t, "float32")) return (double)(float)(u * 200 - 100);
    return u * 200 - 100;
}

TEST(ply_reads_x_y_z_of_every_type_in_ascii_and_both_byte_orders) {
    static const char *const fmts[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    size_t n = 50, nt = sizeof ply_types / sizeof ply_types[0];
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (int fmt = 0; fmt < 3; fmt++)
        for (size_t t = 0; t < nt; t++) {
            const char *tx = ply_types[t], *ty = ply_types[(t + 3) % nt], *tz = ply_types[(t + 7) % nt];
            CONTEXT("format %s, types %s %s %s, seed %zu", fmts[fmt], tx, ty, tz, t);
            gen_rng_t r;
            gen_seed(&r, t);
            tf_buf_t b = {0};
            /* an element before the vertices, extra scalar and list
             * properties around x y z, comments, obj_info, faces after */
            tf_putf(&b, "ply\nformat %s 1.0\ncomment made by test_readers\nobj_info nothing\n"
                        "element camera 2\nproperty float view\nproperty list uchar int ids\n"
                        "element vertex %zu\nproperty uchar red\nproperty %s x\nproperty list ushort float normals\n"
                        "property %s y\nproperty double w\nproperty %s z\nproperty list uint8 uint skip\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n",
                    fmts[fmt], n, tx, ty, tz);
            for (int cam = 0; cam < 2; cam++) {
                ply_put(&b, "float", 1.5, fmt);
                ply_put(&b, "uchar", 2, fmt);
                ply_put(&b, "int", 7, fmt);
                ply_put(&b, "int", 8, fmt);
                if (fmt == 0) tf_puts(&b, "\n");
            }
            for (size_t k = 0; k < n; k++) {
                xyz[3 * k] = ply_value(tx, &r);
                xyz[3 * k + 1] = ply_value(ty, &r);
                xyz[3 * k + 2] = ply_value(tz, &r);
                ply_put(&b, "uchar", 255, fmt);
                ply_put(&b, tx, xyz[3 * k], fmt);
                ply_put(&b, "ushort", 3, fmt);
                for (int j = 0; j < 3; j++) ply_put(&b, "float", 0.5, fmt);
                ply_put(&b, ty, xyz[3 * k + 1], fmt);
                ply_put(&b, "double", -1, fmt);
                ply_put(&b, tz, xyz[3 * k + 2], fmt);
                ply_put(&b, "uint8", 0, fmt);
                if (fmt == 0) tf_puts(&b, "\n");
            }
            ply_put(&b, "uchar", 3, fmt);
            for (int j = 0; j < 3; j++) ply_put(&b, "int", j, fmt);
            if (fmt == 0) tf_puts(&b, "\n");
            hd_cloud_t *c = read_ok(tf_write("types.ply", b.data, b.size));
            check_points(c, xyz, n);
            if (c) CHECK_EQ(c->n_faces, 1);
            hd_cloud_free(c);
            tf_free(&b);
        }
    free(xyz);
}

TEST(ply_ascii_tolerates_crlf_line_ends_and_a_missing_final_newline) {
    const char *p = tf_printf("crlf.ply", "ply\r\nformat ascii 1.0\r\nelement vertex 2\r\nproperty float x\r\n"
                                          "property float y\r\nproperty float z\r\nend_header\r\n1 2 3\r\n4 5 6");
    double want[6] = {1, 2, 3, 4, 5, 6};
    hd_cloud_t *c = read_ok(p);
    check_points(c, want, 2);
    hd_cloud_free(c);
}

/* ---- XYZ / CSV / PTS ----------------------------------------------------- */

TEST(xyz_reads_blanks_commas_semicolons_headers_comments_and_extra_columns) {
    size_t n = 200;
    double *xyz = points(11, n, -1e6, 1e6);
    CONTEXT("seed 11");
    static const char *const seps[] = {" ", "\t", ",", ", ", ";", "  \t "};
    for (size_t s = 0; s < sizeof seps / sizeof seps[0]; s++) {
        tf_buf_t b = {0};
        if (s % 2) tf_putf(&b, "x%sy%sz%sintensity\n", seps[s], seps[s], seps[s]);
        for (size_t k = 0; k < n; k++) {
            if (k % 17 == 0) tf_puts(&b, "# a comment\n\n   \n// another\n");
            tf_putf(&b, "%.17g%s%.17g%s%.17g", xyz[3 * k], seps[s], xyz[3 * k + 1], seps[s], xyz[3 * k + 2]);
            if (k % 3 == 0) tf_putf(&b, "%s42%snot-a-number", seps[s], seps[s]);
            tf_puts(&b, k % 5 == 0 ? "\r\n" : "\n");
        }
        hd_cloud_t *c = read_ok(tf_write(s % 3 == 0 ? "seps.csv" : s % 3 == 1 ? "seps.txt" : "seps.xyz", b.data, b.size - 1));
        check_points(c, xyz, n);
        hd_cloud_free(c);
        tf_free(&b);
    }
    free(xyz);
}

TEST(pts_point_count_line_is_skipped) {
    const char *p = tf_printf("leica.pts", "2\n1.5 2.5 3.5 -1200 10 20 30\n4 5 6 7 8 9 10\n");
    double want[6] = {1.5, 2.5, 3.5, 4, 5, 6};
    hd_cloud_t *c = read_ok(p);
    check_points(c, want, 2);
    hd_cloud_free(c);
}

TEST(text_numbers_in_every_notation_read_as_strtod_reads_them) {
    static const char *const tokens[] = {"0", "-0", "+1", "1.", ".5", "-.5e-3", "1e10", "1E+10", "123456789012345678901234567890",
                                         "0.1", "3.141592653589793238462643383279", "1e-320", "4.9e-324", "9.99e152",
                                         "0x1.8p1", "000012.5000", "9007199254740993", "2.2250738585072011e-308", "7e22", "7e23"};
    size_t n = sizeof tokens / sizeof tokens[0];
    tf_buf_t b = {0};
    double *want = malloc(3 * n * sizeof *want);
    for (size_t k = 0; k < n; k++) {
        tf_putf(&b, "%s %s %s\n", tokens[k], tokens[(k + 1) % n], tokens[(k + 2) % n]);
        for (int d = 0; d < 3; d++) want[3 * k + d] = strtod(tokens[(k + d) % n], NULL);
    }
    hd_cloud_t *c = read_ok(tf_write("notation.xyz", b.data, b.size));
    check_points(c, want, n);
    hd_cloud_free(c);
    tf_free(&b);
    free(want);
}

/* ---- OBJ, OFF, STL ---------------------------------------------------------- */

TEST(obj_reads_v_lines_among_other_statements) {
    size_t n = 100;
    double *xyz = points(12, n, -50, 50);
    CONTEXT("seed 12");
    tf_buf_t b = {0};
    tf_puts(&b, "# exported\nmtllib a.mtl\no thing\n");
    for (size_t k = 0; k < n; k++) {
        tf_putf(&b, "v %.17g %.17g %.17g%s\n", xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2], k % 2 ? " 1.0" : " 0.5 0.25 0.125");
        tf_puts(&b, "vn 0 0 1\nvt 0.5 0.5\n");
        if (k >= 2) tf_putf(&b, "f %zu/1/1 %zu//2 -1\n", k - 1, k);
    }
    tf_puts(&b, "usemtl red\ns off\ng group\nl 1 2\n");
    hd_cloud_t *c = read_ok(tf_write("scene.obj", b.data, b.size));
    check_points(c, xyz, n);
    if (c) CHECK_EQ(c->n_faces, n - 2);
    hd_cloud_free(c);
    tf_free(&b);
    free(xyz);
}

TEST(off_reads_every_variant_keyword_comments_and_extra_columns) {
    size_t n = 30;
    double *xyz = points(13, n, -5, 5);
    CONTEXT("seed 13");
    static const char *const heads[] = {"OFF\n%zu 1 0\n", "COFF\n%zu 1 0\n", "NOFF\n# normals\n%zu 1 0\n", "CNOFF %zu 1 0\n",
                                        "%zu 1 0\n", "nOFF\n3\n%zu 1 0\n", "STOFF\n\n%zu 1\n"};
    static const char *const extra[] = {"", " 255 0 0 255", " 0 0 1", " 0 0 1 0.5 0.5 0.5 1", "", "", " 0.5 0.5"};
    for (size_t h = 0; h < sizeof heads / sizeof heads[0]; h++) {
        CONTEXT("seed 13, header %zu", h);
        tf_buf_t b = {0};
        tf_putf(&b, heads[h], n);
        for (size_t k = 0; k < n; k++) {
            if (k == n / 2) tf_puts(&b, "# comment between vertices\n\n");
            tf_putf(&b, "%.17g %.17g %.17g%s  # trailing comment\n", xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2], extra[h]);
        }
        tf_puts(&b, "3 0 1 2 255 255 255\n");
        hd_cloud_t *c = read_ok(tf_write("variant.off", b.data, b.size));
        check_points(c, xyz, n);
        if (c) CHECK_EQ(c->n_faces, 1);
        hd_cloud_free(c);
        tf_free(&b);
    }
    free(xyz);
}

static void stl_binary(tf_buf_t *b, const double *xyz, size_t n_tri, const char *header80) {
    char h[80] = {0};
    memcpy(h, header80, strlen(header80) < 80 ? strlen(header80) : 80);
    tf_put(b, h, 80);
    tf_u32(b, (uint32_t)n_tri, 0);
    for (size_t t = 0; t < n_tri; t++) {
        for (int d = 0; d < 3; d++) tf_f32(b, 0.0f, 0);
        for (int v = 0; v < 9; v++) tf_f32(b, (float)xyz[9 * t + v], 0);
        tf_u16(b, 0, 0);
    }
}

TEST(stl_binary_even_with_a_solid_header_and_ascii_read_the_corners) {
    size_t nt = 40;
    double *xyz = points(14, 3 * nt, -1, 1);
    to_float(xyz, 3 * nt);
    CONTEXT("seed 14");
    tf_buf_t b = {0};
    stl_binary(&b, xyz, nt, "solid but binary");
    hd_cloud_t *c = read_ok(tf_write("part.stl", b.data, b.size));
    check_points(c, xyz, 3 * nt);
    if (c) CHECK_EQ(c->n_faces, nt);
    hd_cloud_free(c);
    tf_free(&b);
    tf_puts(&b, "solid part\n");
    for (size_t t = 0; t < nt; t++) {
        tf_puts(&b, "  facet normal 0 0 1\n    outer loop\n");
        for (int v = 0; v < 3; v++)
            tf_putf(&b, "      vertex %.17g %.17g %.17g\n", xyz[9 * t + 3 * v], xyz[9 * t + 3 * v + 1], xyz[9 * t + 3 * v + 2]);
        tf_puts(&b, "    endloop\n  endfacet\n");
    }
    tf_puts(&b, "endsolid part\n");
    c = read_ok(tf_write("ascii.stl", b.data, b.size));
    check_points(c, xyz, 3 * nt);
    if (c) CHECK_EQ(c->n_faces, nt);
    hd_cloud_free(c);
    tf_free(&b);
    free(xyz);
}

/* ---- PCD ------------------------------------------------------------------ */

TEST(pcd_reads_f_i_u_fields_of_every_size_between_other_fields) {
    /* x: U16, y: I8 (twice, COUNT 2), z: F8; padding fields around */
    size_t n = 64;
    gen_rng_t r;
    gen_seed(&r, 15);
    CONTEXT("seed 15");
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t k = 0; k < n; k++) {
        xyz[3 * k] = floor(gen_unit(&r) * 65535);
        xyz[3 * k + 1] = floor(gen_unit(&r) * 255) - 128;
        xyz[3 * k + 2] = gen_unit(&r) * 2e3 - 1e3;
    }
    for (int data = 0; data < 2; data++) {
        tf_buf_t b = {0};
        tf_putf(&b, "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS rgb x _ y z\nSIZE 4 2 1 1 8\n"
                    "TYPE U U U I F\nCOUNT 1 1 3 2 1\nWIDTH %zu\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %zu\nDATA %s\n",
                n, n, data ? "binary" : "ascii");
        for (size_t k = 0; k < n; k++) {
            if (data) {
                tf_u32(&b, 0xffffff, 0);
                tf_u16(&b, (unsigned)xyz[3 * k], 0);
                for (int j = 0; j < 3; j++) tf_u8(&b, 0);
                tf_u8(&b, (unsigned)(int)xyz[3 * k + 1] & 255);
                tf_u8(&b, 7);
                tf_f64(&b, xyz[3 * k + 2], 0);
            } else {
                tf_putf(&b, "16777215 %.17g 0 0 0 %.17g 7 %.17g\n", xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]);
            }
        }
        hd_cloud_t *c = read_ok(tf_write("fields.pcd", b.data, b.size));
        check_points(c, xyz, n);
        hd_cloud_free(c);
        tf_free(&b);
    }
    free(xyz);
}

/* LZF with literal runs only (a valid stream any decoder must accept). */
static void lzf_literal(tf_buf_t *b, const unsigned char *p, size_t n) {
    for (size_t k = 0; k < n; k += 32) {
        size_t m = n - k < 32 ? n - k : 32;
        tf_u8(b, (unsigned)(m - 1));
        tf_put(b, p + k, m);
    }
}

TEST(pcd_binary_compressed_fields_of_different_sizes_read_from_their_blocks) {
    size_t n = 40;
    double *xyz = points(16, n, -10, 10);
    CONTEXT("seed 16");
    for (size_t k = 0; k < n; k++) xyz[3 * k + 1] = (double)(float)xyz[3 * k + 1];
    tf_buf_t soa = {0}, b = {0};
    for (size_t k = 0; k < n; k++) tf_f64(&soa, xyz[3 * k], 0);
    for (size_t k = 0; k < n; k++) tf_u8(&soa, 9); /* a 1-byte field between */
    for (size_t k = 0; k < n; k++) tf_f32(&soa, (float)xyz[3 * k + 1], 0);
    for (size_t k = 0; k < n; k++) tf_f64(&soa, xyz[3 * k + 2], 0);
    tf_buf_t z = {0};
    lzf_literal(&z, soa.data, soa.size);
    tf_putf(&b, "VERSION .7\nFIELDS x label y z\nSIZE 8 1 4 8\nTYPE F U F F\nWIDTH %zu\nHEIGHT 1\nPOINTS %zu\n"
                "DATA binary_compressed\n", n, n);
    tf_u32(&b, (uint32_t)z.size, 0);
    tf_u32(&b, (uint32_t)soa.size, 0);
    tf_put(&b, z.data, z.size);
    hd_cloud_t *c = read_ok(tf_write("mixed.pcd", b.data, b.size));
    check_points(c, xyz, n);
    hd_cloud_free(c);
    tf_free(&b);
    tf_free(&z);
    tf_free(&soa);
    free(xyz);
}

/* ---- LAS ------------------------------------------------------------------- */

static const unsigned las_min_record[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

/* A LAS file of version 1.minor, point format fmt, records of rec bytes,
 * n points with integer coordinates X; the expected doubles are
 * X * scale + offset. */
static const char *write_las(unsigned minor, unsigned fmt, unsigned rec, size_t n, gen_rng_t *r, double *want) {
    static const double scale[3] = {0.001, 0.01, 0.00025}, offset[3] = {400000.5, -3e6, 12.25};
    unsigned header = minor >= 4 ? 375 : minor == 3 ? 235 : 227;
    unsigned vlr = 54 + 10; /* one VLR with 10 bytes of payload */
    tf_buf_t b = {0};
    tf_puts(&b, "LASF");
    tf_u16(&b, 0, 0);
    tf_u16(&b, 0, 0);
    for (int k = 0; k < 16; k++) tf_u8(&b, 0);
    tf_u8(&b, 1);
    tf_u8(&b, minor);
    char id[64] = "test_readers";
    tf_put(&b, id, 32);
    tf_put(&b, id, 32);
    tf_u16(&b, 1, 0);
    tf_u16(&b, 2024, 0);
    tf_u16(&b, header, 0);
    tf_u32(&b, header + vlr, 0);
    tf_u32(&b, 1, 0);
    tf_u8(&b, fmt);
    tf_u16(&b, rec, 0);
    tf_u32(&b, minor >= 4 ? 0 : (uint32_t)n, 0); /* 1.4: legacy count 0 */
    for (int k = 0; k < 5; k++) tf_u32(&b, 0, 0);
    for (int k = 0; k < 3; k++) tf_f64(&b, scale[k], 0);
    for (int k = 0; k < 3; k++) tf_f64(&b, offset[k], 0);
    for (int k = 0; k < 6; k++) tf_f64(&b, 0, 0);
    if (minor >= 3) tf_u64(&b, 0, 0);
    if (minor >= 4) {
        tf_u64(&b, 0, 0);
        tf_u32(&b, 0, 0);
        tf_u64(&b, n, 0);
        for (int k = 0; k < 15; k++) tf_u64(&b, 0, 0);
    }
    tf_u16(&b, 0, 0);
    tf_put(&b, "user_id_here____", 16);
    tf_u16(&b, 7, 0);
    tf_u16(&b, 10, 0);
    char desc[32] = "vlr";
    tf_put(&b, desc, 32);
    tf_put(&b, "0123456789", 10);
    for (size_t k = 0; k < n; k++) {
        for (int d = 0; d < 3; d++) {
            int32_t X = (int32_t)(gen_u64(r) >> 33) - (1 << 30);
            tf_u32(&b, (uint32_t)X, 0);
            want[3 * k + d] = (double)X * scale[d] + offset[d];
        }
        for (unsigned j = 12; j < rec; j++) tf_u8(&b, j);
    }
    const char *p = tf_write("cloud.las", b.data, b.size);
    tf_free(&b);
    return p;
}

TEST(las_versions_1_0_to_1_4_and_point_formats_0_to_10_apply_scale_and_offset) {
    size_t n = 33;
    double *want = malloc(3 * n * sizeof *want);
    for (unsigned minor = 0; minor <= 4; minor++)
        for (unsigned fmt = 0; fmt <= 10; fmt++) {
            if (fmt > 5 && minor < 4) continue;
            if (fmt > 3 && minor < 3) continue;
            if (fmt > 1 && minor < 2) continue;
            for (unsigned extra = 0; extra <= 5; extra += 5) {
                gen_rng_t r;
                gen_seed(&r, 100 * minor + fmt);
                CONTEXT("LAS 1.%u, point format %u, %u extra bytes, seed %u", minor, fmt, extra, 100 * minor + fmt);
                hd_cloud_t *c = read_ok(write_las(minor, fmt, las_min_record[fmt] + extra, n, &r, want));
                check_points(c, want, n);
                hd_cloud_free(c);
            }
        }
    free(want);
}

/* ---- NPY ------------------------------------------------------------------- */

static const char *write_npy(const double *xyz, size_t n, int f8, int big, int fortran, int version) {
    tf_buf_t h = {0}, b = {0};
    tf_putf(&h, "{'descr': '%c%c%d', 'fortran_order': %s, 'shape': (%zu, 3), }", big ? '>' : '<', 'f', f8 ? 8 : 4,
            fortran ? "True" : "False", n);
    size_t pre = version == 1 ? 10 : 12;
    while ((pre + h.size + 1) % 64) tf_puts(&h, " ");
    tf_puts(&h, "\n");
    tf_put(&b, "\x93NUMPY", 6);
    tf_u8(&b, (unsigned)version);
    tf_u8(&b, 0);
    if (version == 1) tf_u16(&b, (unsigned)h.size, 0);
    else tf_u32(&b, (uint32_t)h.size, 0);
    tf_put(&b, h.data, h.size);
    for (size_t i = 0; i < 3 * n; i++) {
        size_t k = fortran ? i % n : i / 3, d = fortran ? i / n : i % 3;
        if (f8) tf_f64(&b, xyz[3 * k + d], big);
        else tf_f32(&b, (float)xyz[3 * k + d], big);
    }
    const char *p = tf_write("array.npy", b.data, b.size);
    tf_free(&h);
    tf_free(&b);
    return p;
}

TEST(npy_reads_float32_and_float64_either_byte_order_c_and_fortran_order) {
    size_t n = 77;
    double *xyz = points(17, n, -1e3, 1e3), *xf = points(17, n, -1e3, 1e3);
    to_float(xf, n);
    for (int f8 = 0; f8 < 2; f8++)
        for (int big = 0; big < 2; big++)
            for (int fortran = 0; fortran < 2; fortran++)
                for (int version = 1; version <= 3; version++) {
                    CONTEXT("seed 17, f%d, big %d, fortran %d, version %d", f8 ? 8 : 4, big, fortran, version);
                    hd_cloud_t *c = read_ok(write_npy(xyz, n, f8, big, fortran, version));
                    check_points(c, f8 ? xyz : xf, n);
                    hd_cloud_free(c);
                }
    free(xyz);
    free(xf);
}

/* ---- storage, threads, selection ------------------------------------------- */

TEST(float32_storage_keeps_floats_exactly_and_rounds_doubles_to_nearest) {
    size_t n = 100;
    double *xyz = points(18, n, -1, 1), *xf = points(18, n, -1, 1);
    to_float(xf, n);
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.dtype = HD_FLOAT32;
    hd_cloud_t *c = read_with(write_npy(xyz, n, 1, 0, 0, 1), &o);
    if (c) CHECK_EQ(c->dtype, HD_FLOAT32);
    check_points(c, xf, n);
    hd_cloud_free(c);
    c = read_with(write_npy(xyz, n, 0, 1, 1, 1), &o);
    check_points(c, xf, n);
    hd_cloud_free(c);
    free(xyz);
    free(xf);
}

TEST(text_parsing_gives_the_same_points_and_error_line_at_any_thread_count) {
    size_t n = 120000; /* about 6 MB: several chunks */
    double *xyz = points(19, n, -1e4, 1e4);
    CONTEXT("seed 19");
    tf_buf_t b = {0};
    for (size_t k = 0; k < n; k++) tf_putf(&b, "%.17g %.17g %.17g\n", xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]);
    const char *p = tf_write("big.xyz", b.data, b.size);
    static const int threads[] = {1, 2, 3, 8};
    for (int t = 0; t < 4; t++) {
        hd_read_options_t o;
        hd_read_options_init(&o);
        o.threads = threads[t];
        hd_cloud_t *c = read_with(p, &o);
        check_points(c, xyz, n);
        hd_cloud_free(c);
    }
    /* two bad lines late in the file: the first is reported */
    size_t at = b.size - 40 * 1000;
    while (b.data[at - 1] != '\n') at++;
    long long line = 1;
    for (size_t k = 0; k < at; k++) line += b.data[k] == '\n';
    memcpy(b.data + at, "oops", 4);
    memcpy(b.data + b.size - 30, "bad!", 4);
    p = tf_write("bad.xyz", b.data, b.size);
    for (int t = 0; t < 4; t++) {
        hd_read_options_t o;
        hd_read_options_init(&o);
        o.threads = threads[t];
        hd_cloud_t *c = NULL;
        hd_error_t e;
        CHECK_RC(hd_read_file(p, &o, &c, &e), HD_EFORMAT);
        CHECK_EQ(e.line, line);
        char want[64];
        snprintf(want, sizeof want, ":%lld: ", line);
        CHECK(strstr(e.message, want) != NULL);
    }
    tf_free(&b);
    free(xyz);
}

TEST(format_comes_from_the_option_then_the_extension_then_the_content) {
    const char *p = tf_printf("points.dat", "1 2 3\n4 5 6\n");
    hd_cloud_t *c = read_ok(p); /* unknown extension: sniffed as xyz */
    if (c) CHECK(strcmp(c->format, "xyz") == 0);
    hd_cloud_free(c);
    p = tf_printf("actually_ply.xyz", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                                      "property float z\nend_header\n1 2 3\n");
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.format = "ply";
    c = read_with(p, &o);
    if (c) CHECK(strcmp(c->format, "ply") == 0 && c->count == 1);
    hd_cloud_free(c);
    /* content that contradicts a signature-bearing extension is named */
    hd_error_t e;
    p = tf_write("cloud.ply", "LASF", 4);
    CHECK_RC(hd_read_file(p, NULL, &c, &e), HD_EFORMAT);
    CHECK(strstr(e.message, "content is las") && strstr(e.message, "--format las"));
}

TEST(laz_files_are_read_and_a_compressed_las_without_its_laszip_vlr_is_refused) {
    hd_cloud_t *c;
    hd_error_t e;
    CHECK_RC(hd_read_file("no_such.laz", NULL, &c, &e), HD_EIO);
    CHECK_RC(hd_read_file("tests/corpus/laz/fmt0_chunks16.laz", NULL, &c, &e), HD_OK);
    CHECK_EQ(c->count, 40);
    hd_cloud_free(c);
    /* a LAS file whose point format has the LASzip compression bit */
    size_t n = 2;
    double want[6];
    gen_rng_t r;
    gen_seed(&r, 1);
    const char *p = write_las(2, 1, 28, n, &r, want);
    FILE *f = fopen(p, "r+b");
    fseek(f, 104, SEEK_SET);
    fputc(0x81, f);
    fclose(f);
    CHECK_RC(hd_read_file(p, NULL, &c, &e), HD_EFORMAT);
    CHECK(strstr(e.message, "compressed (LAZ)") && strstr(e.message, "no LASzip VLR"));
    CHECK_EQ(e.offset, 104);
}

TEST(every_format_is_listed_with_a_description) {
    int n = 0;
    for (const char *const *f = hd_formats(); *f; f++, n++) {
        CHECK(hd_format_description(*f) != NULL);
        CHECK(strlen(hd_format_description(*f)) > 10);
    }
    CHECK_EQ(n, 9);
    CHECK(hd_format_description("laz") != NULL);
    CHECK(hd_format_description("zip") == NULL);
}

TEST(format_of_path_is_the_format_the_extension_selects) {
    CHECK(strcmp(hd_format_of_path("scan.PLY"), "ply") == 0);
    CHECK(strcmp(hd_format_of_path("dir.v2/points.csv"), "xyz") == 0);
    CHECK(strcmp(hd_format_of_path("m.coff"), "off") == 0);
    CHECK(strcmp(hd_format_of_path("cloud.npy"), "npy") == 0);
    CHECK(strcmp(hd_format_of_path("scan.laz"), "laz") == 0);
    CHECK(hd_format_of_path("dir.ply/README") == NULL);
    CHECK(hd_format_of_path("mask.nii.gz") == NULL);
    CHECK(hd_format_of_path("noext") == NULL);
    CHECK(hd_format_of_path(NULL) == NULL);
    /* every name it gives is one hd_read_file takes as a format */
    for (const char *const *f = hd_formats(); *f; f++) {
        char path[32];
        snprintf(path, sizeof path, "x.%s", *f);
        CHECK(strcmp(hd_format_of_path(path), *f) == 0);
    }
}
