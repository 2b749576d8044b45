/*
 * text.c -- text input cut into chunks and parsed in parallel, and the
 * messages that name a file and a line.
 *
 * A text region is cut into chunks of about a megabyte, each ending just
 * after a newline, so every chunk holds whole lines and no line is split.
 * Parsing is three steps.  (1) In parallel, each chunk counts the lines that
 * may hold a point (a cheap scan, one memchr per line), bounded by its
 * bytes over the shortest line a point needs, so the bound never exceeds
 * what the file can hold.  (2) The result array is reserved once for the
 * total, each chunk gets the window of it that follows the previous
 * chunks' windows, and the chunks are parsed in parallel, each writing its
 * points straight into its window: no chunk-local copies, so each point is
 * written once and the memory is touched once.  A chunk counts its lines
 * and, on its first problem, records the code, its line within the chunk
 * and a message, then stops.  (3) The chunks are visited in file order:
 * the first chunk with a problem gives THE error, whose absolute line is
 * the region's first line plus the lines of all earlier chunks, and
 * otherwise each window is moved down to close the gap left by lines that
 * held no point (comments, a header; usually there is none).  The result is
 * therefore the same, point for point and error for error, at any thread
 * count.
 */
#include "io.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

/* The message "NAME[:LINE | : byte OFFSET]: what" into r's error, its
 * line and offset set (-1: none; a line wins over an offset). */
static int vplace(hd__read_t *r, int code, long long line, long long offset, const char *fmt, va_list ap) {
    hd_error_t *err = r->err;
    if (!err) return code;
    char place[40] = "", what[768];
    if (line >= 0) snprintf(place, sizeof place, ":%lld", line);
    else if (offset >= 0) snprintf(place, sizeof place, ": byte %lld", offset);
    vsnprintf(what, sizeof what, fmt, ap);
    hd__err(err, code, "%s%s: %s", r->f->name, place, what);
    err->line = line;
    err->offset = offset;
    return code;
}

int hd__io_err_line(hd__read_t *r, int code, long long line, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vplace(r, code, line, -1, fmt, ap);
    va_end(ap);
    return code;
}

int hd__io_err_at(hd__read_t *r, int code, long long offset, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vplace(r, code, -1, offset, fmt, ap);
    va_end(ap);
    return code;
}

int hd__io_err(hd__read_t *r, int code, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vplace(r, code, -1, -1, fmt, ap);
    va_end(ap);
    return code;
}

/* Whether d[0..n) starts with code units of `width` bytes (2 or 4) holding
 * printable ASCII (tabs and line ends included) in their low byte, `big`
 * endian, up to the first line end or 8 units, at least 2 of them: UTF-16
 * or UTF-32 text without a byte-order mark.  A binary header ("A\0\0\0"
 * then zeros, say) has a NUL or control unit among them and is not. */
static int wide_ascii(const unsigned char *d, size_t n, size_t width, int big) {
    size_t units = 0;
    for (size_t k = 0; k + width <= n && units < 8; k += width) {
        unsigned c = d[big ? k + width - 1 : k];
        for (size_t j = 1; j < width; j++)
            if (d[big ? k + width - 1 - j : k + j]) return 0;
        if (!((c >= 0x20 && c < 0x7f) || c == '\t' || c == '\r' || c == '\n')) return 0;
        units++;
        if (c == '\n') break;
    }
    return units >= 2;
}

int hd__text_encoding(const unsigned char *d, size_t n, size_t *bom) {
    *bom = 0;
    if (n >= 4 && ((d[0] == 0xff && d[1] == 0xfe && !d[2] && !d[3]) || (!d[0] && !d[1] && d[2] == 0xfe && d[3] == 0xff)))
        return 32;
    if (n >= 2 && ((d[0] == 0xff && d[1] == 0xfe) || (d[0] == 0xfe && d[1] == 0xff))) return 16;
    if (n >= 3 && d[0] == 0xef && d[1] == 0xbb && d[2] == 0xbf) {
        *bom = 3;
        return 8;
    }
    if (wide_ascii(d, n, 4, 0) || wide_ascii(d, n, 4, 1)) return 32;
    if (wide_ascii(d, n, 2, 0) || wide_ascii(d, n, 2, 1)) return 16;
    return 8;
}

int hd__text_begin(hd__read_t *r, const char **start) {
    size_t bom;
    int bits = hd__text_encoding(r->f->data, r->f->size, &bom);
    *start = (const char *)r->f->data + bom;
    if (bits == 8) return HD_OK;
    return hd__io_err_line(r, HD_EFORMAT, 1, "UTF-%d text; convert to UTF-8 (iconv -f UTF-%d -t UTF-8)", bits, bits);
}

