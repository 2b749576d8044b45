/*
 * test_io_hostile.c -- files made to break the readers (issue "Hostile
 * files") are refused with a message that names the file and the place, or
 * read right; never a crash, a write out of bounds or a silent wrong read.
 * Each behaviour below once failed: a face list whose length its count
 * type cannot hold overran a 1-byte buffer; an OBJ relative index wrapped
 * onto a real vertex; a semicolon CSV with decimal commas gave wrong
 * points; a binary STL whose header starts with "solid" was taken for an
 * empty ascii file; decimal commas and thousands separators between
 * blank-separated fields were read as more columns; a UTF-8 byte-order mark
 * lost the first point, UTF-16 text gave misleading messages (an STL
 * triangle count of 1818521189); a malformed number on line 1 was skipped
 * as a header; classic Mac OS line ends (a '\r' alone) made a file one
 * line, read as its first point.  The test runs in the release and the ASan builds.
 */
#include "check.h"
#include "files.h"

#include <stdlib.h>

enum { NONE, LINE, OFFSET };

static hd_read_options_t sampling(size_t n) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.mesh = HD_MESH_SAMPLE;
    o.sample = n;
    return o;
}

/* Reading `path` with `opt` fails with `code`; the message starts with the
 * path, contains `needle`, and names the line or byte `at` as `kind` says. */
static void refused(const char *path, const hd_read_options_t *opt, int code, const char *needle, int kind,
                    long long at) {
    hd_cloud_t *c = NULL;
    hd_error_t e;
    CONTEXT("%s", path);
    CHECK_RC(hd_read_file(path, opt, &c, &e), code);
    CHECK(c == NULL);
    if (strncmp(e.message, path, strlen(path)) != 0)
        hdt_fail(__FILE__, __LINE__, "message '%s' does not start with the file name", e.message);
    if (!strstr(e.message, needle)) hdt_fail(__FILE__, __LINE__, "message '%s' lacks '%s'", e.message, needle);
    if (kind == LINE) CHECK_EQ(e.line, at);
    if (kind == OFFSET) CHECK_EQ(e.offset, at);
}

/* Reading `path` gives exactly the n points xyz (as doubles). */
static void reads(const char *path, const hd_read_options_t *opt, const double *xyz, size_t n) {
    hd_cloud_t *c = NULL;
    hd_error_t e;
    CONTEXT("%s", path);
    int rc = hd_read_file(path, opt, &c, &e);
    if (rc) {
        hdt_fail(__FILE__, __LINE__, "refused: %s", e.message);
        return;
    }
    CHECK_EQ(c->count, n);
    hd_points_t p = hd_cloud_points(c);
    for (size_t k = 0; k < 3 * n && k < 3 * c->count; k++) CHECK_BITS(((const double *)p.data)[k], xyz[k]);
    hd_cloud_free(c);
}

/* The file: a face element before the vertices, whose uchar list
 * length is 2^64 - 1, followed by `items` int-sized tokens that do not fit
 * an int either. */
