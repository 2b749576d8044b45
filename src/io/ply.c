/*
 * ply.c -- the Stanford polygon file format (PLY), ascii and binary.
 *
 * Format (Turk, "The PLY polygon file format", 1994; the paulbourke.net and
 * RPly descriptions agree): a text header, "ply", then "format ascii 1.0",
 * "format binary_little_endian 1.0" or "format binary_big_endian 1.0",
 * "comment"/"obj_info" lines, and "element NAME COUNT" each followed by its
 * "property TYPE NAME" or "property list COUNT_TYPE ITEM_TYPE NAME" lines,
 * up to "end_header".  The data holds the elements in header order, COUNT
 * instances each, each instance its properties in order.  Types are char
 * uchar short ushort int uint float double and their sized aliases int8
 * uint8 int16 uint16 int32 uint32 float32 float64.
 *
 * What is read: element "vertex", properties x, y, z of any numeric type
 * (widened to double exactly); every other element and property is skipped
 * by its declared size (lists by their counts).  With --sample, element
 * "face" with list property vertex_indices (or vertex_index) is read too.
 *
 * Invariants.  Every count in the header is checked against the bytes after
 * the header before anything is allocated: a binary instance occupies at
 * least the sum of its scalar sizes and list count sizes, an ascii instance
 * at least two bytes per property, so a vertex count of 2^62 is refused as
 * "more than the file can hold", never allocated.  Fixed-size binary
 * vertices are converted in parallel straight from the mapping
 * (hd__binary_points); ascii vertices are one instance per line (every PLY
 * writer does this; the spec only requires whitespace) and are parsed in
 * parallel chunks (hd__text_parallel) with correctly rounded conversions.
 * After the vertices, the remaining elements are still checked to be
 * present (binary: walked or measured; ascii: enough lines), so a truncated
 * file is reported, not silently accepted.
 */
#include "io.h"

#include <stdlib.h>
#include <strings.h>

#define MAX_ELEMENTS 64
#define MAX_PROPS 256

typedef struct {
    const char *name;
    size_t len;
    hd__type_t type;       /* scalar type, or list item type */
    hd__type_t count_type; /* HD__T_NONE for a scalar */
} prop_t;

typedef struct {
    const char *name;
    size_t len;
    uint64_t count;
    long long line;
    prop_t *props; /* n_props of them, grown as they are declared */
    int n_props, cap_props;
    int has_list;
    size_t fixed; /* bytes of scalars and list counts per instance */
} elem_t;

typedef struct {
    hd__read_t *r;
    int format; /* 0 ascii, 1 little, 2 big */
    elem_t el[MAX_ELEMENTS];
    int n_el;
    size_t data; /* offset of the first data byte */
    long long data_line;
} ply_t;

static int is(const char *s, size_t n, const char *word) {
    return strlen(word) == n && memcmp(s, word, n) == 0;
}

static hd__type_t type_of(const char *s, size_t n) {
    static const struct {
        const char *a, *b;
        hd__type_t t;
    } names[] = {{"char", "int8", HD__T_I8},     {"uchar", "uint8", HD__T_U8},
                 {"short", "int16", HD__T_I16},  {"ushort", "uint16", HD__T_U16},
                 {"int", "int32", HD__T_I32},    {"uint", "uint32", HD__T_U32},
                 {"float", "float32", HD__T_F32}, {"double", "float64", HD__T_F64}};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++)
        if (is(s, n, names[k].a) || is(s, n, names[k].b)) return names[k].t;
    return HD__T_NONE;
}

/* The largest value an integer type can hold (0 for the float types, which
 * can be neither a list count nor a vertex index). */
static uint64_t int_max(hd__type_t t) {
    switch (t) {
    case HD__T_I8: return INT8_MAX;
    case HD__T_U8: return UINT8_MAX;
    case HD__T_I16: return INT16_MAX;
    case HD__T_U16: return UINT16_MAX;
    case HD__T_I32: return INT32_MAX;
    case HD__T_U32: return UINT32_MAX;
    default: return 0;
    }
}

static const char *type_name(hd__type_t t) {
    static const char *const names[] = {"none", "char", "uchar", "short", "ushort", "int", "uint",
                                        "int64", "uint64", "float", "double"};
    return names[t];
}

/* The first property of e after index `after` named `name`, or -1. */
static int prop_index_after(const elem_t *e, int after, const char *name) {
    for (int k = after + 1; k < e->n_props; k++)
        if (is(e->props[k].name, e->props[k].len, name)) return k;
    return -1;
}

static int prop_index(const elem_t *e, const char *name) { return prop_index_after(e, -1, name); }

