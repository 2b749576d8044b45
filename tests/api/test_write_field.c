/*
 * test_write_field.c -- hd_write_field and hd_write_fields: per-point
 * fields written back into the input's own format, every other byte kept;
 * the points past a threshold alone; and the refusals.
 *
 * The outputs are checked two ways: read back by hd_read_file (the same
 * points), and taken apart here byte by byte, independently of the writer
 * (the PLY header and records, the LAS extra-bytes VLR and records), so
 * that a value is found where the format says and equal bit for bit.
 */
#include "check.h"
#include "files.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- helpers -------------------------------------------------------------- */

static uint64_t le(const unsigned char *p, int n) {
    uint64_t v = 0;
    for (int i = n - 1; i >= 0; i--) v = v << 8 | p[i];
    return v;
}
static double le_f64(const unsigned char *p) {
    uint64_t u = le(p, 8);
    double v;
    memcpy(&v, &u, 8);
    return v;
}
static double be_f64(const unsigned char *p) {
    uint64_t u = 0;
    for (int i = 0; i < 8; i++) u = u << 8 | p[i];
    double v;
    memcpy(&v, &u, 8);
    return v;
}

/* The points hd_read_file gives for path (doubles), count in *n. */
static double *points_of(const char *path, size_t *n) {
    hd_cloud_t *c = NULL;
    hd_error_t err;
    if (hd_read_file(path, NULL, &c, &err) != HD_OK) {
        CONTEXT("%s", err.message);
        *n = 0;
        return NULL;
    }
    hd_points_t p = hd_cloud_points(c);
    double *xyz = malloc(3 * p.count * sizeof *xyz + 1);
    for (size_t k = 0; k < p.count; k++) hd_points_get(&p, k, xyz + 3 * k);
    *n = p.count;
    hd_cloud_free(c);
    return xyz;
}

/* Values with every kind of double a distance can be: 0, tiny, huge,
 * repeated, not short in decimal. */
static void values(double *v, size_t n) {
    for (size_t k = 0; k < n; k++) v[k] = (double)(k * 7919 % 1000) / 3.0 + 1e-7 * (double)k;
    if (n > 0) v[0] = 0.0;
    if (n > 1) v[1] = 5e-324;
    if (n > 2) v[2] = 1e300;
    if (n > 3) v[3] = v[2];
}

static int write_field(const char *in, const char *out, const double *v, size_t n, hd_keep_t keep, double d,
                       size_t *written, hd_error_t *err) {
    hd_write_options_t o;
    hd_write_options_init(&o);
    o.keep = keep;
    o.threshold = d;
    return hd_write_field(in, out, v, n, &o, written, err);
}

/* The names and values of up to three fields: distance (values()),
 * nearest (an index), sign (+-1); field j's n values at v + j * n. */
static const char *const names3[3] = {"distance", "nearest", "sign"};

static void values3(double *v, size_t n) {
    values(v, n);
    for (size_t k = 0; k < n; k++) {
        v[n + k] = (double)(k * 31 % 17) - 1.0;
        v[2 * n + k] = k % 3 ? 1.0 : -1.0;
    }
}

static int write_fields(const char *in, const char *out, const double *v, size_t n, size_t nf, hd_keep_t keep,
                        double d, size_t *written, hd_error_t *err) {
    hd_write_options_t o;
    hd_write_options_init(&o);
    o.keep = keep;
    o.threshold = d;
    hd_field_t f[3];
    for (size_t j = 0; j < nf; j++) f[j].name = names3[j], f[j].values = v + j * n;
    return hd_write_fields(in, out, f, nf, n, &o, written, err);
}

/* No "*.tmp-*" file is left in the test directory. */
static int no_temporaries(void) {
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", tf_path("x"));
    *strrchr(dir, '/') = 0;
    DIR *d = opendir(dir);
    int clean = 1;
    for (struct dirent *e; d && (e = readdir(d));) clean &= strstr(e->d_name, ".tmp-") == NULL;
    if (d) closedir(d);
    return clean;
}

/* ---- PLY ------------------------------------------------------------------ */
TEST(ply_ascii_keeps_every_line_and_adds_the_property) {
    const char *in = tf_printf("a.ply", "ply\r\nformat ascii 1.0\r\ncomment kept\r\nelement vertex 4\r\nproperty float x\r\n"
                                        "property float y\r\nproperty float z\r\nproperty uchar red\r\nelement face 2\r\n"
                                        "property list uchar int vertex_indices\r\nend_header\r\n"
                                        "0 0 0 7\r\n1 0 0 8  \r\n0 1 0 9\r\n1.5 1 0.25 10\r\n3 0 1 2\r\n3 1 2 3\r\n");
    double v[4];
    values(v, 4);
    const char *out = tf_path("a_out.ply");
    hd_error_t err;
    size_t written = 0;
    CHECK_RC(write_field(in, out, v, 4, HD_KEEP_ALL, 0, &written, &err), HD_OK);
    CHECK_EQ(written, 4);
    size_t n;
    char *d = (char *)tf_read(out, &n);
    CHECK(d && strstr(d, "property uchar red\r\nproperty double distance\r\nelement face 2\r\n"));
    CHECK(d && strstr(d, "comment kept\r\n"));
    CHECK(d && strstr(d, "\r\n3 0 1 2\r\n3 1 2 3\r\n"));
    /* each vertex line: its own values, then the value's shortest text */
    const char *lines[4] = {"0 0 0 7 ", "1 0 0 8 ", "0 1 0 9 ", "1.5 1 0.25 10 "};
    const char *p = d ? strstr(d, "end_header\r\n") + 12 : NULL;
    for (int k = 0; p && k < 4; k++) {
        CONTEXT("vertex %d", k);
        CHECK(strncmp(p, lines[k], strlen(lines[k])) == 0);
        char *end;
        double got = strtod(p + strlen(lines[k]), &end);
        CHECK_BITS(got, v[k]);
        CHECK(strncmp(end, "\r\n", 2) == 0);
        p = end + 2;
    }
    size_t m;
    double *xyz = points_of(out, &m);
    CHECK_EQ(m, 4);
    CHECK(xyz && xyz[9] == 1.5 && xyz[11] == 0.25);
    free(xyz);
    free(d);
}

