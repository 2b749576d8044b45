/*
 * test_io_errors.c -- every reader refuses bad input with the right code and
 * a message that names the file and the line (text) or byte offset (binary)
 * of the problem: truncated data, counts beyond the file (a vertex count of
 * 2^62 must be refused, never allocated), unknown types, missing x/y/z,
 * NaN and infinity, numbers too large, and words where numbers belong.
 */
#include "check.h"
#include "files.h"

#include <math.h>
#include <stdlib.h>
#include <sys/stat.h>

enum { NONE, LINE, OFFSET };

/* Reading `path` fails with `code`; the message starts with the path and
 * contains `needle`; err->line or err->offset is `at` as `kind` says. */
static void refused(const char *path, int code, const char *needle, int kind, long long at) {
    hd_cloud_t *c = NULL;
    hd_error_t e;
    CHECK_RC(hd_read_file(path, NULL, &c, &e), code);
    CHECK(c == NULL);
    CHECK_EQ(e.code, code);
    if (strncmp(e.message, path, strlen(path)) != 0)
        hdt_fail(__FILE__, __LINE__, "message '%s' does not start with the file name", e.message);
    if (!strstr(e.message, needle)) hdt_fail(__FILE__, __LINE__, "message '%s' lacks '%s'", e.message, needle);
    char place[64];
    if (kind == LINE) {
        CHECK_EQ(e.line, at);
        CHECK_EQ(e.offset, -1);
        snprintf(place, sizeof place, "%s:%lld: ", path, at);
        if (strncmp(e.message, place, strlen(place)) != 0)
            hdt_fail(__FILE__, __LINE__, "message '%s' does not start with '%s'", e.message, place);
    } else if (kind == OFFSET) {
        if (at < 0) at = e.offset; /* any offset, as long as there is one */
        CHECK(e.offset >= 0);
        CHECK_EQ(e.offset, at);
        CHECK_EQ(e.line, -1);
        snprintf(place, sizeof place, ": byte %lld: ", at);
        if (!strstr(e.message, place)) hdt_fail(__FILE__, __LINE__, "message '%s' lacks '%s'", e.message, place);
    }
}

static const char *ply_head(const char *fmt, const char *count, const char *ztype) {
    static char h[512];
    snprintf(h, sizeof h, "ply\nformat %s 1.0\nelement vertex %s\nproperty float x\nproperty float y\nproperty %s z\nend_header\n",
             fmt, count, ztype);
    return h;
}

/* ---- PLY ----------------------------------------------------------------- */

TEST(ply_bad_headers_are_refused_with_their_line) {
    refused(tf_printf("a.ply", "plyx\n"), HD_EFORMAT, "not a PLY file", LINE, 1);
    refused(tf_printf("b.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"), HD_EFORMAT, "before 'end_header'", LINE, 4);
    refused(tf_printf("c.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n"), HD_EFORMAT,
            "unknown property type 'float128'", LINE, 4);
    refused(tf_printf("d.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"), HD_EUNSUPPORTED, "unknown PLY format", LINE, 2);
    refused(tf_printf("e.ply", "ply\nformat ascii 2.0\nend_header\n"), HD_EUNSUPPORTED, "version '2.0'", LINE, 2);
    refused(tf_printf("f.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n"),
            HD_EFORMAT, "no property 'z'", LINE, 3);
    refused(tf_printf("g.ply", "ply\nformat ascii 1.0\nelement face 0\nend_header\n"), HD_EFORMAT, "no element 'vertex'", NONE, 0);
    refused(tf_printf("h.ply", "ply\nformat ascii 1.0\nelement vertex -3\nend_header\n"), HD_EFORMAT, "not a whole number", LINE, 3);
    refused(tf_printf("i.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n"), HD_EFORMAT, "before any 'element'", LINE, 3);
    refused(tf_printf("j.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\nproperty float y\n"
                               "property float z\nend_header\n1 0 0 0\n"),
            HD_EFORMAT, "'x' is a list", LINE, 3);
    refused(tf_printf("k.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int l\nproperty float x\n"
                               "property float y\nproperty float z\nend_header\n"),
            HD_EFORMAT, "list count cannot be", LINE, 4);
    refused(tf_printf("l.ply", "ply\nformat ascii 1.0\nwhatever\nend_header\n"), HD_EFORMAT, "unknown header keyword", LINE, 3);
}

TEST(ply_counts_beyond_the_file_are_refused_without_allocating) {
    /* 2^62 and 2^64 - 1 vertices in a file of a few bytes */
    refused(tf_printf("huge.ply", "%s1 2 3\n", ply_head("ascii", "4611686018427387904", "float")), HD_EFORMAT,
            "file can hold at most", LINE, 3);
    const char *h2 = ply_head("binary_little_endian", "18446744073709551615", "float");
    refused(tf_printf("huge2.ply", "%s", h2), HD_EFORMAT, "file ends inside element vertex", OFFSET, (long long)strlen(h2));
    refused(tf_printf("huge3.ply", "%s", ply_head("ascii", "18446744073709551616", "float")), HD_EFORMAT, "not a whole number", LINE, 3);
    /* a list element before the vertices claiming 2^62 instances */
    refused(tf_printf("huge4.ply", "ply\nformat binary_little_endian 1.0\nelement junk 4611686018427387904\n"
                                   "property list uchar int a\n%s",
                      ply_head("binary_little_endian", "1", "float") + strlen("ply\nformat binary_little_endian 1.0\n")),
            HD_EFORMAT, "file ends inside element junk", OFFSET, 0 + (long long)strlen("ply\nformat binary_little_endian 1.0\n"
                                                                                       "element junk 4611686018427387904\n"
                                                                                       "property list uchar int a\n") +
                                                                       (long long)strlen(ply_head("binary_little_endian", "1", "float")) -
                                                                       (long long)strlen("ply\nformat binary_little_endian 1.0\n"));
}