/* Parse the header into p; sets p->data to the first byte after it. */
static int header(ply_t *p) {
    hd__read_t *r = p->r;
    const char *s = (const char *)r->f->data, *end = s + r->f->size, *q;
    int rc = hd__text_begin(r, &q);
    if (rc) return rc;
    long long line = 0;
    int have_format = 0;
    for (;;) {
        if (q >= end) return hd__io_err_line(r, HD_EFORMAT, line + 1, "header ends before 'end_header'");
        line++;
        const char *eol = hd__eol(q, end), *cur = q, *tb, *te;
        q = eol + (eol < end);
        if (line == 1) {
            if (!hd__token(&cur, eol, &tb, &te) || !is(tb, (size_t)(te - tb), "ply"))
                return hd__io_err_line(r, HD_EFORMAT, 1, "not a PLY file (it does not start with 'ply')");
            continue;
        }
        if (!hd__token(&cur, eol, &tb, &te)) continue; /* blank header line: tolerated */
        size_t n = (size_t)(te - tb);
        if (is(tb, n, "comment") || is(tb, n, "obj_info")) continue;
        if (is(tb, n, "end_header")) {
            if (!have_format) return hd__io_err_line(r, HD_EFORMAT, line, "no 'format' line in the header");
            p->data = (size_t)(q - s);
            p->data_line = line + 1;
            return HD_OK;
        }
        if (is(tb, n, "format")) {
            const char *vb, *ve;
            if (!hd__token(&cur, eol, &tb, &te) || !hd__token(&cur, eol, &vb, &ve))
                return hd__io_err_line(r, HD_EFORMAT, line, "'format' needs a type and a version");
            n = (size_t)(te - tb);
            if (is(tb, n, "ascii")) p->format = 0;
            else if (is(tb, n, "binary_little_endian")) p->format = 1;
            else if (is(tb, n, "binary_big_endian")) p->format = 2;
            else return hd__io_err_line(r, HD_EUNSUPPORTED, line, "unknown PLY format '%.*s'", (int)n, tb);
            if (!is(vb, (size_t)(ve - vb), "1.0") && !is(vb, (size_t)(ve - vb), "1"))
                return hd__io_err_line(r, HD_EUNSUPPORTED, line, "unsupported PLY version '%.*s'",
                                       (int)(ve - vb), vb);
            have_format = 1;
        } else if (is(tb, n, "element")) {
            const char *cb, *ce, *nb, *ne;
            if (!hd__token(&cur, eol, &nb, &ne) || !hd__token(&cur, eol, &cb, &ce))
                return hd__io_err_line(r, HD_EFORMAT, line, "'element' needs a name and a count");
            if (p->n_el == MAX_ELEMENTS)
                return hd__io_err_line(r, HD_EUNSUPPORTED, line, "more than %d elements", MAX_ELEMENTS);
            elem_t *e = &p->el[p->n_el++];
            memset(e, 0, sizeof *e);
            e->name = nb;
            e->len = (size_t)(ne - nb);
            e->line = line;
            if (!hd__parse_u64(cb, ce, &e->count))
                return hd__io_err_line(r, HD_EFORMAT, line, "element count '%.*s' is not a whole number",
                                       (int)(ce - cb), cb);
        } else if (is(tb, n, "property")) {
            if (!p->n_el) return hd__io_err_line(r, HD_EFORMAT, line, "'property' before any 'element'");
            elem_t *e = &p->el[p->n_el - 1];
            if (e->n_props == MAX_PROPS)
                return hd__io_err_line(r, HD_EUNSUPPORTED, line, "more than %d properties", MAX_PROPS);
            if (e->n_props == e->cap_props) {
                int cap = e->cap_props ? 2 * e->cap_props : 8;
                prop_t *np = hd__realloc_array(e->props, (size_t)cap, sizeof *np);
                if (!np) return hd__io_err(r, HD_ENOMEM, "out of memory for the header");
                e->props = np;
                e->cap_props = cap;
            }
            prop_t *pr = &e->props[e->n_props];
            memset(pr, 0, sizeof *pr);
            const char *nb, *ne;
            if (!hd__token(&cur, eol, &tb, &te))
                return hd__io_err_line(r, HD_EFORMAT, line, "'property' needs a type and a name");
            if (is(tb, (size_t)(te - tb), "list")) {
                const char *ib, *ie;
                if (!hd__token(&cur, eol, &tb, &te) || !hd__token(&cur, eol, &ib, &ie) ||
                    !hd__token(&cur, eol, &nb, &ne))
                    return hd__io_err_line(r, HD_EFORMAT, line,
                                           "'property list' needs a count type, an item type and a name");
                pr->count_type = type_of(tb, (size_t)(te - tb));
                pr->type = type_of(ib, (size_t)(ie - ib));
                if (!pr->count_type || !pr->type) {
                    const char *bad = pr->count_type ? ib : tb, *bade = pr->count_type ? ie : te;
                    return hd__io_err_line(r, HD_EFORMAT, line, "unknown property type '%.*s'",
                                           (int)(bade - bad), bad);
                }
                if (pr->count_type == HD__T_F32 || pr->count_type == HD__T_F64)
                    return hd__io_err_line(r, HD_EFORMAT, line, "a list count cannot be of type '%.*s'",
                                           (int)(te - tb), tb);
                e->has_list = 1;
                e->fixed += hd__type_size(pr->count_type);
            } else {
                pr->type = type_of(tb, (size_t)(te - tb));
                if (!pr->type)
                    return hd__io_err_line(r, HD_EFORMAT, line, "unknown property type '%.*s'",
                                           (int)(te - tb), tb);
                if (!hd__token(&cur, eol, &nb, &ne))
                    return hd__io_err_line(r, HD_EFORMAT, line, "'property' needs a name");
                e->fixed += hd__type_size(pr->type);
            }
            pr->name = nb;
            pr->len = (size_t)(ne - nb);
            e->n_props++;
        } else {
            return hd__io_err_line(r, HD_EFORMAT, line, "unknown header keyword '%.*s'", (int)n, tb);
        }
    }
}

