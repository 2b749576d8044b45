/*
 * off.c -- the Object File Format (OFF) of Geomview, and its COFF, NOFF,
 * CNOFF variants.
 *
 * Format (Geomview manual, "OFF files"; the Princeton shape benchmark and
 * CGAL write the same): an optional keyword line "[ST][C][N][4][n]OFF",
 * then "NVertices NFaces NEdges", then NVertices lines "x y z" followed by
 * whatever the prefixes add (normals for N, a colour for C, texture
 * coordinates for ST), then NFaces lines "n v1 ... vn" with an optional
 * colour.  '#' starts a comment anywhere; blank lines may appear anywhere.
 * The counts may follow the keyword on its own line ("OFF 8 6 12").  Only
 * three-dimensional ascii OFF is read: 4OFF, nOFF with a dimension other
 * than 3, and "OFF BINARY" are refused by name.
 *
 * Each vertex is one line (every writer does this); the first three numbers
 * are x, y, z, and more are ignored.  The vertex lines are found by counting
 * content lines (so comments between them are fine), then parsed in
 * parallel chunks; the vertex count is checked against the file size first,
 * and the face lines are counted (vertices mode) or parsed (--sample) so a
 * truncated file is reported with its line.
 */
#include "io.h"

#include <stdlib.h>

typedef struct {
    int faces;   /* parse face lines rather than vertex lines */
    uint64_t nv; /* vertex count, for checking face indices */
} off_ctx_t;

/* Tokens of a line up to a '#' comment. */
static int next_token(const char **q, const char *eol, const char **tb, const char **te) {
    if (!hd__token(q, eol, tb, te) || **tb == '#') {
        *q = eol;
        return 0;
    }
    return 1;
}

static void chunk(void *ctx, hd__chunk_t *c) {
    const off_ctx_t *o = ctx;
    const char *p = c->begin, *end = c->end, *tb, *te;
    long long line = 0;
    uint64_t idx[64];
    for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);) {
        line++;
        if (!o->faces) {
            const char *s = q;
            while (s < eol && hd__is_blank((unsigned char)*s)) s++;
            if (s == eol || *s == '#') continue; /* blank or comment */
            if (!hd__chunk_vertex(c, &q, eol, line, "", "expected a vertex (x y z)", 1)) return;
            continue;
        }
        if (!next_token(&q, eol, &tb, &te)) continue; /* blank or comment */
        uint64_t n;
        if (!hd__parse_u64(tb, te, &n)) {
            hd__chunk_fail(c, HD_EFORMAT, line, "face size '%.*s' is not a whole number", (int)(te - tb > 40 ? 40 : te - tb), tb);
            return;
        }
        if (n < 3) {
            hd__chunk_fail(c, HD_EFORMAT, line, "face with %llu vertices (at least 3 are needed)", (unsigned long long)n);
            return;
        }
        if (n > (uint64_t)(eol - q) / 2 + 1) {
            hd__chunk_fail(c, HD_EFORMAT, line, "face of %llu vertices does not fit on its line", (unsigned long long)n);
            return;
        }
        uint64_t *ix = n <= 64 ? idx : hd__malloc_array((size_t)n, sizeof *ix);
        if (!ix) {
            hd__chunk_fail(c, HD_ENOMEM, line, "out of memory for a face of %llu vertices", (unsigned long long)n);
            return;
        }
        for (uint64_t k = 0; k < n; k++) {
            int found = next_token(&q, eol, &tb, &te);
            if (!found || !hd__parse_u64(tb, te, &ix[k])) {
                hd__chunk_fail(c, HD_EFORMAT, line, "face: expected %llu vertex indices, index %llu is %s",
                               (unsigned long long)n, (unsigned long long)k + 1, found ? "not a whole number" : "missing");
                if (ix != idx) free(ix);
                return;
            }
            if (ix[k] >= o->nv) {
                hd__chunk_fail(c, HD_EFORMAT, line, "face refers to vertex %llu, but there are %llu vertices",
                               (unsigned long long)ix[k], (unsigned long long)o->nv);
                if (ix != idx) free(ix);
                return;
            }
        }
        if (!hd__chunk_face(c, ix, idx, (size_t)n, line)) return;
    }
    c->lines = line;
}

/* A token stream over the header lines, skipping comments. */
typedef struct {
    const char *p, *end, *q, *eol;
    long long line;
} stream_t;

/* The next token; *new_line is set when it starts a new line. */
static int stream_next(stream_t *s, const char **tb, const char **te, int *new_line) {
    *new_line = 0;
    for (;;) {
        if (s->q && next_token(&s->q, s->eol, tb, te)) return 1;
        if (s->p >= s->end) return 0;
        s->line++;
        s->eol = hd__eol(s->p, s->end);
        s->q = s->p;
        s->p = s->eol + (s->eol < s->end);
        *new_line = 1;
    }
}