static const char *binary_ply(const char *name, int big) {
    tf_buf_t b = {0};
    tf_putf(&b, "ply\nformat binary_%s_endian 1.0\nelement vertex 3\nproperty double x\nproperty float y\n"
                "property int z\nproperty uchar quality\nelement face 1\nproperty list uchar uint vertex_indices\n"
                "element extra 1\nproperty short s\nend_header\n",
            big ? "big" : "little");
    for (int k = 0; k < 3; k++) {
        tf_f64(&b, k + 0.5, big);
        tf_f32(&b, (float)k * 2, big);
        tf_u32(&b, (uint32_t)(-k), big);
        tf_u8(&b, (unsigned)(200 + k));
    }
    tf_u8(&b, 3);
    for (uint32_t k = 0; k < 3; k++) tf_u32(&b, k, big);
    tf_u16(&b, 0x1234, big);
    return tf_finish(&b, name);
}

static void binary_case(int big) {
    CONTEXT("big-endian %d", big);
    const char *in = binary_ply(big ? "be.ply" : "le.ply", big);
    size_t nin;
    unsigned char *src = tf_read(in, &nin);
    double v[3];
    values(v, 3);
    const char *out = tf_path(big ? "be_out.ply" : "le_out.ply");
    hd_error_t err;
    CHECK_RC(write_field(in, out, v, 3, HD_KEEP_ALL, 0, NULL, &err), HD_OK);
    size_t n;
    unsigned char *d = tf_read(out, &n);
    const char *hend = d ? strstr((char *)d, "end_header\n") : NULL;
    CHECK(hend && strstr((char *)d, "property uchar quality\nproperty double distance\nelement face 1\n"));
    if (!hend || !src) return;
    const unsigned char *p = (const unsigned char *)hend + 11;
    const unsigned char *s = (const unsigned char *)strstr((char *)src, "end_header\n") + 11;
    for (int k = 0; k < 3; k++) { /* the 17-byte record as it was, then the value */
        CHECK(memcmp(p, s, 17) == 0);
        CHECK_BITS(big ? be_f64(p + 17) : le_f64(p + 17), v[k]);
        p += 25;
        s += 17;
    }
    size_t tail = nin - (size_t)(s - src); /* the face and extra elements, byte for byte */
    CHECK_EQ((size_t)(d + n - p), tail);
    CHECK(memcmp(p, s, tail) == 0);
    size_t m;
    double *xyz = points_of(out, &m);
    CHECK(m == 3 && xyz && xyz[3] == 1.5 && xyz[4] == 2 && xyz[5] == -1);
    free(xyz);
    free(d);
    free(src);
}

TEST(ply_binary_records_keep_their_bytes_and_gain_the_double) {
    binary_case(0);
    binary_case(1);
}

TEST(ply_subset_keeps_the_vertices_past_the_threshold_only) {
    const char *in = binary_ply("sub.ply", 0);
    double v[3] = {1.0, 3.0, 2.0};
    hd_error_t err;
    size_t written = 0;
    const char *out = tf_path("far.ply");
    CHECK_RC(write_field(in, out, v, 3, HD_KEEP_FARTHER, 1.0, &written, &err), HD_OK);
    CHECK_EQ(written, 2);
    size_t n;
    char *d = (char *)tf_read(out, &n);
    CHECK(d && strstr(d, "element vertex 2\n") && !strstr(d, "element face") && !strstr(d, "element extra"));
    size_t m;
    double *xyz = points_of(out, &m);
    CHECK(m == 2 && xyz && xyz[0] == 1.5 && xyz[3] == 2.5);
    free(xyz);
    free(d);
    /* d <= D: the complement, the field included */
    CHECK_RC(write_field(in, tf_path("near.ply"), v, 3, HD_KEEP_NEARER, 1.0, &written, &err), HD_OK);
    CHECK_EQ(written, 1);
    d = (char *)tf_read(tf_path("near.ply"), &n);
    const char *h = d ? strstr(d, "end_header\n") : NULL;
    CHECK(h && n == (size_t)(h + 11 - d) + 25 && le_f64((unsigned char *)h + 11 + 17) == 1.0);
    free(d);
}