/* ---- binary ------------------------------------------------------------- */

/* An integer of type t at b (signed types sign-extended); 0 for floats. */
static int load_int(const unsigned char *b, hd__type_t t, int big, int64_t *out) {
    switch (t) {
    case HD__T_I8: *out = (int8_t)b[0]; return 1;
    case HD__T_U8: *out = b[0]; return 1;
    case HD__T_I16: *out = (int16_t)hd__ld_u16(b, big); return 1;
    case HD__T_U16: *out = hd__ld_u16(b, big); return 1;
    case HD__T_I32: *out = (int32_t)hd__ld_u32(b, big); return 1;
    case HD__T_U32: *out = hd__ld_u32(b, big); return 1;
    default: return 0;
    }
}

/* Walk `e` instance by instance from *pos (binary with lists), collecting
 * vertices (when xyz is not NULL) or faces (when `face` >= 0 and r->tris). */
static int walk_binary(ply_t *p, const elem_t *e, size_t *pos, const int *xyz, int face, uint64_t nv) {
    hd__read_t *r = p->r;
    const unsigned char *d = r->f->data;
    size_t size = r->f->size, at = *pos;
    int big = p->format == 2;
    uint64_t idx[64];
    for (uint64_t k = 0; k < e->count; k++) {
        double v[3] = {0, 0, 0};
        size_t start = at;
        for (int j = 0; j < e->n_props; j++) {
            const prop_t *pr = &e->props[j];
            if (!pr->count_type) {
                size_t sz = hd__type_size(pr->type);
                if (size - at < sz) goto truncated;
                if (xyz)
                    for (int c = 0; c < 3; c++)
                        if (xyz[c] == j) v[c] = hd__ld_value(d + at, pr->type, big);
                at += sz;
                continue;
            }
            size_t csz = hd__type_size(pr->count_type), isz = hd__type_size(pr->type);
            if (size - at < csz) goto truncated;
            int64_t cnt;
            load_int(d + at, pr->count_type, big, &cnt);
            if (cnt < 0)
                return hd__io_err_at(r, HD_EFORMAT, (long long)at, "element %.*s %llu: negative list length %lld",
                                     (int)e->len, e->name, (unsigned long long)k, (long long)cnt);
            at += csz;
            if ((uint64_t)cnt > (size - at) / isz) goto truncated;
            if (j == face && r->tris) {
                if (pr->type == HD__T_F32 || pr->type == HD__T_F64)
                    return hd__io_err_at(r, HD_EFORMAT, (long long)at, "face vertex indices are not integers");
                if (cnt < 3)
                    return hd__io_err_at(r, HD_EFORMAT, (long long)(at - csz),
                                         "face %llu with %lld vertices (at least 3 are needed)", (unsigned long long)k,
                                         (long long)cnt);
                uint64_t *ix = (uint64_t)cnt <= 64 ? idx : hd__malloc_array((size_t)cnt, sizeof *ix);
                if (!ix) return hd__io_err(r, HD_ENOMEM, "out of memory for a face of %lld vertices", (long long)cnt);
                int rc = HD_OK;
                for (int64_t q = 0; q < cnt && !rc; q++) {
                    int64_t x;
                    load_int(d + at + (size_t)q * isz, pr->type, big, &x);
                    if (x < 0 || (uint64_t)x >= nv)
                        rc = hd__io_err_at(r, HD_EFORMAT, (long long)(at + (size_t)q * isz),
                                           "face %llu refers to vertex %lld, but there are %llu vertices",
                                           (unsigned long long)k, (long long)x, (unsigned long long)nv);
                    ix[q] = (uint64_t)x;
                }
                if (!rc && hd__tris_add(r->tris, ix, (size_t)cnt)) rc = hd__io_err(r, HD_ENOMEM, "out of memory for faces");
                if (ix != idx) free(ix);
                if (rc) return rc;
            }
            at += (size_t)cnt * isz;
        }
        if (xyz) {
            int rc = hd__sink_push(r->sink, v);
            if (rc) return hd__io_err_at(r, rc, (long long)start, "vertex %llu: %s", (unsigned long long)k,
                                         hd__point_problem(rc));
        }
    }
    *pos = at;
    return HD_OK;
truncated:
    return hd__io_err_at(r, HD_EFORMAT, (long long)size, "file ends inside element %.*s (%llu declared)",
                         (int)e->len, e->name, (unsigned long long)e->count);
}

