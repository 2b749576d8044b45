/*
 * test_io_sweep.c -- a hostile sweep of every reader, on bytes in memory
 * (hd__read_buffer).  Small valid files of every format and variant (four
 * points; a tetrahedron's four faces for the meshes) are
 *   1. cut at every byte,
 *   2. given header counts, list lengths and face indices of 0, 1, 2, 2^31,
 *      2^32 + 1, 2^62 and 2^64 - 1 (as text, or in the binary field
 *      truncated to its width),
 *   3. followed by one stray byte, a newline, or a second copy of
 *      themselves,
 *   4. mutated one header byte at a time (0x00, 0xff, '9', '-', ' '),
 *   5. (text) put after a UTF-8 byte-order mark, encoded as UTF-16 and
 *      UTF-32 with and without marks, written with decimal commas or
 *      thousands separators between fields separated by every separator,
 *      given a malformed number or a header as their first line,
 * and read as vertices (double and float storage) and, for the meshes,
 * sampled.  Every variant is copied into a heap block of exactly its size,
 * so a read past its end is an AddressSanitizer error.
 *
 * The contract, everywhere: a read either succeeds with finite points
 * within range, or fails with a nonzero code, no cloud, and a message that
 * starts with the file name; it never crashes, never hangs (an alarm stops
 * a hung sweep), and never asks for absurd memory: allocations beyond
 * 1 GiB fail here (ASan: max_allocation_size_mb with
 * allocator_may_return_null; release: an address-space limit), so a count
 * that reached malloc shows up as HD_ENOMEM (or HD_EOVERFLOW), which is a
 * failure.  And no silent wrong read: a file whose count or binary layout
 * fixes its points is read whole or refused, never partially.
 *
 * A case that fails because a reader is not fixed yet is listed in
 * EXPECTED_FAILURES below with the reason; such a case is reported as an
 * expected failure, and an entry that no longer fails makes the test fail,
 * so the list shrinks as the readers are fixed.  HD_SWEEP_VERBOSE=1 in the
 * environment prints every violation, expected or not.
 */
#include "check.h"
#include "files.h"
#include "io/io.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <unistd.h>

/* ---- the allocation guard ------------------------------------------------ */

#define GUARD_BYTES ((size_t)1 << 30)

#if defined(__SANITIZE_ADDRESS__)
#define HD_SWEEP_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define HD_SWEEP_ASAN 1
#endif
#endif

#ifdef HD_SWEEP_ASAN
/* Read by ASan at start-up, before ASAN_OPTIONS (which may add to it). */
__attribute__((used, visibility("default"))) const char *__asan_default_options(void) {
    return "allocator_may_return_null=1:max_allocation_size_mb=1024";
}
#else
/* Release build: the address space may grow by at most GUARD_BYTES (plus
 * slack for the test's own small allocations), so a larger allocation
 * fails.  Reads here use one thread: no thread stacks or arenas. */
__attribute__((constructor)) static void limit_address_space(void) {
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long pages = 0;
    if (!f) return;
    if (fscanf(f, "%lu", &pages) != 1) pages = 0;
    fclose(f);
    if (!pages) return;
    struct rlimit rl;
    if (getrlimit(RLIMIT_AS, &rl) != 0) return;
    rlim_t want = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + GUARD_BYTES;
    if (rl.rlim_max != RLIM_INFINITY && want > rl.rlim_max) want = rl.rlim_max;
    if (rl.rlim_cur == RLIM_INFINITY || rl.rlim_cur > want) {
        rl.rlim_cur = want;
        setrlimit(RLIMIT_AS, &rl);
    }
}
#endif

/* ---- expected failures ---------------------------------------------------- */

/* Cases that fail today because a reader is not fixed yet.  A case key is
 * "SAMPLE SWEEP CASE MODE", e.g. "pcd_ascii count WIDTH=0 vertices/f64";
 * an entry matches every key it is a prefix of when the key goes on with
 * ' ' or '=' there (so "pcd_ascii count WIDTH" is every WIDTH value in
 * every mode), and only the violation whose message contains `symptom`.
 * Remove an entry when its reader is fixed: an entry that matches no
 * failure fails the test. */
typedef struct {
    const char *key;
    const char *symptom;
    const char *why;
    int hits;
} xfail_t;

/* Empty: the PCD WIDTH x HEIGHT check and the OFF face of fewer than 3
 * vertices that the sweep found were fixed in the readers. */
static xfail_t EXPECTED_FAILURES[] = {
    {NULL, NULL, NULL, 0},
};

static xfail_t *xfail_for(const char *key, const char *msg) {
    for (xfail_t *x = EXPECTED_FAILURES; x->key; x++) {
        size_t n = strlen(x->key);
        if (strncmp(key, x->key, n) == 0 && (key[n] == '\0' || key[n] == ' ' || key[n] == '=') &&
            strstr(msg, x->symptom))
            return x;
    }
    return NULL;
}

static int n_xfail_seen;

/* A violation of the contract in case `key`: an expected failure, or a
 * test failure naming the case. */
