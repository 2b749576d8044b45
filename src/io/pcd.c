/*
 * pcd.c -- Point Cloud Library PCD files, version 0.7 (and the 0.6 header
 * without VERSION), data ascii, binary and binary_compressed.
 *
 * Format (PCL documentation, "The PCD (Point Cloud Data) file format"): a
 * text header of lines "VERSION", "FIELDS name...", "SIZE bytes...", "TYPE
 * F|I|U...", "COUNT n..." (optional, default 1), "WIDTH", "HEIGHT",
 * "VIEWPOINT", "POINTS" (optional: WIDTH * HEIGHT), "DATA ascii|binary|
 * binary_compressed", comments starting with '#'.  The data starts right
 * after the DATA line.  ascii: one point per line, the fields' values in
 * order (COUNT values per field).  binary: POINTS records of sum(SIZE *
 * COUNT) bytes, little-endian (PCL writes the machine's order; every
 * machine it runs on is little-endian).  binary_compressed: two uint32, the
 * compressed and uncompressed sizes, then LZF data (lzf.c) that expands to
 * the fields one after another ("structure of arrays"): all points' first
 * field, then all points' second, and so on, which is what PCL's
 * writeBinaryCompressed and Open3D produce.
 *
 * x, y, z may be F of size 4 or 8, or I/U of size 1, 2, 4 or 8; only their
 * first element is read when COUNT > 1.  PCL marks missing points of an
 * organised cloud with NaN; such a file is refused (a NaN coordinate), as
 * everywhere.  Counts are checked against the file before any allocation;
 * the uncompressed size of binary_compressed must equal POINTS times the
 * record size and cannot exceed what the compressed bytes can expand to
 * (an LZF command of 3 bytes yields at most 264).
 */
#include "io.h"

#include <stdlib.h>

#define MAX_FIELDS 256

typedef struct {
    const char *name;
    size_t len;
    uint64_t size, count;
    char type;
} field_t;

typedef struct {
    field_t f[MAX_FIELDS];
    int n, have_size, have_type, have_count;
    uint64_t width, height, points;
    int have_width, have_height, have_points;
    int data; /* 0 ascii, 1 binary, 2 binary_compressed */
    size_t start;
    long long start_line;
    int xyz[3];
    uint64_t rec;      /* record bytes */
    uint64_t off[3];   /* byte offset of x, y, z in a record */
    uint64_t token[3]; /* ascii: token index of x, y, z */
    uint64_t tokens;   /* ascii: tokens per line */
} pcd_t;

static int word(const char *tb, const char *te, const char *w) {
    size_t n = strlen(w);
    return (size_t)(te - tb) == n && memcmp(tb, w, n) == 0;
}

static hd__type_t coord_type(const field_t *f) {
    if (f->type == 'F') return f->size == 4 ? HD__T_F32 : f->size == 8 ? HD__T_F64 : HD__T_NONE;
    int u = f->type == 'U';
    switch (f->size) {
    case 1: return u ? HD__T_U8 : HD__T_I8;
    case 2: return u ? HD__T_U16 : HD__T_I16;
    case 4: return u ? HD__T_U32 : HD__T_I32;
    case 8: return u ? HD__T_U64 : HD__T_I64;
    default: return HD__T_NONE;
    }
}