static int read_binary(ply_t *p, int v, const int *xyz, int face_el, int face) {
    hd__read_t *r = p->r;
    size_t pos = p->data, size = r->f->size;
    int big = p->format == 2;
    for (int k = 0; k < p->n_el; k++) {
        const elem_t *e = &p->el[k];
        int rc;
        if (!e->has_list) {
            if (e->fixed && e->count > (size - pos) / e->fixed)
                return hd__io_err_at(r, HD_EFORMAT, (long long)size,
                                     "file ends inside element %.*s: %llu declared, room for %zu",
                                     (int)e->len, e->name, (unsigned long long)e->count, (size - pos) / e->fixed);
            if (k == v) {
                size_t off[3];
                hd__type_t type[3];
                for (int c = 0; c < 3; c++) {
                    off[c] = 0;
                    for (int j = 0; j < xyz[c]; j++) off[c] += hd__type_size(e->props[j].type);
                    type[c] = e->props[xyz[c]].type;
                }
                rc = hd__binary_points(r, r->f->data + pos, (size_t)e->count, e->fixed, off, type, big, pos);
                if (rc) return rc;
            }
            pos += (size_t)e->count * e->fixed;
            continue;
        }
        if (e->count > (size - pos) / (e->fixed ? e->fixed : 1))
            return hd__io_err_at(r, HD_EFORMAT, (long long)size,
                                 "file ends inside element %.*s: %llu declared, room for at most %zu",
                                 (int)e->len, e->name, (unsigned long long)e->count, (size - pos) / e->fixed);
        if (k == v && (rc = hd__sink_reserve(r->sink, (size_t)e->count)))
            return hd__io_err(r, rc, "cannot allocate %llu vertices", (unsigned long long)e->count);
        if ((rc = walk_binary(p, e, &pos, k == v ? xyz : NULL, k == face_el ? face : -1,
                              k > v ? r->sink->count : UINT64_MAX)))
            return rc;
    }
    if (pos != size)
        return hd__io_err_at(r, HD_EFORMAT, (long long)pos,
                             "%zu bytes after the last element (%.*s, %llu declared): a count is lower than the data",
                             size - pos, (int)p->el[p->n_el - 1].len, p->el[p->n_el - 1].name,
                             (unsigned long long)p->el[p->n_el - 1].count);
    return HD_OK;
}

/* ---- ascii ------------------------------------------------------------- */

typedef struct {
    const elem_t *e;
    int xyz[3];
    int face;    /* property index of the face list, or -1 */
    uint64_t nv; /* vertices read so far, for checking face indices */
} ascii_ctx_t;

/* One instance line: the properties of e in order; x/y/z kept in v, the
 * face list (if wanted) added to c->tris. */