int hd__read_off(hd__read_t *r) {
    const char *s0, *end = (const char *)r->f->data + r->f->size, *tb, *te;
    int rc = hd__text_begin(r, &s0);
    if (rc) return rc;
    stream_t st = {s0, end, NULL, NULL, 0};
    int nl;
    if (!stream_next(&st, &tb, &te, &nl)) return hd__io_err_line(r, HD_EFORMAT, 1, "empty file: no OFF header");
    size_t n = (size_t)(te - tb);
    if (n >= 3 && memcmp(te - 3, "OFF", 3) == 0) {
        int dim_follows = 0;
        for (const char *c = tb; c < te - 3; c++) {
            if (*c == '4') return hd__io_err_line(r, HD_EUNSUPPORTED, st.line, "4D OFF ('%.*s') is not supported", (int)n, tb);
            if (*c == 'n') dim_follows = 1;
            else if (!strchr("STCN", *c))
                return hd__io_err_line(r, HD_EFORMAT, st.line, "unknown OFF keyword '%.*s'", (int)(n > 40 ? 40 : n), tb);
        }
        if (!stream_next(&st, &tb, &te, &nl))
            return hd__io_err_line(r, HD_EFORMAT, st.line, "file ends after the OFF keyword");
        if (dim_follows) {
            uint64_t dim;
            if (!hd__parse_u64(tb, te, &dim) || dim != 3)
                return hd__io_err_line(r, HD_EUNSUPPORTED, st.line, "nOFF of dimension '%.*s' (only 3 is read)",
                                       (int)(te - tb > 40 ? 40 : te - tb), tb);
            if (!stream_next(&st, &tb, &te, &nl))
                return hd__io_err_line(r, HD_EFORMAT, st.line, "file ends after the OFF keyword");
        }
        if (!nl && te - tb == 6 && memcmp(tb, "BINARY", 6) == 0)
            return hd__io_err_line(r, HD_EUNSUPPORTED, st.line, "binary OFF is not supported (convert it to ascii OFF or PLY)");
    }
    /* the counts: vertices and faces, then edges (ignored, may be missing) */
    uint64_t counts[3] = {0, 0, 0};
    long long line = st.line;
    for (int k = 0; k < 3; k++) {
        if (k > 0 && !next_token(&st.q, st.eol, &tb, &te)) {
            if (k == 2) break;
            return hd__io_err_line(r, HD_EFORMAT, line, "expected the counts 'vertices faces edges' on one line");
        }
        if (!hd__parse_u64(tb, te, &counts[k]))
            return hd__io_err_line(r, HD_EFORMAT, line, "expected the %s count, found '%.*s'",
                                   k == 0 ? "vertex" : k == 1 ? "face" : "edge", (int)(te - tb > 40 ? 40 : te - tb), tb);
    }
    const char *p = st.p;
    uint64_t nv = counts[0], nf = counts[1];
    size_t left = (size_t)(end - p);
    if (nv > (left + 1) / 6)
        return hd__io_err_line(r, HD_EFORMAT, line, "%llu vertices declared, but the rest of the file can hold at most %llu",
                               (unsigned long long)nv, (unsigned long long)((left + 1) / 6));
    r->n_faces = (size_t)nf;
    uint64_t found, lines;
    const char *stop = hd__skip_content_lines(p, end, nv, &found, &lines);
    if (found < nv)
        return hd__io_err_line(r, HD_EFORMAT, line + (long long)lines + 1, "file ends after %llu of %llu vertices",
                               (unsigned long long)found, (unsigned long long)nv);
    rc = hd__sink_reserve(r->sink, (size_t)nv);
    if (rc) return hd__io_err(r, rc, "cannot allocate %llu vertices", (unsigned long long)nv);
    off_ctx_t o = {0, nv};
    hd__text_job_t job = {chunk, NULL, hd__content_lines, 6, &o};
    if ((rc = hd__text_parallel(r, p, stop, line + 1, &job, NULL))) return rc;
    line += (long long)lines;
    p = stop;
    left = (size_t)(end - p);
    if (nf > (left + 1) / 2)
        return hd__io_err_line(r, HD_EFORMAT, line, "%llu faces declared, but the rest of the file can hold at most %llu",
                               (unsigned long long)nf, (unsigned long long)((left + 1) / 2));
    stop = hd__skip_content_lines(p, end, nf, &found, &lines);
    if (found < nf)
        return hd__io_err_line(r, HD_EFORMAT, line + (long long)lines + 1, "file ends after %llu of %llu faces",
                               (unsigned long long)found, (unsigned long long)nf);
    if (r->tris) {
        o.faces = 1;
        job.candidates = hd__no_candidates;
        if ((rc = hd__text_parallel(r, p, stop, line + 1, &job, NULL))) return rc;
    }
    /* counts lower than the data: never a silent partial read */
    uint64_t extra, more;
    hd__skip_content_lines(stop, end, 1, &extra, &more);
    if (extra)
        return hd__io_err_line(r, HD_EFORMAT, line + (long long)lines + (long long)more,
                               "more data after the %llu vertices and %llu faces the counts declare",
                               (unsigned long long)nv, (unsigned long long)nf);
    return HD_OK;
}