TEST(ply_binary_vertices_larger_than_a_block_keep_their_bytes) {
    /* a vertex with a list of 20000 ints (80 KB, more than the writer
     * gathers before writing) between small ones */
    tf_buf_t b = {0};
    tf_putf(&b, "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nproperty list int int ids\nend_header\n");
    for (int k = 0; k < 3; k++) {
        for (int c = 0; c < 3; c++) tf_f32(&b, (float)(k + c), 0);
        uint32_t m = k == 1 ? 20000 : 2;
        tf_u32(&b, m, 0);
        for (uint32_t i = 0; i < m; i++) tf_u32(&b, i * 3 + (uint32_t)k, 0);
    }
    const char *in = tf_finish(&b, "biglist.ply");
    size_t nin;
    unsigned char *src = tf_read(in, &nin);
    double v[9];
    values3(v, 3);
    hd_error_t err;
    CHECK_RC(write_fields(in, tf_path("biglist_out.ply"), v, 3, 2, HD_KEEP_ALL, 0, NULL, &err), HD_OK);
    size_t n;
    unsigned char *d = tf_read(tf_path("biglist_out.ply"), &n);
    const char *h = d ? strstr((char *)d, "end_header\n") : NULL;
    const unsigned char *s = src ? (const unsigned char *)strstr((char *)src, "end_header\n") + 11 : NULL;
    CHECK(h && s && n == (size_t)((const unsigned char *)h + 11 - d) + (nin - (size_t)(s - src)) + 3 * 16);
    const unsigned char *p = h ? (const unsigned char *)h + 11 : NULL;
    for (int k = 0; p && s && k < 3; k++) {
        size_t rec = 16 + 4 * (k == 1 ? 20000 : 2);
        CHECK(memcmp(p, s, rec) == 0);
        CHECK_BITS(le_f64(p + rec), v[k]);
        CHECK_BITS(le_f64(p + rec + 8), v[3 + k]);
        p += rec + 16;
        s += rec;
    }
    free(d);
    free(src);
}

