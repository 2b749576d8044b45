/*
 * stl.c -- STL (stereolithography) triangles, binary and ascii.
 *
 * Binary STL: an 80-byte header (arbitrary text, which may itself start
 * with "solid"), a little-endian uint32 triangle count, then per triangle
 * 50 bytes: a normal and three corners as little-endian float32 x y z, and a
 * 2-byte attribute.  Ascii STL: "solid NAME", then per triangle "facet
 * normal nx ny nz / outer loop / vertex x y z (three times) / endloop /
 * endfacet", and "endsolid NAME".
 *
 * STL has no shared vertices: the points read are the three corners of
 * every triangle, in file order, duplicates kept (that is how the bundled
 * wuson_stl.ply was made).  With --sample, triangle t is corners 3t..3t+2.
 *
 * Which variant: a file whose size is exactly 84 + 50 * count is binary
 * (even when its header starts with "solid", as many exporters write).
 * Otherwise a file starting with "solid" is ascii when its first 4 KiB name
 * a "facet" or "endsolid" (every ascii STL with content does), and anything
 * else is binary: a binary header that starts with "solid" is never taken
 * for an empty ascii file.  A file that is not binary by its size is text
 * first: a UTF-8 byte-order mark is skipped and UTF-16 or UTF-32 refused by
 * name (hd__text_begin), so an ascii STL saved as UTF-16 is never read as
 * binary with the triangle count its text makes (1818521189).  A binary file must hold exactly its declared
 * triangles: fewer bytes is a truncation, more is data the count does not
 * cover (a wrong count, or two files joined), and both are errors naming
 * the numbers, never a silent partial read.  Binary corners are
 * converted in parallel from the mapping; ascii lines in parallel chunks,
 * every "vertex" line giving a point, and the total must be three per
 * facet.
 */
#include "io.h"

#include <stdio.h>

static int word(const char *tb, const char *te, const char *w) {
    size_t n = strlen(w);
    return (size_t)(te - tb) == n && memcmp(tb, w, n) == 0;
}

static int keyword(const char *tb, const char *te) {
    return word(tb, te, "vertex") || word(tb, te, "facet") || word(tb, te, "outer") || word(tb, te, "endloop") ||
           word(tb, te, "endfacet") || word(tb, te, "endsolid");
}

/* Whether the rest [q, eol) of a line whose statement is `what` holds
 * another statement, which reading a statement a line would skip: any
 * token after a vertex's x y z, a keyword after facet, outer, endloop or
 * endfacet, or "facet normal" then "outer loop" on the solid line (whose
 * name is any words; a file written on one line was read as no points).
 * Then the problem is recorded and 1 returned. */
static int another_statement(hd__chunk_t *c, long long line, const char *what, const char *q, const char *eol) {
    const char *tb, *te, *prev = q, *pte = q, *facet = NULL;
    int solid = strcmp(what, "solid") == 0, vertex = strcmp(what, "vertex") == 0;
    while (hd__token(&q, eol, &tb, &te)) {
        if (solid && !facet && word(tb, te, "normal") && word(prev, pte, "facet")) facet = prev;
        int found = solid ? facet && word(tb, te, "loop") && word(prev, pte, "outer") : vertex || keyword(tb, te);
        prev = tb;
        pte = te;
        if (found && solid) tb = facet;
        if (found) {
            hd__chunk_fail(c, HD_EFORMAT, line, "'%.*s' after '%s' on one line: an ascii STL is read one statement a line",
                           (int)(te - tb > 40 ? 40 : te - tb), tb, what);
            return 1;
        }
    }
    return 0;
}

static void chunk(void *ctx, hd__chunk_t *c) {
    (void)ctx;
    const char *p = c->begin, *end = c->end, *tb, *te;
    long long line = 0;
    for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);) {
        line++;
        if (!hd__token(&q, eol, &tb, &te)) continue;
        if (word(tb, te, "vertex")) {
            if (!hd__chunk_vertex(c, &q, eol, line, "vertex: ", "vertex: expected x y z", 0) ||
                another_statement(c, line, "vertex", q, eol))
                return;
        } else if (word(tb, te, "endsolid")) {
            continue;
        } else if (word(tb, te, "solid") || keyword(tb, te)) {
            char what[16];
            snprintf(what, sizeof what, "%.*s", (int)(te - tb), tb);
            if (another_statement(c, line, what, q, eol)) return;
            c->aux += strcmp(what, "facet") == 0;
        } else {
            hd__chunk_fail(c, HD_EFORMAT, line, "unknown ascii STL keyword '%.*s'", (int)(te - tb > 40 ? 40 : te - tb), tb);
            return;
        }
    }
    c->lines = line;
}

static size_t candidates(void *ctx, const char *p, const char *end) {
    (void)ctx;
    return hd__keyword_lines(p, end, "vertex");
}