/* A header line's list of n values (SIZE, TYPE, COUNT). */
static int list(hd__read_t *r, pcd_t *p, const char **q, const char *eol, long long line, const char *key,
                int which) {
    const char *tb, *te;
    if (!p->n) return hd__io_err_line(r, HD_EFORMAT, line, "%s before FIELDS", key);
    for (int k = 0; k < p->n; k++) {
        if (!hd__token(q, eol, &tb, &te))
            return hd__io_err_line(r, HD_EFORMAT, line, "%s has %d values, FIELDS has %d", key, k, p->n);
        field_t *f = &p->f[k];
        if (which == 1) {
            if (te - tb != 1 || !strchr("FIU", *tb))
                return hd__io_err_line(r, HD_EFORMAT, line, "unknown TYPE '%.*s' (F, I or U)", (int)(te - tb > 20 ? 20 : te - tb), tb);
            f->type = *tb;
        } else {
            uint64_t v;
            if (!hd__parse_u64(tb, te, &v) || v == 0 || v > ((uint64_t)1 << 32))
                return hd__io_err_line(r, HD_EFORMAT, line, "%s value '%.*s' is not a positive whole number", key,
                                       (int)(te - tb > 20 ? 20 : te - tb), tb);
            if (which == 0 && v != 1 && v != 2 && v != 4 && v != 8)
                return hd__io_err_line(r, HD_EFORMAT, line, "SIZE %llu (sizes are 1, 2, 4 or 8)", (unsigned long long)v);
            if (which == 0) f->size = v;
            else f->count = v;
        }
    }
    if (hd__token(q, eol, &tb, &te))
        return hd__io_err_line(r, HD_EFORMAT, line, "%s has more values than FIELDS (%d)", key, p->n);
    return HD_OK;
}

static int header(hd__read_t *r, pcd_t *p) {
    const char *s = (const char *)r->f->data, *end = s + r->f->size, *q, *tb, *te;
    int rc = hd__text_begin(r, &q);
    if (rc) return rc;
    long long line = 0;
    for (;;) {
        if (q >= end) return hd__io_err_line(r, HD_EFORMAT, line + 1, "header ends before the DATA line");
        line++;
        const char *eol = hd__eol(q, end), *c = q;
        q = eol + (eol < end);
        if (!hd__token(&c, eol, &tb, &te) || *tb == '#') continue;
        long long at = line;
        if (word(tb, te, "VERSION") || word(tb, te, "VIEWPOINT")) continue;
        if (word(tb, te, "FIELDS")) {
            if (p->n) return hd__io_err_line(r, HD_EFORMAT, at, "FIELDS given twice");
            while (hd__token(&c, eol, &tb, &te)) {
                if (p->n == MAX_FIELDS) return hd__io_err_line(r, HD_EUNSUPPORTED, at, "more than %d fields", MAX_FIELDS);
                field_t *f = &p->f[p->n++];
                f->name = tb;
                f->len = (size_t)(te - tb);
                f->size = 4;
                f->type = 'F';
                f->count = 1;
            }
            if (!p->n) return hd__io_err_line(r, HD_EFORMAT, at, "FIELDS names no field");
        } else if (word(tb, te, "SIZE")) {
            int rc = list(r, p, &c, eol, at, "SIZE", 0);
            if (rc) return rc;
            p->have_size = 1;
        } else if (word(tb, te, "TYPE")) {
            int rc = list(r, p, &c, eol, at, "TYPE", 1);
            if (rc) return rc;
            p->have_type = 1;
        } else if (word(tb, te, "COUNT")) {
            int rc = list(r, p, &c, eol, at, "COUNT", 2);
            if (rc) return rc;
        } else if (word(tb, te, "WIDTH") || word(tb, te, "HEIGHT") || word(tb, te, "POINTS")) {
            const char *key = tb;
            uint64_t *dst = *key == 'W' ? &p->width : *key == 'H' ? &p->height : &p->points;
            int *have = *key == 'W' ? &p->have_width : *key == 'H' ? &p->have_height : &p->have_points;
            if (!hd__token(&c, eol, &tb, &te) || !hd__parse_u64(tb, te, dst))
                return hd__io_err_line(r, HD_EFORMAT, at, "%.*s needs a whole number", (int)(*key == 'P' ? 6 : 5), key);
            *have = 1;
        } else if (word(tb, te, "DATA")) {
            if (!hd__token(&c, eol, &tb, &te))
                return hd__io_err_line(r, HD_EFORMAT, at, "DATA needs ascii, binary or binary_compressed");
            if (word(tb, te, "ascii")) p->data = 0;
            else if (word(tb, te, "binary")) p->data = 1;
            else if (word(tb, te, "binary_compressed")) p->data = 2;
            else return hd__io_err_line(r, HD_EUNSUPPORTED, at, "unknown DATA '%.*s' (ascii, binary or binary_compressed)",
                                        (int)(te - tb > 30 ? 30 : te - tb), tb);
            p->start = (size_t)(q - s);
            p->start_line = line + 1;
            return HD_OK;
        } else {
            return hd__io_err_line(r, HD_EFORMAT, at, "unknown PCD header keyword '%.*s'", (int)(te - tb > 30 ? 30 : te - tb), tb);
        }
    }
}