TEST(ply_truncated_data_is_refused_with_its_place) {
    tf_buf_t b = {0};
    const char *h = ply_head("binary_big_endian", "10", "float");
    tf_puts(&b, h);
    for (int k = 0; k < 14; k++) tf_f32(&b, 1.0f, 1);
    refused(tf_write("t.ply", b.data, b.size), HD_EFORMAT, "10 declared, room for 4", OFFSET, (long long)b.size);
    tf_free(&b);
    refused(tf_printf("t2.ply", "%s1.000 2.000 3.000\n4.000 5.000 6.000\n", ply_head("ascii", "3", "float")), HD_EFORMAT,
            "3 declared, 2 found", LINE, 10);
    refused(tf_printf("t3.ply", "%s1.000 2.000\n", ply_head("ascii", "1", "float")), HD_EFORMAT, "found end of line", LINE, 8);
    refused(tf_printf("t4.ply", "%s1 2 3 4\n", ply_head("ascii", "1", "float")), HD_EFORMAT, "more values", LINE, 8);
    /* faces promised after the vertices but missing */
    refused(tf_printf("t5.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                                "element face 2\nproperty list uchar int vertex_indices\nend_header\n1 2 3\n3 0 0 0\n"),
            HD_EFORMAT, "inside element face: 2 declared, 1 found", LINE, 12);
    b = (tf_buf_t){0};
    tf_puts(&b, "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n");
    for (int k = 0; k < 3; k++) tf_f32(&b, 1.0f, 0);
    tf_u8(&b, 3);
    tf_u32(&b, 0, 0);
    refused(tf_write("t6.ply", b.data, b.size), HD_EFORMAT, "inside element face", OFFSET, (long long)b.size);
    tf_free(&b);
}

TEST(ply_nan_infinity_and_words_are_refused_with_their_place) {
    refused(tf_printf("n.ply", "%s1 2 3\n1 nan 3\n", ply_head("ascii", "2", "float")), HD_ENONFINITE, "NaN or infinite", LINE, 9);
    refused(tf_printf("n2.ply", "%s1 2 inf\n", ply_head("ascii", "1", "float")), HD_ENONFINITE, "NaN or infinite", LINE, 8);
    refused(tf_printf("n3.ply", "%s1 2 1e200\n", ply_head("ascii", "1", "double")), HD_ERANGE, "beyond 1e153", LINE, 8);
    refused(tf_printf("n4.ply", "%s1 two 3\n", ply_head("ascii", "1", "float")), HD_EFORMAT, "'two' is not a number", LINE, 8);
    tf_buf_t b = {0};
    const char *h = ply_head("binary_little_endian", "3", "double");
    tf_puts(&b, h);
    for (int k = 0; k < 2; k++) {
        tf_f32(&b, 1.0f, 0);
        tf_f32(&b, 2.0f, 0);
        tf_f64(&b, k ? INFINITY : 3.0, 0);
    }
    tf_f32(&b, NAN, 0);
    tf_f32(&b, 0, 0);
    tf_f64(&b, 0, 0);
    /* the first bad point: point 1's z at header + 16 + 8 */
    refused(tf_write("n5.ply", b.data, b.size), HD_ENONFINITE, "point 1", OFFSET, (long long)strlen(h) + 16 + 8);
    tf_free(&b);
    b = (tf_buf_t){0};
    tf_puts(&b, "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list char int vertex_indices\nend_header\n");
    for (int k = 0; k < 9; k++) tf_f32(&b, (float)k, 0);
    size_t at = b.size;
    tf_u8(&b, 0xff); /* list length -1 */
    refused(tf_write("n6.ply", b.data, b.size), HD_EFORMAT, "negative list length", OFFSET, (long long)at);
    tf_free(&b);
}

TEST(ply_binary_face_index_out_of_range_is_refused_when_sampling) {
    tf_buf_t b = {0};
    tf_puts(&b, "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n");
    for (int k = 0; k < 9; k++) tf_f32(&b, (float)k, 0);
    tf_u8(&b, 3);
    tf_u32(&b, 0, 0);
    size_t at = b.size;
    tf_u32(&b, 99, 0);
    tf_u32(&b, 1, 0);
    const char *p = tf_write("face.ply", b.data, b.size);
    tf_free(&b);
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.mesh = HD_MESH_SAMPLE;
    o.sample = 3;
    hd_cloud_t *c;
    hd_error_t e;
    CHECK_RC(hd_read_file(p, &o, &c, &e), HD_EFORMAT);
    CHECK_EQ(e.offset, (long long)at);
    CHECK(strstr(e.message, "vertex 99") != NULL);
}

/* ---- XYZ, OBJ, OFF, STL ---------------------------------------------------- */

TEST(xyz_bad_lines_are_refused_with_their_line) {
    refused(tf_printf("a.xyz", "1 2 3\n4 5\n"), HD_EFORMAT, "expected 3 numbers (x y z), found 2", LINE, 2);
    refused(tf_printf("b.xyz", "1 2 3\n\n# c\n4 five 6\n"), HD_EFORMAT, "'five' is not a number (column 2)", LINE, 4);
    refused(tf_printf("c.csv", "x,y,z\n1,2,3\nnan,2,3\n"), HD_ENONFINITE, "NaN or infinite", LINE, 3);
    refused(tf_printf("d.txt", "1 2 3\n1 -inf 3\n"), HD_ENONFINITE, "NaN or infinite", LINE, 2);
    refused(tf_printf("e.xyz", "1 2 1e400\n"), HD_ENONFINITE, "NaN or infinite", LINE, 1);
    refused(tf_printf("f.xyz", "1 2 3\n1 2 -2e153\n"), HD_ERANGE, "beyond 1e153", LINE, 2);
    refused(tf_printf("g.xyz", "%s", ""), HD_EEMPTY, "no points", NONE, 0);
    refused(tf_printf("h.csv", "x,y,z\n"), HD_EEMPTY, "no points", NONE, 0);
    refused(tf_printf("i.pts", "12\n1 2\n"), HD_EFORMAT, "found 2", LINE, 2);
    refused(tf_printf("j.xyz", "1 2 3\n7\n"), HD_EFORMAT, "found 1", LINE, 2);
}

TEST(obj_bad_vertices_are_refused_with_their_line) {
    refused(tf_printf("a.obj", "# c\nv 1 2\n"), HD_EFORMAT, "expected x y z, found 2", LINE, 2);
    refused(tf_printf("b.obj", "v 1 2 3\nvn 0 0 1\nv 1 y 3\n"), HD_EFORMAT, "'y' is not a number", LINE, 3);
    refused(tf_printf("c.obj", "v 1 2 3\nv nan 0 0\n"), HD_ENONFINITE, "NaN or infinite", LINE, 2);
    refused(tf_printf("d.obj", "vt 0 0\nvn 0 0 1\n"), HD_EEMPTY, "no points", NONE, 0);
}

TEST(off_bad_headers_counts_and_vertices_are_refused_with_their_line) {
    refused(tf_printf("a.off", "OFF\n4611686018427387904 0 0\n1 2 3\n"), HD_EFORMAT, "can hold at most", LINE, 2);
    refused(tf_printf("b.off", "OFF\n3 0 0\n1.000 2.000 3.000\n4.000 5.000 6.000\n"), HD_EFORMAT, "after 2 of 3 vertices", LINE, 5);
    refused(tf_printf("c.off", "OFF\n2 2 0\n1 2 3\n4 5 6\n3 0 1 0\n"), HD_EFORMAT, "after 1 of 2 faces", LINE, 6);
    refused(tf_printf("d.off", "OFF\n2 0 0\n1 2 3\n4 x 6\n"), HD_EFORMAT, "'x' is not a number", LINE, 4);
    refused(tf_printf("e.off", "OFF\n2 0 0\n1 2 3\n4.0000 5.0000\n"), HD_EFORMAT, "found 2 numbers", LINE, 4);
    refused(tf_printf("f.off", "OFF\n1 0 0\n1 inf 3\n"), HD_ENONFINITE, "NaN or infinite", LINE, 3);
    refused(tf_printf("g.off", "4OFF\n1 0 0\n1 2 3 4\n"), HD_EUNSUPPORTED, "4D OFF", LINE, 1);
    refused(tf_printf("h.off", "OFF BINARY\n"), HD_EUNSUPPORTED, "binary OFF", LINE, 1);
    refused(tf_printf("i.off", "nOFF 4\n1 0 0\n"), HD_EUNSUPPORTED, "dimension '4'", LINE, 1);
    refused(tf_printf("j.off", "OFF\n# only a comment\n7\n"), HD_EFORMAT, "counts", LINE, 3);
    refused(tf_printf("k.off", "OFF\nmany 0 0\n"), HD_EFORMAT, "expected the vertex count", LINE, 2);
    refused(tf_printf("l.off", "OFF\n"), HD_EFORMAT, "file ends", LINE, 1);
}

TEST(stl_truncated_and_malformed_files_are_refused_with_their_place) {
    tf_buf_t b = {0};
    char h[80] = "binary";
    tf_put(&b, h, 80);
    tf_u32(&b, 1000, 0);
    for (int k = 0; k < 100; k++) tf_u8(&b, 0);
    refused(tf_write("a.stl", b.data, b.size), HD_EFORMAT, "declares 1000 triangles", OFFSET, 80);
    tf_free(&b);
    b = (tf_buf_t){0};
    tf_put(&b, h, 80);
    tf_u32(&b, 2, 0);
    for (int t = 0; t < 2; t++) {
        for (int k = 0; k < 3; k++) tf_f32(&b, 0, 0);
        for (int k = 0; k < 9; k++) tf_f32(&b, t == 1 && k == 4 ? NAN : (float)k, 0);
        tf_u16(&b, 0, 0);
    }
    /* triangle 1, corner 1, y: 84 + 50 + 12 + 12 + 4 */
    refused(tf_write("b.stl", b.data, b.size), HD_ENONFINITE, "point 4", OFFSET, 84 + 50 + 12 + 12 + 4);
    tf_free(&b);
    refused(tf_write("c.stl", "abc", 3), HD_EFORMAT, "84-byte header", OFFSET, 3);
    refused(tf_printf("d.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n"
                               "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\n"
                               "endsolid x\n"),
            HD_EFORMAT, "facet with 2 vertices", LINE, 2);
    refused(tf_printf("e.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 zero 0\n"), HD_EFORMAT, "'zero' is not a number",
            LINE, 4);
    refused(tf_printf("f.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n"), HD_EFORMAT, "found 2 numbers", LINE, 4);
    refused(tf_printf("g.stl", "solid x\nfacet normal 0 0 1\nbogus\n"), HD_EFORMAT, "unknown ascii STL keyword 'bogus'", LINE, 3);
}

/* ---- PCD, LAS, NPY ---------------------------------------------------------- */

static const char *pcd(const char *name, const char *fields, const char *size, const char *type, const char *points,
                       const char *data, const void *body, size_t n) {
    tf_buf_t b = {0};
    tf_putf(&b, "# .PCD v0.7\nVERSION 0.7\nFIELDS %s\nSIZE %s\nTYPE %s\nCOUNT 1 1 1\nWIDTH %s\nHEIGHT 1\n"
                "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS %s\nDATA %s\n",
            fields, size, type, points, points, data);
    tf_put(&b, body, n);
    return tf_finish(&b, name);
}

TEST(pcd_bad_headers_and_data_are_refused_with_their_place) {
    refused(pcd("a.pcd", "x y w", "4 4 4", "F F F", "1", "ascii", "1 2 3\n", 6), HD_EFORMAT, "FIELDS has no 'z'", NONE, 0);
    refused(pcd("b.pcd", "x y z", "4 4 2", "F F F", "1", "ascii", "1 2 3\n", 6), HD_EUNSUPPORTED, "field z has TYPE F SIZE 2", NONE, 0);
    refused(pcd("c.pcd", "x y z", "4 4 3", "F F F", "1", "ascii", "1 2 3\n", 6), HD_EFORMAT, "SIZE 3", LINE, 4);
    refused(pcd("d.pcd", "x y z", "4 4 4", "F F Q", "1", "ascii", "1 2 3\n", 6), HD_EFORMAT, "unknown TYPE 'Q'", LINE, 5);
    refused(pcd("e.pcd", "x y z", "4 4", "F F F", "1", "ascii", "1 2 3\n", 6), HD_EFORMAT, "SIZE has 2 values", LINE, 4);
    refused(pcd("f.pcd", "x y z", "4 4 4", "F F F", "1", "zipped", "", 0), HD_EUNSUPPORTED, "unknown DATA 'zipped'", LINE, 11);
    refused(pcd("g.pcd", "x y z", "4 4 4", "F F F", "2", "ascii", "1 2 3\nnan nan nan\n", 18), HD_ENONFINITE, "NaN or infinite",
            LINE, 13);
    refused(pcd("h.pcd", "x y z", "4 4 4", "F F F", "2", "ascii", "1 2 3\n1.000 2.000\n", 18), HD_EFORMAT,
            "expected 3 values, found 2", LINE, 13);
    refused(pcd("i.pcd", "x y z", "4 4 4", "F F F", "3", "ascii", "1.000 2.000 3.000\n1 2 3\n", 24), HD_EFORMAT,
            "POINTS says 3, the data holds 2", NONE, 0);
    refused(pcd("j.pcd", "x y z", "4 4 4", "F F F", "4611686018427387904", "ascii", "1 2 3\n", 6), HD_EFORMAT,
            "file can hold at most", LINE, 11);
    const char *p = pcd("k.pcd", "x y z", "4 4 4", "F F F", "4611686018427387904", "binary", "123456789012", 12);
    refused(p, HD_EFORMAT, "file ends inside the data", OFFSET, 12 + (long long)strlen("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\n"
                                                                                          "SIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                                                                                          "WIDTH 4611686018427387904\nHEIGHT 1\n"
                                                                                          "VIEWPOINT 0 0 0 1 0 0 0\n"
                                                                                          "POINTS 4611686018427387904\n"
                                                                                          "DATA binary\n"));
    refused(tf_printf("l.pcd", "VERSION 0.7\nFIELDS x y z\n"), HD_EFORMAT, "before the DATA line", LINE, 3);
    refused(tf_printf("m.pcd", "VERSION 0.7\nFIELDS x y z\nCOLOR red\n"), HD_EFORMAT, "unknown PCD header keyword 'COLOR'", LINE, 3);
}

TEST(pcd_corrupt_compressed_data_is_refused_with_its_offset) {
    size_t head = strlen("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n"
                         "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA binary_compressed\n");
    /* a back reference before the start of the output */
    unsigned char bad[] = {4, 0, 0, 0, 12, 0, 0, 0, 0x20, 0x05, 0, 0};
    refused(pcd("a.pcd", "x y z", "4 4 4", "F F F", "1", "binary_compressed", bad, sizeof bad), HD_EFORMAT, "corrupt compressed data",
            OFFSET, (long long)head + 8);
    /* uncompressed size that does not match POINTS */
    unsigned char mism[] = {13, 0, 0, 0, 99, 0, 0, 0, 11, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    refused(pcd("b.pcd", "x y z", "4 4 4", "F F F", "1", "binary_compressed", mism, sizeof mism), HD_EFORMAT,
            "uncompressed size 99", OFFSET, (long long)head + 4);
    /* compressed size beyond the file */
    unsigned char big[] = {0xff, 0xff, 0, 0, 12, 0, 0, 0, 0};
    refused(pcd("c.pcd", "x y z", "4 4 4", "F F F", "1", "binary_compressed", big, sizeof big), HD_EFORMAT,
            "compressed size 65535", OFFSET, (long long)head);
    /* a stream that ends short of the promised output */
    unsigned char shrt[] = {5, 0, 0, 0, 12, 0, 0, 0, 3, 1, 2, 3, 4};
    refused(pcd("d.pcd", "x y z", "4 4 4", "F F F", "1", "binary_compressed", shrt, sizeof shrt), HD_EFORMAT,
            "corrupt compressed data", OFFSET, (long long)head + 8 + 5);
}

static tf_buf_t las_header(unsigned minor, unsigned fmt, unsigned rec, uint32_t n, uint32_t offset) {
    tf_buf_t b = {0};
    tf_puts(&b, "LASF");
    for (int k = 0; k < 20; k++) tf_u8(&b, 0);
    tf_u8(&b, 1);
    tf_u8(&b, minor);
    for (int k = 0; k < 68; k++) tf_u8(&b, 0);
    tf_u16(&b, 227, 0);
    tf_u32(&b, offset, 0);
    tf_u32(&b, 0, 0);
    tf_u8(&b, fmt);
    tf_u16(&b, rec, 0);
    tf_u32(&b, n, 0);
    for (int k = 0; k < 5; k++) tf_u32(&b, 0, 0);
    for (int k = 0; k < 3; k++) tf_f64(&b, 0.01, 0);
    for (int k = 0; k < 3; k++) tf_f64(&b, 0, 0);
    for (int k = 0; k < 6; k++) tf_f64(&b, 0, 0);
    return b;
}

TEST(las_bad_headers_and_truncated_points_are_refused_with_their_offset) {
    tf_buf_t b = las_header(2, 0, 20, 5, 227);
    for (int k = 0; k < 2 * 20; k++) tf_u8(&b, 1);
    refused(tf_write("a.las", b.data, b.size), HD_EFORMAT, "5 of 20 bytes declared, room for 2", OFFSET, (long long)b.size);
    tf_free(&b);
    refused(tf_write("b.las", "LASF\0\0\0\0", 8), HD_EFORMAT, "inside the LAS header", OFFSET, 8);
    b = las_header(2, 1, 20, 0, 227);
    refused(tf_write("c.las", b.data, b.size), HD_EFORMAT, "record length 20 is shorter than point format 1's 28", OFFSET, 105);
    tf_free(&b);
    b = las_header(5, 0, 20, 0, 227);
    refused(tf_write("d.las", b.data, b.size), HD_EUNSUPPORTED, "LAS version 1.5", OFFSET, 24);
    tf_free(&b);
    b = las_header(4, 11, 80, 0, 227);
    refused(tf_write("e.las", b.data, b.size), HD_EUNSUPPORTED, "point data format 11", OFFSET, 104);
    tf_free(&b);
    b = las_header(2, 0, 20, 0, 5000);
    refused(tf_write("f.las", b.data, b.size), HD_EFORMAT, "offset to point data 5000", OFFSET, 96);
    tf_free(&b);
    b = las_header(2, 0, 20, 1, 227);
    double nan_ = NAN;
    memcpy(b.data + 139, &nan_, 8); /* y scale */
    for (int k = 0; k < 20; k++) tf_u8(&b, 0);
    refused(tf_write("g.las", b.data, b.size), HD_EFORMAT, "y scale factor is not a finite number", OFFSET, 139);
    tf_free(&b);
    b = las_header(2, 0, 20, 0xffffffffu, 227);
    refused(tf_write("h.las", b.data, b.size), HD_EFORMAT, "room for 0", OFFSET, (long long)b.size);
    tf_free(&b);
    b = las_header(2, 0, 20, 0, 227);
    refused(tf_write("i.las", b.data, b.size), HD_EEMPTY, "no points", NONE, 0);
    tf_free(&b);
}

static const char *npy(const char *name, const char *dict, const void *body, size_t n) {
    tf_buf_t b = {0};
    tf_put(&b, "\x93NUMPY\x01\x00", 8);
    tf_u16(&b, (unsigned)strlen(dict) + 1, 0);
    tf_puts(&b, dict);
    tf_puts(&b, "\n");
    tf_put(&b, body, n);
    return tf_finish(&b, name);
}

TEST(npy_unsupported_arrays_and_truncated_data_are_refused_with_their_offset) {
    double d[6] = {1, 2, 3, 4, 5, NAN};
    const char *good = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }";
    long long data = 10 + (long long)strlen(good) + 1;
    refused(npy("a.npy", "{'descr': '<i4', 'fortran_order': False, 'shape': (2, 3), }", d, 24), HD_EUNSUPPORTED, "dtype '<i4'",
            OFFSET, 20);
    long long shape_at = 10 + (long long)(strstr(good, "(2, 3)") - good);
    refused(npy("b.npy", "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 4), }", d, 48), HD_EUNSUPPORTED, "shape (2, 4)",
            OFFSET, shape_at);
    refused(npy("c.npy", "{'descr': '<f8', 'fortran_order': False, 'shape': (6,), }", d, 48), HD_EUNSUPPORTED, "shape (6,)", OFFSET,
            shape_at);
    refused(npy("d.npy", "{'descr': '<f8', 'fortran_order': False, 'shape': (4611686018427387904, 3), }", d, 48), HD_EFORMAT,
            "file ends inside the data", OFFSET, 10 + 78 + 48);
    refused(npy("e.npy", "{'descr': '<f8', 'fortran_order': maybe, 'shape': (2, 3), }", d, 48), HD_EFORMAT,
            "fortran_order is neither", OFFSET, 44);
    refused(npy("f.npy", "{'descr': '<f8', 'shape': (2, 3), }", d, 48), HD_EFORMAT, "no 'fortran_order'", OFFSET, 10);
    refused(npy("g.npy", good, d, 48), HD_ENONFINITE, "point 1", OFFSET, data + 40);
    refused(tf_write("h.npy", "\x93NUMPY\x01\x00\xff\x7f{", 11), HD_EFORMAT, "inside the .npy header", OFFSET, 11);
    refused(tf_write("i.npy", "\x93NUMPY\x09\x00\x00\x00", 10), HD_EUNSUPPORTED, "version 9.0", OFFSET, 6);
    refused(tf_write("j.npy", "NUMPY", 5), HD_EFORMAT, "not a NumPy", OFFSET, 0);
}

TEST(npy_header_giving_a_key_twice_is_refused) {
    /* Python keeps the last value: numpy reads (1, 3) and 1 point, where the
     * first 'shape' once read 2 */
    double d[6] = {1, 2, 3, 4, 5, 6};
    refused(npy("s2.npy", "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), 'shape': (1, 3), }", d, 48),
            HD_EFORMAT, "'shape' twice", OFFSET, 10);
    refused(npy("d2.npy", "{'descr': '<f8', 'fortran_order': False, 'descr': '<f4', 'shape': (4, 3), }", d, 48),
            HD_EFORMAT, "'descr' twice", OFFSET, 10);
    refused(npy("f2.npy", "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), \"fortran_order\": True}", d, 48),
            HD_EFORMAT, "'fortran_order' twice", OFFSET, 10);
}

/* ---- counts lower than the data: never a silent partial read ---------------- */

TEST(ply_and_pcd_naming_a_coordinate_or_the_vertices_twice_are_refused) {
    /* the first x, the first vertex element, were read: (1, 2, 3) where a
     * reader taking the last one reads 9 or (4, 5, 6) */
    const char *head = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
    refused(tf_printf("px.ply", "%sproperty float x\nend_header\n1 2 3 9\n", head), HD_EFORMAT,
            "declares property 'x' twice", LINE, 3);
    refused(tf_printf("pv.ply", "%selement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
                                "1 2 3\n4 5 6\n",
                      head),
            HD_EFORMAT, "element 'vertex' declared twice (first on line 3)", LINE, 7);
    refused(tf_printf("pf.ply", "%selement face 0\nproperty list uchar int vertex_indices\nelement face 0\n"
                                "property list uchar int vertex_indices\nend_header\n1 2 3\n",
                      head),
            HD_EFORMAT, "element 'face' declared twice", LINE, 9);
    refused(tf_printf("px.pcd", "VERSION 0.7\nFIELDS x y z x\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 1\n"
                                "HEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3 9\n"),
            HD_EFORMAT, "FIELDS names 'x' twice", NONE, 0);
}

TEST(ply_count_lower_than_the_data_is_refused_naming_the_extra_data) {
    refused(tf_printf("low.ply", "%s1 2 3\n4 5 6\n7 8 9\n", ply_head("ascii", "1", "float")), HD_EFORMAT,
            "data after the last element (vertex, 1 declared)", LINE, 9);
    tf_buf_t b = {0};
    const char *h = ply_head("binary_little_endian", "1", "float");
    tf_puts(&b, h);
    for (int k = 0; k < 9; k++) tf_f32(&b, (float)k, 0);
    refused(tf_write("low.ply", b.data, b.size), HD_EFORMAT, "24 bytes after the last element", OFFSET,
            (long long)strlen(h) + 12);
    tf_free(&b);
    /* blank lines after the data are no data */
    hd_cloud_t *c;
    hd_error_t e;
    CHECK_RC(hd_read_file(tf_printf("blank.ply", "%s1 2 3\n\n  \n", ply_head("ascii", "1", "float")), NULL, &c, &e), HD_OK);
    CHECK_EQ(c->count, 1);
    hd_cloud_free(c);
}

TEST(off_counts_lower_than_the_data_are_refused_with_the_line) {
    refused(tf_printf("low.off", "OFF\n1 0 0\n1 2 3\n4 5 6\n7 8 9\n"), HD_EFORMAT, "more data after the 1 vertices and 0 faces",
            LINE, 4);
    refused(tf_printf("low2.off", "OFF\n3 1 0\n1 2 3\n4 5 6\n7 8 9\n3 0 1 2\n# end\n3 0 1 2\n"), HD_EFORMAT,
            "after the 3 vertices and 1 faces", LINE, 8);
}

TEST(pts_count_line_must_equal_the_points) {
    refused(tf_printf("low.pts", "1\n1 2 3\n4 5 6\n7 8 9\n"), HD_EFORMAT, "the count line says 1 points, the file holds 3", LINE,
            1);
    refused(tf_printf("high.pts", "4\n1 2 3\n"), HD_EFORMAT, "says 4 points, the file holds 1", LINE, 1);
}

TEST(pcd_binary_count_lower_than_the_data_is_refused_but_zero_padding_is_read) {
    float pts[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    refused(pcd("low.pcd", "x y z", "4 4 4", "F F F", "1", "binary", pts, sizeof pts), HD_EFORMAT,
            "24 bytes after the data: POINTS 1", OFFSET, -1);
    unsigned char padded[12 + 100] = {0};
    memcpy(padded, pts, 12);
    hd_cloud_t *c;
    hd_error_t e;
    CHECK_RC(hd_read_file(pcd("pad.pcd", "x y z", "4 4 4", "F F F", "1", "binary", padded, sizeof padded), NULL, &c, &e), HD_OK);
    CHECK_EQ(c->count, 1);
    hd_cloud_free(c);
}

TEST(pcd_width_times_height_must_be_points) {
    const char *head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH %d\nHEIGHT %d\n"
                       "POINTS 2\nDATA ascii\n1 2 3\n4 5 6\n";
    refused(tf_printf("wh.pcd", head, 1, 1), HD_EFORMAT, "WIDTH 1 x HEIGHT 1 is not POINTS 2", NONE, 0);
    refused(tf_printf("wh.pcd", head, 2, 2), HD_EFORMAT, "WIDTH 2 x HEIGHT 2 is not POINTS 2", NONE, 0);
    hd_cloud_t *c;
    hd_error_t e;
    CHECK_RC(hd_read_file(tf_printf("wh.pcd", head, 2, 0), NULL, &c, &e), HD_OK); /* HEIGHT 0 is 1, as in PCL */
    CHECK_EQ(c->count, 2);
    hd_cloud_free(c);
}

TEST(off_face_of_fewer_than_three_vertices_is_refused_when_sampling) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.mesh = HD_MESH_SAMPLE;
    o.sample = 4;
    hd_cloud_t *c;
    hd_error_t e;
    CHECK_RC(hd_read_file(tf_printf("two.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 0 1 255 0 0\n"), &o, &c, &e),
             HD_EFORMAT);
    CHECK(strstr(e.message, "two.off:7: face with 2 vertices (at least 3 are needed)") != NULL);
}

/* Reading `path` as HD_MESH_SAMPLE: its return code, the error in *e. */
static int read_sampled(const char *path, hd_error_t *e) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.mesh = HD_MESH_SAMPLE;
    o.sample = 4;
    hd_cloud_t *c = NULL;
    int rc = hd_read_file(path, &o, &c, e);
    hd_cloud_free(c);
    return rc;
}