static void vertex_chunk(void *ctx, hd__chunk_t *c) {
    const ascii_ctx_t *a = ctx;
    const elem_t *e = a->e;
    const char *p = c->begin, *end = c->end;
    long long line = 0;
    uint64_t idx[64];
    for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);) {
        line++;
        const char *tb = q, *te = q;
        double v[3] = {0, 0, 0};
        int found = 0;
        for (int j = 0; j < e->n_props; j++) {
            const prop_t *pr = &e->props[j];
            int cc = pr->count_type ? -1 : j == a->xyz[0] ? 0 : j == a->xyz[1] ? 1 : j == a->xyz[2] ? 2 : -1;
            int got = cc >= 0 ? hd__next_double(&q, eol, &v[cc], &tb, &te) : hd__token(&q, eol, &tb, &te);
            if (!got) {
                hd__chunk_fail(c, HD_EFORMAT, line, "element %.*s: expected a value for property %.*s, found end of line",
                               (int)e->len, e->name, (int)pr->len, pr->name);
                return;
            }
            if (got < 0) {
                hd__chunk_fail(c, HD_EFORMAT, line, "'%.*s' is not a number (property %.*s)", (int)(te - tb > 40 ? 40 : te - tb),
                               tb, (int)pr->len, pr->name);
                return;
            }
            found += cc >= 0;
            if (!pr->count_type) continue;
            uint64_t cnt;
            if (!hd__parse_u64(tb, te, &cnt)) {
                hd__chunk_fail(c, HD_EFORMAT, line, "list length '%.*s' is not a whole number",
                               (int)(te - tb > 40 ? 40 : te - tb), tb);
                return;
            }
            /* The count must fit its declared type, and every item needs a
             * token of at least one byte and a separator: both are checked
             * before anything is allocated or stored. */
            if (cnt > int_max(pr->count_type)) {
                hd__chunk_fail(c, HD_EFORMAT, line, "list %.*s: length %llu does not fit its count type %s",
                               (int)pr->len, pr->name, (unsigned long long)cnt, type_name(pr->count_type));
                return;
            }
            if (cnt > (uint64_t)(eol - q + 1) / 2) {
                hd__chunk_fail(c, HD_EFORMAT, line, "list %.*s: %llu values declared, but the line holds at most %llu",
                               (int)pr->len, pr->name, (unsigned long long)cnt,
                               (unsigned long long)((eol - q + 1) / 2));
                return;
            }
            int keep = j == a->face;
            if (keep && cnt < 3) {
                hd__chunk_fail(c, HD_EFORMAT, line, "face with %llu vertices (at least 3 are needed)", (unsigned long long)cnt);
                return;
            }
            uint64_t *ix = idx;
            if (keep && cnt > 64 && !(ix = hd__malloc_array((size_t)cnt, sizeof *ix))) {
                hd__chunk_fail(c, HD_ENOMEM, line, "out of memory for a face of %llu vertices", (unsigned long long)cnt);
                return;
            }
            for (uint64_t k = 0; k < cnt; k++) {
                if (!hd__token(&q, eol, &tb, &te)) {
                    hd__chunk_fail(c, HD_EFORMAT, line, "list %.*s: expected %llu values, found %llu",
                                   (int)pr->len, pr->name, (unsigned long long)cnt, (unsigned long long)k);
                    if (ix != idx) free(ix);
                    return;
                }
                if (keep && !hd__parse_u64(tb, te, &ix[k])) {
                    hd__chunk_fail(c, HD_EFORMAT, line, "face vertex index '%.*s' is not a whole number",
                                   (int)(te - tb > 40 ? 40 : te - tb), tb);
                    if (ix != idx) free(ix);
                    return;
                }
                if (keep && ix[k] > int_max(pr->type)) {
                    hd__chunk_fail(c, HD_EFORMAT, line, "face vertex index %llu does not fit its type %s",
                                   (unsigned long long)ix[k], type_name(pr->type));
                    if (ix != idx) free(ix);
                    return;
                }
                if (keep && ix[k] >= a->nv) {
                    hd__chunk_fail(c, HD_EFORMAT, line, "face refers to vertex %llu, but there are %llu vertices",
                                   (unsigned long long)ix[k], (unsigned long long)a->nv);
                    if (ix != idx) free(ix);
                    return;
                }
            }
            if (keep && !hd__chunk_face(c, ix, idx, (size_t)cnt, line)) return;
        }
        if (hd__token(&q, eol, &tb, &te)) {
            hd__chunk_fail(c, HD_EFORMAT, line, "element %.*s: more values than its %d properties ('%.*s')",
                           (int)e->len, e->name, e->n_props, (int)(te - tb > 40 ? 40 : te - tb), tb);
            return;
        }
        if (found == 3 && !hd__chunk_push(c, line, v)) return;
    }
    c->lines = line;
}

/* After the last element only blank lines may follow: anything else means
 * a count lower than the data, and a silent partial read is never made. */
static int trailing_lines(ply_t *p, const char *q, long long line) {
    hd__read_t *r = p->r;
    const char *end = (const char *)r->f->data + r->f->size;
    for (; q < end; line++) {
        const char *eol = hd__eol(q, end), *tb, *te, *cur = q;
        if (hd__token(&cur, eol, &tb, &te))
            return hd__io_err_line(r, HD_EFORMAT, line, "data after the last element (%.*s, %llu declared): "
                                   "a count is lower than the data",
                                   (int)p->el[p->n_el - 1].len, p->el[p->n_el - 1].name,
                                   (unsigned long long)p->el[p->n_el - 1].count);
        q = eol + (eol < end);
    }
    return HD_OK;
}