int hd__parse_u64(const char *s, const char *end, uint64_t *out) {
    if (s == end) return 0;
    uint64_t v = 0;
    for (; s < end; s++) {
        unsigned d = (unsigned)(*s - '0');
        if (d >= 10 || v > (UINT64_MAX - d) / 10) return 0;
        v = v * 10 + d;
    }
    *out = v;
    return 1;
}

const char *hd__skip_lines(const char *p, const char *end, uint64_t n, uint64_t *skipped) {
    uint64_t k = 0;
    while (k < n && p < end) {
        const char *e = memchr(p, '\n', (size_t)(end - p));
        k++;
        p = e ? e + 1 : end;
    }
    *skipped = k;
    return p;
}

const char *hd__skip_content_lines(const char *p, const char *end, uint64_t n,
                                   uint64_t *found, uint64_t *lines) {
    uint64_t k = 0, all = 0;
    while (k < n && p < end) {
        const char *e = memchr(p, '\n', (size_t)(end - p)), *q = p;
        if (!e) e = end;
        while (q < e && hd__is_blank((unsigned char)*q)) q++;
        k += q < e && *q != '#';
        all++;
        p = e < end ? e + 1 : end;
    }
    *found = k;
    *lines = all;
    return p;
}

void hd__chunk_fail(hd__chunk_t *c, int code, long long line, const char *fmt, ...) {
    c->rc = code;
    c->err_line = line;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->msg, sizeof c->msg, fmt, ap);
    va_end(ap);
}

int hd__chunk_face(hd__chunk_t *c, uint64_t *ix, const uint64_t *idx, size_t n, long long line) {
    int rc = hd__tris_add(&c->tris, ix, n);
    if (ix != idx) free(ix);
    if (rc) {
        hd__chunk_fail(c, rc, line, "out of memory for faces");
        return 0;
    }
    c->aux++;
    return 1;
}

typedef struct {
    hd__chunk_t *chunks;
    const hd__text_job_t *job;
} run_t;

static size_t all_lines(void *ctx, const char *p, const char *end) {
    (void)ctx;
    uint64_t n;
    hd__skip_lines(p, end, UINT64_MAX, &n);
    return (size_t)n;
}

size_t hd__keyword_lines(const char *p, const char *end, const char *word) {
    size_t n = 0, len = strlen(word);
    const char *tb, *te;
    for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);)
        n += hd__token(&q, eol, &tb, &te) && (size_t)(te - tb) == len && memcmp(tb, word, len) == 0;
    return n;
}

size_t hd__no_candidates(void *ctx, const char *begin, const char *end) {
    (void)ctx;
    (void)begin;
    (void)end;
    return 0;
}

size_t hd__content_lines(void *ctx, const char *begin, const char *end) {
    (void)ctx;
    uint64_t found, lines;
    hd__skip_content_lines(begin, end, UINT64_MAX, &found, &lines);
    return (size_t)found;
}

/* The first '\r' of [p, end) followed by a byte other than '\n' or '\r'
 * (a line end of classic Mac OS, or a stray one inside a line), or NULL.
 * Every reader ends lines at '\n' only and takes '\r' for a blank, so the
 * lines such a '\r' ends would be read as one: "1 2 3\r4 5 6\r" as the
 * point (1, 2, 3) and nothing else.  "\r\n" and "\r\r\n" end lines. */
static const char *lone_cr(const char *p, const char *end) {
    while ((p = memchr(p, '\r', (size_t)(end - p))) != NULL && p + 1 < end && (p[1] == '\n' || p[1] == '\r')) p++;
    return p && p + 1 < end ? p : NULL;
}

static void count_chunk(void *ctx, size_t task, int worker) {
    (void)worker;
    run_t *run = ctx;
    hd__chunk_t *c = &run->chunks[task];
    c->lone_cr = lone_cr(c->begin, c->end);
    size_t (*count)(void *, const char *, const char *) = run->job->candidates ? run->job->candidates : all_lines;
    size_t n = count(run->job->ctx, c->begin, c->end);
    size_t most = ((size_t)(c->end - c->begin) + 1) / (run->job->min_line ? run->job->min_line : 1);
    c->room = n < most ? n : most;
}

static void parse_chunk(void *ctx, size_t task, int worker) {
    (void)worker;
    run_t *run = ctx;
    run->job->parse(run->job->ctx, &run->chunks[task]);
}

static long long count_lines(const char *p, const char *end) {
    long long n = 0;
    for (; p < end; p++) n += *p == '\n';
    return n;
}

#define CHUNK_BYTES ((size_t)1 << 20)

/* HD_EFORMAT naming the line of the first lone '\r' of the chunks (in
 * file order), or HD_OK when there is none. */