static void violation(const char *file, int line, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void violation(const char *file, int line, const char *key, const char *fmt, ...) {
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    static int verbose = -1;
    if (verbose < 0) verbose = getenv("HD_SWEEP_VERBOSE") != NULL;
    if (verbose) printf("  VIOLATION %s: %s\n", key, msg);
    xfail_t *x = xfail_for(key, msg);
    if (x) {
        if (x->hits++ == 0) printf("  expected failure [%s]: %s: %s\n", x->key, key, msg);
        n_xfail_seen++;
        return;
    }
    hdt_fail(file, line, "%s: %s", key, msg);
}
#define VIOLATION(key, ...) violation(__FILE__, __LINE__, key, __VA_ARGS__)

/* The sweeps that ran (a test run may pick some by name): an entry is
 * checked only when its sweep ran. */
static char sweeps_ran[8][16];
static void sweep_ran(const char *sweep) {
    for (int k = 0; k < 8; k++) {
        if (strcmp(sweeps_ran[k], sweep) == 0) return;
        if (!sweeps_ran[k][0]) {
            snprintf(sweeps_ran[k], sizeof sweeps_ran[k], "%s", sweep);
            return;
        }
    }
}
static int did_run(const char *key) {
    const char *sp = strchr(key, ' ');
    for (int k = 0; sp && k < 8 && sweeps_ran[k][0]; k++) {
        size_t n = strlen(sweeps_ran[k]);
        if (strncmp(sp + 1, sweeps_ran[k], n) == 0 && (sp[1 + n] == ' ' || sp[1 + n] == '\0')) return 1;
    }
    return 0;
}

/* ---- the sample files ---------------------------------------------------- */

/* The four points (exact in float and in LAS's 0.25 steps; the last text
 * coordinate is a single digit, so cutting it removes the token) and the
 * tetrahedron's faces. */
static const double PTS[4][3] = {{0, 0, 0}, {1.5, 0, 0}, {0, -2.25, 0}, {0.5, 0.5, 3}};
static const int FACES[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

enum kind { COUNT, LIST, INDEX };

/* A header count, list length or face index, and where it is. */
typedef struct {
    char label[40];
    size_t off, len; /* its bytes */
    int width;       /* 0: decimal text; 1, 2, 4, 8: a binary integer */
    int big;
    int pad;         /* text right-padded with spaces to len (npy) */
    int kind;
    uint64_t lo, hi; /* the values the file reads right with */
    int has_also;    /* `also` may be read right or refused */
    uint64_t also;
} field_t;

typedef struct {
    const char *id;
    const char *name; /* its name in messages; the extension picks the reader */
    int counted;      /* a count or the binary layout fixes the points */
    int binary;
    int mesh;
    size_t header;    /* header bytes, for the byte mutations */
    tf_buf_t b;
    field_t f[12];
    int nf;
} sample_t;

static void text_field(sample_t *s, const char *label, int kind, uint64_t truth, uint64_t lo, uint64_t hi,
                       int pad) {
    field_t *f = &s->f[s->nf++];
    snprintf(f->label, sizeof f->label, "%s", label);
    f->off = s->b.size;
    tf_putf(&s->b, "%llu", (unsigned long long)truth);
    if (pad)
        while (s->b.size - f->off < 20) tf_u8(&s->b, ' ');
    f->len = s->b.size - f->off;
    f->width = 0;
    f->pad = pad;
    f->kind = kind;
    f->lo = lo;
    f->hi = hi;
}
static void count_text(sample_t *s, const char *label, uint64_t truth) {
    text_field(s, label, COUNT, truth, truth, truth, 0);
}

static void put_int(unsigned char *p, int width, int big, uint64_t v) {
    for (int k = 0; k < width; k++) p[big ? width - 1 - k : k] = (unsigned char)(v >> (8 * k));
}

static void bin_field(sample_t *s, const char *label, int kind, uint64_t truth, uint64_t lo, uint64_t hi, int width,
                      int big) {
    field_t *f = &s->f[s->nf++];
    snprintf(f->label, sizeof f->label, "%s", label);
    f->off = s->b.size;
    unsigned char tmp[8];
    put_int(tmp, width, big, truth);
    tf_put(&s->b, tmp, (size_t)width);
    f->len = (size_t)width;
    f->width = width;
    f->big = big;
    f->pad = 0;
    f->kind = kind;
    f->lo = lo;
    f->hi = hi;
}

/* A field found after the fact (binary headers written in one go). */
static void bin_field_at(sample_t *s, const char *label, size_t off, int width, uint64_t truth) {
    field_t *f = &s->f[s->nf++];
    snprintf(f->label, sizeof f->label, "%s", label);
    f->off = off;
    f->len = (size_t)width;
    f->width = width;
    f->big = 0;
    f->pad = 0;
    f->kind = COUNT;
    f->lo = f->hi = truth;
}

static void put_coord_text(tf_buf_t *b, const double *p, const char *sep) {
    tf_putf(b, "%g%s%g%s%g", p[0], sep, p[1], sep, p[2]);
}

/* PLY: ascii (float, list uchar int), little endian (float, list uchar
 * int), big endian (double, list uint uint). */
static void build_ply(sample_t *s, int format) {
    static const char *const fmt[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    int big = format == 2;
    const char *vt = format == 2 ? "double" : "float";
    const char *lt = format == 2 ? "uint uint" : "uchar int";
    int cw = format == 2 ? 4 : 1;
    tf_putf(&s->b, "ply\nformat %s 1.0\ncomment a hostile sweep\nelement vertex ", fmt[format]);
    count_text(s, "element vertex", 4);
    tf_putf(&s->b, "\nproperty %s x\nproperty %s y\nproperty %s z\nelement face ", vt, vt, vt);
    count_text(s, "element face", 4);
    tf_putf(&s->b, "\nproperty list %s vertex_indices\nend_header\n", lt);
    s->header = s->b.size;
    for (int k = 0; k < 4; k++) {
        if (format == 0) {
            put_coord_text(&s->b, PTS[k], " ");
            tf_puts(&s->b, "\n");
        } else {
            for (int c = 0; c < 3; c++) {
                if (format == 2) tf_f64(&s->b, PTS[k][c], 1);
                else tf_f32(&s->b, (float)PTS[k][c], 0);
            }
        }
    }
    for (int k = 0; k < 4; k++) {
        int first = k == 0, last = k == 3;
        if (format == 0) {
            if (first || last) text_field(s, first ? "first list length" : "last list length", LIST, 3, 3, 3, 0);
            else tf_puts(&s->b, "3");
            for (int j = 0; j < 3; j++) {
                tf_puts(&s->b, " ");
                if ((first && j == 1) || (last && j == 2))
                    text_field(s, first ? "first face index" : "last face index", INDEX, (uint64_t)FACES[k][j], 0, 3, 0);
                else tf_putf(&s->b, "%d", FACES[k][j]);
            }
            tf_puts(&s->b, "\n");
        } else {
            if (first || last) bin_field(s, first ? "first list length" : "last list length", LIST, 3, 3, 3, cw, big);
            else {
                unsigned char tmp[4];
                put_int(tmp, cw, big, 3);
                tf_put(&s->b, tmp, (size_t)cw);
            }
            for (int j = 0; j < 3; j++) {
                if ((first && j == 1) || (last && j == 2))
                    bin_field(s, first ? "first face index" : "last face index", INDEX, (uint64_t)FACES[k][j], 0, 3, 4, big);
                else tf_u32(&s->b, (uint32_t)FACES[k][j], big);
            }
        }
    }
}

static void build_obj(sample_t *s) {
    tf_puts(&s->b, "# a hostile sweep\no tetrahedron\n");
    for (int k = 0; k < 4; k++) {
        tf_puts(&s->b, "v ");
        put_coord_text(&s->b, PTS[k], " ");
        tf_puts(&s->b, "\n");
    }
    for (int k = 0; k < 4; k++) {
        tf_puts(&s->b, "f");
        for (int j = 0; j < 3; j++) {
            tf_puts(&s->b, " ");
            if ((k == 0 && j == 1) || (k == 3 && j == 2))
                text_field(s, k == 0 ? "first face index" : "last face index", INDEX, (uint64_t)FACES[k][j] + 1, 1, 4, 0);
            else tf_putf(&s->b, "%d", FACES[k][j] + 1);
        }
        tf_puts(&s->b, "\n");
    }
}

static void build_off(sample_t *s) {
    tf_puts(&s->b, "OFF\n");
    count_text(s, "vertices", 4);
    tf_puts(&s->b, " ");
    count_text(s, "faces", 4);
    tf_puts(&s->b, " 6\n");
    s->header = s->b.size;
    for (int k = 0; k < 4; k++) {
        put_coord_text(&s->b, PTS[k], " ");
        tf_puts(&s->b, "\n");
    }
    for (int k = 0; k < 4; k++) {
        if (k == 0) text_field(s, "first face size", LIST, 3, 3, 3, 0);
        else tf_puts(&s->b, "3");
        for (int j = 0; j < 3; j++) {
            tf_puts(&s->b, " ");
            if ((k == 0 && j == 1) || (k == 3 && j == 2))
                text_field(s, k == 0 ? "first face index" : "last face index", INDEX, (uint64_t)FACES[k][j], 0, 3, 0);
            else tf_putf(&s->b, "%d", FACES[k][j]);
        }
        tf_puts(&s->b, "\n");
    }
}

static void build_stl(sample_t *s, int binary) {
    if (!binary) {
        tf_puts(&s->b, "solid sweep\n");
        for (int k = 0; k < 4; k++) {
            tf_puts(&s->b, "facet normal 0 0 0\nouter loop\n");
            for (int j = 0; j < 3; j++) {
                tf_puts(&s->b, "vertex ");
                put_coord_text(&s->b, PTS[FACES[k][j]], " ");
                tf_puts(&s->b, "\n");
            }
            tf_puts(&s->b, "endloop\nendfacet\n");
        }
        tf_puts(&s->b, "endsolid sweep\n");
        return;
    }
    char h[80];
    memset(h, 0, sizeof h);
    memcpy(h, "a hostile sweep: binary STL", 27);
    tf_put(&s->b, h, sizeof h);
    bin_field(s, "triangles", COUNT, 4, 4, 4, 4, 0);
    s->header = s->b.size;
    for (int k = 0; k < 4; k++) {
        for (int c = 0; c < 3; c++) tf_f32(&s->b, 0.0f, 0);
        for (int j = 0; j < 3; j++)
            for (int c = 0; c < 3; c++) tf_f32(&s->b, (float)PTS[FACES[k][j]][c], 0);
        tf_u16(&s->b, 0, 0);
    }
}

/* xyz (blanks), csv (header line, commas), pts (count line, extra
 * columns). */
static void build_text(sample_t *s, int variant) {
    if (variant == 1) tf_puts(&s->b, "x,y,z\n");
    if (variant == 2) {
        count_text(s, "count line", 4);
        tf_puts(&s->b, "\n");
        s->header = s->b.size;
    }
    for (int k = 0; k < 4; k++) {
        put_coord_text(&s->b, PTS[k], variant == 1 ? "," : " ");
        if (variant == 2) tf_putf(&s->b, " -%d 7 8 %d", k + 1, k + 1);
        tf_puts(&s->b, "\n");
    }
}

/* PCD: ascii (x y z), binary (x y z as F8 and a U2 intensity),
 * binary_compressed (x y z as F4, LZF literal runs). */
static void build_pcd(sample_t *s, int data) {
    tf_puts(&s->b, "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n");
    if (data == 1) tf_puts(&s->b, "FIELDS x y z intensity\nSIZE 8 8 8 2\nTYPE F F F U\nCOUNT 1 1 1 1\n");
    else tf_puts(&s->b, "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n");
    tf_puts(&s->b, "WIDTH ");
    count_text(s, "WIDTH", 4);
    tf_puts(&s->b, "\nHEIGHT ");
    count_text(s, "HEIGHT", 1);
    /* PCL reads HEIGHT 0 as 1 (an unorganised cloud) */
    s->f[s->nf - 1].has_also = 1;
    s->f[s->nf - 1].also = 0;
    tf_puts(&s->b, "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS ");
    count_text(s, "POINTS", 4);
    tf_puts(&s->b, data == 0 ? "\nDATA ascii\n" : data == 1 ? "\nDATA binary\n" : "\nDATA binary_compressed\n");
    s->header = s->b.size;
    if (data == 0) {
        for (int k = 0; k < 4; k++) {
            put_coord_text(&s->b, PTS[k], " ");
            tf_puts(&s->b, "\n");
        }
    } else if (data == 1) {
        for (int k = 0; k < 4; k++) {
            for (int c = 0; c < 3; c++) tf_f64(&s->b, PTS[k][c], 0);
            tf_u16(&s->b, 100u + (unsigned)k, 0);
        }
    } else {
        /* the fields one after another: all x, all y, all z */
        tf_buf_t raw = {0};
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 4; k++) tf_f32(&raw, (float)PTS[k][c], 0);
        bin_field(s, "compressed size", COUNT, raw.size + 2, raw.size + 2, raw.size + 2, 4, 0);
        bin_field(s, "uncompressed size", COUNT, raw.size, raw.size, raw.size, 4, 0);
        s->header = s->b.size;
        /* LZF literal runs: a control byte L - 1 < 32, then L bytes */
        tf_u8(&s->b, 31);
        tf_put(&s->b, raw.data, 32);
        tf_u8(&s->b, (unsigned)(raw.size - 32 - 1));
        tf_put(&s->b, raw.data + 32, raw.size - 32);
        tf_free(&raw);
    }
}

/* LAS 1.2 point format 0 (227-byte header), LAS 1.4 point format 6 (375
 * bytes, legacy count 0 as the specification asks, 64-bit count 4);
 * coordinates X * 0.25. */
static void build_las(sample_t *s, int v14) {
    tf_buf_t *b = &s->b;
    unsigned header = v14 ? 375 : 227, rec = v14 ? 30 : 20;
    tf_puts(b, "LASF");
    for (int k = 4; k < 24; k++) tf_u8(b, 0);
    tf_u8(b, 1);
    tf_u8(b, v14 ? 4 : 2);
    char sw[64];
    memset(sw, 0, sizeof sw);
    memcpy(sw, "hostile sweep", 13);
    tf_put(b, sw, 64); /* system identifier, generating software */
    tf_u16(b, 1, 0);   /* creation day */
    tf_u16(b, 2024, 0);
    tf_u16(b, header, 0);          /* 94 */
    tf_u32(b, header, 0);          /* 96: offset to point data */
    tf_u32(b, 0, 0);               /* 100: VLRs */
    tf_u8(b, v14 ? 6 : 0);         /* 104 */
    tf_u16(b, rec, 0);             /* 105 */
    tf_u32(b, v14 ? 0 : 4, 0);     /* 107: legacy count */
    for (int k = 0; k < 5; k++) tf_u32(b, k == 0 && !v14 ? 4 : 0, 0);
    for (int c = 0; c < 3; c++) tf_f64(b, 0.25, 0); /* 131 */
    for (int c = 0; c < 3; c++) tf_f64(b, 0, 0);    /* 155 */
    double mx[3] = {1.5, 0.5, 3}, mn[3] = {0, -2.25, 0};
    for (int c = 0; c < 3; c++) {
        tf_f64(b, mx[c], 0);
        tf_f64(b, mn[c], 0);
    }
    if (v14) {
        tf_u64(b, 0, 0); /* 227: waveform */
        tf_u64(b, 0, 0); /* 235: first EVLR */
        tf_u32(b, 0, 0); /* 243: EVLRs */
        tf_u64(b, 4, 0); /* 247: 64-bit count */
        for (int k = 0; k < 15; k++) tf_u64(b, k == 0 ? 4 : 0, 0);
    }
    CHECK_EQ(b->size, header);
    s->header = b->size;
    bin_field_at(s, "header size", 94, 2, header);
    bin_field_at(s, "point offset", 96, 4, header);
    bin_field_at(s, "record length", 105, 2, rec);
    bin_field_at(s, "legacy count", 107, 4, v14 ? 0 : 4);
    if (v14) bin_field_at(s, "64-bit count", 247, 8, 4);
    for (int k = 0; k < 4; k++) {
        for (int c = 0; c < 3; c++) tf_u32(b, (uint32_t)(int32_t)(PTS[k][c] * 4), 0);
        tf_u16(b, 10, 0); /* intensity */
        if (v14) {
            tf_u8(b, 0x11);
            tf_u8(b, 0);
            tf_u8(b, 2);
            tf_u8(b, 0);
            tf_u16(b, 0, 0);
            tf_u16(b, 1, 0);
            tf_f64(b, 1000.0 + k, 0);
        } else {
            tf_u8(b, 0x09);
            tf_u8(b, 2);
            tf_u8(b, 0);
            tf_u8(b, 0);
            tf_u16(b, 1, 0);
        }
    }
}

/* NPY 1.0 '<f8' C order; NPY 2.0 '>f4' Fortran order.  The shape's
 * numbers sit in 20-character slots padded with spaces, so any value fits
 * without moving the header's end. */
static void build_npy(sample_t *s, int v2) {
    tf_buf_t *b = &s->b;
    tf_put(b, "\x93NUMPY", 6);
    tf_u8(b, v2 ? 2 : 1);
    tf_u8(b, 0);
    size_t pre = v2 ? 12 : 10;
    size_t len_at = b->size;
    if (v2) tf_u32(b, 0, 0);
    else tf_u16(b, 0, 0);
    tf_puts(b, v2 ? "{'descr': '>f4', 'fortran_order': True, 'shape': (" : "{'descr': '<f8', 'fortran_order': False, 'shape': (");
    text_field(s, "shape rows", COUNT, 4, 4, 4, 1);
    tf_puts(b, ", ");
    text_field(s, "shape columns", COUNT, 3, 3, 3, 1);
    tf_puts(b, "), }");
    while ((b->size + 1) % 64) tf_u8(b, ' ');
    tf_u8(b, '\n');
    size_t hlen = b->size - pre;
    put_int(b->data + len_at, v2 ? 4 : 2, 0, hlen);
    bin_field_at(s, "header length", len_at, v2 ? 4 : 2, hlen);
    s->header = b->size;
    for (int k = 0; k < 12; k++) {
        int pt = v2 ? k % 4 : k / 3, c = v2 ? k / 4 : k % 3;
        if (v2) tf_f32(b, (float)PTS[pt][c], 1);
        else tf_f64(b, PTS[pt][c], 0);
    }
}

enum {
    PLY_ASCII, PLY_LE, PLY_BE, OBJ, OFF, STL_ASCII, STL_BINARY, XYZ, CSV, PTS_COUNT,
    PCD_ASCII, PCD_BINARY, PCD_COMPRESSED, LAS_12, LAS_14, NPY_1, NPY_2, N_SAMPLES
};

static sample_t samples[N_SAMPLES];

static void build_all(void) {
    static int built;
    if (built) return;
    built = 1;
    static const struct {
        const char *id, *name;
        int counted, binary, mesh;
    } info[N_SAMPLES] = {
        {"ply_ascii", "sweep.ply", 1, 0, 1},        {"ply_binary_le", "sweep.ply", 1, 1, 1},
        {"ply_binary_be", "sweep.ply", 1, 1, 1},    {"obj", "sweep.obj", 0, 0, 1},
        {"off", "sweep.off", 1, 0, 1},              {"stl_ascii", "sweep.stl", 0, 0, 1},
        {"stl_binary", "sweep.stl", 1, 1, 1},       {"xyz", "sweep.xyz", 0, 0, 0},
        {"csv", "sweep.csv", 0, 0, 0},              {"pts", "sweep.pts", 1, 0, 0},
        {"pcd_ascii", "sweep.pcd", 1, 0, 0},        {"pcd_binary", "sweep.pcd", 1, 1, 0},
        {"pcd_binary_compressed", "sweep.pcd", 1, 1, 0}, {"las_1_2", "sweep.las", 1, 1, 0},
        {"las_1_4", "sweep.las", 1, 1, 0},          {"npy_1_f8_c", "sweep.npy", 1, 1, 0},
        {"npy_2_f4_be_fortran", "sweep.npy", 1, 1, 0},
    };
    for (int k = 0; k < N_SAMPLES; k++) {
        sample_t *s = &samples[k];
        memset(s, 0, sizeof *s);
        s->id = info[k].id;
        s->name = info[k].name;
        s->counted = info[k].counted;
        s->binary = info[k].binary;
        s->mesh = info[k].mesh;
    }
    build_ply(&samples[PLY_ASCII], 0);
    build_ply(&samples[PLY_LE], 1);
    build_ply(&samples[PLY_BE], 2);
    build_obj(&samples[OBJ]);
    build_off(&samples[OFF]);
    build_stl(&samples[STL_ASCII], 0);
    build_stl(&samples[STL_BINARY], 1);
    build_text(&samples[XYZ], 0);
    build_text(&samples[CSV], 1);
    build_text(&samples[PTS_COUNT], 2);
    build_pcd(&samples[PCD_ASCII], 0);
    build_pcd(&samples[PCD_BINARY], 1);
    build_pcd(&samples[PCD_COMPRESSED], 2);
    build_las(&samples[LAS_12], 0);
    build_las(&samples[LAS_14], 1);
    build_npy(&samples[NPY_1], 0);
    build_npy(&samples[NPY_2], 1);
}

/* ---- reading ------------------------------------------------------------- */

enum { V64, V32, S64, N_MODES };
static const char *const MODE[N_MODES] = {"vertices/f64", "vertices/f32", "sample/f64"};
#define SAMPLE_N 16
#define SAMPLE_SEED 20240611u

static int modes_of(const sample_t *s) { return s->mesh ? N_MODES : S64; }

static hd_read_options_t options(int mode) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.threads = 1;
    if (mode == V32) o.dtype = HD_FLOAT32;
    if (mode == S64) {
        o.mesh = HD_MESH_SAMPLE;
        o.sample = SAMPLE_N;
        o.seed = SAMPLE_SEED;
    }
    return o;
}

/* What a read gave, compared with the whole file's read in the same mode. */
enum { REFUSED, SAME, FEWER, MORE, DIFFERENT, DOUBLED, N_OUTCOMES };
static const char *const OUTCOME[N_OUTCOMES] = {"refused", "read right", "read fewer points", "read more points",
                                                "read other points", "read the points twice"};

static hd_cloud_t *reference[N_SAMPLES][N_MODES];
static long long n_reads;

static size_t point_bytes(const hd_cloud_t *c) { return c->dtype == HD_FLOAT32 ? 12 : 24; }

/* Read d[0..n) (copied into a block of exactly n bytes) as sample s in
 * `mode`, check the contract, and classify the result.  *kept (may be
 * NULL) receives the cloud on success, else it is freed. */
/* The message of the last refusal observe() saw. */
static char refusal[sizeof(((hd_error_t *)0)->message)];

static int observe_with(const sample_t *s, int sidx, const unsigned char *d, size_t n, const hd_read_options_t *opt,
                        int mode, const char *key, hd_cloud_t **kept) {
    CONTEXT("%s (%zu bytes, sampling seed %u)", key, n, SAMPLE_SEED);
    unsigned char *copy = malloc(n ? n : 1);
    if (!copy) {
        hdt_fail(__FILE__, __LINE__, "out of memory in the test");
        return REFUSED;
    }
    if (n) memcpy(copy, d, n);
    hd_read_options_t o = *opt;
    hd_cloud_t *c = (hd_cloud_t *)copy; /* must become NULL on failure */
    hd_error_t e;
    memset(&e, 0, sizeof e);
    int rc = hd__read_buffer(copy, n, s->name, &o, &c, &e);
    n_reads++;
    free(copy);
    if (kept) *kept = NULL;
    if (rc != HD_OK) {
        size_t nl = strlen(s->name);
        if (c != NULL) VIOLATION(key, "refused (%s) but the cloud pointer was not set to NULL", hd_err_name(rc));
        if (e.code != rc) VIOLATION(key, "returned %s but err->code is %s", hd_err_name(rc), hd_err_name(e.code));
        if (strncmp(e.message, s->name, nl) != 0 || e.message[nl] != ':')
            VIOLATION(key, "message '%s' does not start with '%s:'", e.message, s->name);
        if (rc == HD_ENOMEM || rc == HD_EOVERFLOW)
            VIOLATION(key, "%s: a count reached the allocator (more than 1 GiB asked for?): %s", hd_err_name(rc),
                      e.message);
        if (rc == HD_EINVAL) VIOLATION(key, "HD_EINVAL for a file: %s", e.message);
        snprintf(refusal, sizeof refusal, "%s", e.message);
        return REFUSED;
    }
    if (!c) {
        VIOLATION(key, "succeeded without a cloud");
        return REFUSED;
    }
    int out = SAME;
    if (c->count == 0) VIOLATION(key, "succeeded with no points");
    if (mode == S64 && c->count != SAMPLE_N) VIOLATION(key, "sampled %zu points, asked for %d", c->count, SAMPLE_N);
    if (mode != S64 && c->count > n) VIOLATION(key, "%zu points from %zu bytes", c->count, n);
    hd_points_t p = hd_cloud_points(c);
    for (size_t k = 0; k < c->count; k++) {
        double q[3];
        hd_points_get(&p, k, q);
        for (int j = 0; j < 3; j++)
            if (!isfinite(q[j]) || fabs(q[j]) > HD_MAX_COORD) {
                VIOLATION(key, "point %zu has coordinate %g", k, q[j]);
                k = c->count;
                break;
            }
    }
    const hd_cloud_t *ref = reference[sidx][mode];
    if (ref) {
        size_t pb = point_bytes(ref);
        if (c->dtype != ref->dtype) out = DIFFERENT;
        else if (c->count == ref->count) out = memcmp(c->data, ref->data, c->count * pb) == 0 ? SAME : DIFFERENT;
        else if (c->count < ref->count) out = FEWER;
        else if (c->count == 2 * ref->count && memcmp(c->data, ref->data, ref->count * pb) == 0 &&
                 memcmp((char *)c->data + ref->count * pb, ref->data, ref->count * pb) == 0)
            out = DOUBLED;
        else out = MORE;
    }
    if (kept) *kept = c;
    else hd_cloud_free(c);
    return out;
}

static int observe(const sample_t *s, int sidx, const unsigned char *d, size_t n, int mode, const char *key,
                   hd_cloud_t **kept) {
    hd_read_options_t o = options(mode);
    return observe_with(s, sidx, d, n, &o, mode, key, kept);
}

static void setup(void) {
    build_all();
    for (int s = 0; s < N_SAMPLES; s++)
        for (int m = 0; m < modes_of(&samples[s]); m++)
            if (!reference[s][m]) {
                char key[128];
                snprintf(key, sizeof key, "%s whole %s", samples[s].id, MODE[m]);
                hd_cloud_t *c = NULL;
                if (observe(&samples[s], s, samples[s].b.data, samples[s].b.size, m, key, &c) == REFUSED)
                    hdt_fail(__FILE__, __LINE__, "%s: the valid sample file is refused", key);
                reference[s][m] = c;
            }
}

/* ---- the behaviours ------------------------------------------------------ */

TEST(the_allocation_guard_refuses_more_than_one_gib) {
    /* Without this, "no count reaches the allocator" would be vacuous. */
    static void *volatile sink;
    volatile size_t big = GUARD_BYTES + ((size_t)256 << 20);
#ifdef HD_SWEEP_ASAN
    fprintf(stderr, "  (ASan's warning that 0x%zx bytes could not be allocated is this test's own request)\n", (size_t)big);
#endif
    void *p = malloc(big);
    sink = p;
    CHECK(sink == NULL);
    free(p);
    p = malloc(1 << 20);
    sink = p;
    CHECK(sink != NULL);
    free(p);
}

TEST(every_sample_file_reads_its_points_exactly_in_every_mode) {
    setup();
    for (int s = 0; s < N_SAMPLES; s++) {
        const hd_cloud_t *c = reference[s][V64];
        if (!c) continue;
        CONTEXT("%s", samples[s].id);
        size_t want = s == STL_ASCII || s == STL_BINARY ? 12 : 4;
        CHECK_EQ(c->count, want);
        for (size_t k = 0; k < c->count && k < want; k++) {
            int pt = want == 12 ? FACES[k / 3][k % 3] : (int)k;
            for (int j = 0; j < 3; j++) CHECK_BITS(((const double *)c->data)[3 * k + j], PTS[pt][j]);
        }
        const hd_cloud_t *f = reference[s][V32];
        CHECK(f && f->count == want && f->dtype == HD_FLOAT32);
        if (samples[s].mesh) {
            const hd_cloud_t *m = reference[s][S64];
            CHECK(m && m->count == SAMPLE_N);
            /* the same tetrahedron in every mesh format gives the same samples */
            if (m && reference[PLY_ASCII][S64])
                CHECK(memcmp(m->data, reference[PLY_ASCII][S64]->data, SAMPLE_N * 24) == 0);
        }
    }
}

/* 1. Truncation. */
static void sweep_prefixes(int counted, long long *cases, long long *read) {
    setup();
    sweep_ran("prefix");
    alarm(120);
    for (int s = 0; s < N_SAMPLES; s++) {
        const sample_t *S = &samples[s];
        if (S->counted != counted) continue;
        for (int m = 0; m < modes_of(S); m++) {
            const hd_cloud_t *ref = reference[s][m];
            if (!ref) continue;
            for (size_t n = 0; n < S->b.size; n++) {
                char key[128];
                snprintf(key, sizeof key, "%s prefix %zu %s", S->id, n, MODE[m]);
                hd_cloud_t *c = NULL;
                int out = observe(S, s, S->b.data, n, m, key, &c);
                (*cases)++;
                if (out != REFUSED) (*read)++;
                if (counted) {
                    if (out != REFUSED && out != SAME)
                        VIOLATION(key, "a file cut to %zu of %zu bytes %s (%zu points, the whole file has %zu)", n,
                                  S->b.size, OUTCOME[out], c ? c->count : 0, ref->count);
                } else if (out == MORE) {
                    VIOLATION(key, "a file cut to %zu bytes read more points than the whole file", n);
                } else if (m != S64 && (out == FEWER || out == DIFFERENT) && c && c->count > 1) {
                    /* all but the last point (whose last number may be cut) are the file's first points */
                    if (memcmp(c->data, ref->data, (c->count - 1) * point_bytes(c)) != 0)
                        VIOLATION(key, "a file cut to %zu bytes read points that are not the file's first ones", n);
                }
                hd_cloud_free(c);
            }
        }
    }
    alarm(0);
}

TEST(a_truncated_counted_or_binary_file_is_refused_never_read_partially) {
    long long cases = 0, read = 0;
    sweep_prefixes(1, &cases, &read);
    printf("  %lld prefixes of counted/binary files, %lld read whole (trailing newline or padding cut)\n", cases, read);
}

TEST(a_truncated_text_file_without_counts_reads_a_prefix_of_its_points_or_is_refused) {
    long long cases = 0, read = 0;
    sweep_prefixes(0, &cases, &read);
    printf("  %lld prefixes of obj/stl ascii/xyz/csv files, %lld read\n", cases, read);
}

/* 2. Header counts, list lengths and face indices. */
static const uint64_t VALUES[] = {0, 1, 2, (uint64_t)1 << 31, ((uint64_t)1 << 32) + 1, (uint64_t)1 << 62, UINT64_MAX};

/* The file s with field f set to v (truncated to a binary field's width);
 * *stored: the value the field holds. */
static tf_buf_t with_value(const sample_t *s, const field_t *f, uint64_t v, uint64_t *stored) {
    tf_buf_t b = {0};
    if (f->width) {
        tf_put(&b, s->b.data, s->b.size);
        *stored = f->width == 8 ? v : v & (((uint64_t)1 << (8 * f->width)) - 1);
        put_int(b.data + f->off, f->width, f->big, *stored);
        return b;
    }
    *stored = v;
    char text[32];
    snprintf(text, sizeof text, "%llu", (unsigned long long)v);
    tf_put(&b, s->b.data, f->off);
    tf_puts(&b, text);
    if (f->pad)
        for (size_t k = strlen(text); k < f->len; k++) tf_u8(&b, ' ');
    tf_put(&b, s->b.data + f->off + f->len, s->b.size - f->off - f->len);
    return b;
}

static const char *const KIND[] = {"count", "list", "index"};

static void sweep_fields(int kind, long long *cases, long long *refused) {
    setup();
    sweep_ran(KIND[kind]);
    alarm(120);
    for (int s = 0; s < N_SAMPLES; s++) {
        const sample_t *S = &samples[s];
        for (int k = 0; k < S->nf; k++) {
            const field_t *f = &S->f[k];
            if (f->kind != kind) continue;
            for (size_t v = 0; v < sizeof VALUES / sizeof VALUES[0]; v++) {
                uint64_t stored;
                tf_buf_t b = with_value(S, f, VALUES[v], &stored);
                int right = stored >= f->lo && stored <= f->hi;
                for (int m = 0; m < modes_of(S); m++) {
                    char key[160];
                    snprintf(key, sizeof key, "%s %s %s=%llu %s", S->id, KIND[kind], f->label, (unsigned long long)stored,
                             MODE[m]);
                    int out = observe(S, s, b.data, b.size, m, key, NULL);
                    (*cases)++;
                    *refused += out == REFUSED;
                    if (f->has_also && stored == f->also) {
                        if (out != REFUSED && out != SAME)
                            VIOLATION(key, "%s %llu may be refused or read right, but the file %s", f->label,
                                      (unsigned long long)stored, OUTCOME[out]);
                    } else if (kind == INDEX && right) {
                        /* another vertex of the file: a valid file */
                        if (out == REFUSED || (m != S64 && out != SAME))
                            VIOLATION(key, "face index %llu is in range, but the file %s", (unsigned long long)stored,
                                      OUTCOME[out]);
                    } else if (right) {
                        if (out != SAME)
                            VIOLATION(key, "the true value %llu, but the file %s", (unsigned long long)stored,
                                      OUTCOME[out]);
                    } else if (kind == COUNT || m == S64) {
                        if (out != REFUSED)
                            VIOLATION(key, "%s %llu (true: %llu) is not refused: the file %s", f->label,
                                      (unsigned long long)stored, (unsigned long long)f->lo, OUTCOME[out]);
                    } else if (out != REFUSED && out != SAME) {
                        /* faces are not needed for the vertices: ignoring them is fine, misreading is not */
                        VIOLATION(key, "%s %llu: the vertices %s", f->label, (unsigned long long)stored, OUTCOME[out]);
                    }
                }
                tf_free(&b);
            }
        }
    }
    alarm(0);
}

TEST(header_counts_other_than_the_true_one_are_refused_without_allocating) {
    long long cases = 0, refused = 0;
    sweep_fields(COUNT, &cases, &refused);
    printf("  %lld header counts (element, vertex, face, WIDTH/HEIGHT/POINTS, PTS, STL, LAS, NPY shape and sizes), "
           "%lld refused\n",
           cases, refused);
}

TEST(face_list_lengths_that_disagree_with_their_items_are_refused_when_sampling) {
    long long cases = 0, refused = 0;
    sweep_fields(LIST, &cases, &refused);
    printf("  %lld face list lengths (ply, off), %lld refused\n", cases, refused);
}

TEST(face_indices_beyond_the_vertices_are_refused_when_sampling) {
    long long cases = 0, refused = 0;
    sweep_fields(INDEX, &cases, &refused);
    printf("  %lld face indices (ply, obj, off), %lld refused\n", cases, refused);
}

/* 3. Bytes after the data. */
enum { TAIL_ZERO, TAIL_BYTE, TAIL_NEWLINE, TAIL_COPY, N_TAILS };
static const char *const TAIL[N_TAILS] = {"one byte 0x00", "one byte 0xa5", "a newline", "a second copy"};
static const char *const TAIL_KEY[N_TAILS] = {"zero", "byte", "newline", "copy"};

/* Bytes after the data that docs/formats.md says are read as if absent. */
static const struct {
    int sample, tail;
} TOLERATED[] = {
    {PCD_BINARY, TAIL_ZERO},     /* PCL pads binary files with zeros */
    {PCD_COMPRESSED, TAIL_ZERO}, /* the same after the compressed block */
};

static int tolerated(int s, int t) {
    for (size_t k = 0; k < sizeof TOLERATED / sizeof TOLERATED[0]; k++)
        if (TOLERATED[k].sample == s && TOLERATED[k].tail == t) return 1;
    return 0;
}

static void sweep_tails(int group, char *accepted, size_t cap) {
    setup();
    sweep_ran("tail");
    alarm(120);
    accepted[0] = '\0';
    for (int s = 0; s < N_SAMPLES; s++) {
        const sample_t *S = &samples[s];
        int g = S->binary ? 0 : S->counted ? 1 : 2;
        if (g != group) continue;
        for (int t = 0; t < N_TAILS; t++) {
            tf_buf_t b = {0};
            tf_put(&b, S->b.data, S->b.size);
            if (t == TAIL_ZERO) tf_u8(&b, 0);
            if (t == TAIL_BYTE) tf_u8(&b, 0xa5);
            if (t == TAIL_NEWLINE) tf_u8(&b, '\n');
            if (t == TAIL_COPY) tf_put(&b, S->b.data, S->b.size);
            int took = 0;
            for (int m = 0; m < modes_of(S); m++) {
                char key[128];
                snprintf(key, sizeof key, "%s tail %s %s", S->id, TAIL_KEY[t], MODE[m]);
                int out = observe(S, s, b.data, b.size, m, key, NULL);
                took |= out != REFUSED;
                int ok;
                if (tolerated(s, t)) ok = out == SAME;
                else if (group == 0) ok = out == REFUSED; /* binary: the layout covers every byte */
                else if (t == TAIL_NEWLINE) ok = out == SAME;
                else if (group == 1) ok = out == REFUSED || (t != TAIL_COPY && out == SAME);
                else ok = out == REFUSED || out == SAME || (t == TAIL_COPY && (out == DOUBLED || m == S64));
                if (!ok) VIOLATION(key, "%s after the data: the file %s", TAIL[t], OUTCOME[out]);
            }
            if (took) {
                char one[96];
                snprintf(one, sizeof one, "%s%s (%s)", accepted[0] ? ", " : "", S->id, TAIL[t]);
                strncat(accepted, one, cap - strlen(accepted) - 1);
            }
            tf_free(&b);
        }
    }
    alarm(0);
}

TEST(bytes_after_the_data_of_a_binary_file_are_refused) {
    char accepted[2048];
    sweep_tails(0, accepted, sizeof accepted);
    printf("  binary files accepting trailing bytes: %s\n", accepted[0] ? accepted : "none");
}

TEST(a_counted_text_file_refuses_more_data_than_its_counts_and_tolerates_a_newline) {
    char accepted[2048];
    sweep_tails(1, accepted, sizeof accepted);
    printf("  counted text files accepting trailing bytes: %s\n", accepted[0] ? accepted : "none");
}

TEST(a_text_file_without_counts_reads_appended_points_as_more_points_or_refuses_them) {
    char accepted[2048];
    sweep_tails(2, accepted, sizeof accepted);
    printf("  uncounted text files accepting trailing bytes: %s\n", accepted[0] ? accepted : "none");
}

/* 4. One header byte at a time. */
static void sweep_header_bytes(int binary, long long *cases, long long *read) {
    static const unsigned char BYTES[] = {0x00, 0xff, '9', '-', ' '};
    setup();
    sweep_ran("header");
    alarm(120);
    for (int s = 0; s < N_SAMPLES; s++) {
        const sample_t *S = &samples[s];
        if (S->binary != binary || !S->header) continue;
        tf_buf_t b = {0};
        tf_put(&b, S->b.data, S->b.size);
        for (size_t at = 0; at < S->header; at++) {
            unsigned char was = b.data[at];
            for (size_t v = 0; v < sizeof BYTES; v++) {
                if (BYTES[v] == was) continue;
                b.data[at] = BYTES[v];
                for (int m = 0; m < modes_of(S); m++) {
                    if (m == V32) continue;
                    char key[128];
                    snprintf(key, sizeof key, "%s header byte %zu=0x%02x %s", S->id, at, BYTES[v], MODE[m]);
                    int out = observe(S, s, b.data, b.size, m, key, NULL);
                    (*cases)++;
                    *read += out != REFUSED;
                }
            }
            b.data[at] = was;
        }
        tf_free(&b);
    }
    alarm(0);
}

TEST(single_byte_header_mutations_of_binary_files_keep_the_contract) {
    long long cases = 0, read = 0;
    sweep_header_bytes(1, &cases, &read);
    printf("  %lld header byte mutations of binary files, %lld read (a byte the reader ignores or a value)\n", cases,
           read);
}

TEST(single_byte_header_mutations_of_counted_text_files_keep_the_contract) {
    long long cases = 0, read = 0;
    sweep_header_bytes(0, &cases, &read);
    printf("  %lld header byte mutations of counted text files, %lld read\n", cases, read);
}

/* 5. Text: encodings, decimal commas with every separator, first lines.
 * Each shape once gave a silent wrong read or a misleading message. */

/* Samples whose first bytes are text (an ascii file, or a PLY or PCD
 * header before binary data). */
static int starts_as_text(int s) { return s < LAS_12 && s != STL_BINARY; }

TEST(a_utf8_byte_order_mark_is_skipped_before_text_and_refused_before_binary) {
    long long cases = 0;
    setup();
    sweep_ran("text");
    for (int s = 0; s < N_SAMPLES; s++) {
        const sample_t *S = &samples[s];
        tf_buf_t b = {0};
        tf_puts(&b, "\xef\xbb\xbf");
        tf_put(&b, S->b.data, S->b.size);
        for (int m = 0; m < modes_of(S); m++) {
            char key[128];
            snprintf(key, sizeof key, "%s text utf-8-bom %s", S->id, MODE[m]);
            int out = observe(S, s, b.data, b.size, m, key, NULL);
            cases++;
            if (starts_as_text(s) ? out != SAME : out != REFUSED)
                VIOLATION(key, "a UTF-8 byte-order mark before the file: the file %s (%s)", OUTCOME[out],
                          starts_as_text(s) ? "it is skipped" : "binary: refused");
        }
        tf_free(&b);
    }
    printf("  %lld files after a UTF-8 byte-order mark\n", cases);
}

TEST(utf16_and_utf32_text_is_refused_naming_its_encoding) {
    long long cases = 0;
    static const struct {
        const char *name;
        int width, big, bom;
    } ENC[] = {{"utf-16le-bom", 2, 0, 1}, {"utf-16be-bom", 2, 1, 1}, {"utf-16le", 2, 0, 0}, {"utf-16be", 2, 1, 0},
               {"utf-32le-bom", 4, 0, 1}, {"utf-32be-bom", 4, 1, 1}, {"utf-32le", 4, 0, 0}, {"utf-32be", 4, 1, 0}};
    setup();
    sweep_ran("text");
    for (int s = 0; s < N_SAMPLES; s++) {
        const sample_t *S = &samples[s];
        if (S->binary) continue;
        for (size_t k = 0; k < sizeof ENC / sizeof ENC[0]; k++) {
            tf_buf_t b = {0};
            tf_wide(&b, S->b.data, S->b.size, ENC[k].width, ENC[k].big, ENC[k].bom);
            char want[40];
            snprintf(want, sizeof want, "UTF-%d text; convert to UTF-8", 8 * ENC[k].width);
            for (int m = 0; m < modes_of(S); m++) {
                char key[128];
                snprintf(key, sizeof key, "%s text %s %s", S->id, ENC[k].name, MODE[m]);
                int out = observe(S, s, b.data, b.size, m, key, NULL);
                cases++;
                if (out != REFUSED) VIOLATION(key, "%s text: the file %s", ENC[k].name, OUTCOME[out]);
                else if (!strstr(refusal, want)) VIOLATION(key, "message '%s' lacks '%s'", refusal, want);
            }
            tf_free(&b);
        }
    }
    printf("  %lld text files in UTF-16 and UTF-32, with and without byte-order marks\n", cases);
}

/* The XYZ sample's points written with `sep` between the fields, each
 * with a decimal comma ("-2,25"), or numbers with a thousands separator
 * ("2,101.5").  Every field holds one comma, so every line has six
 * comma-separated numbers: read as columns, the file is consistent and
 * wrong. */
static tf_buf_t comma_text(const char *sep, int thousands) {
    tf_buf_t b = {0};
    for (int k = 0; k < 4; k++) {
        for (int j = 0; j < 3; j++) {
            char num[32];
            if (thousands) {
                snprintf(num, sizeof num, "%d,%03d.5", 1 + k, 100 * j + k);
            } else {
                snprintf(num, sizeof num, "%.2f", PTS[k][j]);
                *strchr(num, '.') = ',';
            }
            tf_putf(&b, "%s%s", j ? sep : "", num);
        }
        tf_puts(&b, "\n");
    }
    return b;
}

TEST(decimal_commas_and_thousands_separators_with_every_separator_are_refused_unless_the_option_says) {
    long long cases = 0;
    static const char *const SEP[] = {" ", "\t", "  ", " \t ", ";", " ; ", "\t;"};
    static const char *const SEP_NAME[] = {"space", "tab", "spaces", "blanks", "semicolon", "spaced-semicolon",
                                           "tab-semicolon"};
    setup();
    sweep_ran("text");
    const sample_t *S = &samples[XYZ];
    for (size_t k = 0; k < sizeof SEP / sizeof SEP[0]; k++)
        for (int thousands = 0; thousands < 2; thousands++) {
            tf_buf_t b = comma_text(SEP[k], thousands);
            for (int m = 0; m < N_MODES - 1; m++)
                for (int option = 0; option < 4; option++) {
                    /* options 2 and 3: without the final newline (a heap block ending at the last digit) */
                    char key[128];
                    snprintf(key, sizeof key, "xyz text %s-%s%s%s %s", thousands ? "thousands" : "decimal-comma",
                             SEP_NAME[k], option & 1 ? "-option" : "", option & 2 ? "-no-final-newline" : "", MODE[m]);
                    hd_read_options_t o = options(m);
                    o.decimal_comma = option & 1;
                    int out = observe_with(S, XYZ, b.data, b.size - (option >> 1), &o, m, key, NULL);
                    cases++;
                    int want = (option & 1) && !thousands ? SAME : REFUSED;
                    if (out != want)
                        VIOLATION(key, "%s between fields: the file %s, expected %s", SEP_NAME[k], OUTCOME[out],
                                  OUTCOME[want]);
                }
            tf_free(&b);
        }
    printf("  %lld files with decimal commas or thousands separators\n", cases);
}

TEST(a_malformed_number_on_the_first_line_is_refused_and_a_header_is_skipped) {
    long long cases = 0;
    static const char *const MALFORMED[] = {"1.#QNAN 2 3", "1.5D+03 0 0", "3.14abc 1 1", "-", "+.5e 1 2", "1.#IND,0,0",
                                            "0x 1 2", ". 1 2"};
    static const char *const HEADER[] = {"x y z", "X,Y,Z", "# comment", "index,x,y,z", "infrared;x", "title\n\nx y z"};
    setup();
    sweep_ran("text");
    static const int TEXT[] = {XYZ, CSV};
    for (size_t t = 0; t < 2; t++) {
        const sample_t *S = &samples[TEXT[t]];
        for (int kind = 0; kind < 2; kind++) {
            size_t n = kind ? sizeof HEADER / sizeof HEADER[0] : sizeof MALFORMED / sizeof MALFORMED[0];
            for (size_t k = 0; k < n; k++)
                for (int where = 0; where < 2; where++) {
                    if (kind && where) continue; /* a header is a first line */
                    const char *line = kind ? HEADER[k] : MALFORMED[k];
                    /* line 1, or after the sample's first line */
                    const unsigned char *nl = memchr(S->b.data, '\n', S->b.size);
                    size_t cut = where ? (size_t)(nl - S->b.data) + 1 : 0;
                    tf_buf_t b = {0};
                    tf_put(&b, S->b.data, cut);
                    tf_putf(&b, "%s\n", line);
                    tf_put(&b, S->b.data + cut, S->b.size - cut);
                    for (int m = 0; m < N_MODES - 1; m++) {
                        char key[160];
                        snprintf(key, sizeof key, "%s text %s-line-%d '%s' %s", S->id, kind ? "header" : "malformed",
                                 where + 1, line, MODE[m]);
                        int out = observe(S, TEXT[t], b.data, b.size, m, key, NULL);
                        cases++;
                        int want = kind ? SAME : REFUSED;
                        if (out != want)
                            VIOLATION(key, "'%s' as line %d: the file %s, expected %s", line, where + 1, OUTCOME[out],
                                      OUTCOME[want]);
                    }
                    tf_free(&b);
                }
        }
    }
    printf("  %lld files with a malformed first or second line, or a header\n", cases);
}

TEST(zz_every_expected_failure_still_fails) {
    for (xfail_t *x = EXPECTED_FAILURES; x->key; x++)
        if (did_run(x->key) && !x->hits)
            hdt_fail(__FILE__, __LINE__, "expected failure '%s' (%s) no longer fails: remove it from EXPECTED_FAILURES",
                     x->key, x->why);
}

TEST(zz_summary_and_cleanup) {
    printf("  %lld reads in all, %d expected failures seen\n", n_reads, n_xfail_seen);
    for (int s = 0; s < N_SAMPLES; s++) {
        for (int m = 0; m < N_MODES; m++) {
            hd_cloud_free(reference[s][m]);
            reference[s][m] = NULL;
        }
        tf_free(&samples[s].b);
    }
}