static int read_ascii(ply_t *p, int v, const int *xyz, int face_el, int face) {
    hd__read_t *r = p->r;
    const char *s = (const char *)r->f->data, *end = s + r->f->size;
    const char *q = s + p->data;
    long long line = p->data_line;
    for (int k = 0; k < p->n_el; k++) {
        const elem_t *e = &p->el[k];
        size_t left = (size_t)(end - q);
        /* an instance needs at least 2 bytes per property (value and
         * separator), but the last line may lack its newline */
        uint64_t room = e->n_props ? (left + 1) / (2 * (uint64_t)e->n_props) : left + 1;
        if (e->count > room)
            return hd__io_err_line(r, HD_EFORMAT, e->line,
                                   "element %.*s: %llu declared, but the file can hold at most %llu",
                                   (int)e->len, e->name, (unsigned long long)e->count, (unsigned long long)room);
        uint64_t got;
        const char *stop = hd__skip_lines(q, end, e->count, &got);
        if (got < e->count)
            return hd__io_err_line(r, HD_EFORMAT, line + (long long)got,
                                   "file ends inside element %.*s: %llu declared, %llu found",
                                   (int)e->len, e->name, (unsigned long long)e->count, (unsigned long long)got);
        int want_faces = k == face_el && face >= 0 && r->tris;
        if (k != v && !want_faces) { /* neither vertices nor wanted faces: skipped */
            q = stop;
            line += (long long)e->count;
            continue;
        }
        ascii_ctx_t a = {e, {-1, -1, -1}, -1, k > v ? r->sink->count : UINT64_MAX};
        if (k == v) memcpy(a.xyz, xyz, sizeof a.xyz);
        else a.face = face;
        if (k == v) {
            int rc = hd__sink_reserve(r->sink, (size_t)e->count);
            if (rc) return hd__io_err(r, rc, "cannot allocate %llu vertices", (unsigned long long)e->count);
        }
        /* every line of the vertex element is a vertex; face lines are none */
        hd__text_job_t job = {vertex_chunk, NULL, k == v ? NULL : hd__no_candidates, 2 * (size_t)e->n_props, &a};
        int rc = hd__text_parallel(r, q, stop, line, &job, NULL);
        if (rc) return rc;
        q = stop;
        line += (long long)e->count;
    }
    return trailing_lines(p, q, line);
}

int hd__read_ply(hd__read_t *r) {
    ply_t *p = calloc(1, sizeof *p);
    if (!p) return hd__io_err(r, HD_ENOMEM, "out of memory");
    p->r = r;
    int rc = header(p);
    int v = -1, face_el = -1, face = -1, xyz[3] = {-1, -1, -1};
    for (int k = 0; rc == HD_OK && k < p->n_el; k++) {
        const elem_t *e = &p->el[k];
        int *seen = is(e->name, e->len, "vertex") ? &v : is(e->name, e->len, "face") ? &face_el : NULL;
        if (seen && *seen >= 0) /* which one other readers take is anybody's guess */
            rc = hd__io_err_line(r, HD_EFORMAT, e->line, "element '%.*s' declared twice (first on line %lld)",
                                 (int)e->len, e->name, p->el[*seen].line);
        else if (seen)
            *seen = k;
    }
    if (rc == HD_OK && v < 0) rc = hd__io_err(r, HD_EFORMAT, "the header declares no element 'vertex'");
    for (int c = 0; rc == HD_OK && c < 3; c++) {
        const char *name = c == 0 ? "x" : c == 1 ? "y" : "z";
        xyz[c] = prop_index(&p->el[v], name);
        if (xyz[c] < 0)
            rc = hd__io_err_line(r, HD_EFORMAT, p->el[v].line, "element vertex has no property '%s'", name);
        else if (prop_index_after(&p->el[v], xyz[c], name) >= 0)
            rc = hd__io_err_line(r, HD_EFORMAT, p->el[v].line, "element vertex declares property '%s' twice", name);
        else if (p->el[v].props[xyz[c]].count_type)
            rc = hd__io_err_line(r, HD_EFORMAT, p->el[v].line, "vertex property '%s' is a list", name);
    }
    if (rc == HD_OK && face_el >= 0) {
        r->n_faces = (size_t)p->el[face_el].count;
        face = prop_index(&p->el[face_el], "vertex_indices");
        if (face < 0) face = prop_index(&p->el[face_el], "vertex_index");
        if (face >= 0 && !p->el[face_el].props[face].count_type) face = -1;
    }
    if (rc == HD_OK && r->tris && face < 0)
        rc = hd__io_err(r, HD_EFORMAT, "has no faces to sample from (no element 'face' with a "
                                       "'vertex_indices' list)");
    if (rc == HD_OK && r->tris && int_max(p->el[face_el].props[face].type) == 0)
        rc = hd__io_err_line(r, HD_EFORMAT, p->el[face_el].line, "face vertex indices are of type %s, not integers",
                             type_name(p->el[face_el].props[face].type));
    if (rc == HD_OK)
        rc = p->format ? read_binary(p, v, xyz, face_el, face) : read_ascii(p, v, xyz, face_el, face);
    /* Faces declared before the vertices could not be checked while they
     * were read (the vertex count was not known yet): check them now,
     * before anything uses them. */
    if (rc == HD_OK && r->tris && face_el < v)
        for (size_t k = 0; k < 3 * r->tris->count; k++)
            if (r->tris->v[k] >= r->sink->count) {
                rc = hd__io_err_line(r, HD_EFORMAT, p->el[face_el].line,
                                     "element face refers to vertex %llu, but the file has %zu vertices",
                                     (unsigned long long)r->tris->v[k], r->sink->count);
                break;
            }
    for (int k = 0; k < p->n_el; k++) free(p->el[k].props);
    free(p);
    return rc;
}

