/*
 * obj.c -- Wavefront OBJ: the vertices ("v" lines) and, for --sample, the
 * faces ("f" lines).
 *
 * Format (Wavefront "Object Files (.obj)", Appendix B1 of the Advanced
 * Visualizer manual): one statement per line, the keyword first.  "v x y z
 * [w]" is a geometric vertex (some writers append r g b; only x y z are
 * kept).  "f v1 v2 v3 ..." is a polygon whose references are "v", "v/vt",
 * "v//vn" or "v/vt/vn"; v counts from 1 in file order, and a negative v
 * counts back from the latest vertex (-1 is the vertex just above).  Every
 * other statement (vt, vn, g, o, s, usemtl, mtllib, l, p, curves) and '#'
 * comments (also at the end of an "f" line) are ignored; a trailing '\'
 * continuation ends the face (continued lines are not joined).
 *
 * The file is parsed in parallel chunks of whole lines.  A chunk does not
 * know how many vertices came before it, so a relative reference is stored
 * as "chunk-local vertex count + offset" with a flag, and resolved when the
 * chunks are merged in order (fix_chunk), where the number of earlier
 * vertices is known.  References are then checked against the final vertex
 * count; if one is out of range, a serial pass finds the first such line so
 * the message names it.
 */
#include "io.h"

#include <assert.h>
#include <stdlib.h>

#define REL ((uint64_t)1 << 63)
#define REL_MASK (((uint64_t)1 << 62) - 1)
/* An index no file can reach: a stored reference at or above it is out of
 * range whatever the vertex count.  Relative references are clamped to
 * -FAR, so "chunk-local count + offset" always lies in (-2^61, 2^61), the
 * range the 62-bit field below represents exactly (a chunk holds fewer than
 * 2^60 vertices, each needing 8 bytes of text). */
#define FAR ((int64_t)1 << 60)
#define BAD ((uint64_t)FAR << 2) /* absolute, never < a vertex count */

/* Parse the vertex part of a face reference "v[/vt[/vn]]" in [tb, te):
 * 1 with *value (1-based, or negative: counting back), 0 when malformed.
 * Magnitudes beyond FAR are clamped to FAR: they are out of range in any
 * file, and the clamp keeps the arithmetic below from wrapping into range
 * (a reference of -(2^62 - 1) once landed on a real vertex). */
static int face_ref(const char *tb, const char *te, int64_t *value) {
    const char *slash = memchr(tb, '/', (size_t)(te - tb));
    if (slash) te = slash;
    int neg = tb < te && *tb == '-';
    uint64_t v;
    if (!hd__parse_u64(tb + neg, te, &v)) {
        /* all digits but beyond uint64_t: out of range, not malformed */
        const char *d = tb + neg;
        while (d < te && *d >= '0' && *d <= '9') d++;
        if (d != te || te == tb + neg) return 0;
        v = (uint64_t)FAR;
    }
    if (v == 0) return 0;
    if (v > (uint64_t)FAR) v = (uint64_t)FAR;
    *value = neg ? -(int64_t)v : (int64_t)v;
    return 1;
}

/* What may follow a vertex's x y z: numbers (w, or a colour r g b some
 * writers append) and a comment.  Anything else - another statement on the
 * same line, "v 1 2 3 v 4 5 6" - would otherwise lose a vertex without a
 * word: 1 when the tail is acceptable, 0 after failing the chunk. */
static int vertex_tail(hd__chunk_t *c, const char *q, const char *eol, long long line) {
    const char *tb, *te;
    double ignored;
    int k;
    while ((k = hd__next_double(&q, eol, &ignored, &tb, &te)) != 0) {
        if (k > 0) continue;
        if (*tb == '#') return 1;
        hd__chunk_fail(c, HD_EFORMAT, line, "vertex: '%.*s' after x y z is not a number (one statement a line)",
                       (int)(te - tb > 40 ? 40 : te - tb), tb);
        return 0;
    }
    return 1;
}

