/*
 * text.c -- text input cut into chunks and parsed in parallel, and the
 * messages that name a file and a line.
 *
 * A text region is cut into chunks of about a megabyte, each ending just
 * after a newline, so every chunk holds whole lines and no line is split.
 * Chunks are independent tasks for hd__parallel_for: each parses its lines
 * into its own point array (and its own triangles), counts its lines, and on
 * the first problem records the code, its line within the chunk and a
 * message, then stops.  Afterwards the chunks are visited in file order: the
 * first chunk with a problem gives THE error, whose absolute line is the
 * region's first line plus the lines of all earlier chunks (each chunk
 * that finished reports its count; the framework counts the newlines of
 * one that did not say), and otherwise the points are appended in order.  The result is therefore the
 * same, point for point and error for error, at any thread count.
 */
#include "io.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

static int vplace(hd__read_t *r, int code, const char *place, const char *fmt,
                  va_list ap) {
    hd_error_t *err = r->err;
    if (!err) return code;
    char what[768];
    vsnprintf(what, sizeof what, fmt, ap);
    hd__err(err, code, "%s%s: %s", r->f->name, place, what);
    return code;
}

int hd__io_err_line(hd__read_t *r, int code, long long line, const char *fmt, ...) {
    char place[32];
    snprintf(place, sizeof place, ":%lld", line);
    va_list ap;
    va_start(ap, fmt);
    vplace(r, code, place, fmt, ap);
    va_end(ap);
    if (r->err) r->err->line = line;
    return code;
}

int hd__io_err_at(hd__read_t *r, int code, long long offset, const char *fmt, ...) {
    char place[40];
    snprintf(place, sizeof place, ": byte %lld", offset);
    va_list ap;
    va_start(ap, fmt);
    vplace(r, code, place, fmt, ap);
    va_end(ap);
    if (r->err) r->err->offset = offset;
    return code;
}

int hd__io_err(hd__read_t *r, int code, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vplace(r, code, "", fmt, ap);
    va_end(ap);
    return code;
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

typedef struct {
    hd__chunk_t *chunks;
    hd__chunk_fn fn;
    void *ctx;
} run_t;

static void run_chunk(void *ctx, size_t task, int worker) {
    (void)worker;
    run_t *run = ctx;
    run->fn(run->ctx, &run->chunks[task]);
}

static long long count_lines(const char *p, const char *end) {
    long long n = 0;
    for (; p < end; p++) n += *p == '\n';
    return n;
}

#define CHUNK_BYTES ((size_t)1 << 20)

int hd__text_parallel(hd__read_t *r, const char *begin, const char *end,
                      long long first_line, hd__chunk_fn fn,
                      hd__chunk_fix_fn fix, void *ctx, uint64_t *aux_total) {
    size_t size = (size_t)(end - begin);
    size_t n = size / CHUNK_BYTES + 1;
    if (n > 4096) n = 4096;
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
        hd__sink_init(&c->pts, r->sink->dtype);
        hd__tris_init(&c->tris);
        used++;
        p = stop;
    }
    run_t run = {chunks, fn, ctx};
    int rc = hd__parallel_for(r->threads, used, run_chunk, &run);
    if (rc) hd__io_err(r, rc, "could not parse in parallel: %s", hd_strerror(rc));
    /* room for every point once, rather than growing while appending */
    size_t total = 0;
    for (size_t k = 0; k < used && !chunks[k].rc; k++) total += chunks[k].pts.count;
    if (rc == HD_OK && (rc = hd__sink_reserve(r->sink, total)))
        hd__io_err(r, rc, "out of memory for %zu points", total);
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
        if (fix) fix(ctx, c, r->sink->count);
        if ((rc = hd__sink_append(r->sink, &c->pts)) ||
            (r->tris && (rc = hd__tris_append(r->tris, &c->tris))))
            hd__io_err(r, rc, "out of memory for the points read");
    }
    for (size_t k = 0; k < used; k++) {
        hd__sink_free(&chunks[k].pts);
        hd__tris_free(&chunks[k].tris);
    }
    free(chunks);
    if (aux_total) *aux_total = aux;
    return rc;
}