/* ---- writing a field back (hd_write_field) ------------------------------ */
/* The file is copied element by element.  Header: every line as it is,
 * except `element vertex N` (a subset's count), `property double NAME`
 * added after the vertex element's last property, and, in a subset, the
 * lines of the other elements left out (their instances refer to vertices
 * by index).  Data: a vertex instance is copied with the value after it
 * (binary: 8 bytes in the file's byte order; ascii: a blank and the
 * shortest decimal that reads back to it, before the line's end); other
 * elements' bytes are copied as they are. */

/* Bytes of the binary instance of e at pos, or 0 when it does not fit in
 * size (the reader has accepted the file, so this is a guard). */
static size_t instance_size(const elem_t *e, const unsigned char *d, size_t pos, size_t size, int big) {
    if (!e->has_list) return e->fixed <= size - pos ? e->fixed : 0;
    size_t at = pos;
    for (int j = 0; j < e->n_props; j++) {
        const prop_t *pr = &e->props[j];
        size_t cs = hd__type_size(pr->count_type ? pr->count_type : pr->type);
        if (cs > size - at) return 0;
        if (!pr->count_type) {
            at += cs;
            continue;
        }
        double c = hd__ld_value(d + at, pr->count_type, big);
        at += cs;
        if (!(c >= 0) || c > (double)((size - at) / hd__type_size(pr->type))) return 0;
        at += (size_t)c * hd__type_size(pr->type);
    }
    return at - pos;
}

/* The line terminator of the line ending at eol ("\r\n", "\n" or none). */
static const char *line_end(const char *q, const char *eol, const char *end) {
    if (eol == end) return "\n";
    return eol > q && eol[-1] == '\r' ? "\r\n" : "\n";
}

static void put_str(hd__writer_t *w, const char *s) { hd__w_put(w, s, strlen(s)); }

/* The header as described above. */
static void write_header(hd__writer_t *w, const ply_t *p, int v, int subset, size_t kept) {
    const char *s = (const char *)w->in->data, *hend = s + p->data, *q = s, *eol;
    int k = -1;
    for (const char *line; hd__next_line(&q, hend, &line, &eol);) {
        const char *cur = line, *tb, *te;
        int tok = hd__token(&cur, eol, &tb, &te);
        int is_el = tok && is(tb, (size_t)(te - tb), "element"), is_end = tok && is(tb, (size_t)(te - tb), "end_header");
        const char *nl = line_end(line, eol, hend);
        for (size_t j = 0; (is_el || is_end) && k == v && j < w->nf; j++) {
            put_str(w, "property double ");
            put_str(w, w->f[j].name);
            put_str(w, nl);
        }
        if (is_el) k++;
        if (subset && k >= 0 && k != v && !is_end) continue; /* another element: left out */
        if (is_el && k == v && subset) {
            char buf[64];
            snprintf(buf, sizeof buf, "element %.*s %zu", (int)p->el[v].len, p->el[v].name, kept);
            put_str(w, buf);
            put_str(w, nl);
            continue;
        }
        hd__w_put(w, line, (size_t)(q - line));
    }
}

/* Bytes gathered into blocks of BLOCK before they are written. */
enum { BLOCK = 1 << 16 };
typedef struct {
    unsigned char *buf; /* BLOCK bytes */
    size_t used;
} staged_t;

static void stage(hd__writer_t *w, staged_t *s, const void *p, size_t n) {
    if (s->used + n > BLOCK) {
        hd__w_put(w, s->buf, s->used);
        s->used = 0;
    }
    if (n > BLOCK) {
        hd__w_put(w, p, n);
        return;
    }
    memcpy(s->buf + s->used, p, n);
    s->used += n;
}