TEST(ply_with_the_property_already_is_refused) {
    const char *in = tf_printf("has.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                                          "property float z\nproperty float distance\nend_header\n0 0 0 1\n");
    double v = 2;
    hd_error_t err;
    CHECK_RC(write_field(in, tf_path("has_out.ply"), &v, 1, HD_KEEP_ALL, 0, NULL, &err), HD_EINVAL);
    CHECK(strstr(err.message, "already has a property 'distance'"));
    CHECK(access(tf_path("has_out.ply"), F_OK) != 0);
}

/* Several fields: one `property double` each, in order, after the
 * vertex's own; each vertex line or record gets the values in that
 * order; a subset is chosen by the first field. */
static void ply_ascii_fields(size_t nf) {
    CONTEXT("%zu fields", nf);
    const char *in = tf_printf("af.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                         "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                         "end_header\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n3 0 1 2\n");
    double v[12];
    values3(v, 4);
    const char *out = tf_path("af_out.ply");
    hd_error_t err;
    size_t written = 0;
    CHECK_RC(write_fields(in, out, v, 4, nf, HD_KEEP_ALL, 0, &written, &err), HD_OK);
    CHECK_EQ(written, 4);
    size_t n;
    char *d = (char *)tf_read(out, &n);
    char want[256] = "property float z\n";
    for (size_t j = 0; j < nf; j++) snprintf(want + strlen(want), 64, "property double %s\n", names3[j]);
    strcat(want, "element face 1\n");
    CHECK(d && strstr(d, want));
    const char *p = d ? strstr(d, "end_header\n") + 11 : NULL;
    for (size_t k = 0; p && k < 4 && !hdt_failed(); k++) {
        CONTEXT("vertex %zu", k);
        for (int c = 0; c < 3; c++) strtod(p, (char **)&p); /* x y z */
        for (size_t j = 0; j < nf; j++) {
            char *end;
            CHECK(*p == ' ');
            CHECK_BITS(strtod(p, &end), v[j * 4 + k]);
            p = end;
        }
        CHECK(*p == '\n');
        p++;
    }
    CHECK(p && strcmp(p, "3 0 1 2\n") == 0);
    free(d);
}

static void ply_binary_fields(int big, size_t nf) {
    CONTEXT("big-endian %d, %zu fields", big, nf);
    const char *in = binary_ply(big ? "bef.ply" : "lef.ply", big);
    size_t nin;
    unsigned char *src = tf_read(in, &nin);
    double v[9];
    values3(v, 3);
    const char *out = tf_path("bf_out.ply");
    hd_error_t err;
    for (int subset = 0; subset < 2; subset++) {
        CONTEXT("subset %d", subset);
        double d0 = v[0]; /* the first point's first value: the subset keeps the two others */
        size_t written = 0;
        CHECK_RC(write_fields(in, out, v, 3, nf, subset ? HD_KEEP_FARTHER : HD_KEEP_ALL, d0, &written, &err), HD_OK);
        size_t n;
        unsigned char *d = tf_read(out, &n);
        const char *hend = d ? strstr((char *)d, "end_header\n") : NULL;
        CHECK(hend && strstr((char *)d, nf == 2 ? "property uchar quality\nproperty double distance\nproperty double "
                                                  "nearest\n"
                                                : "property double distance\nproperty double nearest\nproperty double "
                                                  "sign\n"));
        CHECK(hend && strstr((char *)d, subset ? "\nend_header\n" : "\nelement face 1\n"));
        if (!hend || !src) return;
        const unsigned char *p = (const unsigned char *)hend + 11;
        const unsigned char *s = (const unsigned char *)strstr((char *)src, "end_header\n") + 11;
        size_t kept = 0;
        for (int k = 0; k < 3; k++, s += 17) {
            if (subset && !(v[k] > d0)) continue;
            CHECK(memcmp(p, s, 17) == 0);
            for (size_t j = 0; j < nf; j++) CHECK_BITS(big ? be_f64(p + 17 + 8 * j) : le_f64(p + 17 + 8 * j), v[j * 3 + k]);
            p += 17 + 8 * nf;
            kept++;
        }
        CHECK_EQ(written, kept);
        if (!subset) { /* the face and extra elements, byte for byte */
            size_t tail = nin - (size_t)(s - src);
            CHECK(n - (size_t)(p - d) == tail && memcmp(p, s, tail) == 0);
        } else {
            CHECK(kept == 2 && p == d + n);
        }
        free(d);
    }
    free(src);
}

TEST(ply_takes_two_and_three_fields_in_one_pass) {
    for (size_t nf = 2; nf <= 3; nf++) {
        ply_ascii_fields(nf);
        ply_binary_fields(0, nf);
        ply_binary_fields(1, nf);
    }
}

/* ---- LAS ------------------------------------------------------------------ */
/* A LAS file: version 1.minor, point format fmt, n points with `extra`
 * undescribed extra bytes each, and (1.4) one extended VLR after them. */
static const char *las_file(const char *name, unsigned minor, unsigned fmt, size_t n, unsigned extra) {
    static const unsigned base[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
    size_t header = minor >= 4 ? 375 : 227, rec = base[fmt] + extra, vlr = 54 + 10;
    tf_buf_t b = {0};
    tf_put(&b, "LASF", 4);
    while (b.size < 24) tf_u8(&b, 0);
    tf_u8(&b, 1);
    tf_u8(&b, minor);
    while (b.size < 94) tf_u8(&b, 'g');
    tf_u16(&b, (unsigned)header, 0);
    tf_u32(&b, (uint32_t)(header + vlr + 3), 0); /* 3 user bytes before the points */
    tf_u32(&b, 1, 0);
    tf_u8(&b, fmt);
    tf_u16(&b, (unsigned)rec, 0);
    tf_u32(&b, fmt >= 6 ? 0 : (uint32_t)n, 0);
    for (int r = 0; r < 5; r++) tf_u32(&b, fmt >= 6 ? 0 : (uint32_t)(r == 0 ? n : 0), 0);
    for (int c = 0; c < 3; c++) tf_f64(&b, 0.01, 0);
    for (int c = 0; c < 3; c++) tf_f64(&b, 100.0 * c, 0);
    for (int c = 0; c < 6; c++) tf_f64(&b, 12345.0, 0); /* bounds: rewritten in a subset */
    if (minor >= 4) {
        tf_u64(&b, 0, 0); /* waveform */
        tf_u64(&b, header + vlr + 3 + n * rec, 0);
        tf_u32(&b, 1, 0);
        tf_u64(&b, n, 0);
        for (int r = 0; r < 15; r++) tf_u64(&b, r == 0 ? n : 0, 0);
    }
    while (b.size < header) tf_u8(&b, 0);
    tf_u16(&b, 0, 0); /* a VLR of 10 bytes */
    char user[16] = "someone";
    tf_put(&b, user, 16);
    tf_u16(&b, 7, 0);
    tf_u16(&b, 10, 0);
    char desc[32] = "kept";
    tf_put(&b, desc, 32);
    tf_put(&b, "0123456789", 10);
    tf_put(&b, "usr", 3);
    for (size_t k = 0; k < n; k++) {
        tf_u32(&b, (uint32_t)(k * 100), 0);
        tf_u32(&b, (uint32_t)(-(int)k), 0);
        tf_u32(&b, (uint32_t)(k * k), 0);
        size_t done = 12;
        tf_u16(&b, 1000, 0);
        tf_u8(&b, fmt >= 6 ? (unsigned)((1 + k % 3) | 3 << 4) : (unsigned)((1 + k % 3) | 3 << 3));
        done += 3;
        while (done < rec) tf_u8(&b, (unsigned)(k + done)), done++;
    }
    if (minor >= 4) { /* an extended VLR */
        tf_u16(&b, 0, 0);
        tf_put(&b, user, 16);
        tf_u16(&b, 9, 0);
        tf_u64(&b, 4, 0);
        tf_put(&b, desc, 32);
        tf_put(&b, "EVLR", 4);
    }
    return tf_finish(&b, name);
}

typedef struct {
    size_t header, offset, rec, count;
    unsigned n_vlr;
    const unsigned char *eb; /* the extra-bytes VLR's data */
    size_t eb_len;
} las_t;

static int las_parse(const unsigned char *d, las_t *L) {
    memset(L, 0, sizeof *L);
    L->header = le(d + 94, 2);
    L->offset = le(d + 96, 4);
    L->n_vlr = (unsigned)le(d + 100, 4);
    L->rec = le(d + 105, 2);
    L->count = d[25] >= 4 ? le(d + 247, 8) : le(d + 107, 4);
    size_t p = L->header;
    for (unsigned i = 0; i < L->n_vlr; i++) {
        size_t len = le(d + p + 20, 2);
        if (memcmp(d + p + 2, "LASF_Spec", 10) == 0 && le(d + p + 18, 2) == 4) {
            L->eb = d + p + 54;
            L->eb_len = len;
        }
        p += 54 + len;
    }
    return L->eb != NULL;
}

static void las_case(unsigned minor, unsigned fmt) {
    CONTEXT("LAS 1.%u format %u", minor, fmt);
    size_t n = 50;
    unsigned extra = 3;
    const char *in = las_file(minor >= 4 ? "in14.las" : "in12.las", minor, fmt, n, extra);
    double *v = malloc(n * sizeof *v);
    values(v, n);
    const char *out = tf_path("out.las");
    hd_error_t err;
    CHECK_RC(write_field(in, out, v, n, HD_KEEP_ALL, 0, NULL, &err), HD_OK);
    size_t ni, no;
    unsigned char *s = tf_read(in, &ni), *d = tf_read(out, &no);
    las_t I, O;
    las_parse(s, &I);
    CHECK(las_parse(d, &O));
    CHECK_EQ(O.n_vlr, I.n_vlr + 1);
    CHECK_EQ(O.rec, I.rec + 8);
    CHECK_EQ(O.offset, I.offset + 54 + 2 * 192);
    CHECK_EQ(O.count, n);
    /* descriptors: the 3 undescribed bytes, then a double named distance */
    CHECK(O.eb_len == 384 && O.eb[2] == 0 && O.eb[3] == 3 && O.eb[192 + 2] == 10);
    CHECK(strcmp((const char *)O.eb + 192 + 4, "distance") == 0);
    CHECK(memcmp(d + O.offset - 3, "usr", 3) == 0);
    for (size_t k = 0; k < n; k++) {
        CHECK(memcmp(d + O.offset + k * O.rec, s + I.offset + k * I.rec, I.rec) == 0);
        CHECK_BITS(le_f64(d + O.offset + k * O.rec + I.rec), v[k]);
    }
    if (minor >= 4) { /* the extended VLR follows the points, its start moved */
        size_t evlr = le(d + 235, 8);
        CHECK_EQ(evlr, O.offset + n * O.rec);
        CHECK(evlr + 64 == no && memcmp(d + no - 4, "EVLR", 4) == 0);
    }
    size_t m;
    double *xyz = points_of(out, &m), *xyz0 = points_of(in, &m);
    CHECK(xyz && xyz0 && memcmp(xyz, xyz0, 3 * n * sizeof *xyz) == 0);
    free(xyz);
    free(xyz0);
    free(s);
    free(d);
    /* the subset: counts, counts by return and bounds of the kept points */
    size_t written = 0;
    CHECK_RC(write_field(in, out, v, n, HD_KEEP_FARTHER, 100.0, &written, &err), HD_OK);
    d = tf_read(out, &no);
    CHECK(las_parse(d, &O));
    CHECK_EQ(O.count, written);
    uint64_t by[4] = {0};
    size_t kept = 0;
    double maxx = -1e308;
    for (size_t k = 0; k < n; k++)
        if (v[k] > 100.0) {
            CHECK(memcmp(d + O.offset + kept * O.rec + 12, &(uint16_t){1000}, 2) == 0);
            CHECK_BITS(le_f64(d + O.offset + kept * O.rec + O.rec - 8), v[k]);
            by[1 + k % 3]++;
            if ((double)(k * 100) * 0.01 > maxx) maxx = (double)(k * 100) * 0.01;
            kept++;
        }
    CHECK_EQ(written, kept);
    CHECK_BITS(le_f64(d + 179), maxx);
    if (minor >= 4) {
        CHECK_EQ(le(d + 255, 8), by[1]);
        CHECK_EQ(le(d + 263, 8), by[2]);
        CHECK_EQ(le(d + 107, 4), fmt >= 6 ? 0 : kept);
    } else {
        CHECK_EQ(le(d + 107, 4), kept);
        CHECK_EQ(le(d + 111, 4), by[1]);
        CHECK_EQ(le(d + 119, 4), by[3]);
    }
    free(d);
    free(v);
}

TEST(las_records_keep_their_bytes_and_gain_an_extra_bytes_dimension) {
    las_case(2, 1);
    las_case(4, 6);
    las_case(4, 3);
}

TEST(las_with_the_dimension_already_is_refused) {
    const char *in = las_file("eb.las", 2, 0, 4, 0);
    double v[4] = {1, 2, 3, 4};
    hd_error_t err;
    CHECK_RC(write_field(in, tf_path("eb1.las"), v, 4, HD_KEEP_ALL, 0, NULL, &err), HD_OK);
    CHECK_RC(write_field(tf_path("eb1.las"), tf_path("eb2.las"), v, 4, HD_KEEP_ALL, 0, NULL, &err), HD_EINVAL);
    CHECK(strstr(err.message, "already describes a dimension 'distance'"));
    /* another name goes after it */
    hd_write_options_t o;
    hd_write_options_init(&o);
    o.name = "second";
    CHECK_RC(hd_write_field(tf_path("eb1.las"), tf_path("eb2.las"), v, 4, &o, NULL, &err), HD_OK);
    size_t n;
    unsigned char *d = tf_read(tf_path("eb2.las"), &n);
    las_t L;
    CHECK(d && las_parse(d, &L) && L.eb_len == 384 && L.rec == 36);
    CHECK(d && strcmp((const char *)L.eb + 192 + 4, "second") == 0 && le_f64(d + L.offset + 36 * 3 + 28) == 4.0);
    free(d);
}

/* Several fields: one descriptor each after the undescribed bytes' one,
 * named, with its kept values' range; 8 bytes each after every record. */
static void las_fields_case(unsigned minor, unsigned fmt, size_t nf, int subset) {
    CONTEXT("LAS 1.%u format %u, %zu fields, subset %d", minor, fmt, nf, subset);
    size_t n = 40;
    const char *in = las_file("inf.las", minor, fmt, n, 3);
    double *v = malloc(3 * n * sizeof *v);
    values3(v, n);
    const char *out = tf_path("outf.las");
    hd_error_t err;
    size_t written = 0;
    CHECK_RC(write_fields(in, out, v, n, nf, subset ? HD_KEEP_FARTHER : HD_KEEP_ALL, 100.0, &written, &err), HD_OK);
    size_t ni, no;
    unsigned char *s = tf_read(in, &ni), *d = tf_read(out, &no);
    las_t I, O;
    las_parse(s, &I);
    CHECK(las_parse(d, &O));
    CHECK_EQ(O.rec, I.rec + 8 * nf);
    CHECK_EQ(O.offset, I.offset + 54 + 192 * (1 + nf));
    CHECK(O.eb_len == 192 * (1 + nf) && O.eb[2] == 0 && O.eb[3] == 3);
    for (size_t j = 0; j < nf; j++) {
        const unsigned char *e = O.eb + 192 * (1 + j);
        CONTEXT("descriptor of %s", names3[j]);
        CHECK(e[2] == 10 && e[3] == 6 && strcmp((const char *)e + 4, names3[j]) == 0);
        double lo = 0, hi = 0;
        int any = 0;
        for (size_t k = 0; k < n; k++)
            if (!subset || v[k] > 100.0) {
                double x = v[j * n + k];
                if (!any || x < lo) lo = x;
                if (!any || x > hi) hi = x;
                any = 1;
            }
        CHECK_BITS(le_f64(e + 64), lo);
        CHECK_BITS(le_f64(e + 88), hi);
    }
    size_t kept = 0;
    for (size_t k = 0; k < n && !hdt_failed(); k++) {
        if (subset && !(v[k] > 100.0)) continue;
        const unsigned char *r = d + O.offset + kept * O.rec;
        CHECK(memcmp(r, s + I.offset + k * I.rec, I.rec) == 0);
        for (size_t j = 0; j < nf; j++) CHECK_BITS(le_f64(r + I.rec + 8 * j), v[j * n + k]);
        kept++;
    }
    CHECK(written == kept && O.count == kept);
    if (minor >= 4) CHECK(le(d + 235, 8) == O.offset + kept * O.rec && memcmp(d + no - 4, "EVLR", 4) == 0);
    free(s), free(d), free(v);
}

TEST(las_takes_several_fields_with_a_descriptor_each) {
    for (size_t nf = 2; nf <= 3; nf++)
        for (int subset = 0; subset < 2; subset++) {
            las_fields_case(2, 1, nf, subset);
            las_fields_case(4, 6, nf, subset);
            las_fields_case(4, 3, nf, subset);
        }
    /* an extra-bytes VLR with one field gets the others' descriptors after it */
    const char *in = las_file("ebf.las", 2, 0, 4, 0);
    double v[12];
    values3(v, 4);
    hd_error_t err;
    CHECK_RC(write_field(in, tf_path("ebf1.las"), v, 4, HD_KEEP_ALL, 0, NULL, &err), HD_OK);
    hd_write_options_t o;
    hd_write_options_init(&o);
    hd_field_t f[2] = {{"nearest", v + 4}, {"sign", v + 8}};
    CHECK_RC(hd_write_fields(tf_path("ebf1.las"), tf_path("ebf2.las"), f, 2, 4, &o, NULL, &err), HD_OK);
    size_t n;
    unsigned char *d = tf_read(tf_path("ebf2.las"), &n);
    las_t L;
    CHECK(d && las_parse(d, &L) && L.eb_len == 3 * 192 && L.rec == 20 + 24);
    for (int j = 0; d && j < 3; j++) {
        CHECK(strcmp((const char *)L.eb + 192 * j + 4, names3[j]) == 0);
        for (size_t k = 0; k < 4; k++) CHECK_BITS(le_f64(d + L.offset + k * L.rec + 20 + 8 * j), v[4 * j + k]);
    }
    free(d);
}

/* ---- text ----------------------------------------------------------------- */
TEST(text_lines_kept_with_the_value_as_a_column) {
    const char *in = tf_printf("pts.csv", "X,Y,Z\n# a comment\n1.5,2,3\n\n4,5,6,7\n");
    double v[2] = {0.1, 2.0 / 3.0};
    hd_error_t err;
    CHECK_RC(write_field(in, tf_path("o.csv"), v, 2, HD_KEEP_ALL, 0, NULL, &err), HD_OK);
    size_t n;
    char *d = (char *)tf_read(tf_path("o.csv"), &n);
    CHECK(d && strcmp(d, "X,Y,Z,distance\n# a comment\n1.5,2,3,0.1\n\n4,5,6,7,0.6666666666666666\n") == 0);
    free(d);
    /* a PTS count line gets the subset's count */
    in = tf_printf("s.pts", "3\n1 2 3\n4 5 6\n7 8 9\n");
    double w[3] = {5, 1, 6};
    CHECK_RC(write_field(in, tf_path("o.pts"), w, 3, HD_KEEP_FARTHER, 2, NULL, &err), HD_OK);
    d = (char *)tf_read(tf_path("o.pts"), &n);
    CHECK(d && strcmp(d, "2\n1 2 3 5\n7 8 9 6\n") == 0);
    free(d);
    /* semicolons and decimal commas */
    hd_read_options_t ro;
    hd_read_options_init(&ro);
    ro.decimal_comma = 1;
    hd_write_options_t o;
    hd_write_options_init(&o);
    o.read = &ro;
    in = tf_printf("dc.csv", "1,5;2;3\r\n");
    double u = 0.25;
    CHECK_RC(hd_write_field(in, tf_path("dc_out.csv"), &u, 1, &o, NULL, &err), HD_OK);
    d = (char *)tf_read(tf_path("dc_out.csv"), &n);
    CHECK(d && strcmp(d, "1,5;2;3;0,25\r\n") == 0);
    free(d);
    /* two fields: each value with its decimal comma, semicolons between */
    double u2 = 1.5;
    hd_field_t f[2] = {{"distance", &u}, {"nearest", &u2}};
    CHECK_RC(hd_write_fields(in, tf_path("dcf_out.csv"), f, 2, 1, &o, NULL, &err), HD_OK);
    d = (char *)tf_read(tf_path("dcf_out.csv"), &n);
    CHECK(d && strcmp(d, "1,5;2;3;0,25;1,5\r\n") == 0);
    free(d);
}

TEST(text_takes_several_columns_in_one_pass) {
    const char *in = tf_printf("pf.csv", "X,Y,Z\n1.5,2,3\n4,5,6\n7,8,9\n");
    double v[9] = {0.1, 2.0 / 3.0, 0.3, 3, 0, 12, 1, -1, 1};
    hd_error_t err;
    CHECK_RC(write_fields(in, tf_path("pf2.csv"), v, 3, 2, HD_KEEP_ALL, 0, NULL, &err), HD_OK);
    size_t n;
    char *d = (char *)tf_read(tf_path("pf2.csv"), &n);
    CHECK(d && strcmp(d, "X,Y,Z,distance,nearest\n1.5,2,3,0.1,3\n4,5,6,0.6666666666666666,0\n7,8,9,0.3,12\n") == 0);
    free(d);
    CHECK_RC(write_fields(in, tf_path("pf3.csv"), v, 3, 3, HD_KEEP_FARTHER, 0.2, NULL, &err), HD_OK);
    d = (char *)tf_read(tf_path("pf3.csv"), &n);
    CHECK(d && strcmp(d, "X,Y,Z,distance,nearest,sign\n4,5,6,0.6666666666666666,0,-1\n7,8,9,0.3,12,1\n") == 0);
    free(d);
}

TEST(fields_without_a_name_or_with_one_twice_are_refused) {
    const char *in = tf_printf("nf.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                                         "property float z\nproperty float nearest\nend_header\n0 0 0 1\n1 1 1 2\n");
    double v[2] = {1, 2};
    const char *out = tf_path("nf_out.ply");
    hd_write_options_t o;
    hd_write_options_init(&o);
    hd_error_t err;
    hd_field_t twice[2] = {{"distance", v}, {"distance", v}};
    CHECK_RC(hd_write_fields(in, out, twice, 2, 2, &o, NULL, &err), HD_EINVAL);
    CHECK(strstr(err.message, "fields 1 and 2 are both named 'distance'"));
    hd_field_t empty[2] = {{"distance", v}, {"", v}};
    CHECK_RC(hd_write_fields(in, out, empty, 2, 2, &o, NULL, &err), HD_EINVAL);
    hd_field_t none[1] = {{"distance", NULL}};
    CHECK_RC(hd_write_fields(in, out, none, 1, 2, &o, NULL, &err), HD_EINVAL);
    CHECK_RC(hd_write_fields(in, out, twice, 0, 2, &o, NULL, &err), HD_EINVAL);
    CHECK_RC(hd_write_fields(in, out, twice, 8192, 2, &o, NULL, &err), HD_EINVAL); /* checked before any is read */
    CHECK(strstr(err.message, "8192 fields, at most 8191"));
    CHECK_RC(hd_write_fields(in, out, NULL, 1, 2, &o, NULL, &err), HD_EINVAL);
    hd_field_t had[2] = {{"distance", v}, {"nearest", v}}; /* the second is a property of the file */
    CHECK_RC(hd_write_fields(in, out, had, 2, 2, &o, NULL, &err), HD_EINVAL);
    CHECK(strstr(err.message, "already has a property 'nearest'"));
    CHECK(access(out, F_OK) != 0);
    CHECK(no_temporaries());
}

TEST(obj_subset_keeps_its_lines_without_the_faces) {
    const char *in = tf_printf("m.obj", "# cube\nv 0 0 0\nv 1 0 0\nvn 0 0 1\nv 0 1 0\nf 1 2 3\n");
    double v[3] = {3, 0, 4};
    hd_error_t err;
    size_t written;
    CHECK_RC(write_field(in, tf_path("m_out.obj"), v, 3, HD_KEEP_FARTHER, 1, &written, &err), HD_OK);
    size_t n;
    char *d = (char *)tf_read(tf_path("m_out.obj"), &n);
    CHECK(d && strcmp(d, "# cube\nv 0 0 0\nvn 0 0 1\nv 0 1 0\n") == 0);
    free(d);
    CHECK_RC(write_field(in, tf_path("m_all.obj"), v, 3, HD_KEEP_ALL, 0, NULL, &err), HD_EUNSUPPORTED);
    CHECK(strstr(err.message, "no place for a per-vertex value"));
}

/* ---- refusals and failures ---------------------------------------------- */
TEST(bad_arguments_are_refused_and_nothing_is_written) {
    const char *in = tf_printf("b.xyz", "1 2 3\n4 5 6\n");
    double v[2] = {1, 2};
    hd_error_t err;
    CHECK_RC(write_field(in, tf_path("b_out.xyz"), v, 3, HD_KEEP_ALL, 0, NULL, &err), HD_EINVAL);
    CHECK(strstr(err.message, "3 values for a file of 2 points"));
    CHECK_RC(write_field(in, tf_path("b_out.ply"), v, 2, HD_KEEP_ALL, 0, NULL, &err), HD_EINVAL);
    CHECK(strstr(err.message, "is xyz, so the output is xyz too"));
    CHECK_RC(write_field(in, in, v, 2, HD_KEEP_ALL, 0, NULL, &err), HD_EINVAL);
    CHECK(strstr(err.message, "is the input itself"));
    CHECK_RC(write_field(in, tf_path("b_out.xyz"), v, 2, HD_KEEP_FARTHER, 0.0 / 0.0, NULL, &err), HD_EINVAL);
    hd_write_options_t o;
    hd_write_options_init(&o);
    o.name = "two words";
    CHECK_RC(hd_write_field(in, tf_path("b_out.xyz"), v, 2, &o, NULL, &err), HD_EINVAL);
    CHECK(access(tf_path("b_out.xyz"), F_OK) != 0);
    CHECK(no_temporaries());
}

TEST(a_stream_is_refused_before_it_is_read) {
    const char *fifo = tf_path("fifo.xyz");
    CHECK(mkfifo(fifo, 0600) == 0);
    double v[1] = {1};
    hd_error_t err;
    CHECK_RC(write_field(fifo, tf_path("fifo_out.xyz"), v, 1, HD_KEEP_ALL, 0, NULL, &err), HD_EUNSUPPORTED);
    CHECK(strstr(err.message, "not a regular file"));
    CHECK_RC(write_field("-", tf_path("fifo_out.xyz"), v, 1, HD_KEEP_ALL, 0, NULL, &err), HD_EUNSUPPORTED);
}

TEST(an_output_that_cannot_be_written_is_an_io_error) {
    const char *in = tf_printf("w.xyz", "1 2 3\n");
    double v[1] = {1};
    hd_error_t err;
    CHECK_RC(write_field(in, "/nonexistent-dir/out.xyz", v, 1, HD_KEEP_ALL, 0, NULL, &err), HD_EIO);
    CHECK(strstr(err.message, "/nonexistent-dir/out.xyz: cannot create: No such file or directory"));
}

TEST(a_file_size_limit_leaves_no_file) {
    /* a write beyond RLIMIT_FSIZE fails with EFBIG once SIGXFSZ is ignored:
     * what a disk that fills half-way does too (ENOSPC) */
    size_t n = 20000;
    tf_buf_t b = {0};
    for (size_t k = 0; k < n; k++) tf_putf(&b, "%zu 1 2\n", k);
    const char *in = tf_finish(&b, "big.xyz");
    double *v = malloc(3 * n * sizeof *v);
    values3(v, n);
    struct rlimit old, lim;
    getrlimit(RLIMIT_FSIZE, &old);
    lim = old;
    lim.rlim_cur = 64 * 1024;
    void (*prev)(int) = signal(SIGXFSZ, SIG_IGN);
    CHECK(setrlimit(RLIMIT_FSIZE, &lim) == 0);
    hd_error_t err, err3;
    int rc = write_field(in, tf_path("big_out.xyz"), v, n, HD_KEEP_ALL, 0, NULL, &err);
    int rc3 = write_fields(in, tf_path("big_out3.xyz"), v, n, 3, HD_KEEP_ALL, 0, NULL, &err3);
    setrlimit(RLIMIT_FSIZE, &old);
    signal(SIGXFSZ, prev);
    CHECK_RC(rc, HD_EIO);
    CHECK(strstr(err.message, "cannot write: File too large"));
    CHECK(access(tf_path("big_out.xyz"), F_OK) != 0);
    CHECK_RC(rc3, HD_EIO); /* three fields in one pass: the same */
    CHECK(strstr(err3.message, "cannot write: File too large"));
    CHECK(access(tf_path("big_out3.xyz"), F_OK) != 0);
    CHECK(no_temporaries());
    free(v);
}