static const char *ply_faces_first(const char *name, const char *count, int items) {
    tf_buf_t b = {0};
    tf_puts(&b, "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
                "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
    tf_puts(&b, count);
    for (int k = 0; k < items; k++) tf_puts(&b, " 4702111234474983745");
    tf_puts(&b, "\n0 0 0\n1 0 0\n0 1 0\n");
    return tf_finish(&b, name);
}

TEST(ply_list_length_beyond_its_count_type_is_refused_before_any_item_is_stored) {
    hd_read_options_t o = sampling(100);
    refused(ply_faces_first("overflow.ply", "18446744073709551615", 20000), &o, HD_EFORMAT,
            "length 18446744073709551615 does not fit its count type uchar", LINE, 10);
}

TEST(ply_face_lists_are_not_parsed_when_only_vertices_are_read) {
    /* the faces are skipped line by line: nothing of theirs is stored */
    const double want[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    reads(ply_faces_first("overflow2.ply", "18446744073709551615", 200), NULL, want, 3);
}

TEST(ply_list_length_beyond_the_line_is_refused_before_allocating) {
    hd_read_options_t o = sampling(10);
    /* 255 fits a uchar, but the line holds 2 items */
    refused(ply_faces_first("long.ply", "255", 2), &o, HD_EFORMAT, "255 values declared, but the line holds at most",
            LINE, 10);
}

TEST(ply_face_index_beyond_its_item_type_is_refused) {
    hd_read_options_t o = sampling(10);
    refused(ply_faces_first("item.ply", "3", 3), &o, HD_EFORMAT, "4702111234474983745 does not fit its type int", LINE,
            10);
}

TEST(ply_faces_before_vertices_are_checked_against_the_vertex_count) {
    const char *head = "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
                       "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    hd_read_options_t o = sampling(10);
    refused(tf_printf("bad.ply", "%s3 0 1 5\n0 0 0\n1 0 0\n0 1 0\n", head), &o, HD_EFORMAT,
            "refers to vertex 5, but the file has 3 vertices", LINE, 3);
    hd_cloud_t *c = NULL;
    hd_error_t e;
    CHECK_RC(hd_read_file(tf_printf("good.ply", "%s3 0 1 2\n0 0 0\n1 0 0\n0 1 0\n", head), &o, &c, &e), HD_OK);
    CHECK_EQ(c->count, 10);
    hd_cloud_free(c);
    /* binary, the same order */
    tf_buf_t b = {0};
    tf_puts(&b, "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uchar uint vertex_indices\n"
                "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
    tf_u8(&b, 3);
    tf_u32(&b, 0, 0);
    tf_u32(&b, 1, 0);
    tf_u32(&b, 4000000000u, 0);
    for (int k = 0; k < 9; k++) tf_f32(&b, k == 3 || k == 7 ? 1.0f : 0.0f, 0);
    refused(tf_write("bad.ply", b.data, b.size), &o, HD_EFORMAT, "refers to vertex 4000000000", LINE, 3);
    tf_free(&b);
}

TEST(ply_face_indices_of_a_float_type_are_refused) {
    hd_read_options_t o = sampling(10);
    refused(tf_printf("float.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                   "property float z\nelement face 1\nproperty list uchar float vertex_indices\n"
                                   "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
            &o, HD_EFORMAT, "not integers", LINE, 7);
}

static const char *five_then_face(const char *name, const char *face, int after) {
    tf_buf_t b = {0};
    tf_puts(&b, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\n");
    tf_putf(&b, "f %s\n", face);
    for (int k = 0; k < after; k++) tf_putf(&b, "v %d 2 2\n", k);
    return tf_finish(&b, name);
}

TEST(obj_relative_index_far_beyond_the_vertices_does_not_wrap_onto_one) {
    hd_read_options_t o = sampling(10);
    /* -(2^62 - 1): with 5 vertices before it, its 62-bit field once
     * wrapped to 6, a real vertex when more vertices follow */
    refused(five_then_face("wrap.obj", "1 2 -4611686018427387903", 3), &o, HD_EFORMAT,
            "face refers to vertex -4611686018427387903, but the file has 8 vertices", LINE, 6);
    refused(five_then_face("wrap2.obj", "1 2 -4611686018427387903/1/1", 0), &o, HD_EFORMAT, "-4611686018427387903,",
            LINE, 6);
    refused(five_then_face("wrap3.obj", "1 2 -9223372036854775808", 3), &o, HD_EFORMAT, "refers to vertex", LINE, 6);
    refused(five_then_face("wrap4.obj", "1 2 99999999999999999999999", 3), &o, HD_EFORMAT, "refers to vertex", LINE, 6);
    refused(five_then_face("wrap5.obj", "1 2 -6", 0), &o, HD_EFORMAT, "refers to vertex -6", LINE, 6);
}

TEST(obj_relative_index_in_range_names_the_right_vertex) {
    hd_read_options_t o = sampling(4);
    o.seed = 3;
    hd_cloud_t *c = NULL, *d = NULL;
    hd_error_t e;
    CHECK_RC(hd_read_file(five_then_face("rel.obj", "-5 -4 -3", 2), &o, &c, &e), HD_OK);
    CHECK_RC(hd_read_file(five_then_face("abs.obj", "1 2 3", 2), &o, &d, &e), HD_OK);
    CHECK_EQ(c->count, d->count);
    CHECK(memcmp(c->data, d->data, c->count * 3 * sizeof(double)) == 0);
    hd_cloud_free(c);
    hd_cloud_free(d);
}

TEST(csv_with_decimal_commas_is_refused_without_the_option_naming_line_and_option) {
    /* "1,5" is 1.5 in a German spreadsheet and 1500 with an English
     * thousands separator: only the user can say which */
    refused(tf_printf("eu.csv", "1,5;2,5;3,5\n4,25;5,5;6,75\n"), NULL, HD_EFORMAT,
            "'1,5' has a decimal comma (column 1)", LINE, 1);
    refused(tf_printf("eu2.csv", "x;y;z;i\n1;2;3;99\n4 ; 5,5 ; 6;0\n"), NULL, HD_EFORMAT,
            "'5,5' has a decimal comma (column 2)", LINE, 3);
    refused(tf_printf("eu3.csv", "1,500;2,000;3,000\n"), NULL, HD_EFORMAT, "decimal_comma", LINE, 1);
}

TEST(csv_with_decimal_commas_is_read_right_with_the_option) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.decimal_comma = 1;
    const double want[] = {1.5, 2.5, 3.5, 4.25, 5.5, 6.75};
    reads(tf_printf("eu.csv", "1,5;2,5;3,5\n4,25;5,5;6,75\n"), &o, want, 2);
    reads(tf_printf("eu2.csv", "x;y;z;i\n1,5;2,5;3,5;99\n4,25 ; 5,5 ; 6,75;0\n"), &o, want, 2);
    reads(tf_printf("eu3.txt", "1,5 2,5 3,5\n4,25\t5,5 6,75\n"), &o, want, 2);
    const double plain[] = {1, 2, 3, 4, 5, 6};
    reads(tf_printf("eu4.csv", "1;2;3\n4;5;6\n"), &o, plain, 2);
    /* with the option a comma never separates fields */
    refused(tf_printf("commas.csv", "1;2;3\n1,5,2,5,3,5\n"), &o, HD_EFORMAT, "is not a number", LINE, 2);
    o.decimal_comma = 2;
    refused(tf_printf("eu5.csv", "1;2;3\n"), &o, HD_EINVAL, "decimal_comma must be 0 or 1", NONE, 0);
}

TEST(csv_with_semicolons_or_commas_and_decimal_points_is_read_by_default) {
    const double want[] = {1.5, 2.5, 3.5, 4.25, 5.5, 6.75};
    reads(tf_printf("semi.csv", "1.5;2.5;3.5\n4.25 ; 5.5 ; 6.75\n"), NULL, want, 2);
    const double plain[] = {1, 2, 3, 4, 5, 6};
    reads(tf_printf("semi2.csv", "1;2;3\n4;5;6\n"), NULL, plain, 2);
    reads(tf_printf("comma.csv", "x,y,z\n1,2,3\n4,5,6\n"), NULL, plain, 2);
}

TEST(csv_whose_separators_cannot_be_told_apart_is_refused_with_its_line) {
    refused(tf_printf("mixed.csv", "1,2,3\n4;5;6\n"), NULL, HD_EFORMAT, "mixed separators", LINE, 2);
    refused(tf_printf("two.csv", "1;2;3\n1,2,5;3;4\n"), NULL, HD_EFORMAT, "'1,2,5' is not a number", LINE, 2);
    refused(tf_printf("both.csv", "1;2;3\n1.5,0;2;3\n"), NULL, HD_EFORMAT, "is not a number", LINE, 2);
}

static const char *solid_binary_stl(const char *name, int triangles, int extra) {
    tf_buf_t b = {0};
    char h[80];
    memset(h, ' ', sizeof h);
    memcpy(h, "solid part exported by CAD", 26);
    h[79] = '\n';
    tf_put(&b, h, 80);
    tf_u32(&b, (uint32_t)triangles, 0);
    for (int t = 0; t < triangles; t++) {
        for (int k = 0; k < 3; k++) tf_f32(&b, k == 2 ? 1.0f : 0.0f, 0);
        for (int k = 0; k < 9; k++) tf_f32(&b, (float)(t + (k == 3 || k == 7)), 0);
        tf_u16(&b, 0, 0);
    }
    for (int k = 0; k < extra; k++) tf_u8(&b, '\n');
    return tf_finish(&b, name);
}

TEST(stl_binary_whose_header_starts_with_solid_is_read_as_binary) {
    const double want[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 1, 2, 1, 1, 1, 2, 1};
    reads(solid_binary_stl("solid.stl", 2, 0), NULL, want, 6);
    hd_read_options_t o = sampling(5);
    hd_cloud_t *c = NULL;
    hd_error_t e;
    CHECK_RC(hd_read_file(solid_binary_stl("solid2.stl", 2, 0), &o, &c, &e), HD_OK);
    CHECK_EQ(c->count, 5);
    hd_cloud_free(c);
}

TEST(stl_binary_with_bytes_after_its_triangles_is_refused_naming_both_sizes) {
    refused(solid_binary_stl("tail.stl", 2, 1), NULL, HD_EFORMAT, "declares 2 triangles (184 bytes), but the file has 185",
            OFFSET, 184);
    refused(solid_binary_stl("tail2.stl", 1, 200), NULL, HD_EFORMAT, "200 bytes after the last triangle", OFFSET, 134);
}

TEST(sampling_a_mesh_near_the_coordinate_limit_draws_points_on_it) {
    /* areas of 1e200 square to infinity in the plain sum */
    hd_read_options_t o = sampling(100);
    hd_cloud_t *c = NULL;
    hd_error_t e;
    const char *p = tf_printf("big.obj", "v 0 0 0\nv 1e100 0 0\nv 0 1e100 0\nv 1e150 1e150 1e150\nv -1e150 1e150 0\n"
                                         "f 1 2 3\nf 1 4 5\n");
    int rc = hd_read_file(p, &o, &c, &e);
    if (rc) hdt_fail(__FILE__, __LINE__, "refused: %s", e.message);
    CHECK_EQ(c->count, 100);
    const double *x = c->data;
    for (size_t k = 0; k < 300; k++) CHECK(x[k] >= -1e150 && x[k] <= 1e150);
    hd_cloud_free(c);
    /* a mesh of ordinary size samples exactly as before (the plain path) */
    o.seed = 9;
    const double *d;
    CHECK_RC(hd_read_file(tf_printf("small.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), &o, &c, &e), HD_OK);
    d = c->data;
    for (size_t k = 0; k < 100; k++) CHECK(d[3 * k] >= 0 && d[3 * k + 1] >= 0 && d[3 * k] + d[3 * k + 1] <= 1 + 1e-15);
    hd_cloud_free(c);
}

/* ---- text encodings, decimal commas with every separator, first lines ---- */

TEST(decimal_commas_between_blank_separated_fields_are_refused_naming_line_and_option) {
    /* a European spreadsheet's tab export read as (4, 25, 5) */
    refused(tf_printf("tab.txt", "4,25\t5,5\t6,75\n1,5\t2,5\t3,5\n"), NULL, HD_EFORMAT,
            "'4,25' has a comma between digits where blanks separate fields", LINE, 1);
    refused(tf_printf("space.xyz", "# cloud\n1 2 3\n4,25 5,5 6,75\n"), NULL, HD_EFORMAT, "decimal_comma read option",
            LINE, 3);
    refused(tf_printf("blanks.txt", "1 2 3\n4  \t 5 6,75\n"), NULL, HD_EFORMAT, "'6,75' has a comma between digits",
            LINE, 2);
    refused(tf_printf("z.xyz", "1 2 3,5 100\n"), NULL, HD_EFORMAT, "'3,5'", LINE, 1);
}

TEST(thousands_separators_between_blank_separated_fields_are_refused) {
    /* read as (1, 234.5, 2) and (1, 234, 567.5) */
    refused(tf_printf("th.xyz", "1,234.5 2,345.6 3,456.7\n"), NULL, HD_EFORMAT,
            "'1,234.5' has a comma between digits where blanks separate fields: a decimal comma or a thousands "
            "separator", LINE, 1);
    refused(tf_printf("th2.xyz", "0 0 0\n1,234,567.5 2 3\n"), NULL, HD_EFORMAT, "'1,234,567.5'", LINE, 2);
    refused(tf_printf("th3.xyz", "0 0 0\n7\t8\t1,000\n"), NULL, HD_EFORMAT, "'1,000'", LINE, 2);
}

TEST(decimal_commas_with_every_separator_are_read_with_the_option) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.decimal_comma = 1;
    const double want[] = {4.25, 5.5, 6.75, -1.5, 2, 0.25};
    static const char *const seps[] = {"\t", " ", ";", " ; ", " \t ", "\t;"};
    for (size_t k = 0; k < sizeof seps / sizeof seps[0]; k++) {
        const char *s = seps[k];
        reads(tf_printf("dc.txt", "4,25%s5,5%s6,75\n-1,5%s2%s0,25\n", s, s, s, s), &o, want, 2);
        /* and without the option: refused, never read otherwise */
        refused(tf_printf("dc.txt", "4,25%s5,5%s6,75\n-1,5%s2%s0,25\n", s, s, s, s), NULL, HD_EFORMAT, "decimal_comma",
                LINE, 1);
    }
}

TEST(commas_that_separate_fields_are_still_read) {
    const double want[] = {1, 2, 3, 4, 5, 6};
    reads(tf_printf("c1.csv", "1,2,3\n4,5,6\n"), NULL, want, 2);
    reads(tf_printf("c2.csv", "1, 2, 3\n4 ,5 ,6\n"), NULL, want, 2);
    reads(tf_printf("c3.csv", "x,y,z,name\n1,2,3,a label with blanks\n4,5,6,another one\n"), NULL, want, 2);
    /* a decimal comma after z is in a column that is not read */
    reads(tf_printf("c4.xyz", "1 2 3 0,5\n4 5 6 1,5\n"), NULL, want, 2);
}

/* The same points from `text` with a UTF-8 byte-order mark in front. */
static void bom_reads_the_same(const char *name, const char *text) {
    CONTEXT("%s", name);
    hd_cloud_t *a = NULL, *b = NULL;
    hd_error_t e;
    int rc = hd_read_file(tf_printf(name, "%s", text), NULL, &a, &e);
    if (rc) hdt_fail(__FILE__, __LINE__, "refused without the mark: %s", e.message);
    rc = hd_read_file(tf_printf(name, "\xef\xbb\xbf%s", text), NULL, &b, &e);
    if (rc) hdt_fail(__FILE__, __LINE__, "refused with the mark: %s", e.message);
    if (a && b) {
        CHECK_EQ(b->count, a->count);
        CHECK(b->count == a->count && memcmp(a->data, b->data, a->count * 3 * sizeof(double)) == 0);
    }
    hd_cloud_free(a);
    hd_cloud_free(b);
}

static const char *const PLY_TEXT = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                                    "property float z\nend_header\n9 9 9\n1 2 3\n";
static const char *const PCD_TEXT = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\n"
                                    "HEIGHT 1\nPOINTS 2\nDATA ascii\n9 9 9\n1 2 3\n";
static const char *const STL_TEXT = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 9 9 9\nvertex 1 0 0\n"
                                    "vertex 0 1 0\nendloop\nendfacet\nendsolid s\n";

TEST(a_utf8_byte_order_mark_is_skipped_by_every_text_reader) {
    /* the first point was dropped (taken for a header, or `\xef\xbb\xbfv` an unknown statement) */
    bom_reads_the_same("b.xyz", "9 9 9\n1 2 3\n");
    bom_reads_the_same("b.csv", "9,9,9\n1,2,3\n");
    bom_reads_the_same("h.csv", "x,y,z\n9,9,9\n1,2,3\n");
    bom_reads_the_same("b.pts", "2\n9 9 9 1 2 3 4\n1 2 3 1 2 3 4\n");
    bom_reads_the_same("b.obj", "v 9 9 9\nv 1 2 3\n");
    bom_reads_the_same("b.off", "OFF\n2 0 0\n9 9 9\n1 2 3\n");
    bom_reads_the_same("b.ply", PLY_TEXT);
    bom_reads_the_same("b.pcd", PCD_TEXT);
    bom_reads_the_same("b.stl", STL_TEXT);
    /* and where the content decides the format */
    bom_reads_the_same("b.dat", "9 9 9\n1 2 3\n");
    bom_reads_the_same("o.dat", "v 9 9 9\nv 1 2 3\n");
    bom_reads_the_same("p.dat", PLY_TEXT);
}

/* `text` as UTF-16 or UTF-32 is refused naming the encoding. */
static void wide_refused(const char *name, const char *text) {
    static const struct {
        int width, big, bom;
    } enc[] = {{2, 0, 1}, {2, 1, 1}, {2, 0, 0}, {2, 1, 0}, {4, 0, 1}, {4, 1, 1}, {4, 0, 0}, {4, 1, 0}};
    for (size_t k = 0; k < sizeof enc / sizeof enc[0]; k++) {
        CONTEXT("%s as UTF-%d, %s endian, %s byte-order mark", name, 8 * enc[k].width, enc[k].big ? "big" : "little",
                enc[k].bom ? "with a" : "without a");
        tf_buf_t b = {0};
        tf_wide(&b, text, strlen(text), enc[k].width, enc[k].big, enc[k].bom);
        char want[64];
        snprintf(want, sizeof want, "UTF-%d text; convert to UTF-8", 8 * enc[k].width);
        refused(tf_finish(&b, name), NULL, HD_EFORMAT, want, NONE, 0);
    }
}

TEST(utf16_and_utf32_text_is_refused_naming_the_encoding) {
    /* once "'' is not a number", "no points", or a UTF-16 ascii STL read as
     * binary with 1818521189 triangles */
    wide_refused("w.xyz", "9 9 9\n1 2 3\n");
    wide_refused("w.csv", "x,y,z\n9,9,9\n1,2,3\n");
    wide_refused("w.obj", "v 9 9 9\nv 1 2 3\n");
    wide_refused("w.off", "OFF\n2 0 0\n9 9 9\n1 2 3\n");
    wide_refused("w.ply", PLY_TEXT);
    wide_refused("w.pcd", PCD_TEXT);
    wide_refused("w.stl", STL_TEXT);
    wide_refused("w.dat", "9 9 9\n1 2 3\n");
}

TEST(a_binary_stl_whose_header_looks_like_utf16_is_read_by_its_size) {
    tf_buf_t b = {0};
    tf_wide(&b, "solid part", 10, 2, 0, 1);
    while (b.size < 80) tf_u8(&b, 0);
    tf_u32(&b, 1, 0);
    for (int k = 0; k < 12; k++) tf_f32(&b, k == 2 || k == 5 || k == 10 ? 1.0f : 0.0f, 0);
    tf_u16(&b, 0, 0);
    const double want[] = {0, 0, 1, 0, 0, 0, 0, 1, 0};
    reads(tf_finish(&b, "w16.stl"), NULL, want, 3);
}

TEST(a_malformed_number_on_line_1_is_refused_as_on_line_2) {
    /* line 1 was taken for a header: one point fewer, exit 0 */
    static const char *const bad[] = {"1.#QNAN 2 3", "1.5D+03 0 0", "3.14abc 1 1", "- 1 2", "+.5e 1 2", "1.#INF,0,0",
                                      ".x 1 2"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char tok[16];
        snprintf(tok, sizeof tok, "'%.*s'", (int)strcspn(bad[k], " ,"), bad[k]);
        refused(tf_printf("m1.xyz", "%s\n1 1 1\n", bad[k]), NULL, HD_EFORMAT, tok, LINE, 1);
        refused(tf_printf("m2.xyz", "1 1 1\n%s\n", bad[k]), NULL, HD_EFORMAT, tok, LINE, 2);
    }
    refused(tf_printf("nan.xyz", "nan 1 2\n1 1 1\n"), NULL, HD_ENONFINITE, "NaN", LINE, 1);
    refused(tf_printf("inf.csv", "-Infinity,1,2\n1,1,1\n"), NULL, HD_ENONFINITE, "infinite", LINE, 1);
    refused(tf_printf("count.pts", "1.#QNAN\n1 1 1\n"), NULL, HD_EFORMAT, "'1.#QNAN' is not a number", LINE, 1);
}

TEST(header_lines_are_those_before_the_first_line_that_can_start_a_number) {
    const double want[] = {1, 2, 3, 4, 5, 6};
    static const char *const headers[] = {"x y z\n", "X,Y,Z\n", "index,x,y,z\n", "infrared x y\n", "name;x;y;z\n",
                                          "# exported\nx,y,z\n", "title\n\nx y z (m)\n", "-x -y -z\n", "nanometres\n"};
    for (size_t k = 0; k < sizeof headers / sizeof headers[0]; k++) {
        int semi = strchr(headers[k], ';') != NULL;
        reads(tf_printf("head.csv", "%s1%s2%s3\n4%s5%s6\n", headers[k], semi ? ";" : ",", semi ? ";" : ",",
                        semi ? ";" : ",", semi ? ";" : ","),
              NULL, want, 2);
    }
}

TEST(a_carriage_return_that_ends_no_line_is_refused_by_every_text_reader) {
    /* every reader ends lines at '\n' and takes '\r' for a blank: classic Mac
     * OS line ends made one line of the file, read as its first point alone
     * ("1.5 2 3\r4 5 6\r" as (1.5, 2, 3); a PTS count "3\r1 2 3\r..." as the
     * point (3, 1, 2)), exit 0 */
    const char *const want = "carriage return";
    refused(tf_printf("mac.xyz", "1.5 2 3\r4 5 6\r7 8 9\r"), NULL, HD_EFORMAT, want, LINE, 1);
    refused(tf_printf("mac.pts", "3\r1 2 3\r4 5 6\r7 8 9\r"), NULL, HD_EFORMAT, want, LINE, 1);
    refused(tf_printf("mac.csv", "x,y,z\r1,2,3\r4,5,6\r"), NULL, HD_EFORMAT, want, LINE, 1);
    refused(tf_printf("mac.obj", "v 1 2 3\rv 4 5 6\rv 7 8 9\r"), NULL, HD_EFORMAT, want, LINE, 1);
    refused(tf_printf("mac.stl", "solid s\rfacet normal 0 0 1\router loop\rvertex 9 9 9\rvertex 1 0 0\r"
                                 "vertex 0 1 0\rendloop\rendfacet\rendsolid s\r"),
            NULL, HD_EFORMAT, want, LINE, 1);
    /* a stray one in a file of LF or CR LF lines, naming its line */
    refused(tf_printf("mixed.xyz", "0 0 0\n1 2 3\r4 5 6\n7 8 9\n"), NULL, HD_EFORMAT, want, LINE, 2);
    refused(tf_printf("mixed.obj", "v 0 0 0\r\nv 1 2 3\rv 4 5 6\r\n"), NULL, HD_EFORMAT, want, LINE, 2);
    refused(tf_printf("mixed.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                   "property float z\nend_header\n0 0 0\n1 2 3\r4 5 6\n7 8 9\n"),
            NULL, HD_EFORMAT, want, LINE, 9);
    refused(tf_printf("mixed.off", "OFF\n3 0 0\n0 0 0\n1 2 3\r4 5 6\n7 8 9\n"), NULL, HD_EFORMAT, want, LINE, 4);
    refused(tf_printf("mixed.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\n"
                                   "HEIGHT 1\nPOINTS 3\nDATA ascii\n0 0 0\n1 2 3\r4 5 6\n7 8 9\n"),
            NULL, HD_EFORMAT, want, LINE, 11);
}

TEST(line_ends_of_cr_lf_and_cr_cr_lf_are_read) {
    const double want[] = {1, 2, 3, 4, 5, 6};
    reads(tf_printf("crlf.xyz", "1 2 3\r\n4 5 6\r\n"), NULL, want, 2);
    reads(tf_printf("crcrlf.xyz", "1 2 3\r\r\n4 5 6\r\r\n"), NULL, want, 2);
    reads(tf_printf("crend.xyz", "1 2 3\r\n4 5 6\r"), NULL, want, 2);
    reads(tf_printf("crlf.obj", "v 1 2 3\r\nv 4 5 6\r\n"), NULL, want, 2);
}

TEST(quoted_numbers_are_refused_naming_the_line_never_read_as_a_header) {
    /* "\"1\",\"2\",\"3\"" was a header line: a file of quoted numbers read as
     * no points (with the empty policy zero, the distance 0, exit 0) */
    refused(tf_printf("q.csv", "\"x\",\"y\",\"z\"\n\"1.5\",\"2\",\"3\"\n\"4\",\"5\",\"6\"\n"), NULL, HD_EFORMAT,
            "quoted numbers are not read", LINE, 2);
    refused(tf_printf("q1.csv", "\"1.5\",\"2\",\"3\"\n"), NULL, HD_EFORMAT, "'\"1.5\"' is not a number", LINE, 1);
    refused(tf_printf("q2.txt", "\"-1\"\t\"2\"\t\"3\"\n"), NULL, HD_EFORMAT, "quoted numbers", LINE, 1);
    /* quoted names still head a header */
    const double want[] = {1, 2, 3};
    reads(tf_printf("qh.csv", "\"x\",\"y\",\"z\"\n1,2,3\n"), NULL, want, 1);
    reads(tf_printf("qh2.csv", "\"\",\"name\"\n1,2,3\n"), NULL, want, 1);
}

TEST(with_the_decimal_comma_option_a_point_is_refused_as_a_thousands_separator) {
    /* "1.234;2.345;3,5" (a German export whose numbers have a thousands
     * separator: 1234, 2345, 3.5) was read as (1.234, 2.345, 3.5), exit 0 */
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.decimal_comma = 1;
    refused(tf_printf("de.csv", "1;2;3\n1.234;2.345;3,5\n"), &o, HD_EFORMAT, "'1.234' has a point (column 1)", LINE, 2);
    refused(tf_printf("de2.txt", "0,5\t2\t1.000\n"), &o, HD_EFORMAT, "'1.000' has a point (column 3)", LINE, 1);
    refused(tf_printf("de3.csv", "1.234,5;2;3\n"), &o, HD_EFORMAT, "'1.234,5' is not a number", LINE, 1);
    refused(tf_printf("de4.csv", "1e3;.5;3\n"), &o, HD_EFORMAT, "'.5' has a point (column 2)", LINE, 1);
    /* without the option a point is the decimal point */
    const double want[] = {1.234, 2.345, 3.5};
    reads(tf_printf("en.csv", "1.234;2.345;3.5\n"), NULL, want, 1);
}

TEST(an_ascii_stl_statement_after_another_on_its_line_is_refused) {
    /* the rest of a line was skipped: "vertex 0 0 0 vertex 5 5 5" lost (5, 5,
     * 5) and "vertex 0 0 0 7" read, exit 0; a file written on one line was
     * its solid line alone, read as no points */
    refused(tf_printf("one.stl", "solid s facet normal 0 0 1 outer loop vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 "
                                 "endloop endfacet endsolid s\n"),
            NULL, HD_EFORMAT, "'facet normal", LINE, 1);
    refused(tf_printf("v2.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0 vertex 5 5 5\nvertex 1 0 0\n"
                                "vertex 0 1 0\nendloop\nendfacet\nendsolid s\n"),
            NULL, HD_EFORMAT, "'vertex' after 'vertex' on one line", LINE, 4);
    refused(tf_printf("v4.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0 7\nvertex 1 0 0\n"
                                "vertex 0 1 0\nendloop\nendfacet\nendsolid s\n"),
            NULL, HD_EFORMAT, "'7' after 'vertex'", LINE, 4);
    refused(tf_printf("fo.stl", "solid s\nfacet normal 0 0 1 outer loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                                "endloop endfacet\nendsolid s\n"),
            NULL, HD_EFORMAT, "'outer' after 'facet'", LINE, 2);
    /* a solid's name is any words */
    const double want[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    reads(tf_printf("name.stl", "solid facet normal maps, outer vertex loop\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                                "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid facet normal maps\n"),
          NULL, want, 3);
}