TEST(off_face_index_that_is_no_whole_number_is_named_so_not_missing) {
    hd_error_t e;
    CHECK_RC(read_sampled(tf_printf("neg.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"), &e), HD_EFORMAT);
    CHECK(strstr(e.message, "neg.off:6: face: expected 3 vertex indices, index 3 is not a whole number") != NULL);
    CHECK_RC(read_sampled(tf_printf("short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n"), &e), HD_EFORMAT);
    CHECK(strstr(e.message, "short.off:6: face: expected 3 vertex indices, index 3 is missing") != NULL);
}

/* A PLY face list of 0, 1 or 2 vertices is refused as OBJ's and OFF's are
 * (it was dropped without a word): ascii with its line, binary with the
 * offset of its list count. */
TEST(ply_face_of_fewer_than_three_vertices_is_refused_when_sampling) {
    const char *head = "ply\nformat %s 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                       "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
    for (int n = 0; n < 3; n++) {
        hd_error_t e;
        const char *faces[] = {"0", "1 0", "2 0 1"};
        char h[400], want[80];
        snprintf(h, sizeof h, head, "ascii");
        const char *p = tf_printf("few.ply", "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n%s\n", h, faces[n]);
        CHECK_RC(read_sampled(p, &e), HD_EFORMAT);
        snprintf(want, sizeof want, "few.ply:14: face with %d vertices (at least 3 are needed)", n);
        if (!strstr(e.message, want)) hdt_fail(__FILE__, __LINE__, "n = %d: '%s' lacks '%s'", n, e.message, want);

        tf_buf_t b = {0};
        snprintf(h, sizeof h, head, "binary_little_endian");
        tf_puts(&b, h);
        for (int k = 0; k < 9; k++) tf_f32(&b, k == 3 || k == 7 ? 1.0f : 0.0f, 0);
        tf_u8(&b, 3);
        for (int k = 0; k < 3; k++) tf_u32(&b, (uint32_t)k, 0);
        size_t at = b.size;
        tf_u8(&b, (uint8_t)n);
        for (int k = 0; k < n; k++) tf_u32(&b, (uint32_t)k, 0);
        p = tf_write("few_bin.ply", b.data, b.size);
        tf_free(&b);
        CHECK_RC(read_sampled(p, &e), HD_EFORMAT);
        CHECK_EQ(e.offset, (long long)at);
        snprintf(want, sizeof want, "face 1 with %d vertices (at least 3 are needed)", n);
        if (!strstr(e.message, want)) hdt_fail(__FILE__, __LINE__, "n = %d: '%s' lacks '%s'", n, e.message, want);
    }
}