static int refuse_lone_cr(hd__read_t *r, const hd__chunk_t *chunks, size_t used, long long first_line) {
    long long line = first_line;
    for (size_t k = 0; k < used; k++) {
        if (chunks[k].lone_cr)
            return hd__io_err_line(r, HD_EFORMAT, line + count_lines(chunks[k].begin, chunks[k].lone_cr),
                                   "a carriage return ('\\r') that no line feed follows: lines end with LF or "
                                   "CR LF here, and this one would run into the next (classic Mac OS line ends? "
                                   "convert them: tr '\\r' '\\n')");
        line += count_lines(chunks[k].begin, chunks[k].end);
    }
    return HD_OK;
}

int hd__text_parallel(hd__read_t *r, const char *begin, const char *end,
                      long long first_line, const hd__text_job_t *job,
                      uint64_t *aux_total) {
    if (r->count_only) /* hd_read_count: a text's count is its lines' */
        return hd__io_err(r, HD_EUNSUPPORTED, "the point count of a text variant needs reading it whole");
    size_t size = (size_t)(end - begin);
    size_t n = size / CHUNK_BYTES + 1;
    if (n > 65536) n = 65536;
    hd__chunk_t *chunks = hd__calloc_array(n, sizeof *chunks);
    if (!chunks) return hd__io_err(r, HD_ENOMEM, "out of memory for %zu text chunks", n);
    size_t used = 0;
    const char *p = begin;
    while (p < end && used < n) {
        const char *stop = used + 1 == n ? end : p + size / n;
        if (stop > end) stop = end;
        if (stop < end) {
            const char *nl = memchr(stop, '\n', (size_t)(end - stop));
            stop = nl ? nl + 1 : end;
        }
        hd__chunk_t *c = &chunks[used];
        c->begin = p;
        c->end = stop;
        c->index = (int)used;
        c->lines = -1;
        hd__tris_init(&c->tris);
        used++;
        p = stop;
    }
    run_t run = {chunks, job};
    hd__sink_t *s = r->sink;
    size_t el = s->dtype == HD_FLOAT32 ? 3 * sizeof(float) : 3 * sizeof(double);
    /* 1: how many points each chunk may hold; room for all of them at once */
    hd__parallel_for(r->threads, used, count_chunk, &run);
    size_t total = 0;
    for (size_t k = 0; k < used; k++) total += chunks[k].room;
    int rc = refuse_lone_cr(r, chunks, used, first_line);
    if (rc == HD_OK && (rc = hd__sink_reserve(s, total)) != HD_OK)
        hd__io_err(r, rc, "cannot allocate %zu points", total);
    /* 2: every chunk parses into its window of the array */
    size_t at = s->count;
    for (size_t k = 0; rc == HD_OK && k < used; k++) {
        hd__chunk_t *c = &chunks[k];
        c->pts.data = s->data ? (char *)s->data + at * el : NULL; /* NULL when there is no room at all */
        c->pts.count = 0;
        c->pts.cap = c->room;
        c->pts.dtype = s->dtype;
        c->pts.fixed = 1;
        at += c->room;
    }
    if (rc == HD_OK) hd__parallel_for(r->threads, used, parse_chunk, &run);
    /* 3: in file order, the first problem or the windows closed up */
    long long line = first_line;
    uint64_t aux = 0;
    for (size_t k = 0; k < used && rc == HD_OK; k++) {
        hd__chunk_t *c = &chunks[k];
        if (c->rc) {
            rc = hd__io_err_line(r, c->rc, line + c->err_line - 1, "%s", c->msg);
            break;
        }
        line += c->lines >= 0 ? c->lines : count_lines(c->begin, c->end);
        aux += c->aux;
        if (job->fix) job->fix(job->ctx, c, s->count);
        if (c->pts.count) {
            char *dst = (char *)s->data + s->count * el;
            if (dst != (char *)c->pts.data) memmove(dst, c->pts.data, c->pts.count * el);
            s->count += c->pts.count;
        }
        if (r->tris && (rc = hd__tris_append(r->tris, &c->tris))) hd__io_err(r, rc, "out of memory for the faces read");
    }
    for (size_t k = 0; k < used; k++) hd__tris_free(&chunks[k].tris);
    free(chunks);
    if (aux_total) *aux_total = aux;
    return rc;
}

int hd__chunk_vertex(hd__chunk_t *c, const char **q, const char *eol, long long line,
                     const char *prefix, const char *expected, int comment_ends) {
    double v[3];
    const char *tb, *te;
    int got = 0, k;
    while (got < 3 && (k = hd__next_double(q, eol, &v[got], &tb, &te)) != 0) {
        if (k < 0 && comment_ends && *tb == '#') break;
        if (k < 0) {
            hd__chunk_fail(c, HD_EFORMAT, line, "%s'%.*s' is not a number", prefix,
                           (int)(te - tb > 40 ? 40 : te - tb), tb);
            return 0;
        }
        got++;
    }
    if (got < 3) {
        hd__chunk_fail(c, HD_EFORMAT, line, "%s, found %d number%s", expected, got, got == 1 ? "" : "s");
        return 0;
    }
    return hd__chunk_push(c, line, v);
}