/* The first facet that does not have exactly three vertices (serial; only
 * run when the totals disagree). */
static int report_bad_facet(hd__read_t *r, const char *p) {
    const char *end = (const char *)r->f->data + r->f->size, *tb, *te;
    long long line = 0, facet_line = 0;
    int n = -1;
    for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);) {
        line++;
        if (!hd__token(&q, eol, &tb, &te)) continue;
        if (word(tb, te, "vertex")) {
            if (n < 0) return hd__io_err_line(r, HD_EFORMAT, line, "vertex outside a facet");
            n++;
        } else if (word(tb, te, "facet") || word(tb, te, "endsolid")) {
            if (n >= 0 && n != 3)
                return hd__io_err_line(r, HD_EFORMAT, facet_line, "facet with %d vertices (a triangle has 3)", n);
            n = word(tb, te, "facet") ? 0 : -1;
            facet_line = line;
        }
    }
    if (n >= 0 && n != 3)
        return hd__io_err_line(r, HD_EFORMAT, facet_line, "facet with %d vertices (a triangle has 3)", n);
    return hd__io_err(r, HD_EFORMAT, "the vertices are not three per facet");
}

static int add_triangles(hd__read_t *r, size_t n_tri) {
    if (!r->tris) return HD_OK;
    for (size_t t = 0; t < n_tri; t++) {
        uint64_t v[3] = {3 * (uint64_t)t, 3 * (uint64_t)t + 1, 3 * (uint64_t)t + 2};
        if (hd__tris_add(r->tris, v, 3)) return hd__io_err(r, HD_ENOMEM, "out of memory for %zu triangles", n_tri);
    }
    return HD_OK;
}

/* Whether the first 4 KiB hold "facet" or "endsolid": an ascii STL with
 * content, not a binary header that happens to start with "solid". */
static int text_keyword(const unsigned char *d, size_t size) {
    size_t n = size < 4096 ? size : 4096;
    for (size_t j = 0; j + 5 <= n; j++)
        if (memcmp(d + j, "facet", 5) == 0 || (j + 8 <= n && memcmp(d + j, "endsolid", 8) == 0)) return 1;
    return 0;
}

int hd__read_stl(hd__read_t *r) {
    const unsigned char *d = r->f->data;
    size_t size = r->f->size, k;
    uint64_t n = size >= 84 ? hd__ld_u32(d + 80, 0) : 0;
    int exact = size >= 84 && 84 + 50 * n == size;
    /* text unless the size says binary: UTF-16 refused, a UTF-8 mark skipped */
    const char *s = (const char *)d;
    if (!exact) {
        int rc = hd__text_begin(r, &s);
        if (rc) return rc;
    }
    k = (size_t)((const unsigned char *)s - d);
    while (k < size && (d[k] == ' ' || d[k] == '\t' || d[k] == '\r' || d[k] == '\n')) k++;
    int solid = size - k >= 5 && memcmp(d + k, "solid", 5) == 0;
    if (solid && !exact && size >= 84 && !text_keyword(d, size)) solid = 0;
    if (solid && !exact) {
        uint64_t facets = 0;
        /* the shortest vertex line is "vertex 0 0 0\n" */
        hd__text_job_t job = {chunk, NULL, candidates, 14, NULL};
        int rc = hd__text_parallel(r, s, (const char *)d + size, 1, &job, &facets);
        if (rc) return rc;
        if (r->sink->count != 3 * facets) return report_bad_facet(r, s);
        r->n_faces = (size_t)facets;
        return add_triangles(r, (size_t)facets);
    }
    if (size < 84)
        return hd__io_err_at(r, HD_EFORMAT, (long long)size, "binary STL needs an 84-byte header, the file has %zu bytes", size);
    if (n > (size - 84) / 50)
        return hd__io_err_at(r, HD_EFORMAT, 80, "binary STL declares %llu triangles (%llu bytes), but the file has %zu bytes",
                             (unsigned long long)n, (unsigned long long)(84 + 50 * n), size);
    if (84 + 50 * n != size)
        return hd__io_err_at(r, HD_EFORMAT, (long long)(84 + 50 * n),
                             "binary STL declares %llu triangles (%llu bytes), but the file has %zu bytes: "
                             "%llu bytes after the last triangle",
                             (unsigned long long)n, (unsigned long long)(84 + 50 * n), size,
                             (unsigned long long)(size - 84 - 50 * n));
    hd__layout_t L = {3 * (size_t)n, 3, 50, 12, {0, 4, 8}, {HD__T_F32, HD__T_F32, HD__T_F32}, 0, NULL, NULL, 96};
    int rc = hd__binary_read(r, d + 96, &L);
    if (rc) return rc;
    r->n_faces = (size_t)n;
    return add_triangles(r, (size_t)n);
}