TEST(las_count_lower_than_the_data_is_refused) {
    tf_buf_t b = las_header(2, 0, 20, 1, 227);
    for (int k = 0; k < 3 * 20; k++) tf_u8(&b, 1);
    refused(tf_write("low.las", b.data, b.size), HD_EFORMAT, "40 bytes after the 1 declared points", OFFSET, 227 + 20);
    tf_free(&b);
}

TEST(npy_data_longer_than_shape_and_dtype_is_refused) {
    double d[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    const char *f4 = "{'descr': '<f4', 'fortran_order': False, 'shape': (3, 3), }";
    refused(npy("f4f8.npy", f4, d, sizeof d), HD_EFORMAT, "shape (3, 3) of float32 needs 36 bytes of data, but 72 follow",
            OFFSET, 10 + (long long)strlen(f4) + 1 + 36);
    const char *one = "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3), }";
    refused(npy("low.npy", one, d, sizeof d), HD_EFORMAT, "needs 24 bytes of data, but 72 follow", OFFSET, -1);
}

/* ---- selection --------------------------------------------------------- */

TEST(unreadable_and_unknown_files_are_refused_with_a_reason) {
    hd_cloud_t *c;
    hd_error_t e;
    CHECK_RC(hd_read_file("/nonexistent/dir/x.ply", NULL, &c, &e), HD_EIO);
    CHECK(strstr(e.message, "cannot open") != NULL);
    CHECK_RC(hd_read_file("/tmp", NULL, &c, &e), HD_EIO);
    refused(tf_write("blob.bin", "\x01\x02\x03", 3), HD_EUNSUPPORTED, "cannot tell the format", NONE, 0);
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.format = "dxf";
    CHECK_RC(hd_read_file(tf_printf("x.xyz", "1 2 3\n"), &o, &c, &e), HD_EUNSUPPORTED);
    CHECK(strstr(e.message, "unknown format 'dxf'") != NULL);
    CHECK_RC(hd_read_file(NULL, NULL, &c, &e), HD_EINVAL);
}

/* A directory chain of 5 names of 240 bytes under the temporary directory
 * (made, with its file NAME holding text, when text is not NULL). */
static const char *deep_path(const char *name, const char *text) {
    static char path[2048];
    char part[241];
    memset(part, 'd', 240);
    part[240] = '\0';
    snprintf(path, sizeof path, "%s", tf_path("deep"));
    for (int k = 0; k < 5; k++) {
        if (text) mkdir(path, 0755);
        size_t l = strlen(path);
        snprintf(path + l, sizeof path - l, "/%.239s%d", part, k);
    }
    if (text) mkdir(path, 0755);
    size_t l = strlen(path);
    snprintf(path + l, sizeof path - l, "/%s", name);
    if (text) {
        FILE *f = fopen(path, "w");
        fputs(text, f);
        fclose(f);
    }
    return path;
}

TEST(a_message_too_long_for_the_record_shortens_the_file_name_and_keeps_the_reason) {
    hd_cloud_t *c;
    hd_error_t e;
    const char *missing = deep_path("missing.xyz", NULL);
    CHECK(strlen(missing) > 1200);
    CHECK_RC(hd_read_file(missing, NULL, &c, &e), HD_EIO);
    CONTEXT("message '%s'", e.message);
    CHECK(strlen(e.message) <= sizeof e.message - 1);
    CHECK(strncmp(e.message, missing, 40) == 0); /* the path's start, */
    CHECK(strstr(e.message, "...") != NULL);    /* its middle left out, */
    size_t n = strlen(e.message);                /* its end and the reason whole */
    const char *end = "/missing.xyz: cannot open: No such file or directory";
    CHECK(n > strlen(end) && strcmp(e.message + n - strlen(end), end) == 0);
    /* numbers in the message stay whole too, and the name's UTF-8 */
    const char *bad = deep_path("Z\xc3\xbcrich.xyz", "1 2 3\n1 2 x\n");
    CHECK_RC(hd_read_file(bad, NULL, &c, &e), HD_EFORMAT);
    CONTEXT("message '%s'", e.message);
    CHECK_EQ(e.line, 2);
    const char *why = "/Z\xc3\xbcrich.xyz:2: 'x' is not a number (column 3)";
    n = strlen(e.message);
    CHECK(n > strlen(why) && strcmp(e.message + n - strlen(why), why) == 0);
    CHECK(n >= sizeof e.message - 1 - 4); /* shortened no more than needed */
}