/* ---- ascii ----------------------------------------------------------- */
static void chunk(void *ctx, hd__chunk_t *c) {
    const pcd_t *p = ctx;
    const char *q = c->begin, *end = c->end, *tb, *te;
    long long line = 0;
    while (q < end) {
        line++;
        const char *eol = hd__eol(q, end), *s = q;
        q = eol + (eol < end);
        if (!hd__token(&s, eol, &tb, &te)) continue; /* blank */
        double v[3];
        uint64_t k = 0;
        int got = 0;
        for (;; k++) {
            for (int d = 0; d < 3; d++)
                if (p->token[d] == k) {
                    if (!hd__parse_double(tb, te, &v[d])) {
                        hd__chunk_fail(c, HD_EFORMAT, line, "'%.*s' is not a number (field %.*s)", (int)(te - tb > 40 ? 40 : te - tb),
                                       tb, (int)p->f[p->xyz[d]].len, p->f[p->xyz[d]].name);
                        return;
                    }
                    got++;
                }
            if (k + 1 == p->tokens || !hd__token(&s, eol, &tb, &te)) break;
        }
        if (k + 1 < p->tokens || got < 3) {
            hd__chunk_fail(c, HD_EFORMAT, line, "expected %llu values, found %llu", (unsigned long long)p->tokens,
                           (unsigned long long)(k + 1));
            return;
        }
        if (hd__token(&s, eol, &tb, &te)) {
            hd__chunk_fail(c, HD_EFORMAT, line, "more than the %llu values the fields declare", (unsigned long long)p->tokens);
            return;
        }
        if (!hd__chunk_push(c, line, v)) return;
    }
    c->lines = line;
}

/* binary_compressed with fields of different sizes: x, y, z each in their
 * own block, read serially. */
static int soa_points(hd__read_t *r, pcd_t *p, const unsigned char *buf, size_t n, hd__type_t type[3], size_t file_off) {
    int rc = hd__sink_reserve(r->sink, n);
    if (rc) return hd__io_err(r, rc, "cannot allocate %zu points", n);
    for (size_t k = 0; k < n; k++) {
        double v[3];
        for (int d = 0; d < 3; d++) {
            const field_t *f = &p->f[p->xyz[d]];
            v[d] = hd__ld_value(buf + p->off[d] * n + k * f->size * f->count, type[d], 0);
        }
        if ((rc = hd__sink_push(r->sink, v)))
            return hd__io_err_at(r, rc, (long long)file_off, "point %zu: %s (in the compressed data)", k, hd__point_problem(rc));
    }
    return HD_OK;
}

/* The offset of the first nonzero byte of data[from, left), or left.  PCL
 * pads binary files with zeros after the data; any other byte there means
 * the data go on past what POINTS declares. */
static size_t nonzero_after(const unsigned char *data, size_t from, size_t left) {
    for (size_t k = from; k < left; k++)
        if (data[k]) return k;
    return left;
}