static int write_binary(hd__writer_t *w, const ply_t *p, int v, int subset) {
    const unsigned char *d = w->in->data;
    size_t pos = p->data, size = w->in->size;
    int big = p->format == 2;
    unsigned char *vals = malloc(8 * w->nf + 1); /* a vertex's values */
    staged_t st = {malloc(BLOCK), 0};
    if (!vals || !st.buf) {
        free(vals), free(st.buf);
        return hd__err(w->err, HD_ENOMEM, "out of memory");
    }
    for (int k = 0; k < p->n_el; k++) {
        const elem_t *e = &p->el[k];
        size_t from = pos;
        for (uint64_t i = 0; i < e->count; i++) {
            size_t n = instance_size(e, d, pos, size, big);
            if (n == 0 && (e->has_list || e->fixed)) {
                free(vals), free(st.buf);
                return hd__err(w->err, HD_EFORMAT, "%s: byte %zu: element %.*s ends early", w->in->name, pos, (int)e->len,
                               e->name);
            }
            if (k == v && hd__w_keep(w, (size_t)i)) {
                stage(w, &st, d + pos, n);
                hd__w_values(w, (size_t)i, big, vals);
                stage(w, &st, vals, 8 * w->nf);
                w->written++;
            }
            pos += n;
            if (k != v && !e->has_list) { /* fixed instances: the block at once */
                pos = from + (size_t)e->count * e->fixed;
                break;
            }
        }
        if (k == v) {
            hd__w_put(w, st.buf, st.used);
            st.used = 0;
        }
        if (k != v && !subset) hd__w_put(w, d + from, pos - from);
    }
    free(vals), free(st.buf);
    return HD_OK;
}

static int write_ascii(hd__writer_t *w, const ply_t *p, int v, int subset) {
    const char *s = (const char *)w->in->data, *end = s + w->in->size, *q = s + p->data;
    char num[40];
    num[0] = ' ';
    for (int k = 0; k < p->n_el; k++) {
        const elem_t *e = &p->el[k];
        const char *from = q;
        if (k != v) {
            uint64_t got;
            q = hd__skip_lines(q, end, e->count, &got);
            if (!subset) hd__w_put(w, from, (size_t)(q - from));
            continue;
        }
        for (uint64_t i = 0; i < e->count; i++) {
            const char *line, *eol;
            if (!hd__next_line(&q, end, &line, &eol))
                return hd__err(w->err, HD_EFORMAT, "%s: file ends inside element %.*s", w->in->name, (int)e->len, e->name);
            if (!hd__w_keep(w, (size_t)i)) continue;
            const char *c = eol;
            while (c > line && hd__is_blank((unsigned char)c[-1])) c--;
            hd__w_put(w, line, (size_t)(c - line));
            for (size_t j = 0; j < w->nf; j++) hd__w_put(w, num, 1 + hd__shortest(w->f[j].values[i], num + 1));
            put_str(w, line_end(line, eol, end));
            w->written++;
        }
    }
    if (!subset) hd__w_put(w, q, (size_t)(end - q)); /* blank lines after the last element */
    return HD_OK;
}

int hd__write_ply(hd__writer_t *w) {
    ply_t *p = calloc(1, sizeof *p);
    if (!p) return hd__err(w->err, HD_ENOMEM, "out of memory");
    hd__sink_t none;
    hd__sink_init(&none, HD_FLOAT64);
    hd__read_t r = {w->in, w->ropt, 1, &none, NULL, 0, w->err, 0, 0, 0};
    p->r = &r;
    int rc = header(p), v = -1;
    for (int k = 0; rc == HD_OK && k < p->n_el; k++)
        if (is(p->el[k].name, p->el[k].len, "vertex")) v = k;
    if (rc == HD_OK && v < 0) rc = hd__err(w->err, HD_EFORMAT, "%s: the header declares no element 'vertex'", w->in->name);
    for (size_t j = 0; rc == HD_OK && j < w->nf; j++)
        if (prop_index(&p->el[v], w->f[j].name) >= 0)
            rc = hd__err(w->err, HD_EINVAL, "%s: element vertex already has a property '%s' (line %lld's element); "
                                            "choose another name",
                         w->in->name, w->f[j].name, p->el[v].line);
    if (rc == HD_OK && p->el[v].count != w->n)
        rc = hd__err(w->err, HD_EINVAL, "%s: %zu values for %llu vertices", w->in->name, w->n,
                     (unsigned long long)p->el[v].count);
    int subset = w->keep != HD_KEEP_ALL;
    if (rc == HD_OK) {
        write_header(w, p, v, subset, hd__w_kept(w));
        rc = p->format ? write_binary(w, p, v, subset) : write_ascii(w, p, v, subset);
    }
    for (int k = 0; k < p->n_el; k++) free(p->el[k].props);
    free(p);
    return rc;
}