static void chunk(void *ctx, hd__chunk_t *c) {
    const int *want_faces = ctx;
    const char *p = c->begin, *end = c->end, *tb, *te;
    long long line = 0;
    uint64_t idx[64];
    for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);) {
        line++;
        if (!hd__token(&q, eol, &tb, &te) || te - tb != 1) continue;
        if (*tb == 'v') {
            if (!hd__chunk_vertex(c, &q, eol, line, "vertex: ", "vertex: expected x y z", 0) ||
                !vertex_tail(c, q, eol, line))
                return;
        } else if (*tb == 'f') {
            c->aux++;
            if (!*want_faces) continue;
            size_t n = 0, cap = 64;
            uint64_t *ix = idx;
            while (hd__token(&q, eol, &tb, &te)) {
                if (*tb == '\\' || *tb == '#') break;
                int64_t v;
                if (!face_ref(tb, te, &v)) {
                    hd__chunk_fail(c, HD_EFORMAT, line, "face: '%.*s' is not a vertex reference", (int)(te - tb > 40 ? 40 : te - tb), tb);
                    if (ix != idx) free(ix);
                    return;
                }
                if (n == cap) {
                    uint64_t *nx = hd__malloc_array(cap * 2, sizeof *nx);
                    if (!nx) {
                        if (ix != idx) free(ix);
                        hd__chunk_fail(c, HD_ENOMEM, line, "out of memory for a face");
                        return;
                    }
                    memcpy(nx, ix, n * sizeof *nx);
                    if (ix != idx) free(ix);
                    ix = nx;
                    cap *= 2;
                }
                assert(c->pts.count < (size_t)FAR);
                ix[n++] = v >= FAR ? BAD
                          : v > 0  ? (uint64_t)(v - 1)
                                   : REL | ((uint64_t)((int64_t)c->pts.count + v) & REL_MASK);
            }
            int rc = n >= 3 ? hd__tris_add(&c->tris, ix, n) : HD_OK;
            if (ix != idx) free(ix);
            if (n < 3) {
                hd__chunk_fail(c, HD_EFORMAT, line, "face with %zu vertices (at least 3 are needed)", n);
                return;
            }
            if (rc) {
                hd__chunk_fail(c, rc, line, "out of memory for faces");
                return;
            }
        }
    }
    c->lines = line;
}

static size_t candidates(void *ctx, const char *p, const char *end) {
    (void)ctx;
    return hd__keyword_lines(p, end, "v");
}

/* Resolve relative references now that the vertices before the chunk are
 * known; an unresolvable one becomes BAD (out of range). */
static void fix_chunk(void *ctx, hd__chunk_t *c, size_t before) {
    (void)ctx;
    for (size_t k = 0; k < 3 * c->tris.count; k++) {
        uint64_t v = c->tris.v[k];
        if (!(v & REL)) continue;
        int64_t local = (int64_t)((v & REL_MASK) << 2) >> 2; /* sign-extend 62 bits */
        assert(local > -2 * FAR && local < 2 * FAR);
        int64_t abs_ = (int64_t)before + local;
        c->tris.v[k] = abs_ < 0 ? BAD : (uint64_t)abs_;
    }
}

/* The first face line whose reference is out of range (serial; only run
 * when one is known to exist). */
static int report_bad_reference(hd__read_t *r, const char *p, size_t nv) {
    const char *end = (const char *)r->f->data + r->f->size, *tb, *te;
    long long line = 0;
    uint64_t seen = 0;
    for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);) {
        line++;
        if (!hd__token(&q, eol, &tb, &te) || te - tb != 1) continue;
        if (*tb == 'v') seen++;
        if (*tb != 'f') continue;
        while (hd__token(&q, eol, &tb, &te)) {
            int64_t v;
            if (*tb == '\\' || *tb == '#' || !face_ref(tb, te, &v)) break;
            const char *slash = memchr(tb, '/', (size_t)(te - tb));
            if (slash) te = slash;
            int64_t abs_ = v > 0 ? v - 1 : (int64_t)seen + v;
            if (abs_ < 0 || (uint64_t)abs_ >= nv)
                return hd__io_err_line(r, HD_EFORMAT, line, "face refers to vertex %.*s, but the file has %zu vertices",
                                       (int)(te - tb > 40 ? 40 : te - tb), tb, nv);
        }
    }
    return hd__io_err(r, HD_EFORMAT, "a face refers to a vertex that does not exist");
}

int hd__read_obj(hd__read_t *r) {
    const char *s, *end = (const char *)r->f->data + r->f->size;
    int rc = hd__text_begin(r, &s);
    if (rc) return rc;
    int want_faces = r->tris != NULL;
    uint64_t faces = 0;
    /* the shortest vertex line is "v 0 0 0\n" */
    hd__text_job_t job = {chunk, fix_chunk, candidates, 8, &want_faces};
    rc = hd__text_parallel(r, s, end, 1, &job, &faces);
    if (rc) return rc;
    r->n_faces = (size_t)faces;
    if (r->tris)
        for (size_t k = 0; k < 3 * r->tris->count; k++)
            if (r->tris->v[k] >= r->sink->count) return report_bad_reference(r, s, r->sink->count);
    return HD_OK;
}