int hd__read_pcd(hd__read_t *r) {
    pcd_t *p = calloc(1, sizeof *p);
    if (!p) return hd__io_err(r, HD_ENOMEM, "out of memory");
    int rc = header(r, p);
    hd__type_t type[3] = {HD__T_NONE, HD__T_NONE, HD__T_NONE};
    for (int d = 0; rc == HD_OK && d < 3; d++) {
        p->xyz[d] = -1;
        uint64_t off = 0, tok = 0;
        for (int k = 0; k < p->n; k++) {
            if (word(p->f[k].name, p->f[k].name + p->f[k].len, d == 0 ? "x" : d == 1 ? "y" : "z")) {
                for (int j = k + 1; j < p->n; j++)
                    if (word(p->f[j].name, p->f[j].name + p->f[j].len, d == 0 ? "x" : d == 1 ? "y" : "z"))
                        rc = hd__io_err(r, HD_EFORMAT, "FIELDS names '%c' twice", "xyz"[d]);
                p->xyz[d] = k;
                p->off[d] = off;
                p->token[d] = tok;
                break;
            }
            off += p->f[k].size * p->f[k].count;
            tok += p->f[k].count;
        }
        if (p->xyz[d] < 0) {
            rc = hd__io_err(r, HD_EFORMAT, "FIELDS has no '%c'", "xyz"[d]);
            break;
        }
        type[d] = coord_type(&p->f[p->xyz[d]]);
        if (!type[d])
            rc = hd__io_err(r, HD_EUNSUPPORTED, "field %c has TYPE %c SIZE %llu (readable: F 4/8, I or U 1/2/4/8)", "xyz"[d],
                            p->f[p->xyz[d]].type, (unsigned long long)p->f[p->xyz[d]].size);
    }
    for (int k = 0; rc == HD_OK && k < p->n; k++) {
        /* size <= 8, count <= 2^32, at most 256 fields: no overflow */
        p->rec += p->f[k].size * p->f[k].count;
        p->tokens += p->f[k].count;
    }
    if (rc == HD_OK && p->have_points && p->have_width) {
        /* PCL refuses "HEIGHT x WIDTH != number of points"; HEIGHT 0 (or
         * none) it takes as 1, and so do we */
        uint64_t h = p->have_height && p->height ? p->height : 1;
        if (p->width > UINT64_MAX / h || p->width * h != p->points)
            rc = hd__io_err(r, HD_EFORMAT, "WIDTH %llu x HEIGHT %llu is not POINTS %llu",
                            (unsigned long long)p->width, (unsigned long long)h, (unsigned long long)p->points);
    }
    if (rc == HD_OK && !p->have_points) {
        if (!p->have_width) rc = hd__io_err(r, HD_EFORMAT, "the header gives neither POINTS nor WIDTH");
        else if (p->have_height && p->height && p->width > UINT64_MAX / p->height)
            rc = hd__io_err(r, HD_EFORMAT, "WIDTH * HEIGHT overflows");
        else p->points = p->width * (p->have_height ? p->height : 1);
    }
    size_t left = rc == HD_OK ? r->f->size - p->start : 0;
    const unsigned char *data = r->f->data + (rc == HD_OK ? p->start : 0);
    if (rc == HD_OK && p->data == 0) {
        /* a line holds at least 2 bytes per value */
        if (p->points > (left + 1) / (2 * p->tokens))
            rc = hd__io_err_line(r, HD_EFORMAT, p->start_line - 1, "POINTS %llu, but the file can hold at most %llu",
                                 (unsigned long long)p->points, (unsigned long long)((left + 1) / (2 * p->tokens)));
        if (rc == HD_OK && (rc = hd__sink_reserve(r->sink, (size_t)p->points)))
            rc = hd__io_err(r, rc, "cannot allocate %llu points", (unsigned long long)p->points);
        if (rc == HD_OK)
        {
            /* blank lines are skipped; a point line has 2 bytes per value */
            hd__text_job_t job = {chunk, NULL, hd__content_lines, (size_t)(2 * p->tokens), p};
            rc = hd__text_parallel(r, (const char *)data, (const char *)data + left, p->start_line, &job, NULL);
        }
        if (rc == HD_OK && r->sink->count != p->points)
            rc = hd__io_err(r, HD_EFORMAT, "POINTS says %llu, the data holds %zu", (unsigned long long)p->points, r->sink->count);
    } else if (rc == HD_OK && p->data == 1) {
        if (p->points > left / p->rec)
            rc = hd__io_err_at(r, HD_EFORMAT, (long long)r->f->size,
                               "file ends inside the data: POINTS %llu of %llu bytes need %llu bytes, %zu are left",
                               (unsigned long long)p->points, (unsigned long long)p->rec,
                               (unsigned long long)(p->points <= UINT64_MAX / p->rec ? p->points * p->rec : UINT64_MAX), left);
        size_t nz;
        if (rc == HD_OK && (nz = nonzero_after(data, (size_t)(p->points * p->rec), left)) < left)
            rc = hd__io_err_at(r, HD_EFORMAT, (long long)(p->start + nz),
                               "%llu bytes after the data: POINTS %llu of %llu bytes make %llu bytes, the file has %zu "
                               "(only zeros may follow, as PCL pads)",
                               (unsigned long long)(left - p->points * p->rec), (unsigned long long)p->points,
                               (unsigned long long)p->rec, (unsigned long long)(p->points * p->rec), left);
        size_t off[3] = {(size_t)p->off[0], (size_t)p->off[1], (size_t)p->off[2]};
        if (rc == HD_OK) rc = hd__binary_points(r, data, (size_t)p->points, (size_t)p->rec, off, type, 0, p->start);
    } else if (rc == HD_OK) {
        if (left < 8) {
            rc = hd__io_err_at(r, HD_EFORMAT, (long long)r->f->size, "file ends before the compressed sizes");
        } else {
            uint64_t csize = hd__ld_u32(data, 0), usize = hd__ld_u32(data + 4, 0);
            uint64_t want = p->points <= UINT64_MAX / p->rec ? p->points * p->rec : UINT64_MAX;
            if (csize > left - 8)
                rc = hd__io_err_at(r, HD_EFORMAT, (long long)p->start, "compressed size %llu, but only %zu bytes follow",
                                   (unsigned long long)csize, left - 8);

            else if (usize != want)
                rc = hd__io_err_at(r, HD_EFORMAT, (long long)p->start + 4,
                                   "uncompressed size %llu, but POINTS %llu of %llu bytes make %llu", (unsigned long long)usize,
                                   (unsigned long long)p->points, (unsigned long long)p->rec, (unsigned long long)want);
            else if (usize > csize * 88)
                rc = hd__io_err_at(r, HD_EFORMAT, (long long)p->start + 4,
                                   "uncompressed size %llu is more than %llu compressed bytes can expand to",
                                   (unsigned long long)usize, (unsigned long long)csize);
            size_t nz;
            if (rc == HD_OK && (nz = nonzero_after(data, 8 + (size_t)csize, left)) < left)
                rc = hd__io_err_at(r, HD_EFORMAT, (long long)(p->start + nz),
                                   "%llu bytes after the %llu compressed bytes the header declares "
                                   "(only zeros may follow, as PCL pads)",
                                   (unsigned long long)(left - 8 - csize), (unsigned long long)csize);
            unsigned char *buf = NULL;
            if (rc == HD_OK && !(buf = malloc(usize ? (size_t)usize : 1))) rc = hd__io_err(r, HD_ENOMEM, "out of memory");
            size_t bad;
            if (rc == HD_OK && hd__lzf_decompress(data + 8, (size_t)csize, buf, (size_t)usize, &bad))
                rc = hd__io_err_at(r, HD_EFORMAT, (long long)(p->start + 8 + bad), "corrupt compressed data");
            if (rc == HD_OK) {
                size_t n = (size_t)p->points;
                const field_t *fx = &p->f[p->xyz[0]], *fy = &p->f[p->xyz[1]], *fz = &p->f[p->xyz[2]];
                uint64_t sx = fx->size * fx->count;
                if (sx == fy->size * fy->count && sx == fz->size * fz->count) {
                    size_t off[3] = {(size_t)p->off[0] * n, (size_t)p->off[1] * n, (size_t)p->off[2] * n};
                    /* offsets into the decompressed buffer; errors name the compressed block */
                    hd__read_t rr = *r;
                    rc = hd__binary_points(&rr, buf, n, (size_t)sx, off, type, 0, 0);
                    r->ranged = rr.ranged;
                    r->total = rr.total;
                    if (rc && rc != HD__COUNTED && r->err) {
                        char msg[sizeof r->err->message];
                        memcpy(msg, r->err->message, sizeof msg);
                        hd__io_err_at(r, rc, (long long)p->start + 8, "in the compressed data: %s",
                                      strstr(msg, "point ") ? strstr(msg, "point ") : msg);
                    }
                } else {
                    rc = soa_points(r, p, buf, n, type, p->start + 8);
                }
            }
            free(buf);
        }
    }
    free(p);
    return rc;
}
